// SPDX-License-Identifier: GPL-3.0-or-later
//
// Flamenco 3 job type: render a file baked for render anywhere (the Relativity panel's "Bake for
// Render Anywhere", or `render.py FILE --frames A-B --bake-to BAKED.blend`) with plain Blender, one
// task per chunk of frames. The workers need neither the add-on nor Python scripts: the baked file
// plays back everything the add-on's handlers would compute per frame (keyframes, Apparent
// Geometry's meshes per frame inside the file, and the world's per-frame image sequence in the
// folder BAKED_relativity_bake/ beside the file, which must travel with it). The exact camera is
// an OSL shader: for it the workers' Blender must have OSL (Cycles on the CPU).
// Install: copy this file into the "scripts" folder next to the Flamenco Manager executable and
// restart the Manager (docs/farm.md).
//
// Each task runs, on a worker:
//   {blender} {blenderArgs} --disable-autoexec BAKED.blend --render-output OUT/frame_#### \
//       --render-format PNG --frame-start A --frame-end B --render-anim

const JOB_TYPE = {
  label: "Relativistic Render (Baked, Plain Blender)",
  description: "Render a Relativity file baked for render anywhere with plain Blender (no add-on, scripts disabled)",
  settings: [
    // Settings for artists to determine:
    {
      key: "frames",
      type: "string",
      required: true,
      eval: "f'{C.scene.frame_start}-{C.scene.frame_end}'",
      evalInfo: { showLinkButton: true, description: "Scene frame range" },
      description: "Frame range to render, FIRST-LAST, within the baked frames",
    },
    {
      key: "chunk_size",
      type: "int32",
      default: 1,
      description: "Frames rendered by one task (one Blender process)",
      visible: "submission",
    },
    {
      key: "render_output_root",
      type: "string",
      subtype: "dir_path",
      required: true,
      visible: "submission",
      description: "Folder of the job's output; the job name is added to it",
    },
    {
      key: "file_format",
      type: "string",
      choices: ["png", "exr"],
      default: "png",
      visible: "submission",
      description: "PNG, or EXR for linear float",
    },

    // Automatically evaluated settings:
    {
      key: "blendfile",
      type: "string",
      required: true,
      description: "Path of the baked .blend file to render",
      visible: "web",
    },
  ],
};

// "A-B" (or a single frame "N") as [A, B]; anything else is refused at submission.
function frameRange(text) {
  const match = /^\s*(-?\d+)\s*(?:-\s*(-?\d+)\s*)?$/.exec(text);
  if (!match) {
    throw `Relativistic Render (Baked): frames must be FIRST-LAST, got '${text}'`;
  }
  const first = parseInt(match[1], 10);
  const last = match[2] === undefined ? first : parseInt(match[2], 10);
  if (last < first) {
    throw `Relativistic Render (Baked): last frame before first in '${text}'`;
  }
  return [first, last];
}

function compileJob(job) {
  print("Relativistic Render (Baked) job submitted");
  const settings = job.settings;
  const [first, last] = frameRange(settings.frames);
  const chunkSize = Math.max(1, settings.chunk_size || 1);
  const format = settings.file_format === "exr" ? "OPEN_EXR" : "PNG";
  const output = path.join(settings.render_output_root, job.name, "frame_####");

  for (let start = first; start <= last; start += chunkSize) {
    const end = Math.min(start + chunkSize - 1, last);
    const task = author.Task(`render-${start}-${end}`, "blender");
    const command = author.Command("blender-render", {
      exe: "{blender}",
      exeArgs: "{blenderArgs}",
      // after {blenderArgs} (Flamenco's default "-b -y" enables scripts): the baked file needs none
      argsBefore: ["--disable-autoexec"],
      blendfile: settings.blendfile,
      args: [
        "--render-output",
        output,
        "--render-format",
        format,
        "--frame-start",
        `${start}`,
        "--frame-end",
        `${end}`,
        "--render-anim",
      ],
    });
    task.addCommand(command);
    job.addTask(task);
  }
}
