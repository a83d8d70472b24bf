"""Break Repetition's **Tiling and Blending** mode (Heitz & Neyret 2018; Deliot & Heitz 2019;
Burley 2019's truncated Gaussian): the precomputation and the node groups, built by code;
``texsynth.norepeat.blend`` is the numpy reference.

``texsynth.norepeat.gaussianize`` precomputes each map's Gaussianised texture, stored as a new
packed float image (Non-Color), and inverse table, held by an RGB Curves node; a new group per
map reads them through two groups that every material shares:

* **TexSynth Triangle Grid** (Vector, Scale, Seed -> UV 1-3, Weights): the texture space skewed
  onto a triangle grid (Deliot & Heitz's ``TriangleGrid``), each of the point's three triangle
  vertices given a random offset by a hash (the White Noise texture of the integer vertex and
  the seed) snapped to whole texels of the map (Texels: its width and height), and the
  barycentric weights;
* **TexSynth Variance-Preserving Blend** (Gaussian 1-3, Weights -> Gaussian): ``(sum w_i G_i -
  1/2) / sqrt(sum w_i^2) + 1/2`` (Heitz & Neyret 2018, 3.1), computed as ``sum w'_i G'_i`` of
  the centred Gaussian values ``G' = G - 1/2`` (stored so) and the normalised weights ``w' = w
  / |w|`` (the grid's output), the ``+ 1/2`` left to the table's curves;
* **TexSynth T&B <image>** per map: the grid, three reads of the Gaussianised image, the blend
  and the inverse table as an RGB Curves node (``texsynth.norepeat.Gaussianized.curves``).

Only Math, Vector Math, Separate/Combine XYZ, White Noise, Image Texture and RGB Curves nodes:
Cycles and EEVEE both run them. The groups work on whole vectors (a Vector Math node does what
took two or three Math nodes): the render time is mostly the count of nodes and image reads.
Deviations: Blender's White Noise hash, not the paper's sine hash; offsets snapped to whole
texels, so a linear read of an offset copy blurs no more than the plain texture's (a sub-texel
offset averages neighbouring texels, which the variance-preserving blend does not undo:
fine-grained photos came out soft); the table as 257-point curves that Cycles bakes to 256
entries read with linear interpolation, not the 4096-entry table image read once per channel
(three image reads and sums replaced by one node; granite setts, 256 px render: W1 0.00015 and
mean difference 0.0002 against the same group reading the exact table).
"""

import bpy
import numpy as np

from ... import texsynth
from ...texsynth.norepeat import GRID_SCALE, gaussianize
from ...texsynth.norepeat.gaussian import MU
from ..job import Task
from .maps import shader_maps
from .nodes import finish_group, new_group, opaque_alpha, shared_group, stem

#: The mode's enum item, the operator settings its redo panel shows and its report's verb.
ITEM = ("TILING_AND_BLENDING", "Tiling and Blending",
        "Histogram-preserving blend of randomly offset copies on a triangle grid: for "
        "stochastic textures (gravel, grass, sand, rock); structured ones show ghosts")
SETTINGS = ("scale", "seed")
DONE = "tiled and blended"
GRID = "TexSynth Triangle Grid"
BLEND = "TexSynth Variance-Preserving Blend"
#: The image made per map: the Gaussianised texture (name suffix; the table is a curve node).
SUFFIXES = ("tnb_gaussian",)


def prepare(op, src, nodes):
    """The job that Gaussianises every map (``op``: the operator, its settings)."""
    maps, _ = shader_maps(nodes)
    return Task(precompute, [values for _, values in maps])


def precompute(maps, progress=None):
    """Each map's ``Gaussianized`` (the job's work: numpy only)."""
    report = texsynth.Progress(progress)
    out = []
    for n, values in enumerate(maps):
        report(n / len(maps), f"Gaussianising map {n + 1} of {len(maps)}")
        out.append(gaussianize(values))
    report(1.0, "Done")
    return out


def scale(op, result):
    """The Scale node's value: the operator's Scale (triangle-grid cells per texture tile)."""
    return op.scale


def groups(op, result, nodes):
    """One new Gaussianised image and group per source node (same order)."""
    made = []
    for node, g in zip(nodes, result, strict=True):
        gaussian, curves = padded(g)
        image = float_image(f"{stem(node.image)}_{SUFFIXES[0]}", gaussian)
        made.append(map_group(f"TexSynth T&B {stem(node.image)}", image, curves,
                              node.interpolation))
    return made


def link(op, tree, made, result):
    """Nothing to set on the placed nodes: Vector, Scale and Seed are all they take."""


def padded(g):
    """The Gaussian texture centred (``G - 1/2``, as the blend group takes it) as (H, W, 4) RGBA
    for Blender and the table as curves (N, 3); a grey map's one channel is repeated into all
    three."""
    h, w, c = g.gaussian.shape
    gaussian = np.ones((h, w, 4), np.float32)
    gaussian[:, :, :3] = (g.gaussian if c == 3 else g.gaussian[:, :, :1]) - MU
    curves = g.curves()
    return gaussian, curves if c == 3 else np.repeat(curves, 3, axis=1)


def float_image(name, rgba):
    """A new packed float image (Non-Color) of ``rgba`` (H, W, 4), top row first."""
    h, w = rgba.shape[:2]
    image = bpy.data.images.new(name, w, h, alpha=True, float_buffer=True)
    image.colorspace_settings.name = "Non-Color"
    image.alpha_mode = "NONE"
    image.pixels.foreach_set(np.ascontiguousarray(rgba[::-1]).ravel())
    image.pack()
    return image


def triangle_grid(b, uv, s, seed):
    """The triangle grid of ``texsynth.norepeat.blend.triangle_grid`` in nodes: the point's
    three vertices (skewed-grid integers, the seed as their third coordinate) and its
    barycentric weights."""
    # skewed = SKEW @ uv * s (texsynth.norepeat.blend.SKEW) = uv * (s, 2s/sqrt3, 0) + u *
    # (0, -s/sqrt3, 0): the constant vectors fold away when Scale is a Value node
    along = b.combine(s, b.math("MULTIPLY", s, 2 / 3 ** 0.5), 0.0)
    across = b.combine(0.0, b.math("MULTIPLY", s, -1 / 3 ** 0.5), 0.0)
    skewed = b.vector("MULTIPLY_ADD", uv, along, b.scale(across, b.separate(uv)[0]))
    base, f = b.vector("FLOOR", skewed), b.vector("FRACTION", skewed)
    z = b.math("SUBTRACT", 1.0, b.vector("DOT_PRODUCT", f, (1.0, 1.0, 0.0)))
    # vertices (1,0), (0,1) and (0,0) below the diagonal (z > 0), weights (fx, fy, z); (1,1)
    # above it, weights (1 - fy, 1 - fx, -z) = (fx + z, fy + z, -z): the reference's
    # vertices and weights in another order
    near = b.math("MINIMUM", z, 0.0)
    weights = b.vector("ADD", f, b.combine(near, near, b.math("ABSOLUTE", z)))
    above = b.math("LESS_THAN", z, 0.0)
    vertices = (b.vector("ADD", base, b.combine(1.0, 0.0, seed)),
                b.vector("ADD", base, b.combine(0.0, 1.0, seed)),
                b.vector("MULTIPLY_ADD", above, (1.0, 1.0, 0.0),
                         b.vector("ADD", base, b.combine(0.0, 0.0, seed))))
    return vertices, weights


def _build_grid():
    group, b, i = new_group(GRID, [("Vector", "Vector"), ("Scale", "Float", GRID_SCALE),
                                    ("Seed", "Float", 0.0), ("Texels", "Vector")],
                             [("UV 1", "Vector"), ("UV 2", "Vector"), ("UV 3", "Vector"),
                              ("Weights", "Vector")])
    uv = i["Vector"]
    vertices, weights = triangle_grid(b, uv, i["Scale"], i["Seed"])
    texel = b.vector("DIVIDE", (1.0, 1.0, 1.0), i["Texels"])
    uvs = []
    for vertex in vertices:
        offset = b.node("ShaderNodeTexWhiteNoise", (vertex,), noise_dimensions="3D")
        # the offset's first two values snapped to whole texels (the third is below 1: 0)
        uvs.append(b.vector("ADD", uv, b.vector("SNAP", offset.outputs["Color"], texel)))
    # the weights divided by their norm, as the blend needs them
    finish_group(b, uvs + [b.vector("NORMALIZE", weights)])
    return group


def _build_blend():
    group, b, i = new_group(BLEND, [("Gaussian 1", "Color"), ("Gaussian 2", "Color"),
                                     ("Gaussian 3", "Color"), ("Weights", "Vector")],
                             [("Gaussian", "Vector")])
    # (sum w_i G_i - 1/2) / |w| + 1/2 = sum (w_i / |w|) (G_i - 1/2) + 1/2 as sum w_i G_i of
    # centred values (G - 1/2 stored) and normalised weights; the table takes the + 1/2
    w = b.separate(i["Weights"])
    total = b.scale(i["Gaussian 3"], w[2])
    for k in (1, 0):
        total = b.vector("MULTIPLY_ADD", i[f"Gaussian {k + 1}"], w[k], total)
    finish_group(b, [total])
    return group


def map_group(name, gaussian, curves, interpolation):
    """A new group (Vector, Scale, Seed -> Color, Alpha) tiling and blending one map, from its
    Gaussianised image (centred: ``G - 1/2``) and its inverse table as curves
    (``Gaussianized.curves``: (N, 3), the output channels at Gaussian values ``i / (N - 1)``)."""
    group, b, i = new_group(name, [("Vector", "Vector"), ("Scale", "Float", GRID_SCALE),
                                    ("Seed", "Float", 0.0)],
                             [("Color", "Color"), ("Alpha", "Float")])
    grid = b.node("ShaderNodeGroup", node_tree=shared_group(GRID, _build_grid))
    for socket in ("Vector", "Scale", "Seed"):
        b.tree.links.new(i[socket], grid.inputs[socket])
    grid.inputs["Texels"].default_value = (*gaussian.size, 1.0)
    blend = b.node("ShaderNodeGroup", node_tree=shared_group(BLEND, _build_blend))
    for k in range(3):
        read = b.node("ShaderNodeTexImage", (grid.outputs[f"UV {k + 1}"],), image=gaussian,
                      interpolation=interpolation, extension="REPEAT")
        b.tree.links.new(read.outputs["Color"], blend.inputs[f"Gaussian {k + 1}"])
    b.tree.links.new(grid.outputs["Weights"], blend.inputs["Weights"])
    table = b.node("ShaderNodeRGBCurve", (1.0, blend.outputs["Gaussian"]))
    set_curves(table.mapping, curves)
    finish_group(b, [table.outputs["Color"], opaque_alpha(b)])
    return group


def set_curves(mapping, curves):
    """An RGB Curves node's ``mapping`` made the piecewise-linear curves through ``curves``
    (N, 3) at centred Gaussian values x = i / (N - 1) - 1/2: straight segments (vector
    handles), held flat beyond [-1/2, 1/2], not clipped (float maps may exceed 1); the combined
    curve, applied first, the identity over the same range (Cycles bakes the curves over the
    widest x range of the four)."""
    mapping.use_clip = False
    mapping.clip_min_x, mapping.clip_max_x = -0.5, 0.5
    mapping.extend = "HORIZONTAL"
    xs = [k / (len(curves) - 1) - 0.5 for k in range(len(curves))]
    combined = mapping.curves[3].points
    combined[0].location, combined[-1].location = (-0.5, -0.5), (0.5, 0.5)
    for channel in range(3):
        points = mapping.curves[channel].points
        points[0].location, points[-1].location = (xs[0], curves[0, channel]), \
            (xs[-1], curves[-1, channel])
        for x, y in zip(xs[1:-1], curves[1:-1, channel], strict=True):
            points.new(x, y)
        for point in points:
            point.handle_type = "VECTOR"
    mapping.update()
