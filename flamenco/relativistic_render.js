// SPDX-License-Identifier: GPL-3.0-or-later
//
// Flamenco 3 job type: render a frame range through the Relativity add-on's batch script
// (examples/render.py), one task per chunk of frames. Install: copy this file into the "scripts"
// folder next to the Flamenco Manager executable and restart the Manager; the job type
// "Relativistic Render" then appears in the Flamenco add-on's job types (docs/farm.md).
//
// Each task runs, on a worker:
//   {blender} {blenderArgs} FILE.blend --python RENDER_SCRIPT -- --frames=A-B --out=OUT/frame_####.png ...
// The batch script applies the relativistic effect for the chunk's frames (refusing, with a one-line
// reason and exit status 1, a chunk where the camera reaches c), writes each frame to a partial name
// and renames it when complete, and with "Resume" skips frames already complete when Flamenco
// re-queues a task.

const JOB_TYPE = {
  label: "Relativistic Render",
  description: "Render a frame range with the Relativity add-on's batch script (relativistic camera)",
  settings: [
    // Settings for artists to determine:
    {
      key: "frames",
      type: "string",
      required: true,
      eval: "f'{C.scene.frame_start}-{C.scene.frame_end}'",
      evalInfo: { showLinkButton: true, description: "Scene frame range" },
      description: "Frame range to render, FIRST-LAST, e.g. '1-240'",
    },
    {
      key: "chunk_size",
      type: "int32",
      default: 1,
      description: "Frames rendered by one task (one Blender process)",
      visible: "submission",
    },
    {
      key: "render_script",
      type: "string",
      subtype: "file_path",
      required: true,
      description: "examples/render.py of the Relativity repository, as the workers see it",
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
    {
      key: "beta",
      type: "string",
      default: "",
      visible: "submission",
      description: "Observer velocity X,Y,Z (world axes, fraction of c); empty: the file's setting",
    },
    {
      key: "velocity_from_animation",
      type: "bool",
      default: false,
      visible: "submission",
      description: "Observer velocity from the active camera's keyframed motion",
    },
    {
      key: "method",
      type: "string",
      choices: ["file", "camera", "geometry"],
      default: "file",
      visible: "submission",
      description: "Render method; 'file': the .blend's own setting",
    },
    {
      key: "samples",
      type: "int32",
      default: 0,
      visible: "submission",
      description: "Cycles samples; 0: the .blend's own setting",
    },
    {
      key: "spectral_passes",
      type: "int32",
      default: 0,
      visible: "submission",
      description: "Spectral colour with this many passes (exact camera); 0: the fast RGB colour",
    },
    {
      key: "resume",
      type: "bool",
      default: true,
      visible: "submission",
      description: "Skip frames whose output is already complete (a re-queued task)",
    },
    {
      key: "extra_args",
      type: "string",
      default: "",
      visible: "submission",
      description: "More batch script options, separated by spaces, e.g. '--seed=3 --no-searchlight'",
    },

    // Automatically evaluated settings:
    {
      key: "blendfile",
      type: "string",
      required: true,
      description: "Path of the .blend file to render",
      visible: "web",
    },
  ],
};

// "A-B" (or a single frame "N") as [A, B]; anything else is refused at submission.
function frameRange(text) {
  const match = /^\s*(-?\d+)\s*(?:-\s*(-?\d+)\s*)?$/.exec(text);
  if (!match) {
    throw `Relativistic Render: frames must be FIRST-LAST, got '${text}'`;
  }
  const first = parseInt(match[1], 10);
  const last = match[2] === undefined ? first : parseInt(match[2], 10);
  if (last < first) {
    throw `Relativistic Render: last frame before first in '${text}'`;
  }
  return [first, last];
}

// The batch script's options from the job's settings (all but frames and output).
function relativityOptions(settings) {
  const options = [];
  if (settings.beta) {
    options.push(`--beta=${settings.beta.replace(/\s+/g, "")}`);
  }
  if (settings.velocity_from_animation) {
    options.push("--velocity-from-animation");
  }
  if (settings.method && settings.method !== "file") {
    options.push(`--method=${settings.method}`);
  }
  if (settings.samples > 0) {
    options.push(`--samples=${settings.samples}`);
  }
  if (settings.spectral_passes > 0) {
    options.push(`--spectral=${settings.spectral_passes}`);
  }
  options.push(settings.resume ? "--resume" : "--no-resume");
  const extra = (settings.extra_args || "").trim();
  return extra ? options.concat(extra.split(/\s+/)) : options;
}

function compileJob(job) {
  print("Relativistic Render job submitted");
  const settings = job.settings;
  const [first, last] = frameRange(settings.frames);
  const chunkSize = Math.max(1, settings.chunk_size || 1);
  const extension = settings.file_format === "exr" ? "exr" : "png";
  const output = path.join(settings.render_output_root, job.name, `frame_####.${extension}`);
  const options = relativityOptions(settings);

  for (let start = first; start <= last; start += chunkSize) {
    const end = Math.min(start + chunkSize - 1, last);
    const frames = `${start}-${end}`;
    const task = author.Task(`render-${frames}`, "blender");
    const command = author.Command("blender-render", {
      exe: "{blender}",
      exeArgs: "{blenderArgs}",
      argsBefore: [],
      blendfile: settings.blendfile,
      args: ["--python", settings.render_script, "--", `--frames=${frames}`, `--out=${output}`].concat(options),
    });
    task.addCommand(command);
    job.addTask(task);
  }
}
