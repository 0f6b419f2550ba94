"""Build and validate the Relativity extension zip with Blender's own extension tooling.

The manifest lives at the repository top level but the add-on package is ``relativity_addon/``,
so the package is staged in a temporary directory (package contents, the manifest, and the
top-level ``presets/`` folder if there is one, copied to ``presets/`` inside the package), and then
``bl_pkg/cli/blender_ext.py`` from the ``bpy`` wheel is run on it: the same code behind
``blender --command extension build`` and ``... validate``, including its tag list.

Usage::

    python tools/build_extension.py                 # -> build/relativity_addon-<version>.zip
    python tools/build_extension.py --output-dir DIR
    python tools/build_extension.py --validate-only [--manifest PATH]

Exits non-zero when the build or the validation fails.
"""

import argparse
import importlib.util
import os
import shutil
import subprocess
import sys
import tempfile
import tomllib
from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parent.parent
PACKAGE_DIR = REPO_ROOT / "relativity_addon"
MANIFEST_PATH = REPO_ROOT / "blender_manifest.toml"
PRESETS_DIR = REPO_ROOT / "presets"
DEFAULT_OUTPUT_DIR = REPO_ROOT / "build"


def bpy_scripts_dir():
    """The ``<version>/scripts`` folder of the installed ``bpy`` wheel, found without importing bpy."""
    spec = importlib.util.find_spec("bpy")
    if spec is None or not spec.submodule_search_locations:
        raise SystemExit("bpy is not installed in this Python; run ./dev.sh first")
    bpy_dir = Path(next(iter(spec.submodule_search_locations)))
    candidates = sorted(bpy_dir.glob("[0-9]*.[0-9]*/scripts"))
    if not candidates:
        raise SystemExit(f"no <version>/scripts folder in {bpy_dir}")
    return candidates[-1]


def blender_ext_cli():
    """Path of Blender's extension command line tool (stdlib only, runs with any Python 3.11)."""
    return bpy_scripts_dir() / "addons_core" / "bl_pkg" / "cli" / "blender_ext.py"


def blender_valid_tags():
    """The tag list Blender enforces by default in ``blender --command extension build``."""
    return bpy_scripts_dir() / "modules" / "_bpy_internal" / "extensions" / "tags.py"


def run_blender_ext(*args):
    """Run ``blender_ext.py`` with the given sub-command; return (exit code, combined output)."""
    command = [sys.executable, str(blender_ext_cli()), *args, "--valid-tags", str(blender_valid_tags())]
    result = subprocess.run(command, capture_output=True, text=True)
    return result.returncode, result.stdout + result.stderr


def stage_package(stage_dir, manifest_path=MANIFEST_PATH):
    """Copy the package, the manifest and shipped presets into ``stage_dir/relativity_addon``."""
    target = Path(stage_dir) / PACKAGE_DIR.name
    shutil.copytree(PACKAGE_DIR, target, ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
    shutil.copy2(manifest_path, target / "blender_manifest.toml")
    if PRESETS_DIR.is_dir():
        if (target / "presets").exists():
            raise SystemExit("both presets/ and relativity_addon/presets/ exist; keep one")
        shutil.copytree(PRESETS_DIR, target / "presets")
    return target


def manifest_version(manifest_path=MANIFEST_PATH):
    with open(manifest_path, "rb") as fh:
        return tomllib.load(fh)["version"]


def validate(manifest_path=MANIFEST_PATH):
    """Validate the staged package directory; return (ok, output)."""
    with tempfile.TemporaryDirectory(prefix="relativity-stage-") as stage_dir:
        staged = stage_package(stage_dir, manifest_path)
        code, output = run_blender_ext("validate", str(staged))
    return code == 0, output


def build(output_dir=DEFAULT_OUTPUT_DIR, manifest_path=MANIFEST_PATH):
    """Build the extension zip into ``output_dir`` and validate the zip itself.

    Returns (zip path or None, output).
    """
    output_dir = Path(output_dir)
    output_dir.mkdir(parents=True, exist_ok=True)
    zip_path = output_dir / f"relativity_addon-{manifest_version(manifest_path)}.zip"
    zip_path.unlink(missing_ok=True)
    with tempfile.TemporaryDirectory(prefix="relativity-stage-") as stage_dir:
        staged = stage_package(stage_dir, manifest_path)
        code, output = run_blender_ext(
            "build",
            "--source-dir",
            str(staged),
            "--output-filepath",
            str(zip_path),
        )
    if code != 0 or not zip_path.is_file():
        return None, output
    code, validate_output = run_blender_ext("validate", str(zip_path))
    output += validate_output
    if code != 0:
        return None, output
    return zip_path, output


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--output-dir", default=str(DEFAULT_OUTPUT_DIR))
    parser.add_argument("--manifest", default=str(MANIFEST_PATH))
    parser.add_argument("--validate-only", action="store_true")
    args = parser.parse_args(argv)

    if args.validate_only:
        ok, output = validate(Path(args.manifest))
        sys.stdout.write(output)
        return 0 if ok else 1

    zip_path, output = build(args.output_dir, Path(args.manifest))
    sys.stdout.write(output)
    if zip_path is None:
        print("build failed", file=sys.stderr)
        return 1
    print(f"wrote {os.path.relpath(zip_path)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
