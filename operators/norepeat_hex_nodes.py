"""The node groups of ``texsynth.break_repetition``'s Hex Tiling mode (Mikkelsen 2022,
"Practical Real-Time Hex-Tiling", JCGT 11(2)), built by code; ``texsynth.norepeat.hex`` is the
numpy reference.

* **TexSynth Hex Grid** (Vector, Scale, Seed, Rotation, Turns, Texels -> UV 1-3, Angles,
  Weights): the triangle grid of tiling and blending, its vertices read as the centres of
  hexagonal cells; each of the point's three cells turns the texture by a hashed angle in
  ``[-pi, pi) * Rotation`` rounded to a multiple of a ``1 / Turns`` turn (Turns 0: not
  rounded; about the origin: see ``texsynth.norepeat.hex``) and offsets it by a hashed
  amount snapped to whole texels (one White Noise texture of the vertex and the seed gives
  both); the barycentric weights;
* **TexSynth Hex Weights** (Weights, Luminance, Contrast, Sharpness -> Weights): the paper's
  sharpened, luminance-weighted blend weights ``mix(1, L_i, contrast) * w_i ** sharpness``,
  normalised (section 4);
* **TexSynth Hex <image>** per map: the grid, three reads of the user's own image (no new
  image: hex tiling needs no precomputation), the weights and the blend. The active map's group
  outputs its three copies' luminances; the followers' groups take them in, so every map blends
  with the same weights. A normal map's group turns each copy's tangent-space normal with its
  cell (Vector Rotate by minus the angle, section 5.1), blends and renormalises.

Only Math, Vector Math, Separate/Combine XYZ, White Noise, Vector Rotate and Image Texture
nodes: Cycles and EEVEE both run them. Deviations as in ``texsynth.norepeat.hex``; the hash is
Blender's White Noise, so renders match the reference in their statistics, not pixel by pixel.
"""

import bpy

from ..texsynth.norepeat import GRID_SCALE
from ..texsynth.norepeat.hex import CONTRAST, LUMA, SHARPNESS
from .norepeat_nodes import TAG, VERSION, finish_group, new_group, triangle_grid

GRID = "TexSynth Hex Grid"
WEIGHTS = "TexSynth Hex Weights"
PI = 3.141592653589793


def _build_grid():
    group, b, i = new_group(GRID, [("Vector", "Vector"), ("Scale", "Float", GRID_SCALE),
                                    ("Seed", "Float", 0.0), ("Rotation", "Float", 1.0),
                                    ("Turns", "Float", 2.0), ("Texels", "Vector")],
                             [("UV 1", "Vector"), ("UV 2", "Vector"), ("UV 3", "Vector"),
                              ("Angles", "Vector"), ("Weights", "Vector")])
    uv = i["Vector"]
    vertices, weights = triangle_grid(b, uv, i["Scale"], i["Seed"])
    texel = b.vector("DIVIDE", (1.0, 1.0, 1.0), i["Texels"])
    spread = b.math("MULTIPLY", i["Rotation"], 2 * PI)
    start = b.math("MULTIPLY", i["Rotation"], -PI)
    step = b.math("DIVIDE", 2 * PI, i["Turns"])  # Blender's Math gives 0 for Turns 0
    rounded = b.math("GREATER_THAN", i["Turns"], 0.5)
    uvs, angles = [], []
    for vertex in vertices:
        noise = b.node("ShaderNodeTexWhiteNoise", (vertex,), noise_dimensions="3D")
        # the angle from the Value hash, the offset from the Color one's first two values
        # snapped to whole texels (the third is below 1: 0); turned about the origin
        free = b.math("MULTIPLY_ADD", noise.outputs["Value"], spread, start)
        # round(free / step) * step, as floor(free / step + 1/2) * step; kept when Turns is 0
        snapped = b.math("MULTIPLY", b.math("FLOOR", b.math("MULTIPLY_ADD", free, b.math(
            "DIVIDE", 1.0, step), 0.5)), step)
        angle = b.math("MULTIPLY_ADD", rounded, b.math("SUBTRACT", snapped, free), free)
        turned = b.node("ShaderNodeVectorRotate", (uv, None, None, angle),
                        rotation_type="Z_AXIS")
        offset = b.vector("SNAP", noise.outputs["Color"], texel)
        uvs.append(b.vector("ADD", turned.outputs["Vector"], offset))
        angles.append(angle)
    finish_group(b, uvs + [b.combine(*angles), weights])
    return group


def _build_weights():
    group, b, i = new_group(WEIGHTS, [("Weights", "Vector"), ("Luminance", "Vector"),
                                       ("Contrast", "Float", CONTRAST),
                                       ("Sharpness", "Float", SHARPNESS)],
                             [("Weights", "Vector")])
    contrast = i["Contrast"]
    d = b.vector("MULTIPLY_ADD", i["Luminance"], contrast, b.math("SUBTRACT", 1.0, contrast))
    d = b.vector("MAXIMUM", d, (1e-4, 1e-4, 1e-4))
    # w_i ** sharpness per component (Vector Math has no POWER before Blender 4.3)
    sharp = b.combine(*(b.math("POWER", w, i["Sharpness"]) for w in b.separate(i["Weights"])))
    w = b.vector("MULTIPLY", d, sharp)
    finish_group(b, [b.vector("DIVIDE", w, b.vector("DOT_PRODUCT", w, (1.0, 1.0, 1.0)))])
    return group


def shared_group(name):
    """The shared group ``name`` (GRID or WEIGHTS): the file's own if built by this version,
    else a new one."""
    for group in bpy.data.node_groups:
        if group.name.startswith(name) and group.get(TAG) == VERSION \
                and group.bl_idname == "ShaderNodeTree":
            return group
    return {GRID: _build_grid, WEIGHTS: _build_weights}[name]()


def map_group(name, image, interpolation, *, normal=False, follower=False):
    """A new group (Vector, Scale, Seed, Rotation, Turns, Contrast, Sharpness[, Luminance] ->
    Color, Alpha[, Luminance]) hex-tiling one map's own ``image``: a follower takes the active map's
    Luminance in, the active map gives it out; ``normal``: a tangent-space normal map."""
    inputs = [("Vector", "Vector"), ("Scale", "Float", GRID_SCALE), ("Seed", "Float", 0.0),
              ("Rotation", "Float", 1.0), ("Turns", "Float", 2.0), ("Contrast", "Float", CONTRAST),
              ("Sharpness", "Float", SHARPNESS)]
    outputs = [("Color", "Color"), ("Alpha", "Float")]
    if follower:
        inputs.append(("Luminance", "Vector"))
    else:
        outputs.append(("Luminance", "Vector"))
    group, b, i = new_group(name, inputs, outputs)
    grid = b.node("ShaderNodeGroup", node_tree=shared_group(GRID))
    for socket in ("Vector", "Scale", "Seed", "Rotation", "Turns"):
        b.tree.links.new(i[socket], grid.inputs[socket])
    grid.inputs["Texels"].default_value = (*image.size, 1.0)
    copies = [b.node("ShaderNodeTexImage", (grid.outputs[f"UV {k + 1}"],), image=image,
                     interpolation=interpolation, extension="REPEAT").outputs["Color"]
              for k in range(3)]
    if follower:
        luminance = i["Luminance"]
    elif normal:
        luminance = b.combine(1.0, 1.0, 1.0)
    else:
        luma = tuple(float(x) for x in LUMA)
        luminance = b.combine(*(b.vector("DOT_PRODUCT", c, luma) for c in copies))
    weights = b.node("ShaderNodeGroup", node_tree=shared_group(WEIGHTS))
    for socket, value in (("Weights", grid.outputs["Weights"]), ("Luminance", luminance),
                          ("Contrast", i["Contrast"]), ("Sharpness", i["Sharpness"])):
        b.tree.links.new(value, weights.inputs[socket])
    if normal:
        angles = b.separate(grid.outputs["Angles"])
        copies = [b.node("ShaderNodeVectorRotate",
                         (b.vector("MULTIPLY_ADD", c, (2.0, 2.0, 2.0), (-1.0, -1.0, -1.0)),
                          None, None, angles[k]), rotation_type="Z_AXIS",
                         invert=True).outputs["Vector"]
                  for k, c in enumerate(copies)]
    w = b.separate(weights.outputs["Weights"])
    total = b.scale(copies[2], w[2])
    for k in (1, 0):
        total = b.vector("MULTIPLY_ADD", copies[k], w[k], total)
    if normal:
        total = b.vector("MULTIPLY_ADD", b.vector("NORMALIZE", total), (0.5, 0.5, 0.5),
                         (0.5, 0.5, 0.5))
    opaque = b.node("ShaderNodeValue")
    opaque.outputs[0].default_value = 1.0
    finish_group(b, [total, opaque.outputs[0]] + ([] if follower else [luminance]))
    return group


def link(tree, made, rotation, turns, contrast, sharpness):
    """The placed group nodes ``made`` (the active map's first) given the mode's settings, and
    the followers the active map's luminances."""
    for node in made:
        for socket, value in (("Rotation", rotation), ("Turns", float(turns)),
                              ("Contrast", contrast),
                              ("Sharpness", sharpness)):
            node.inputs[socket].default_value = value
    for node in made[1:]:
        tree.links.new(made[0].outputs["Luminance"], node.inputs["Luminance"])
