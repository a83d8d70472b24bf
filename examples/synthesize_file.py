"""Synthesize a seamless texture from an image file, headless, with the TexSynth operator.

    blender -b --python examples/synthesize_file.py -- INPUT [options]
    python examples/synthesize_file.py INPUT [options]          (Python 3.11 with the bpy module)

Builds a plane whose material uses INPUT in an Image Texture node, runs
``bpy.ops.texsynth.synthesize`` on that node, and writes into --out (default ``out``): the
texture as OpenEXR (linear float), the .blend with the material wired to it, and a PNG of the
texture tiled 2 x 2, where a seam would show. The options are the operator's properties:
--width, --height, --method, --seed and every method's parameters (--scales, --orientations,
--iterations, ...); --help lists them.

The add-on is used as installed and enabled in Blender; when it is not, it is loaded from the
repository this script sits in (nothing is installed). That needs numpy, scipy and OpenEXR in
the running Python, which ``python3 addon_build.py setup`` provides for the bpy module; for
``blender -b``, install the extension zip in that Blender first.
"""

import argparse
import atexit
import importlib
import importlib.util
import sys
from pathlib import Path

import bpy

REPO = Path(__file__).resolve().parents[1]
SKIPPED = {"rna_type", "output", "output_dir", "source_image"}  # set by this script
TYPES = {"INT": int, "FLOAT": float, "STRING": str}


def ensure_addon():
    """The add-on's root package: the enabled extension, or this repository loaded by path."""
    if not hasattr(bpy.types, "TEXSYNTH_OT_synthesize"):
        spec = importlib.util.spec_from_file_location(
            "texsynth_addon", REPO / "__init__.py", submodule_search_locations=[str(REPO)])
        module = importlib.util.module_from_spec(spec)
        sys.modules[spec.name] = module
        spec.loader.exec_module(module)
        module.register()
        atexit.register(module.unregister)  # else the bpy 4.2 module crashes on exit
    operator_module = bpy.types.TEXSYNTH_OT_synthesize.__module__
    return importlib.import_module(operator_module.rsplit(".operators", 1)[0])


def parse_args(argv):
    parser = argparse.ArgumentParser(description="Synthesize a seamless texture from a file.")
    parser.add_argument("input", type=Path, help="image file (any format Blender reads)")
    parser.add_argument("--out", type=Path, default=Path("out"), help="output folder")
    for prop in bpy.ops.texsynth.synthesize.get_rna_type().properties:
        if prop.identifier in SKIPPED:
            continue
        flag = "--" + prop.identifier.replace("_", "-")
        extra = {"dest": prop.identifier, "help": prop.description}
        if prop.type == "ENUM":
            choices = [item.identifier for item in prop.enum_items]
            if prop.identifier == "method":  # snake_case names, as texsynth.methods() has them
                choices = [c.lower() for c in choices]
            parser.add_argument(flag, choices=choices, **extra)
        elif prop.type == "BOOLEAN":
            parser.add_argument(flag, action=argparse.BooleanOptionalAction, **extra)
        else:
            parser.add_argument(flag, type=TYPES[prop.type], **extra)
    args = parser.parse_args(argv)
    options = {k: v for k, v in vars(args).items() if k not in ("input", "out") and v is not None}
    if "method" in options:
        options["method"] = options["method"].upper()
    return args.input.resolve(), args.out.resolve(), options


def build_scene(path: Path):
    """An empty file with a plane whose material shows ``path``; its node is made active."""
    bpy.ops.wm.read_homefile(use_empty=True)
    image = bpy.data.images.load(str(path))
    bpy.ops.mesh.primitive_plane_add(size=2.0)
    material = bpy.data.materials.new(path.stem)
    if material.node_tree is None:  # Blender before 5.0
        material.use_nodes = True
    tree = material.node_tree
    shader = next(n for n in tree.nodes if n.bl_idname == "ShaderNodeBsdfPrincipled")
    node = tree.nodes.new("ShaderNodeTexImage")
    node.image = image
    node.location = (shader.location.x - 400.0, shader.location.y)
    tree.links.new(node.outputs["Color"], shader.inputs["Base Color"])
    tree.nodes.active = node
    bpy.context.active_object.data.materials.append(material)
    return tree


def main(argv):
    addon = ensure_addon()
    source, out, options = parse_args(argv)
    tree = build_scene(source)
    try:
        bpy.ops.texsynth.synthesize(output="EXR", output_dir=str(out), **options)
    except RuntimeError as error:
        sys.exit(f"texsynth: {error}")
    image = tree.nodes.active.image
    exr = Path(bpy.path.abspath(image.filepath))

    core = addon.texsynth
    texture = core.io.read_exr(exr)
    if not image.colorspace_settings.is_data:
        texture[:, :, :3] = core.blocks.color.linear_to_srgb(texture[:, :, :3])
    preview = out / f"{exr.stem}_tiled.png"
    core.io.write_png(preview, core.blocks.periodic.tile_preview(texture, 2, 2))

    blend = out / f"{exr.stem}.blend"
    bpy.context.preferences.filepaths.save_version = 0  # no .blend1 backup (this process only)
    bpy.ops.wm.save_as_mainfile(filepath=str(blend))
    bpy.ops.file.make_paths_relative()  # the .blend finds its textures after out/ moves
    bpy.ops.wm.save_mainfile()
    for path in (exr, blend, preview):
        print(f"wrote {path}")


if __name__ == "__main__":
    main(sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else sys.argv[1:])
