// SPDX-License-Identifier: GPL-3.0-or-later
//
// A Flamenco job type: `texsynth batch` as Flamenco tasks, one task per photo, each running
//
//     blender -b --python examples/synthesize_file.py -- PHOTO --width W --height H
//             --method M --seed N --out OUTPUT_DIR [EXTRA...]
//
// in a Blender that has the TexSynth extension installed (synthesize_file.py loads it from the
// repository beside the script when it is not). Each task writes PHOTO's texture as OpenEXR,
// a .blend whose material uses it and a PNG of it tiled 2 x 2 into OUTPUT_DIR (see the
// script's docstring). Install: copy this file into the `scripts` folder next to the
// `flamenco-manager` executable, put the texsynth repository (or at least
// examples/synthesize_file.py) and the photos on the shared storage, and restart the Manager.
// docs/BATCH.md says more, and when to use Dask instead.
//
// The Manager compiles jobs without reading the shared storage, so the photos are listed in
// the job (`photos`, separated by `;`), not found in a folder. Flamenco runs a failed task
// again on another worker; the outputs of a task are written by the script under names of
// their own, so tasks never write each other's files.

const JOB_TYPE = {
    label: "TexSynth Batch",
    description: "A seamless texture from each photo, with Blender and the TexSynth extension",
    settings: [
        { key: "photos", type: "string", required: true,
          description: "Photos on the shared storage, absolute paths separated by ';'" },
        { key: "output_dir", type: "string", subtype: "dir_path", required: true,
          description: "Folder the textures, .blend files and tiled previews are written to" },
        { key: "script", type: "string", subtype: "file_path", required: true,
          description: "examples/synthesize_file.py of the texsynth repository, on the shared storage" },
        { key: "width", type: "int32", default: 1024, description: "Texture width in pixels" },
        { key: "height", type: "int32", default: 1024, description: "Texture height in pixels" },
        { key: "method", type: "string", default: "multiscale_mrf",
          choices: ["heeger_bergen", "efros_leung", "multiscale_mrf", "de_bonet",
                    "cooccurrence", "texture_optimization", "composite"],
          description: "Synthesis method (`texsynth methods` describes them)" },
        { key: "seed", type: "int32", default: 0, description: "Random seed" },
        { key: "extra_args", type: "string", default: "",
          description: "More options of the script, space separated (e.g. '--radius 4')" },
        { key: "blender_cmd", type: "string", default: "{blender}", visible: false },
    ],
};

function compileJob(job) {
    const settings = job.settings;
    const photos = settings.photos.split(";").map((p) => p.trim()).filter((p) => p.length > 0);
    if (photos.length == 0) {
        throw "TexSynth Batch: the job lists no photos";
    }
    const extra = settings.extra_args.split(" ").filter((a) => a.length > 0);
    for (const photo of photos) {
        const name = photo.split(/[\\/]/).pop();
        const task = author.Task(`texsynth-${name}`, "blender");
        // The blender-render command runs `{exe} {exeArgs} {argsBefore} {blendfile} {args}` and
        // needs a non-empty blendfile: the script's path takes that place, after `--python`.
        task.addCommand(author.Command("blender-render", {
            exe: settings.blender_cmd,
            exeArgs: "{blenderArgs}",
            argsBefore: ["-b", "--python"],
            blendfile: settings.script,
            args: ["--", photo,
                   "--width", `${settings.width}`, "--height", `${settings.height}`,
                   "--method", settings.method, "--seed", `${settings.seed}`,
                   "--out", settings.output_dir, ...extra],
        }));
        job.addTask(task);
    }
}
