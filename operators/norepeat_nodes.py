"""The node groups of ``texsynth.break_repetition``, built by code.

Tiling and blending (Heitz & Neyret 2018; Deliot & Heitz 2019, 1.2-1.5), as two groups that
every material shares and one small group per map that holds the map's images:

* **TexSynth Triangle Grid** (Vector, Scale, Seed -> UV 1-3, Weights): the texture space skewed
  onto a triangle grid (Deliot & Heitz's ``TriangleGrid``), each of the point's three triangle
  vertices given a random offset by a hash (the White Noise texture of the integer vertex and
  the seed) snapped to whole texels of the map (Texels: its width and height), and the
  barycentric weights;
* **TexSynth Variance-Preserving Blend** (Gaussian 1-3, Weights -> Table 1-3): ``(sum w_i G_i -
  1/2) / sqrt(sum w_i^2) + 1/2`` (Heitz & Neyret 2018, 3.1), as the three look-up coordinates
  into the table's rows;
* **TexSynth T&B <image>** per map: the grid, three reads of the Gaussianised image, the blend,
  three reads of the table (``texsynth.norepeat.Gaussianized``: the inverse PCA is folded into
  its rows) and their sum.

Only Math, Vector Math, Separate/Combine XYZ, White Noise and Image Texture nodes: Cycles and
EEVEE both run them. Deviations: Blender's White Noise hash, not the paper's sine hash; offsets
snapped to whole texels, so a linear read of an offset copy blurs no more than the plain
texture's (a sub-texel offset averages neighbouring texels, which the variance-preserving blend
does not undo: fine-grained photos came out soft); the table read at its closest entry (4096
entries: a render changed by at most 1/255, and took about 15 % less time than with linear
reads).
"""

import bpy

from ..texsynth.norepeat import GRID_SCALE

GRID = "TexSynth Triangle Grid"
BLEND = "TexSynth Variance-Preserving Blend"
#: Custom property marking a group as built by this module, with the layout's version.
TAG, VERSION = "texsynth_norepeat", 1
ROWS = 3  # table rows: one per decorrelated channel (grey maps leave two at zero)


class _Builder:
    """Nodes of one tree, added left to right, each input a socket or a constant."""

    def __init__(self, tree):
        self.tree = tree
        self.x = 0

    def node(self, kind, inputs=(), **settings):
        node = self.tree.nodes.new(kind)
        for name, value in settings.items():
            setattr(node, name, value)
        node.location = (self.x, 0)
        self.x += 40
        for socket, value in zip(node.inputs, inputs, strict=False):
            if value is None:
                continue
            if isinstance(value, bpy.types.NodeSocket):
                self.tree.links.new(value, socket)
            else:
                socket.default_value = value
        return node

    def math(self, operation, *inputs):
        return self.node("ShaderNodeMath", inputs, operation=operation).outputs[0]

    def vector(self, operation, *inputs):
        node = self.node("ShaderNodeVectorMath", inputs, operation=operation)
        return node.outputs["Value" if operation in ("DOT_PRODUCT", "LENGTH") else "Vector"]

    def scale(self, vector, factor):
        node = self.node("ShaderNodeVectorMath", (vector,), operation="SCALE")
        self.tree.links.new(factor, node.inputs["Scale"])
        return node.outputs["Vector"]

    def separate(self, vector):
        return self.node("ShaderNodeSeparateXYZ", (vector,)).outputs

    def combine(self, *values):
        return self.node("ShaderNodeCombineXYZ", values).outputs[0]


def _new_group(name, inputs, outputs):
    """An empty shader group with the named sockets ((name, type, default) / (name, type))."""
    group = bpy.data.node_groups.new(name, "ShaderNodeTree")
    group[TAG] = VERSION
    for socket_name, kind, *default in inputs:
        socket = group.interface.new_socket(socket_name, in_out="INPUT",
                                            socket_type=f"NodeSocket{kind}")
        if default:
            socket.default_value = default[0]
    for socket_name, kind in outputs:
        group.interface.new_socket(socket_name, in_out="OUTPUT", socket_type=f"NodeSocket{kind}")
    b = _Builder(group)
    return group, b, b.node("NodeGroupInput").outputs


def _finish(b, values):
    out = b.node("NodeGroupOutput")
    for socket, value in zip(out.inputs, values, strict=False):
        b.tree.links.new(value, socket)


def _build_grid():
    group, b, i = _new_group(GRID, [("Vector", "Vector"), ("Scale", "Float", GRID_SCALE),
                                    ("Seed", "Float", 0.0), ("Texels", "Vector")],
                             [("UV 1", "Vector"), ("UV 2", "Vector"), ("UV 3", "Vector"),
                              ("Weights", "Vector")])
    u, v, _ = b.separate(i["Vector"])
    # skewed = SKEW @ uv * scale (texsynth.norepeat.blend.SKEW)
    sx = b.math("MULTIPLY", u, i["Scale"])
    sy = b.math("MULTIPLY", b.math("SUBTRACT", b.math("MULTIPLY", v, 2 / 3 ** 0.5),
                                   b.math("MULTIPLY", u, 1 / 3 ** 0.5)), i["Scale"])
    bx, by = b.math("FLOOR", sx), b.math("FLOOR", sy)
    fx, fy = b.math("SUBTRACT", sx, bx), b.math("SUBTRACT", sy, by)
    z = b.math("SUBTRACT", b.math("SUBTRACT", 1.0, fx), fy)
    c = b.math("GREATER_THAN", z, 0.0)  # 1 below the diagonal
    n = b.math("SUBTRACT", 1.0, c)
    weights = b.combine(b.math("ABSOLUTE", z), b.math("ABSOLUTE", b.math("SUBTRACT", n, fy)),
                        b.math("ABSOLUTE", b.math("SUBTRACT", n, fx)))
    corners = ((n, n), (n, c), (c, n))  # below: (0,0) (0,1) (1,0); above: (1,1) (1,0) (0,1)
    uvs = []
    for dx, dy in corners:
        vertex = b.combine(b.math("ADD", bx, dx), b.math("ADD", by, dy), i["Seed"])
        offset = b.node("ShaderNodeTexWhiteNoise", (vertex,), noise_dimensions="3D")
        r, g, _ = b.separate(offset.outputs["Color"])
        whole = b.vector("FLOOR", b.vector("MULTIPLY", b.combine(r, g, 0.0), i["Texels"]))
        uvs.append(b.vector("ADD", i["Vector"], b.vector("DIVIDE", whole, i["Texels"])))
    _finish(b, uvs + [weights])
    return group


def _build_blend():
    group, b, i = _new_group(BLEND, [("Gaussian 1", "Color"), ("Gaussian 2", "Color"),
                                     ("Gaussian 3", "Color"), ("Weights", "Vector")],
                             [(f"Table {k + 1}", "Vector") for k in range(ROWS)])
    w = b.separate(i["Weights"])
    total = None
    for k in range(3):
        term = b.scale(i[f"Gaussian {k + 1}"], w[k])
        total = term if total is None else b.vector("ADD", total, term)
    norm = b.math("SQRT", b.vector("DOT_PRODUCT", i["Weights"], i["Weights"]))
    g = b.vector("ADD", b.scale(b.vector("SUBTRACT", total, (0.5, 0.5, 0.5)),
                                b.math("DIVIDE", 1.0, norm)), (0.5, 0.5, 0.5))
    channels = b.separate(g)
    _finish(b, [b.combine(channels[k], (k + 0.5) / ROWS, 0.0) for k in range(ROWS)])
    return group


def shared_group(name):
    """The shared group ``name`` (GRID or BLEND): the file's own if built by this version, else
    a new one (a group the user renamed or edited under that name is left alone)."""
    for group in bpy.data.node_groups:
        if group.name.startswith(name) and group.get(TAG) == VERSION \
                and group.bl_idname == "ShaderNodeTree":
            return group
    return {GRID: _build_grid, BLEND: _build_blend}[name]()


def map_group(name, gaussian, table, interpolation):
    """A new group (Vector, Scale, Seed -> Color, Alpha) tiling and blending one map, from its
    Gaussianised image and table image."""
    group, b, i = _new_group(name, [("Vector", "Vector"), ("Scale", "Float", GRID_SCALE),
                                    ("Seed", "Float", 0.0)],
                             [("Color", "Color"), ("Alpha", "Float")])
    grid = b.node("ShaderNodeGroup", node_tree=shared_group(GRID))
    for socket in ("Vector", "Scale", "Seed"):
        b.tree.links.new(i[socket], grid.inputs[socket])
    grid.inputs["Texels"].default_value = (*gaussian.size, 1.0)
    blend = b.node("ShaderNodeGroup", node_tree=shared_group(BLEND))
    for k in range(3):
        read = b.node("ShaderNodeTexImage", (grid.outputs[f"UV {k + 1}"],), image=gaussian,
                      interpolation=interpolation, extension="REPEAT")
        b.tree.links.new(read.outputs["Color"], blend.inputs[f"Gaussian {k + 1}"])
    b.tree.links.new(grid.outputs["Weights"], blend.inputs["Weights"])
    total = None
    for k in range(ROWS):
        read = b.node("ShaderNodeTexImage", (blend.outputs[f"Table {k + 1}"],), image=table,
                      interpolation="Closest", extension="EXTEND")
        term = read.outputs["Color"]
        total = term if total is None else b.vector("ADD", total, term)
    opaque = b.node("ShaderNodeValue")
    opaque.outputs[0].default_value = 1.0
    _finish(b, [total, opaque.outputs[0]])
    return group
