"""Distributed rendering on a real Dask cluster (``render.py --workers N``: a LocalCluster of worker
processes, each with a long-lived Blender process): frames equal a single-process render pixel for
pixel, a killed worker loses nothing, a frame above c fails alone with its reason, a rerun renders
only what is missing or corrupt. Frames are tiny (32x32, 1-2 samples): the cost is the processes."""

import json
import os
import re
import signal
import subprocess
import sys
import time

import numpy as np
import psutil
import pytest

import pipeline_helpers as wh
from relativity_addon import batch
from relativity_addon.batch import farm, frame_files

TINY = ("--resolution=32x32",)


@pytest.fixture
def moving_blend(factory_blender, tmp_path):
    """Camera keyframed along -Z over frames 1-4, emissive sphere."""
    return wh.moving_camera_blend(factory_blender, tmp_path / "moving.blend", 4)


def _frame_lines(result):
    return [line for line in result.stdout.splitlines() if re.match(r"render\.py: frames? \d", line)]


def _listing(folder):
    return sorted(os.listdir(folder))


def _frames_reported(result):
    """Frames named by the per-task progress lines ("frame 3 done", "frames 1-2 done")."""
    frames = []
    for line in _frame_lines(result):
        first, last = re.match(r"render\.py: frames? (\d+)(?:-(\d+))? ", line).groups()
        frames += range(int(first), int(last or first) + 1)
    return sorted(frames)


def test_four_frames_on_two_workers_equal_one_process_and_resume(moving_blend, tmp_path, factory_blender):
    """Two tasks of two frames (--chunk 2) on two workers against one process rendering the four
    frames in turn; then a rerun after deleting one frame and corrupting another."""
    bpy = factory_blender
    common = ("--frames=1-4", "--beta=0,0,-0.5", "--samples=2", "--seed=3", *TINY)
    cluster = tmp_path / "cluster" / "f.png"
    result = wh.run_render_script(moving_blend, *common, f"--out={cluster}", "--workers=2", "--chunk=2")
    assert result.returncode == 0, result.stderr[-3000:]
    assert "local Dask cluster, 2 worker process(es)" in result.stdout
    assert _frames_reported(result) == [1, 2, 3, 4], result.stdout
    assert re.search(r"\(4/4; 0 failed\), about 0\.0 s left", _frame_lines(result)[-1]), result.stdout
    assert "4 frames: 4 rendered, 0 skipped (already complete), 0 failed" in result.stdout
    names = [f"f_{frame:04d}.png" for frame in range(1, 5)]
    assert _listing(cluster.parent) == names  # no partial files left

    single = tmp_path / "single" / "f.png"
    result = wh.run_render_script(moving_blend, *common, f"--out={single}")
    assert result.returncode == 0, result.stderr[-3000:]
    images = {}
    for name in names:
        assert frame_files.problem(cluster.parent / name) is None
        images[name] = wh.read_image(bpy, cluster.parent / name)
        np.testing.assert_array_equal(images[name], wh.read_image(bpy, single.parent / name), err_msg=name)
    assert not np.array_equal(images[names[0]], images[names[3]])  # the frames differ
    for name in names:
        assert images[name][..., 0].max() > 0.5, name  # the sphere is in view

    # The checker refuses cut and corrupted copies of a real frame.
    data = (cluster.parent / names[0]).read_bytes()
    for damaged in (data[:-1], data[: len(data) // 2], data[:500] + bytes([data[500] ^ 0xFF]) + data[501:]):
        (tmp_path / "damaged.png").write_bytes(damaged)
        assert frame_files.problem(tmp_path / "damaged.png") is not None

    # Resume: delete frame 2, corrupt frame 3 (a flipped byte); the rerun renders exactly those two.
    (cluster.parent / names[1]).unlink()
    corrupt = bytearray((cluster.parent / names[2]).read_bytes())
    corrupt[len(corrupt) // 2] ^= 0xFF
    (cluster.parent / names[2]).write_bytes(bytes(corrupt))
    kept = {name: os.stat(cluster.parent / name) for name in (names[0], names[3])}
    result = wh.run_render_script(moving_blend, *common, f"--out={cluster}", "--workers=2", "--chunk=2")
    assert result.returncode == 0, result.stderr[-3000:]
    assert "resume: 2 of 4 frames already complete, skipped" in result.stdout
    assert "4 frames: 2 rendered, 2 skipped (already complete), 0 failed" in result.stdout
    assert _frames_reported(result) == [2, 3], result.stdout
    for name, before in kept.items():
        after = os.stat(cluster.parent / name)
        assert (after.st_ino, after.st_mtime_ns) == (before.st_ino, before.st_mtime_ns), name
    for name in names[1:3]:
        np.testing.assert_array_equal(wh.read_image(bpy, cluster.parent / name), images[name], err_msg=name)
    assert _listing(cluster.parent) == names

    # The single-process script resumes too (--resume): nothing left to render, nothing touched.
    def identities():
        return {
            name: (os.stat(cluster.parent / name).st_ino, os.stat(cluster.parent / name).st_mtime_ns) for name in names
        }

    kept = identities()
    result = wh.run_render_script(moving_blend, *common, f"--out={cluster}", "--resume")
    assert result.returncode == 0, result.stderr[-3000:]
    assert "--resume: 4 of 4 frames already complete, skipped" in result.stdout
    assert "wrote 0 files" in result.stdout
    assert identities() == kept


def _rendering(blender):
    """Whether a worker's Blender process renders: Cycles' progress lines ("| Sample 1/1024") in its
    log, its standard output (4.5), or Cycles' threads (5.2 prints no progress; measured with one
    render thread: 5 threads when set up, 12 while rendering; 4.5: 6 and 7)."""
    try:
        if blender.num_threads() >= 9:
            return True
        with open(os.readlink(f"/proc/{blender.pid}/fd/1"), errors="replace") as log:
            return "| Sample " in log.read()
    except (OSError, psutil.Error):
        return False


def _lifeline_owner(blender, processes):
    """The Dask worker among ``processes`` holding the other end of ``blender``'s lifeline pipe (its
    file descriptor is on its command line, after the reply one): the worker it renders for, which
    is its parent or, for a process the coordinator started and a worker took over, not."""
    try:
        pipe = os.readlink(f"/proc/{blender.pid}/fd/{blender.cmdline()[6]}")
    except (OSError, IndexError):
        return None
    for process in processes:
        try:
            if "multiprocessing" not in " ".join(process.cmdline()):
                continue
            names = os.listdir(f"/proc/{process.pid}/fd")
        except (OSError, psutil.Error):
            continue
        for name in names:
            try:
                if os.readlink(f"/proc/{process.pid}/fd/{name}") == pipe:
                    return process
            except OSError:
                continue
    return None


def test_killed_worker_loses_no_frame(moving_blend, tmp_path, factory_blender):
    """SIGKILL to a worker process while the Blender process it renders with (started by the
    coordinator before the cluster and taken over by the worker, or started by the worker) renders
    a frame: the scheduler reruns the task on a live worker, the Blender process dies with its
    worker (no second writer), every frame ends whole, exit status 0."""
    bpy = factory_blender
    out = tmp_path / "out" / "f.png"
    # Enough samples that Cycles renders for a few seconds (on a busy machine too): the kill must
    # land while it renders.
    common = ("--frames=1-2", "--beta=0,0,-0.5", "--samples=1024", "--resolution=96x96")
    found = {}  # "orphan_dead": whether the killed worker's Blender process ended within a second

    def look(tree):
        for child in tree:
            try:
                if "PR_SET_PDEATHSIG" not in " ".join(child.cmdline()) or not _rendering(child):
                    continue
                owner = _lifeline_owner(child, tree)
            except psutil.NoSuchProcess:
                continue
            if owner is None:
                continue
            assert "distributed" in " ".join(owner.cmdline()) or "multiprocessing" in " ".join(owner.cmdline())
            owner.send_signal(signal.SIGKILL)
            # Its Blender process dies with it at once (it had about a second of rendering left),
            # so no second writer races the task's rerun.
            found["orphan_dead"], until = False, time.monotonic() + 1.0
            while not found["orphan_dead"] and time.monotonic() < until:
                try:
                    found["orphan_dead"] = child.status() == psutil.STATUS_ZOMBIE
                except psutil.NoSuchProcess:
                    found["orphan_dead"] = True
                time.sleep(0.01)
            return True
        return False

    process, stdout, stderr = wh.watch_render_script(moving_blend, (*common, f"--out={out}", "--workers=2"), look, 0.02)
    if not found:
        pytest.fail(
            f"no task process seen rendering (job exit {process.returncode}); "
            f"stdout: {stdout[-1500:]} stderr: {stderr[-1500:]}"
        )
    assert process.returncode == 0, stderr[-3000:]
    assert found["orphan_dead"], "the killed worker's Blender process kept running"
    lines = [line for line in stdout.splitlines() if re.match(r"render\.py: frame \d", line)]
    assert sorted(re.search(r"frame (\d+)", line).group(1) for line in lines) == ["1", "2"], stdout
    assert "2 frames: 2 rendered, 0 skipped (already complete), 0 failed" in stdout
    names = ["f_0001.png", "f_0002.png"]
    assert _listing(out.parent) == names  # nothing half-written left behind
    images = []
    for name in names:
        assert frame_files.problem(out.parent / name) is None  # every chunk's CRC, all pixel rows
        images.append(wh.read_image(bpy, out.parent / name))
        assert images[-1].shape == (96, 96, 4) and images[-1][..., 0].max() > 0.5  # the sphere
    assert not np.array_equal(*images)  # two different frames (pixels against one process: test above)


@pytest.fixture
def running_cluster(tmp_path):
    """``dask scheduler`` and ``dask worker --nworkers 2`` processes, as on a farm (the add-on
    importable on the workers through PYTHONPATH). Yields the scheduler's address."""
    scheduler_file = tmp_path / "scheduler.json"
    dask = [sys.executable, "-m", "dask"]
    env = wh._env()
    quiet = {"stdout": subprocess.DEVNULL, "stderr": subprocess.DEVNULL}
    scheduler = [*dask, "scheduler", "--port=0", "--no-dashboard", f"--scheduler-file={scheduler_file}"]
    started = [subprocess.Popen(scheduler, env=env, **quiet)]
    try:
        address, deadline = None, time.monotonic() + 60
        while address is None and time.monotonic() < deadline:
            try:
                address = json.loads(scheduler_file.read_text())["address"]
            except (FileNotFoundError, ValueError, KeyError):  # not yet written, or half
                time.sleep(0.1)
        assert address, "the scheduler wrote no address"
        started.append(
            subprocess.Popen(
                [*dask, "worker", address, "--nworkers=2", "--nthreads=1", "--no-dashboard"],
                env={**env, "PYTHONPATH": str(wh.REPO_ROOT)},
                **quiet,
            )
        )
        yield address
    finally:
        for process in reversed(started):
            process.terminate()
            try:
                process.wait(timeout=30)
            except subprocess.TimeoutExpired:
                process.kill()
                process.wait()


def test_frame_above_c_fails_alone_with_its_reason(factory_blender, tmp_path, running_cluster):
    """On a running cluster (--scheduler). Linear keys, c = 10 units/s at 24 fps: 0.1 units a frame
    (0.24 c) except between frames 2.5 and 3.5, 0.5 units a frame (1.2 c). Only frame 3's velocity
    (a central difference of half-width 1/64 frame) lies in the fast segment. Output .exr: the
    checker reads real EXR."""
    bpy = factory_blender
    scene, camera, _ = wh.new_scene(bpy, resolution=(32, 32))
    scene.frame_start, scene.frame_end = 1, 5
    wh.keyframe_camera_path(camera, [(1, (0, 0, 0)), (2.5, (0, 0, -0.15)), (3.5, (0, 0, -0.65)), (5, (0, 0, -0.8))])
    blend = wh.save_blend(bpy, tmp_path / "fast.blend")
    out = tmp_path / "out" / "f.exr"
    result = wh.run_render_script(
        blend,
        "--frames=2-4",
        "--velocity-from-animation",
        "--speed-of-light=10",
        "--samples=1",
        *TINY,
        f"--out={out}",
        f"--scheduler={running_cluster}",
        "--threads=1",
    )
    assert result.returncode == 1, result.stderr[-3000:]
    assert f"Dask scheduler {running_cluster}" in result.stdout
    errors = wh.error_lines(result)
    assert len(errors) == 1, result.stderr[-3000:]
    assert errors[0].startswith("render.py: error: frame 3: Camera 'Camera' moves at 1.2 c at frame 3"), errors
    assert "given up" not in errors[0]  # its own failure: not retried as a lost worker
    assert "Traceback" not in result.stderr + result.stdout
    assert "3 frames: 2 rendered, 0 skipped (already complete), 1 failed" in result.stdout
    assert _listing(out.parent) == ["f_0002.exr", "f_0004.exr"]
    for name in ("f_0002.exr", "f_0004.exr"):
        assert frame_files.problem(out.parent / name) is None
        assert np.isfinite(wh.read_image(bpy, out.parent / name)).all()
    data = (out.parent / "f_0002.exr").read_bytes()
    (tmp_path / "cut.exr").write_bytes(data[:-1])
    assert "cut short" in frame_files.problem(tmp_path / "cut.exr")


def test_task_options_chunks_and_output_names():
    """Every option a task repeats survives the round trip through its command line; frames are
    cut into runs of consecutive frames; names are those of a single-process --frames render."""
    parser = batch.build_parser(with_blend_file=True)
    argv = [
        "x.blend",
        "--out=o/f.png",
        "--frames=1-9",
        "--workers=3",
        "--chunk=2",
        "--beta=-0.1,0.25,0.5",
        "--method=geometry",
        "--samples=7",
        "--resolution=40x30",
        "--no-doppler",
        "--shutter=detector_plane",
        "--shutter-time=0.5",
        "--speed-of-light=3",
        "--seed=4",
        "--lorentz-window",
        "--spectral=2",
    ]
    options = parser.parse_args(argv)
    again = parser.parse_args(["x.blend", "--out=o/f.png", *farm.task_options(parser, options)])
    for key, value in vars(options).items():
        if key not in farm.COORDINATOR_OPTIONS:
            assert getattr(again, key) == value, key
    assert not any(
        text.startswith(("--workers", "--chunk", "--frames", "--out")) for text in farm.task_options(parser, options)
    )
    assert farm.chunks([1, 2, 3, 4, 5, 7, 8], 2) == [[1, 2], [3, 4], [5], [7, 8]]
    assert farm.chunks([1, 2, 3], 1) == [[1], [2], [3]]
    pattern = farm.output_pattern("/a/shot.png", several=True)
    for frame in (7, -3):
        assert batch.frame_output_path(pattern, frame, False) == batch.frame_output_path("/a/shot.png", frame, True)
    assert farm.output_pattern("/a/s_###.exr", several=True) == "/a/s_###.exr"
    assert farm.output_pattern("/a/s.exr", several=False) == "/a/s.exr"


def test_single_process_path_imports_no_dask():
    code = (
        "import sys; from relativity_addon import batch; from relativity_addon.batch import farm; "
        "batch.parse(['render.py', 'x.blend', '--out=x.png', '--workers=2']); "
        "found = sorted(m for m in sys.modules if m.split('.')[0] in ('dask', 'distributed', 'bpy')); "
        "print(found); sys.exit(bool(found))"
    )
    result = wh.run_python(code)
    assert result.returncode == 0, result.stderr
