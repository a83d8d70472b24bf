"""``texsynth.break_repetition``: the active Image Texture node's texture made never to repeat
at render time, the other selected Image Texture nodes of the material following.

Mode **Tiling and Blending** (Heitz & Neyret 2018; Deliot & Heitz 2019; Burley 2019's
truncated Gaussian): ``texsynth.norepeat.gaussianize`` precomputes each map's Gaussianised
texture, stored as a new packed float image (Non-Color), and inverse table, held by an RGB
Curves node; a new group node per map (``norepeat_nodes.map_group``) reads them through the
shared node groups and takes over the source node's outgoing links. Every map's group node is
fed by the same Vector (the active node's, so a Mapping node in front keeps working), and by
one Scale and one Seed value node, so albedo, roughness and normal get the same cells. Values
are precomputed as the shader reads them: byte sRGB images decoded to scene-linear, float
images as Blender holds them, Non-Color data as stored.

Mode **Tile Set** (Wang tiles: Cohen et al. 2003; Wei 2004): ``texsynth.norepeat.wang_tiles``
cuts the active map's photo into ``colours**4`` tiles whose edges match, in one atlas with
gutters; the followers' atlases come from the same photo pixels (its position map). Each atlas
is a new packed image stored as its source is (byte or float, the same colour space: the atlas
holds the photo's own values, so any colour space works); a group node per map
(``norepeat_tileset.map_group``) picks each cell's tile from hashed edge colours. The Scale node
is set so that texels keep their size (the photo's width over the tile side).

Mode **Hex Tiling** (Mikkelsen 2022): no precomputation; a group node per map
(``norepeat_hex_nodes.map_group``) reads the user's own image three times, on hexagonal cells
each with a random offset and rotation, blended with the paper's luminance-weighted sharpened
weights; by default the cells turn only by the active map's own symmetry
(``texsynth.norepeat.rotation_symmetry``: half turns, quarter turns for a 4-fold photo), so a
photo's courses, layers and light keep their direction; the followers take the active map's
luminances, so all maps blend alike, and a follower that is a normal map (Non-Color, and its
values decode to unit vectors pointing out) has its normals turned with the cells.

The user's images and nodes are kept; everything is checked and computed before anything is
made: on error or cancel the file is unchanged, and one Ctrl+Z undoes the whole
(``tests/blender/test_break_repetition_undo.py``).
"""

import bpy
import numpy as np

from .. import texsynth
from ..texsynth.blocks.color import srgb_to_linear
from ..texsynth.norepeat import GRID_SCALE, gaussianize, predict_memory
from ..texsynth.norepeat.gaussian import MU
from ..texsynth.norepeat.hex import CONTRAST, SHARPNESS, rotation_symmetry
from . import norepeat_hex_nodes, norepeat_nodes, norepeat_tileset, pixels, source
from .job import JobOperator, Task

MODES = [("TILING_AND_BLENDING", "Tiling and Blending",
          "Histogram-preserving blend of randomly offset copies on a triangle grid: for "
          "stochastic textures (gravel, grass, sand, rock); structured ones show ghosts"),
         ("TILE_SET", "Tile Set",
          "Wang tiles cut from the photo, picked per cell so that neighbours always match, "
          "no blending: for regular and structured textures (bricks, pavers, setts)"),
         ("HEX_TILING", "Hex Tiling",
          "Randomly offset and turned copies on hexagonal cells, the brighter copy winning "
          "at a sharp seam (Mikkelsen 2022): for structured textures (layered rock, bark) and "
          "normal maps; no precomputation")]
#: Hex Tiling's turns: the enum's items and the turns each asks for (AUTO: the photo's own).
TURNS = [("AUTO", "Photo's Symmetry", "Half turns, or quarter turns for a photo with a "
          "4-fold but no 2-fold direction (square setts, tiles): the photo's direction kept"),
         ("HALF", "Half Turns", "Every cell upright or upside down"),
         ("QUARTER", "Quarter Turns", "Multiples of 90 degrees"),
         ("ANY", "Any Angle", "Any angle within Rotation: for textures with no direction "
          "and no light direction (turns courses, layers and shadows every way)"),
         ("NONE", "None", "Offsets only")]
TURN_COUNTS = {"HALF": 2, "QUARTER": 4, "ANY": 0, "NONE": 1}
#: The hint under the buttons: which mode suits which photo. Bricks and setts: Tile Set, the
#: one mode that keeps them whole (no blend; its diamonds and tile middles placed in phase
#: with the courses); the other two offset copies freely and blend or cut across joints.
HINT = "Bricks, setts, tiles: Tile Set (keeps them whole); gravel, grass: Tiling and " \
    "Blending; rock: Hex Tiling"
#: The image made per map: the Gaussianised texture (name suffix; the table is a curve node).
SUFFIXES = ("tnb_gaussian",)
GAP = 300.0  # the new node's place below its source node


def _opaque(image, values):
    """``values`` (read_exemplar's), or ``ValueError`` for a varying alpha."""
    if values.shape[2] == 4:
        raise ValueError(f"Image '{image.name}' has a varying alpha; Break Repetition handles "
                         "opaque textures only")
    return values


def _shader_values(image, values, encoding):
    """``values`` (read_exemplar's) as the shader reads them, (H, W, 3): scene-linear colour or
    data; ``ValueError`` for what the precomputation cannot take."""
    _opaque(image, values)
    if not encoding.is_float and not encoding.is_data:
        if encoding.colorspace != "sRGB":
            raise ValueError(f"Image '{image.name}' is in colour space '{encoding.colorspace}'; "
                             "set it to sRGB or Non-Color, or use a float image")
        values = srgb_to_linear(values).astype(np.float32)
    return values


def _looks_like_normals(values):
    """A tangent-space normal map's content: 3 channels whose decoded vectors ``2 v - 1`` are
    about unit long, pointing out of the surface (blue above 1/2) and tilted both ways on
    average (red and green about 1/2)."""
    if values.shape[2] != 3:
        return False
    n = 2.0 * values.reshape(-1, 3)[::max(1, values.shape[0] * values.shape[1] // 65536)] - 1.0
    return bool(np.median(np.abs(np.linalg.norm(n, axis=1) - 1.0)) < 0.1
                and np.median(n[:, 2]) > 0.3 and np.all(np.abs(n[:, :2].mean(axis=0)) < 0.2))


def _precompute(maps, progress=None):
    """Each map's ``Gaussianized`` (the job's work: numpy only)."""
    report = texsynth.Progress(progress)
    out = []
    for n, (_, values) in enumerate(maps):
        report(n / len(maps), f"Gaussianising map {n + 1} of {len(maps)}")
        out.append(gaussianize(values))
    report(1.0, "Done")
    return out


def _padded(g):
    """The Gaussian texture centred (``G - 1/2``, as the blend group takes it) as (H, W, 4) RGBA
    for Blender and the table as curves (N, 3); a grey map's one channel is repeated into all
    three."""
    h, w, c = g.gaussian.shape
    gaussian = np.ones((h, w, 4), np.float32)
    gaussian[:, :, :3] = (g.gaussian if c == 3 else g.gaussian[:, :, :1]) - MU
    curves = g.curves()
    return gaussian, curves if c == 3 else np.repeat(curves, 3, axis=1)


def _float_image(name, rgba):
    """A new packed float image (Non-Color) of ``rgba`` (H, W, 4), top row first."""
    h, w = rgba.shape[:2]
    image = bpy.data.images.new(name, w, h, alpha=True, float_buffer=True)
    image.colorspace_settings.name = "Non-Color"
    image.alpha_mode = "NONE"
    image.pixels.foreach_set(np.ascontiguousarray(rgba[::-1]).ravel())
    image.pack()
    return image


class TEXSYNTH_OT_break_repetition(JobOperator, bpy.types.Operator):
    """Make the active Image Texture node's texture never repeat at render time (the other
    selected Image Texture nodes follow with the same cells): Tiling and Blending for
    stochastic photos, Tile Set for regular ones; new images and node groups, the originals
    kept"""

    bl_idname = "texsynth.break_repetition"
    bl_label = "Break Repetition"
    bl_options = {"REGISTER", "UNDO"}

    mode: bpy.props.EnumProperty(name="Mode", items=MODES, default="TILING_AND_BLENDING",
                                 options={"SKIP_SAVE"})
    scale: bpy.props.FloatProperty(
        name="Scale", default=GRID_SCALE, min=0.5, max=64.0, options={"SKIP_SAVE"},
        description="Tiling and Blending: triangle-grid cells per texture tile, larger gives "
        "smaller patches (Tile Set sets its Scale node from the tile side instead, so that "
        "texels keep their size)")
    seed: bpy.props.IntProperty(name="Seed", min=0, default=0, options={"SKIP_SAVE"},
                                description="Picks the random offsets (Tile Set: the tiles "
                                "and the edge colours)")
    colours: bpy.props.IntProperty(
        name="Edge Colours", default=2, min=2, max=4, options={"SKIP_SAVE"},
        description="Tile Set: colours per edge direction; colours^4 tiles (more: less "
        "repetition, a larger atlas and a longer precomputation)")
    rotation: bpy.props.FloatProperty(
        name="Rotation", default=1.0, min=0.0, max=1.0, options={"SKIP_SAVE"},
        description="Hex Tiling: the cells' angles span this fraction of a full turn, rounded "
        "to the Turns")
    turns: bpy.props.EnumProperty(
        name="Turns", items=TURNS, default="AUTO", options={"SKIP_SAVE"},
        description="Hex Tiling: the angles a cell may turn by")
    contrast: bpy.props.FloatProperty(
        name="Contrast", default=CONTRAST, min=0.0, max=1.0, options={"SKIP_SAVE"},
        description="Hex Tiling: how much the brighter copy wins at the seams (luminance)")
    sharpness: bpy.props.FloatProperty(
        name="Sharpness", default=SHARPNESS, min=1.0, max=64.0, options={"SKIP_SAVE"},
        description="Hex Tiling: the weights' exponent; larger gives narrower seams")

    def draw(self, context):
        """The redo panel: each mode's own settings."""
        layout = self.layout
        layout.prop(self, "mode")
        layout.prop(self, "colours" if self.mode == "TILE_SET" else "scale")
        layout.prop(self, "seed")
        if self.mode == "HEX_TILING":
            for name in ("turns", "rotation", "contrast", "sharpness"):
                layout.prop(self, name)

    def prepare(self, context):
        """Check every map and copy it out of Blender; raises ``ValueError``."""
        src = source.find_source(context)
        tree = bpy.data.materials[src.material].node_tree
        nodes = [tree.nodes[src.node]] + source.follower_nodes(context, src)
        for node in nodes:
            if node.image.source not in pixels.SUPPORTED_SOURCES:
                raise ValueError(f"Image '{node.image.name}' is a {node.image.source.lower()}; "
                                 "only single still images can be made not to repeat")
        if self.mode == "TILE_SET":
            return self._prepare_tiles(src, nodes)
        budget_need = 0.0
        for node in nodes:
            w, h = node.image.size
            budget_need = max(budget_need, predict_memory((h, w, 3)) + 32.0 * w * h)
        texsynth.validation.check_memory(budget_need, "Break Repetition",
                                         "use smaller images")
        maps, normals = [], []
        for node in nodes:
            values, encoding = pixels.read_exemplar(node.image)
            if min(values.shape[:2]) < 2:
                raise ValueError(f"Image '{node.image.name}' is {values.shape[1]} x "
                                 f"{values.shape[0]} pixels; it needs at least 2 x 2")
            maps.append((node.name, _shader_values(node.image, values, encoding)))
            normals.append(encoding.is_data and _looks_like_normals(values))
        if self.mode == "HEX_TILING":  # nothing to precompute: the flags and the turns
            turns = TURN_COUNTS.get(self.turns)
            image = maps[0][1]
            return Task(lambda progress=None: (normals, rotation_symmetry(image) if turns is None
                                               else turns)), (src, [n.name for n in nodes])
        return Task(_precompute, maps), (src, [n.name for n in nodes])

    def _prepare_tiles(self, src, nodes):
        """Tile Set: every map of one size, opaque; the stored values (no colour conversion:
        the atlas is read as the source image is)."""
        w, h = nodes[0].image.size
        for node in nodes[1:]:
            if tuple(node.image.size) != (w, h):
                raise ValueError(f"Image '{node.image.name}' of node '{node.name}' is "
                                 f"{node.image.size[0]} x {node.image.size[1]}, not {w} x {h} "
                                 f"like '{src.image}': Tile Set needs the maps of one size")
        norepeat_tileset.check(nodes[0].image, len(nodes), self.colours)
        maps = [_opaque(node.image, pixels.read_exemplar(node.image)[0]) for node in nodes]
        job = Task(norepeat_tileset.precompute, maps, colours=self.colours, seed=self.seed)
        return job, (src, [n.name for n in nodes])

    def make(self, result, plan):
        src, names = plan
        tree, active = source.source_node(src)
        if tree is None:
            raise ValueError(f"Node '{src.node}' of material '{src.material}' is gone")
        vector = next((link.from_socket for link in tree.links
                       if link.to_node == active and link.to_socket.name == "Vector"), None)
        x, y = active.location.x - 200.0, active.location.y
        if vector is None:  # the image node's own default: the active UV map
            coords = tree.nodes.new("ShaderNodeUVMap")
            coords.location = (x - 200.0, y)
            vector = coords.outputs["UV"]
        tiles = self.mode == "TILE_SET"
        scale_value = norepeat_tileset.cells_per_tile(result) if tiles else self.scale
        scale, seed = tree.nodes.new("ShaderNodeValue"), tree.nodes.new("ShaderNodeValue")
        for node, label, value, dy in ((scale, "Scale", scale_value, 0.0),
                                       (seed, "Seed", float(self.seed), -100.0)):
            node.label = f"TexSynth {label}"
            node.outputs[0].default_value = value
            node.location = (x, y - GAP + dy)
        if tiles:
            groups = norepeat_tileset.map_groups(result, [tree.nodes[n] for n in names])
        elif self.mode == "HEX_TILING":
            normals, turns = result
            groups = [self._hex_group(tree.nodes[n], normal, k > 0)
                      for k, (n, normal) in enumerate(zip(names, normals, strict=True))]
        else:
            groups = [self._blend_group(tree.nodes[n], g) for n, g in zip(names, result,
                                                                         strict=True)]
        made = [self._place(tree, tree.nodes[name], group, vector, scale, seed)
                for name, group in zip(names, groups, strict=True)]
        if self.mode == "HEX_TILING":
            norepeat_hex_nodes.link(tree, made, self.rotation, turns, self.contrast,
                                    self.sharpness)
        for node in tree.nodes:
            node.select = False
        made[0].select = True
        tree.nodes.active = made[0]
        done = {"TILE_SET": "set with Wang tiles", "HEX_TILING": "hex-tiled"}.get(
            self.mode, "tiled and blended")
        return (f"Break Repetition: {len(made)} map(s) {done}: "
                + ", ".join(f"'{n.node_tree.name}'" for n in made))

    @staticmethod
    def _blend_group(node, g):
        """Tiling and Blending: one map's new image and its group."""
        stem = node.image.name.rsplit(".", 1)[0]
        gaussian, curves = _padded(g)
        image = _float_image(f"{stem}_{SUFFIXES[0]}", gaussian)
        return norepeat_nodes.map_group(f"TexSynth T&B {stem}", image, curves, node.interpolation)

    @staticmethod
    def _hex_group(node, normal, follower):
        """Hex Tiling: one map's group over its own image."""
        stem = node.image.name.rsplit(".", 1)[0]
        return norepeat_hex_nodes.map_group(f"TexSynth Hex {stem}", node.image,
                                            node.interpolation, normal=normal,
                                            follower=follower)

    @staticmethod
    def _place(tree, source_node, group, vector, scale, seed):
        """A group node for ``group`` below ``source_node``, taking over its outgoing links."""
        node = tree.nodes.new("ShaderNodeGroup")
        node.node_tree = group
        node.parent = source_node.parent
        node.location = (source_node.location.x, source_node.location.y - GAP)
        tree.links.new(vector, node.inputs["Vector"])
        tree.links.new(scale.outputs[0], node.inputs["Scale"])
        tree.links.new(seed.outputs[0], node.inputs["Seed"])
        for link in list(tree.links):
            if link.from_node == source_node and link.from_socket.name in ("Color", "Alpha"):
                tree.links.new(node.outputs[link.from_socket.name], link.to_socket)
        return node


classes = (TEXSYNTH_OT_break_repetition,)
register, unregister = bpy.utils.register_classes_factory(classes)
