"""Stacks of maps synthesized consistently (issue 9; Neubeck et al. 2004 sections 2.2, 2.3, 3.2).

Evidence: a PBR set derived from one photo (colour; height = blurred luminance; its normal map;
roughness = a pixelwise function of luminance) synthesized three ways: ``guided`` (section 3.2),
``column`` (one position map for every map, section 2.3) and each map on its own. Consistency
errors and times per mode; the maps and a Cycles render of the lit material tiled 2 x 2. Then the
alignment plane experiment of section 2.2 (Cycles renders of a displaced plane) with its curve.
"""

from __future__ import annotations

import numpy as np
from scipy.ndimage import gaussian_filter

import texsynth
from benchmarks.cycles import cpu_scene
from texsynth.metrics import luminance, seam_ratio
from texsynth.stack import btf

ORDER = 60
TITLE = "Whole materials: maps synthesized consistently (issue 9)"

SEED = 0
PREFERRED = "extremetuxracer/pebbles01.png"
BUMP = 8.0  # height-to-slope factor of the derived normal map


def pbr_set(colour):
    """[colour, height, normal, roughness] derived from a colour photo."""
    lum = luminance(colour)
    height = gaussian_filter(lum, 1.5).astype(np.float32)
    return [colour, height[:, :, None], _normals(height), roughness(colour)]


def roughness(colour):
    return (0.9 - 0.6 * luminance(colour))[:, :, None].astype(np.float32)


def _normals(height):
    gy, gx = np.gradient(BUMP * height)
    n = np.stack([-gx, -gy, np.ones_like(gx)], axis=2)
    return (0.5 + 0.5 * n / np.linalg.norm(n, axis=2, keepdims=True)).astype(np.float32)


def consistency(maps):
    """Roughness vs the colour it derives from (relative, pixelwise) and the normal map vs the
    normals of the height map (mean angle, degrees; non-local, so never exactly 0 at seams)."""
    rough = np.abs(maps[3] - roughness(maps[0])).mean() / maps[3].mean()
    a = maps[2] * 2 - 1
    b = _normals(maps[1][:, :, 0]) * 2 - 1
    cos = (a * b).sum(axis=2) / np.linalg.norm(a, axis=2) / np.linalg.norm(b, axis=2)
    return float(rough), float(np.degrees(np.arccos(np.clip(cos, -1, 1))).mean())


def _independent(stack, side):
    return [texsynth.synthesize(m, side, side, "multiscale_mrf", seed=SEED + v)
            for v, m in enumerate(stack)]


def _render(material_maps, side):
    """Cycles render of a plane with the maps (tiled 2 x 2) under a low sun: float32 RGB."""
    import bpy

    from texsynth.io import read_png

    scene = cpu_scene(16, side, side)
    bpy.ops.mesh.primitive_plane_add(size=2.0)
    plane = bpy.context.active_object
    material = bpy.data.materials.new("pbr")
    material.use_nodes = True
    tree = material.node_tree
    bsdf = next(n for n in tree.nodes if n.bl_idname == "ShaderNodeBsdfPrincipled")
    mapping = tree.nodes.new("ShaderNodeMapping")
    mapping.inputs["Scale"].default_value = (2.0, 2.0, 1.0)
    tree.links.new(tree.nodes.new("ShaderNodeTexCoord").outputs["UV"], mapping.inputs["Vector"])
    nodes = []
    for name, values, colorspace in zip(("colour", "height", "normal", "roughness"),
                                        material_maps, ("sRGB", "Non-Color", "Non-Color",
                                                        "Non-Color"), strict=True):
        h, w = values.shape[:2]
        rgb = np.repeat(values, 3, axis=2) if values.shape[2] == 1 else values
        image = bpy.data.images.new(name, w, h, alpha=True)
        image.colorspace_settings.name = colorspace
        rgba = np.concatenate([rgb, np.ones((h, w, 1), np.float32)], axis=2)
        image.pixels.foreach_set(np.clip(rgba[::-1], 0, 1).ravel())
        node = tree.nodes.new("ShaderNodeTexImage")
        node.image, node.extension = image, "REPEAT"
        tree.links.new(mapping.outputs["Vector"], node.inputs["Vector"])
        nodes.append(node)
    normal_map = tree.nodes.new("ShaderNodeNormalMap")
    bump = tree.nodes.new("ShaderNodeBump")
    bump.inputs["Strength"].default_value = 0.3
    tree.links.new(nodes[0].outputs["Color"], bsdf.inputs["Base Color"])
    tree.links.new(nodes[3].outputs["Color"], bsdf.inputs["Roughness"])
    tree.links.new(nodes[2].outputs["Color"], normal_map.inputs["Color"])
    tree.links.new(nodes[1].outputs["Color"], bump.inputs["Height"])
    tree.links.new(normal_map.outputs["Normal"], bump.inputs["Normal"])
    tree.links.new(bump.outputs["Normal"], bsdf.inputs["Normal"])
    plane.data.materials.append(material)
    bpy.ops.object.light_add(type="SUN", rotation=(np.radians(60), 0.0, np.radians(30)))
    bpy.context.active_object.data.energy = 4.0
    camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
    camera.data.type, camera.data.ortho_scale = "ORTHO", 2.0
    camera.location = (0.0, 0.0, 3.0)
    scene.collection.objects.link(camera)
    scene.camera = camera
    import tempfile
    with tempfile.TemporaryDirectory() as tmp:
        scene.render.filepath = f"{tmp}/render.png"
        bpy.ops.render.render(write_still=True)
        return read_png(f"{tmp}/render.png")[:, :, :3]


def _alignment(ctx):
    """Section 2.2 on Cycles renders of a displaced plane: 9 orthographic views (3 x 3 grid of
    directions, slant up to 28 deg), rectified for height 0; the curve and the chosen height."""
    import tempfile

    from benchmarks.btf_renders import GRID, rectified_views

    rng = np.random.default_rng(3)
    albedo = gaussian_filter(rng.random((GRID, GRID)), 1.0, mode="wrap")
    albedo = (albedo - albedo.min()) / np.ptp(albedo)
    relief = gaussian_filter(rng.standard_normal((GRID, GRID)), 6, mode="wrap")
    height = 4.0 + 1.5 * (relief - relief.mean()) / relief.std()  # pixels, about 8 px deep
    tx, ty = np.meshgrid(np.radians([-20, 0, 20]), np.radians([-20, 0, 20]))
    world = np.stack([np.tan(tx).ravel(), np.tan(ty).ravel(), np.ones(9)], axis=1)
    world /= np.linalg.norm(world, axis=1, keepdims=True)
    with tempfile.TemporaryDirectory() as tmp:
        stack, dirs = rectified_views(albedo, height, world, tmp)
    heights = np.arange(-2.0, 10.01, 1.0 if ctx.quick else 0.5)
    best, curve, realigned = btf.align(stack, dirs, heights)
    plain = stack[[0, 2, 6, 8]]
    sheet = ctx.contact_sheet("stack_btf_views.png", ["-20/-20", "+20/-20", "-20/+20",
                                                       "+20/+20"],
                              [list(plain), list(realigned[[0, 2, 6, 8], :, :, 0])])
    return [f"9 orthographic Cycles renders (emission shader, directions on a 3 x 3 grid up to "
            f"+-20 deg in x and y, slant up to 28 deg) of a {GRID} x {GRID} px textured height "
            f"field of mean height {height.mean():.2f} px (range {np.ptp(height):.1f} px), each "
            f"rectified to the frontal grid of the plane z = 0 with the known camera. "
            f"`texsynth.stack.btf.align` chooses {best:.2f} px.", "",
            "| height px | " + " | ".join(f"{h:g}" for h in heights) + " |",
            "|---" * (len(heights) + 1) + "|",
            "| mean distance | " + " | ".join(f"{c:.4f}" for c in curve) + " |", "",
            f"![corner views]({sheet})", "",
            "Top: the four corner views rectified for height 0 (the surface drifts between "
            "them); bottom: realigned for the chosen height."]


def run(ctx) -> str:
    side, out_side = (64, 96) if ctx.quick else (128, 256)
    tex = next((t for t in ctx.textures if t.name == PREFERRED), ctx.textures[0])
    colour = np.ascontiguousarray(tex.image[:side, :side, :3])
    stack = pbr_set(colour)
    lines = [f"PBR set from `{tex.name}` ({side} x {side} crop: colour, height = blurred "
             "luminance, its normal map, roughness = 0.9 - 0.6 luminance), synthesized to "
             f"{out_side} x {out_side} with `multiscale_mrf` (defaults), seed {SEED}. Roughness "
             "error: mean |R - f(colour)| / mean R (pixelwise relation, 0 when kept). Normal "
             "error: mean angle between the normal map and the normals of the height map "
             "(non-local: seams of the position maps count).", "",
             "| mode | time s | roughness error | normal error (deg) | worst seam ratio |",
             "|---|---|---|---|---|"]
    base_r, base_n = consistency(stack)
    lines.append(f"| exemplar | - | {base_r:.4f} | {base_n:.2f} | - |")
    results = {}
    runs = {
        "column": lambda: texsynth.synthesize_stack(stack, out_side, out_side, seed=SEED,
                                                    mode="column"),
        "guided": lambda: texsynth.synthesize_stack(stack, out_side, out_side, seed=SEED),
        "independent": lambda: _independent(stack, out_side),
    }
    for mode, fn in runs.items():
        m = ctx.measure(fn, repeats=1)
        results[mode] = m.result
        r, n = consistency(m.result)
        seam = max(seam_ratio(v) for v in m.result)
        lines.append(f"| {mode} | {m.median_s:.2f} | {r:.4f} | {n:.2f} | {seam:.2f} |")
    names = ["colour", "height", "normal", "roughness"]
    sheet = ctx.contact_sheet("stack_pbr.png", names,
                              [stack] + [results[m] for m in runs])
    lines += ["", f"![PBR maps]({sheet})", "",
              "Rows: exemplar, column, guided, independent; columns: " + ", ".join(names) + "."]
    try:
        renders = [_render(results[m], 192 if ctx.quick else 384) for m in runs]
    except ImportError:
        renders = None
    if renders is not None:
        img = ctx.contact_sheet("stack_render.png", list(runs), [renders],
                                cell=192 if ctx.quick else 384)
        lines += ["", f"![Cycles renders]({img})", "",
                  "Cycles, orthographic, sun at 30 deg elevation, each material tiled 2 x 2: "
                  "column, guided, independent (left to right)."]

    lines += ["", "### Alignment plane (section 2.2)", ""] + _alignment(ctx)
    return "\n".join(lines)
