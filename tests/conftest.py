"""Shared fixtures for tests that run Blender through the ``bpy`` wheel.

Blender keeps per-user state (preferences, the ``user_default`` extensions repository) under its
user resource folder. Each test process points ``BLENDER_USER_RESOURCES`` at a fresh temporary
folder before anything imports ``bpy``, so tests never read or write the developer's own
``~/.config/blender`` and parallel workers (pytest-xdist) never share an extensions repository.

``bpy`` itself is imported lazily inside the fixtures, so the physics tests pay nothing for it.

Fixtures:

``extension_zip``
    (session) the extension built from the working tree by ``tools/build_extension.py`` into a
    temporary folder, validated by Blender's own tooling.
``factory_blender``
    Blender reset to empty factory settings; anything the add-on left registered (classes,
    handlers) is removed before and after the test.
``relativity_addon``
    ``factory_blender`` plus the add-on enabled the way Blender does it: the built zip is installed
    into the ``user_default`` extensions repository (once per process) and enabled as
    ``bl_ext.user_default.relativity_addon`` with ``addon_utils.enable``. Yields that module name.
"""

import atexit
import os
import shutil
import sys
import tempfile
from pathlib import Path

import pytest
from hypothesis import HealthCheck, settings

REPO_ROOT = Path(__file__).resolve().parent.parent

# Shared CI machines stall now and then: a strategy's draw took 1.1 s under load and Hypothesis
# failed the test for slow input generation, not for a wrong result. Time is not what these
# property tests check (benchmarks do), so neither the health check nor a deadline applies.
settings.register_profile("relativity", suppress_health_check=[HealthCheck.too_slow], deadline=None)
settings.load_profile("relativity")
# The package (for the bpy-free physics tests), the build script and ``blender_support``
# (helpers to enable/disable the add-on), importable from any test.
sys.path[:0] = [str(REPO_ROOT), str(REPO_ROOT / "tools"), str(REPO_ROOT / "tests")]
# Each subsystem's test helpers (camera_helpers, colour_helpers, ...), whichever folder a test is in.
sys.path[3:3] = sorted(str(folder) for folder in (REPO_ROOT / "tests" / "blender").iterdir() if folder.is_dir())

_USER_RESOURCES = tempfile.mkdtemp(prefix="relativity-blender-user-")
atexit.register(shutil.rmtree, _USER_RESOURCES, ignore_errors=True)
os.environ["BLENDER_USER_RESOURCES"] = _USER_RESOURCES

from blender_support import (  # noqa: E402  (after BLENDER_USER_RESOURCES is set)
    ADDON_MODULE,
    disable_addon,
    enable_addon,
    install_extension_zip,
    remove_addon_leftovers,
)


@pytest.fixture(scope="session")
def extension_zip(tmp_path_factory):
    import build_extension

    zip_path, output = build_extension.build(tmp_path_factory.mktemp("extension"))
    assert zip_path is not None, f"extension build failed:\n{output}"
    return zip_path


@pytest.fixture
def factory_blender():
    import bpy

    remove_addon_leftovers()
    bpy.ops.wm.read_factory_settings(use_empty=True)
    yield bpy
    remove_addon_leftovers()


_installed = set()


@pytest.fixture
def relativity_addon(extension_zip, factory_blender):
    import addon_utils

    if extension_zip not in _installed:
        install_extension_zip(extension_zip)
        _installed.add(extension_zip)
    enable_addon()
    yield ADDON_MODULE
    if addon_utils.check(ADDON_MODULE)[1]:
        disable_addon()
