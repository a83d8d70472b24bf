"""Break Repetition's **Hex Tiling** mode (Mikkelsen 2022, "Practical Real-Time Hex-Tiling",
JCGT 11(2)): no precomputation, the node groups built by code; ``texsynth.norepeat.hex`` is the
numpy reference. By default the cells turn only by the active map's own symmetry
(``texsynth.norepeat.rotation_symmetry``: half turns, quarter turns for a 4-fold photo), so a
photo's courses, layers and light keep their direction.

* **TexSynth Hex Grid** (Vector, Scale, Seed, Rotation, Turns, Texels -> UV 1-3, Angles,
  Weights): the triangle grid of tiling and blending, its vertices read as the centres of
  hexagonal cells; each of the point's three cells turns the texture by a hashed angle in
  ``[-pi, pi) * Rotation`` rounded to a multiple of a ``1 / Turns`` turn (Turns 0: of
  ``EPSILON`` radians, not seen; about the origin: see ``texsynth.norepeat.hex``), two Math
  nodes a cell (a Snap of the angle plus half a step), and offsets it by a hashed
  amount snapped to whole texels (one White Noise texture of the vertex and the seed gives
  both); the barycentric weights;
* **TexSynth Hex Weights** (Weights, Luminance, Contrast, Sharpness -> Weights): the paper's
  sharpened, luminance-weighted blend weights ``mix(1, L_i, contrast) * w_i ** sharpness``,
  normalised (section 4), the power one Vector Math node from Blender 4.3;
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

from ...texsynth.norepeat import GRID_SCALE, rotation_symmetry
from ...texsynth.norepeat.hex import CONTRAST, LUMA, SHARPNESS
from ..job import Task
from .blend import triangle_grid
from .maps import shader_maps
from .nodes import finish_group, new_group, opaque_alpha, shared_group, stem

#: The mode's enum item, the operator settings its redo panel shows and its report's verb.
ITEM = ("HEX_TILING", "Hex Tiling",
        "Randomly offset and turned copies on hexagonal cells, the brighter copy winning at a "
        "sharp seam (Mikkelsen 2022): for structured textures (layered rock, bark) and normal "
        "maps; no precomputation")
SETTINGS = ("scale", "seed", "turns", "rotation", "contrast", "sharpness")
DONE = "hex-tiled"
#: The Turns enum's items and the turns each asks for (AUTO: the photo's own).
TURNS = [("AUTO", "Photo's Symmetry", "Half turns, or quarter turns for a photo with a "
          "4-fold but no 2-fold direction (square setts, tiles): the photo's direction kept"),
         ("HALF", "Half Turns", "Every cell upright or upside down"),
         ("QUARTER", "Quarter Turns", "Multiples of 90 degrees"),
         ("ANY", "Any Angle", "Any angle within Rotation: for textures with no direction "
          "and no light direction (turns courses, layers and shadows every way)"),
         ("NONE", "None", "Offsets only")]
TURN_COUNTS = {"HALF": 2, "QUARTER": 4, "ANY": 0, "NONE": 1}
GRID = "TexSynth Hex Grid"
WEIGHTS = "TexSynth Hex Weights"
PI = 3.141592653589793
#: The angle's step (radians) for Turns 0 (any angle): a millionth of a radian, not seen.
EPSILON = 1e-6


def prepare(op, src, nodes):
    """Nothing to precompute: the job gives which maps are normal maps and the turns (the
    active map's symmetry for AUTO)."""
    maps, normals = shader_maps(nodes)
    turns = TURN_COUNTS.get(op.turns)
    image = maps[0][1]
    return Task(lambda progress=None: (normals, rotation_symmetry(image) if turns is None
                                       else turns))


def scale(op, result):
    """The Scale node's value: the operator's Scale (hexagonal cells per texture tile)."""
    return op.scale


def groups(op, result, nodes):
    """One new group per source node over its own image; the followers take the active map's
    luminances."""
    normals, _ = result
    return [map_group(f"TexSynth Hex {stem(node.image)}", node.image, node.interpolation,
                      normal=normal, follower=k > 0)
            for k, (node, normal) in enumerate(zip(nodes, normals, strict=True))]


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
    # a 1 / Turns turn; Turns 0 (Blender's Math divides by 0 as 0): steps of EPSILON radians,
    # the angle as it is
    step = b.math("MAXIMUM", b.math("DIVIDE", 2 * PI, i["Turns"]), EPSILON)
    half = b.math("MULTIPLY_ADD", step, 0.5, start)  # constant: folded once per group
    uvs, angles = [], []
    for vertex in vertices:
        noise = b.node("ShaderNodeTexWhiteNoise", (vertex,), noise_dimensions="3D")
        # the angle from the Value hash, the offset from the Color one's first two values
        # snapped to whole texels (the third is below 1: 0); turned about the origin.
        # round(a / step) * step as Snap(a + step / 2, step) = floor(a / step + 1/2) * step:
        # two nodes a cell
        angle = b.math("SNAP", b.math("MULTIPLY_ADD", noise.outputs["Value"], spread, half),
                       step)
        turned = b.node("ShaderNodeVectorRotate", (uv, None, None, angle),
                        rotation_type="Z_AXIS")
        offset = b.vector("SNAP", noise.outputs["Color"], texel)
        uvs.append(b.vector("ADD", turned.outputs["Vector"], offset))
        angles.append(angle)
    finish_group(b, uvs + [b.combine(*angles), weights])
    return group


def _power(b, vector, exponent):
    """``vector ** exponent`` per component: one Vector Math node from Blender 4.3 (Cycles'
    safe power per component, as the Math node's), three Math nodes before it."""
    if bpy.app.version >= (4, 3, 0):
        return b.vector("POWER", vector, b.combine(exponent, exponent, exponent))
    return b.combine(*(b.math("POWER", w, exponent) for w in b.separate(vector)))


def _build_weights():
    group, b, i = new_group(WEIGHTS, [("Weights", "Vector"), ("Luminance", "Vector"),
                                       ("Contrast", "Float", CONTRAST),
                                       ("Sharpness", "Float", SHARPNESS)],
                             [("Weights", "Vector")])
    contrast = i["Contrast"]
    d = b.vector("MULTIPLY_ADD", i["Luminance"], contrast, b.math("SUBTRACT", 1.0, contrast))
    d = b.vector("MAXIMUM", d, (1e-4, 1e-4, 1e-4))
    sharp = _power(b, i["Weights"], i["Sharpness"])
    w = b.vector("MULTIPLY", d, sharp)
    finish_group(b, [b.vector("DIVIDE", w, b.vector("DOT_PRODUCT", w, (1.0, 1.0, 1.0)))])
    return group


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
    grid = b.node("ShaderNodeGroup", node_tree=shared_group(GRID, _build_grid))
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
    weights = b.node("ShaderNodeGroup", node_tree=shared_group(WEIGHTS, _build_weights))
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
    finish_group(b, [total, opaque_alpha(b)] + ([] if follower else [luminance]))
    return group


def link(op, tree, made, result):
    """The placed group nodes ``made`` (the active map's first) given the mode's settings, and
    the followers the active map's luminances."""
    _, turns = result
    for node in made:
        for socket, value in (("Rotation", op.rotation), ("Turns", float(turns)),
                              ("Contrast", op.contrast), ("Sharpness", op.sharpness)):
            node.inputs[socket].default_value = value
    for node in made[1:]:
        tree.links.new(made[0].outputs["Luminance"], node.inputs["Luminance"])
