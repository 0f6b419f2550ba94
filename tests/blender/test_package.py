"""The extension builds and validates with Blender's own extension tooling (bl_pkg)."""

import zipfile

import build_extension

REQUIRED_IN_ZIP = {"blender_manifest.toml", "__init__.py", "blender/__init__.py", "physics/__init__.py"}


def test_manifest_and_package_validate():
    ok, output = build_extension.validate()
    assert ok, output


def test_build_zip_layout(extension_zip):
    assert extension_zip.name == "relativity_addon-0.1.0.zip"
    with zipfile.ZipFile(extension_zip) as zf:
        names = set(zf.namelist())
    assert REQUIRED_IN_ZIP <= names
    assert not [n for n in names if "__pycache__" in n or n.endswith(".pyc")]


def _broken_manifest(tmp_path, replace, by):
    text = build_extension.MANIFEST_PATH.read_text()
    assert replace in text
    path = tmp_path / "blender_manifest.toml"
    path.write_text(text.replace(replace, by))
    return path


def test_validator_rejects_bad_blender_version(tmp_path):
    broken = _broken_manifest(tmp_path, 'blender_version_min = "4.5.0"', 'blender_version_min = "four"')
    ok, output = build_extension.validate(broken)
    assert not ok
    assert "blender_version_min" in output


def test_validator_rejects_unknown_permission(tmp_path):
    broken = _broken_manifest(tmp_path, "[permissions]\n", '[permissions]\nteleport = "Beam the camera"\n')
    ok, output = build_extension.validate(broken)
    assert not ok
    assert "teleport" in output


def test_build_rejects_unknown_tag(tmp_path):
    broken = _broken_manifest(tmp_path, 'tags = ["Render"', 'tags = ["Warp Drive", "Render"')
    zip_path, output = build_extension.build(tmp_path / "out", broken)
    assert zip_path is None
    assert "Warp Drive" in output
