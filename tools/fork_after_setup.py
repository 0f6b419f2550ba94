"""Can one Blender start serve two farm workers? Set a farm worker's Blender process up once (import
``bpy``, open the file, apply the effect: ``frame_server._Frames``), then ``fork`` two children that
each render two frames, the way a shared start would; print the threads the set-up process had
when it forked and whether each child finished.

    python tools/fork_after_setup.py SCENE.blend OUT_FOLDER [--ext png|exr] [--samples 4]

Measured (docs/farm.md, "Throughput"): ``import bpy`` alone starts native threads (a TBB worker,
OpenEXR's pool, OpenBLAS's); a child has only the thread that forked. PNG frames come out, but an
EXR output never does: the child waits for OpenEXR's pool threads, which it does not have.
"""

import argparse
import os
import sys
import time

REPO_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def _threads() -> int:
    return len(os.listdir("/proc/self/task"))


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("blend")
    parser.add_argument("out")
    parser.add_argument("--ext", choices=("png", "exr"), default="png")
    parser.add_argument("--samples", type=int, default=4)
    parser.add_argument("--timeout", type=float, default=60.0, help="seconds a child may take")
    options = parser.parse_args()
    sys.path.insert(0, REPO_ROOT)
    started = time.monotonic()
    import bpy  # noqa: F401

    from relativity_addon.batch import frame_server

    print(f"import bpy: {time.monotonic() - started:.2f} s, {_threads()} threads", flush=True)
    argv = ["render.py", options.blend, f"--out={os.path.join(options.out, 'f_####.' + options.ext)}"]
    argv += ["--resolution=160x120", f"--samples={options.samples}", "--beta=0,0.48,-0.13", "--threads=1"]
    frames = frame_server._Frames(argv)
    frames.set_up_at(1)
    print(f"set up: {_threads()} threads when forking", flush=True)
    children = []
    for own in ([1, 3], [2, 4]):
        pid = os.fork()
        if pid == 0:
            for frame in own:
                at = time.monotonic()
                reason, _ = frames.render(frame)
                print(
                    f"child {os.getpid()}: frame {frame} {reason or 'done'} in {time.monotonic() - at:.2f} s",
                    flush=True,
                )
            os._exit(0)
        children.append(pid)
    until, hung = time.monotonic() + options.timeout, 0
    for pid in children:
        while os.waitpid(pid, os.WNOHANG) == (0, 0):
            if time.monotonic() > until:
                print(f"child {pid}: still running after {options.timeout:.0f} s: killed", flush=True)
                os.kill(pid, 9)
                os.waitpid(pid, 0)
                hung += 1
                break
            time.sleep(0.1)
    print(f"{len(children) - hung} of {len(children)} children finished; written: {sorted(os.listdir(options.out))}")
    sys.stdout.flush()
    os._exit(1 if hung else 0)


if __name__ == "__main__":
    main()
