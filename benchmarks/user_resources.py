"""Imported by every benchmark before ``bpy``: Blender's user resources in a fresh temporary
folder (unless ``BLENDER_USER_RESOURCES`` is set), so that a benchmark measures this checkout's
add-on and not an extension installed for the user, which ``batch.enable_addon`` would prefer
and ``read_factory_settings`` would drop (as the tests do, tests/conftest.py). Processes the
benchmark starts inherit it."""

import atexit
import os
import shutil
import tempfile

if "BLENDER_USER_RESOURCES" not in os.environ:
    FOLDER = tempfile.mkdtemp(prefix="relativity-benchmark-user-")
    os.environ["BLENDER_USER_RESOURCES"] = FOLDER
    atexit.register(shutil.rmtree, FOLDER, ignore_errors=True)
