"""A farm worker's long-lived Blender process (``render.py --workers N``; docs/farm.md): each worker
loads the file once into one Blender process and renders every frame it is given there; a killed
Blender process is replaced and its frame rendered again; frames rendered by one process in any
order equal a single-process render pixel for pixel. Behaviour, read from the progress lines and
the processes, not from times."""

import json
import os
import re
import signal
import subprocess
import sys
import threading

import numpy as np
import psutil
import pytest

import pipeline_helpers as wh
from relativity_addon.batch import blender_pool, frame_files, frame_server

DONE = re.compile(r"render\.py: frame (\d+) done in [\d.]+ s \(task [\d.]+ s\) on (\S+), Blender pid (\d+) ")


@pytest.fixture
def moving_blend(factory_blender, tmp_path):
    """Camera keyframed along -Z over frames 1-8, emissive sphere."""
    return wh.moving_camera_blend(factory_blender, tmp_path / "moving.blend", 8)


def _done(stdout):
    """(frame, worker, Blender pid) of each progress line of a rendered frame."""
    return [(int(frame), worker, int(pid)) for frame, worker, pid in DONE.findall(stdout)]


def test_each_worker_renders_in_one_blender_process_loaded_while_the_cluster_starts(moving_blend, tmp_path):
    """Six one-frame tasks on two workers (one job, its process tree watched as it runs; these were
    two tests running the same job):

    - every frame names the Blender process that rendered it; a worker's frames all come from one
      process, so at most two processes render six frames;
    - the coordinator starts one Blender process per worker before it starts Dask, and each worker
      takes one over as it starts, so loading Blender, the file and the effect overlaps the
      cluster's start instead of following it: the processes that render were created before any
      of Dask's processes (forkserver, workers) and are the coordinator's children; one per worker,
      and no other Blender process is started."""
    out = tmp_path / "out" / "f.png"
    options = ("--frames=1-6", "--beta=0,0,-0.5", "--samples=2", "--resolution=32x32", f"--out={out}", "--workers=2")
    seen = {}  # pid -> (created, parent pid, command line)

    def look(tree):
        # The command line read again each time (a child not yet exec'd shows its parent's),
        # but not from an ended process waiting to be reaped (it shows none).
        for child in tree:
            try:
                line = " ".join(child.cmdline())
                if line or child.pid not in seen:
                    seen[child.pid] = (child.create_time(), child.ppid(), line)
            except psutil.Error:
                continue
        return False

    process, stdout, stderr = wh.watch_render_script(moving_blend, options, look)
    assert process.returncode == 0, stderr[-3000:]
    done = _done(stdout)
    assert sorted(frame for frame, _, _ in done) == [1, 2, 3, 4, 5, 6], stdout
    processes = {}
    for _, worker, pid in done:
        processes.setdefault(worker, set()).add(pid)
    assert all(len(pids) == 1 for pids in processes.values()), processes  # one Blender per worker
    assert len({pid for _, _, pid in done}) <= 2 < len(done), done  # reused across frames
    assert "6 frames: 6 rendered, 0 skipped (already complete), 0 failed" in stdout
    assert sorted(os.listdir(out.parent)) == [f"f_{frame:04d}.png" for frame in range(1, 7)]
    pids = {pid for _, _, pid in done}
    assert not any(psutil.pid_exists(pid) and psutil.Process(pid).status() != psutil.STATUS_ZOMBIE for pid in pids)

    rendering = {pid for _, _, pid in done}
    launched = {pid for pid, (_, _, line) in seen.items() if "PR_SET_PDEATHSIG" in line}
    blenders = {pid for pid in launched if seen[pid][1] not in launched}  # not a Blender's own child
    dask = [created for created, _, line in seen.values() if "multiprocessing" in line]
    found = f"rendering {rendering}; seen {seen}; stdout {stdout}"
    # Two, or one when a worker rendered all six tiny frames before the other's Blender was ready.
    assert 1 <= len(rendering) <= 2 and rendering <= blenders, found
    assert len(blenders) == 2 and dask, found  # none started besides the two taken over
    assert all(seen[pid][1] == process.pid for pid in blenders), found
    assert max(seen[pid][0] for pid in blenders) < min(dask), found


def test_killed_blender_process_is_restarted_and_its_frame_rendered_again(moving_blend, tmp_path, factory_blender):
    """SIGKILL to a worker's Blender process as soon as it has rendered its first frame (it is then
    rendering its next one): the worker starts a new Blender process, which renders that frame;
    every frame ends whole, once, exit status 0."""
    bpy = factory_blender
    out = tmp_path / "out" / "f.png"
    # Frames of about a second or more (one Cycles thread), so the kill lands in a render.
    options = ("--frames=1-6", "--beta=0,0,-0.5", "--samples=256", "--resolution=64x64", "--seed=2")
    command = [sys.executable, str(wh.RENDER_SCRIPT), str(moving_blend), *options, f"--out={out}", "--workers=2"]
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=wh._env())
    lines, killed = [], None
    try:
        for line in process.stdout:
            lines.append(line)
            match = DONE.match(line)
            if killed is None and match:
                killed = int(match.group(3))
                os.kill(killed, signal.SIGKILL)
        stderr = process.stderr.read()
        process.wait(timeout=240)
    finally:
        if process.poll() is None:
            process.kill()
            process.wait()
    stdout = "".join(lines)
    assert process.returncode == 0, stderr[-3000:]
    assert killed is not None, stdout
    again = re.findall(
        rf"Blender process {killed} ended \(killed by signal 9\)[^\n]*; frame (\d+) rendered again", stdout
    )
    assert len(again) == 1, stdout
    done = _done(stdout)
    assert sorted(frame for frame, _, _ in done) == [1, 2, 3, 4, 5, 6], stdout  # each frame once
    lost_worker = next(worker for _, worker, pid in done if pid == killed)
    worker, pid = next((worker, pid) for frame, worker, pid in done if frame == int(again[0]))
    assert worker == lost_worker and pid != killed  # a new process on the same worker rendered it
    assert "6 frames: 6 rendered, 0 skipped (already complete), 0 failed" in stdout
    names = [f"f_{frame:04d}.png" for frame in range(1, 7)]
    assert sorted(os.listdir(out.parent)) == names  # nothing half-written left behind
    for name in names:
        assert frame_files.problem(out.parent / name) is None
        assert wh.read_image(bpy, out.parent / name)[..., 0].max() > 0.5, name  # the sphere


@pytest.mark.parametrize("method", ["camera", "geometry"])
def test_frames_in_any_order_in_one_process_equal_one_process_in_turn(method, moving_blend, tmp_path, factory_blender):
    """One long-lived Blender process (the worker side's pool, without Dask), set up at frame 3 as
    it starts, renders frames 4, 1, 3 and 2, in that order; the batch script renders 1-4 in turn in
    one process: equal pixel for pixel, all four from the same process."""
    bpy = factory_blender
    common = ["--beta=0,0,-0.5", "--samples=2", "--seed=3", "--resolution=32x32", f"--method={method}"]
    pool = blender_pool.BlenderPool([str(moving_blend), f"--out={tmp_path / 'pool' / 'f_####.png'}", *common], 3)
    try:
        results = pool.render([4, 1, 3, 2])
    finally:
        pool.close()
    assert [r["reason"] for r in results] == [None] * 4, results
    assert len({r["pid"] for r in results}) == 1 and not any(r["lost"] for r in results), results
    single = tmp_path / "single" / "f.png"
    result = wh.run_render_script(moving_blend, "--frames=1-4", *common, f"--out={single}")
    assert result.returncode == 0, result.stderr[-3000:]
    images = []
    for frame in range(1, 5):
        name = f"f_{frame:04d}.png"
        images.append(wh.read_image(bpy, tmp_path / "pool" / name))
        np.testing.assert_array_equal(images[-1], wh.read_image(bpy, single.parent / name), err_msg=name)
        assert images[-1][..., 0].max() > 0.5, name
    assert not np.array_equal(images[0], images[3])


def test_blender_process_is_set_up_before_its_first_frame_is_asked_for(factory_blender, tmp_path):
    """A worker's Blender process applies the effect as it starts, at the job's first frame, so the
    first task does not wait for it: ready, with the effect applied at frame 2, before any frame is
    asked for. Where the camera is at 1.2 c at that frame (frame 3 of this camera path, as in
    test_distributed.py), the process is ready all the same with nothing applied; frame 3 fails
    alone with its reason and frame 2 renders in the same process."""
    bpy = factory_blender
    scene, camera, _ = wh.new_scene(bpy, resolution=(32, 32))
    scene.frame_start, scene.frame_end = 1, 5
    wh.keyframe_camera_path(camera, [(1, (0, 0, 0)), (2.5, (0, 0, -0.15)), (3.5, (0, 0, -0.65)), (5, (0, 0, -0.8))])
    blend = wh.save_blend(bpy, tmp_path / "fast.blend")
    common = [str(blend), f"--out={tmp_path / 'f_####.png'}", "--velocity-from-animation", "--speed-of-light=10"]
    applied = {}
    for setup_frame in (2, 3):
        pool = blender_pool.BlenderPool([*common, "--samples=1", "--resolution=32x32"], setup_frame)
        try:
            pool.prestart()
            process = pool._idle[0]
            assert process.setup_failure() is None
            applied[setup_frame] = process.setup["applied_at"]
            if setup_frame == 3:
                results = pool.render([3, 2])
        finally:
            pool.close()
    assert applied == {2: 2, 3: None}
    assert results[0]["reason"].startswith("Camera 'Camera' moves at 1.2 c at frame 3"), results
    assert results[1]["reason"] is None and results[0]["pid"] == results[1]["pid"], results
    assert sorted(os.listdir(tmp_path)) == ["f_0002.png", "fast.blend"]
    assert frame_files.problem(tmp_path / "f_0002.png") is None


def _threads(pid):
    """Thread id -> (state, CPU seconds) of each thread of process ``pid`` now (/proc)."""
    ticks = os.sysconf("SC_CLK_TCK")
    found = {}
    for thread in os.listdir(f"/proc/{pid}/task"):
        try:
            with open(f"/proc/{pid}/task/{thread}/stat", encoding="ascii") as stat:
                fields = stat.read().rsplit(")", 1)[1].split()
        except OSError:
            continue  # ended meanwhile
        found[int(thread)] = (fields[0], (int(fields[11]) + int(fields[12])) / ticks)
    return found


@pytest.mark.skipif(
    not hasattr(os, "sched_getaffinity") or len(os.sched_getaffinity(0)) < 2, reason="needs two CPUs and Linux"
)
def test_blender_process_of_one_thread_spins_no_other_thread(moving_blend, tmp_path):
    """A worker's Blender process rendering with one Cycles thread (``--threads=1``, what
    ``--workers`` gives each process on a machine of as many cores) renders its frame with that one
    thread: no thread of the process that lived before the frame (Blender's thread pool, OpenEXR's,
    numpy's), the main thread aside (it syncs the scene and writes the file), wants a CPU through
    the frame. On Blender 4.5 without ``blender_pool.start_cpus``, TBB's second thread spun in
    ``sched_yield`` through every frame: runnable (state R) in every sample, and from 0.05 s of CPU
    per frame on a busy machine to the whole frame's, 4.7 s, on an idle one. Read from /proc: the
    threads' states every 20 ms while the frame renders (runnable whether or not the machine's
    load lets it run), and their CPU counters."""
    options = ["--beta=0,0,-0.5", "--samples=512", "--resolution=64x64", "--seed=2", "--threads=1"]
    pool = blender_pool.BlenderPool([str(moving_blend), f"--out={tmp_path / 'f_####.png'}", *options], 1)
    samples, rendering = [], threading.Event()

    def watch(pid):
        while not rendering.is_set():
            samples.append(_threads(pid))
            rendering.wait(0.02)

    try:
        pool.prestart()
        process = pool._idle[0]
        assert process.setup_failure() is None
        assert pool.render([1])[0]["reason"] is None  # the first render: the camera's compile, caches
        before = _threads(process.pid)
        watcher = threading.Thread(target=watch, args=(process.pid,))
        watcher.start()
        try:
            result = pool.render([2])[0]
        finally:
            rendering.set()
            watcher.join()
        after = _threads(process.pid)
    finally:
        pool.close()
    assert result["reason"] is None and result["pid"] == process.pid, result
    lived = set(before) - {process.pid}
    runnable = [sum(1 for sample in samples if sample.get(thread, ("S",))[0] == "R") for thread in sorted(lived)]
    cpu = [round(after[thread][1] - before[thread][1], 2) for thread in sorted(lived) if thread in after]
    found = f"runnable in {runnable} of {len(samples)} samples; CPU {cpu} s; frame {result['seconds']:.2f} s"
    assert len(samples) >= 10, found
    assert max(runnable, default=0) < len(samples) / 2, found
    assert sum(cpu) < 0.05, found


def test_frame_server_reads_every_request_of_one_write_and_ends_when_idle(monkeypatch):
    """Requests that arrive together are all served (none left waiting in a read buffer until
    the idle limit), a stop request ends the loop, and so does a silent, open stdin."""
    monkeypatch.setattr(frame_server, "IDLE_SECONDS", 0.5)
    read_fd, write_fd = os.pipe()
    try:
        os.write(write_fd, b'{"frame": 1}\n{"frame": 2}\n{"stop": true}\n{"frame": 3}\n')
        assert [request["frame"] for request in frame_server._requests(read_fd)] == [1, 2]
        os.write(write_fd, b'{"frame": 4}\n')
        assert [request["frame"] for request in frame_server._requests(read_fd)] == [4]  # then idle: ends
    finally:
        os.close(read_fd)
        os.close(write_fd)


CLUSTER_TIMERS = """
import argparse, json, sys
sys.path.insert(0, sys.argv[1])
from relativity_addon.batch import farm

def timers(server):
    return {name: callback.callback_time for name, callback in server.periodic_callbacks.items()}

options = argparse.Namespace(scheduler=None, workers=2, retries=2)
client, cluster = farm._connect(options, lambda *a, **k: None, [sys.argv[2], "--out=" + sys.argv[3]], "job")
try:
    found = {
        "scheduler": client.run_on_scheduler(lambda dask_scheduler: timers(dask_scheduler)),
        "saturation": client.run_on_scheduler(lambda dask_scheduler: dask_scheduler.WORKER_SATURATION),
        "nannies": [timers(nanny) for nanny in cluster.workers.values()],
        "workers": list(client.run(lambda dask_worker: timers(dask_worker)).values()),
    }
finally:
    client.close()
    cluster.close()
print(json.dumps(found))
"""


def test_local_cluster_leaves_the_cores_to_blender(tmp_path):
    """The scheduler, nannies and workers of ``--workers`` run without Dask's fast monitors, which
    on a few cores take CPU from the renders: no timer in any of them fires more often than every
    250 ms (Dask's own defaults: event-loop checks every 20 ms, memory checks every 100 ms), no
    memory monitor or profiler at all; and the scheduler gives a single-threaded worker one task
    at a time, so the last frames go to whichever worker is free first. Read from the servers of a
    real local cluster."""
    result = wh.run_python(CLUSTER_TIMERS, wh.REPO_ROOT, tmp_path / "absent.blend", tmp_path / "f.png")
    assert result.returncode == 0, result.stderr[-3000:]
    found = json.loads(result.stdout.strip().splitlines()[-1])
    assert len(found["nannies"]) == len(found["workers"]) == 2, found
    servers = [found["scheduler"], *found["nannies"], *found["workers"]]
    fastest = {name: ms for server in servers for name, ms in server.items() if ms < 250}
    assert not fastest, fastest
    assert not any({"memory_monitor", "profile", "profile-cycle"} & set(server) for server in servers), servers
    assert found["saturation"] == 1.0
