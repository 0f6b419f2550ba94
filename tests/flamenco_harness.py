"""Flamenco 3 job types compiled the way Flamenco's Manager compiles them, in node (the JavaScript
engine), with stand-ins for Flamenco's ``author``/``path``/``print``: the static job-type tests and
the real-application stage (which runs the compiled commands with Debian's plain Blender)."""

import json
import subprocess

HARNESS = r"""
const fs = require("fs"), vm = require("vm"), nodePath = require("path");
const source = fs.readFileSync(process.argv[1], "utf8");
const settings = JSON.parse(process.argv[2]);
const tasks = [];
const context = {
  print: () => {},
  path: nodePath.posix,
  author: {
    Task: (name, type) => ({ name, type, commands: [], addCommand(c) { this.commands.push(c); } }),
    Command: (type, parameters) => ({ type, parameters }),
  },
};
vm.createContext(context);
vm.runInContext(source + "\nthis.JOB_TYPE = JOB_TYPE; this.compileJob = compileJob;", context);
context.compileJob({ name: "shot", settings, addTask: (task) => tasks.push(task) });
const keys = context.JOB_TYPE.settings.map((s) => s.key);
process.stdout.write(JSON.stringify({ keys, tasks }));
"""


def compile_job(node, job_type, settings):
    """Run ``compileJob`` of ``job_type`` (a path to the .js file, as ``node`` sees it) for a job named
    "shot" with ``settings`` in ``node`` (a command list, e.g. ``["node"]``). Returns the
    CompletedProcess; its stdout is JSON: the job type's setting keys and the tasks with their
    commands."""
    command = [*node, "-e", HARNESS, str(job_type), json.dumps(settings)]
    return subprocess.run(command, capture_output=True, text=True, timeout=60)
