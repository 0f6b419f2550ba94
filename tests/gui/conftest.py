"""The real-application stage: Debian's Blender (a build without OSL) in a window under Xvfb.

``gui_session`` (once per test session) gets the Debian sid root with Blender from
``tools/blender_root.sh`` (built and cached under ``~/.cache/relativity-addon/`` on the first run),
builds the extension zip as the other tests do, installs it with Blender's own
``blender --command extension install-file -e``, turns the splash screen off in the preferences,
and runs ``gui_driver.py`` in Blender under Xvfb. The root is entered with ``unshare`` and
``chroot`` in a private mount namespace (``/proc``, ``/dev`` and ``/sys`` bound in only for that
process), so nothing stays mounted and parallel runs do not meet.

The last run's screenshots, ``report.json`` and Blender's log are copied to ``out/gui/``.
The tests skip only when told: ``RELATIVITY_SKIP_GUI=1``. Anything else that keeps the stage from
running (no root, no registry, Blender not starting) fails them. ``RELATIVITY_BLENDER_ROOT``
names a root to use instead of the cached one.
"""

import json
import os
import shutil
import subprocess
import sys
import uuid
from pathlib import Path

import pytest

HERE = Path(__file__).resolve().parent
REPO_ROOT = HERE.parent.parent
SCREEN = "1600x1400x24"
TIMEOUT = 900


def _skip_requested():
    return os.environ.get("RELATIVITY_SKIP_GUI", "") not in ("", "0")


def blender_root():
    """The sid root's path, from RELATIVITY_BLENDER_ROOT or built (or reused) by tools/blender_root.sh."""
    given = os.environ.get("RELATIVITY_BLENDER_ROOT")
    if given:
        return Path(given)
    result = subprocess.run(
        ["bash", str(REPO_ROOT / "tools" / "blender_root.sh")], capture_output=True, text=True, timeout=3600
    )
    assert result.returncode == 0, f"tools/blender_root.sh failed:\n{result.stderr[-3000:]}"
    return Path(result.stdout.strip().splitlines()[-1])


def in_root(root, script, timeout=TIMEOUT):
    """Run the shell ``script`` as root inside ``root`` (its own mount namespace)."""
    mounts = f"mount -t proc proc '{root}/proc' && mount --rbind /dev '{root}/dev' && mount --rbind /sys '{root}/sys'"
    command = [
        "unshare",
        "--mount",
        "--propagation",
        "private",
        "--",
        "sh",
        "-c",
        f'{mounts} && exec chroot "$0" sh -ec "$1"',
        str(root),
        script,
    ]
    if os.geteuid() != 0:
        command.insert(0, "sudo")
    clean = {"PATH": "/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin"}  # nothing of the host's
    return subprocess.run(command, capture_output=True, text=True, timeout=timeout, env=clean)


class GuiSession:
    def __init__(self, root, work, result):
        self.root, self.work = root, work
        self.out = work / "out"
        self.stdout, self.stderr = result.stdout, result.stderr
        self.returncode = result.returncode
        path = self.out / "report.json"
        self.report = json.loads(path.read_text()) if path.is_file() else {}

    def log(self):
        return self.stdout + self.stderr

    def describe(self):
        return f"exit {self.returncode}; report: {json.dumps(self.report)[:3000]}\nlog tail:\n{self.log()[-4000:]}"


@pytest.fixture(scope="session")
def debian_root():
    """The Debian sid root with Blender (and node); skipped only when told."""
    if _skip_requested():
        pytest.skip("RELATIVITY_SKIP_GUI is set: the real-application stage was told not to run")
    return blender_root()


@pytest.fixture
def root_work(debian_root):
    """(path on the host, the same path inside the root, run) of a fresh folder in the root's /tmp,
    removed after; ``run(script)`` runs a shell script in the root (:func:`in_root`)."""
    name = f"relativity-test-{uuid.uuid4().hex[:8]}"
    work = debian_root / "tmp" / name
    work.mkdir(parents=True)
    yield work, f"/tmp/{name}", lambda script: in_root(debian_root, script)
    shutil.rmtree(work, ignore_errors=True)


@pytest.fixture(scope="session")
def gui_session(tmp_path_factory, debian_root):
    sys.path.insert(0, str(REPO_ROOT / "tools"))
    import build_extension

    zip_path, output = build_extension.build(tmp_path_factory.mktemp("gui-extension"))
    assert zip_path is not None, f"extension build failed:\n{output}"
    root = debian_root
    name = f"relativity-gui-{uuid.uuid4().hex[:8]}"
    work = root / "tmp" / name
    (work / "out").mkdir(parents=True)
    inside = f"/tmp/{name}"
    shutil.copy(zip_path, work / zip_path.name)
    for script in ("gui_driver.py", "gui_scene.py"):
        shutil.copy(HERE / script, work / script)
    script = f"""
export HOME={inside}/home TMPDIR={inside}/tmp LANG=C.UTF-8
mkdir -p $HOME $TMPDIR
cd {inside}
blender --version | head -n 1
blender --command extension install-file -r user_default -e {inside}/{zip_path.name}
blender -b --python-expr "import bpy; bpy.context.preferences.view.show_splash = False; bpy.ops.wm.save_userpref()"
xvfb-run -a -s '-screen 0 {SCREEN}' blender --python {inside}/gui_driver.py -- {inside}/out
"""
    result = in_root(root, script)
    session = GuiSession(root, work, result)
    (work / "out" / "blender.log").write_text(session.log())
    kept = REPO_ROOT / "out" / "gui"  # the last run's screenshots, report and log, for people to look at
    shutil.rmtree(kept, ignore_errors=True)
    shutil.copytree(work / "out", kept)
    print(f"real-application stage: screenshots, report and log in {kept}")
    yield session
    shutil.rmtree(work, ignore_errors=True)
