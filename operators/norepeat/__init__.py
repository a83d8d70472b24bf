"""``texsynth.break_repetition``: the active Image Texture node's texture made never to repeat
at render time, the other selected Image Texture nodes of the material following.

The wing mirrors the core's ``texsynth/norepeat/``: one module per mode, each holding what the
mode computes before rendering and the node groups that render it,

* ``blend.py``: **Tiling and Blending** (Heitz & Neyret 2018; Deliot & Heitz 2019), the
  Gaussianised texture and inverse table per map;
* ``tiles.py``: **Tile Set** (Wang tiles: Cohen et al. 2003; Wei 2004), an atlas of tiles per
  map, picked per cell from hashed edge colours;
* ``hex.py``: **Hex Tiling** (Mikkelsen 2022), no precomputation, the user's own image read
  three times;

and two helpers: ``nodes.py`` (the group builder, the groups' version tag) and ``maps.py``
(the maps as the shaders read them). ``MODES`` is the table of the mode modules; each has one
interface, which is all this operator calls:

* ``ITEM``: the Mode enum's item; ``SETTINGS``: the operator settings its redo panel shows;
  ``DONE``: the report's verb;
* ``prepare(op, src, nodes) -> Task``: check every map and copy it out of Blender
  (``ValueError`` on bad input, nothing made);
* ``scale(op, result)``: the value of the shared Scale node;
* ``groups(op, result, nodes)``: one new node group per source node, in order;
* ``link(op, tree, made, result)``: the placed group nodes' own settings and links.

Every map's group node is fed by the same Vector (the active node's, so a Mapping node in front
keeps working), and by one Scale and one Seed value node, so albedo, roughness and normal get
the same cells. The user's images and nodes are kept; everything is checked and computed
before anything is made: on error or cancel the file is unchanged, and one Ctrl+Z undoes the
whole (``tests/blender/test_break_repetition_undo.py``).
"""

import bpy

from ...texsynth.norepeat import GRID_SCALE
from ...texsynth.norepeat.hex import CONTRAST, SHARPNESS
from ...texsynth.norepeat.tiles import COLOURS
from .. import pixels, source
from ..job import JobOperator
from . import blend, hex, tiles

#: The mode modules, in the Mode enum's order.
MODES = {module.ITEM[0]: module for module in (blend, tiles, hex)}
#: The hint under the buttons: which mode suits which photo. Bricks and setts: Tile Set, the
#: one mode that keeps them whole (no blend; its diamonds and tile middles placed in phase
#: with the courses); the other two offset copies freely and blend or cut across joints.
HINT = "Bricks, setts, tiles: Tile Set (keeps them whole); gravel, grass: Tiling and " \
    "Blending; rock: Hex Tiling"
GAP = 300.0  # the new node's place below its source node


class TEXSYNTH_OT_break_repetition(JobOperator, bpy.types.Operator):
    """Make the active Image Texture node's texture never repeat at render time (the other
    selected Image Texture nodes follow with the same cells): Tiling and Blending for
    stochastic photos, Tile Set for regular ones; new images and node groups, the originals
    kept"""

    bl_idname = "texsynth.break_repetition"
    bl_label = "Break Repetition"
    bl_options = {"REGISTER", "UNDO"}

    mode: bpy.props.EnumProperty(name="Mode", items=[m.ITEM for m in MODES.values()],
                                 default=blend.ITEM[0], options={"SKIP_SAVE"})
    scale: bpy.props.FloatProperty(
        name="Scale", default=GRID_SCALE, min=0.5, max=64.0, options={"SKIP_SAVE"},
        description="Tiling and Blending: triangle-grid cells per texture tile, larger gives "
        "smaller patches (Tile Set sets its Scale node from the tile side instead, so that "
        "texels keep their size)")
    seed: bpy.props.IntProperty(name="Seed", min=0, default=0, options={"SKIP_SAVE"},
                                description="Picks the random offsets (Tile Set: the tiles "
                                "and the edge colours)")
    colours: bpy.props.IntProperty(
        name="Edge Colours", default=COLOURS, min=2, max=4, options={"SKIP_SAVE"},
        description="Tile Set: colours per edge direction; colours^4 tiles (more: less "
        "repetition, a larger atlas and a longer precomputation)")
    rotation: bpy.props.FloatProperty(
        name="Rotation", default=1.0, min=0.0, max=1.0, options={"SKIP_SAVE"},
        description="Hex Tiling: the cells' angles span this fraction of a full turn, rounded "
        "to the Turns")
    turns: bpy.props.EnumProperty(
        name="Turns", items=hex.TURNS, default="AUTO", options={"SKIP_SAVE"},
        description="Hex Tiling: the angles a cell may turn by")
    contrast: bpy.props.FloatProperty(
        name="Contrast", default=CONTRAST, min=0.0, max=1.0, options={"SKIP_SAVE"},
        description="Hex Tiling: how much the brighter copy wins at the seams (luminance)")
    sharpness: bpy.props.FloatProperty(
        name="Sharpness", default=SHARPNESS, min=1.0, max=64.0, options={"SKIP_SAVE"},
        description="Hex Tiling: the weights' exponent; larger gives narrower seams")

    def draw(self, context):
        """The redo panel: the mode and its own settings."""
        self.layout.prop(self, "mode")
        for name in MODES[self.mode].SETTINGS:
            self.layout.prop(self, name)

    def prepare(self, context):
        """Check every map and copy it out of Blender (the mode's work); raises
        ``ValueError``."""
        src = source.find_source(context)
        tree = bpy.data.materials[src.material].node_tree
        nodes = [tree.nodes[src.node]] + source.follower_nodes(context, src)
        for node in nodes:
            if node.image.source not in pixels.SUPPORTED_SOURCES:
                raise ValueError(f"Image '{node.image.name}' is a {node.image.source.lower()}; "
                                 "only single still images can be made not to repeat")
        return MODES[self.mode].prepare(self, src, nodes), (src, [n.name for n in nodes])

    def make(self, result, plan):
        src, names = plan
        mode = MODES[self.mode]
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
        scale, seed = tree.nodes.new("ShaderNodeValue"), tree.nodes.new("ShaderNodeValue")
        for node, label, value, dy in ((scale, "Scale", mode.scale(self, result), 0.0),
                                       (seed, "Seed", float(self.seed), -100.0)):
            node.label = f"TexSynth {label}"
            node.outputs[0].default_value = value
            node.location = (x, y - GAP + dy)
        sources = [tree.nodes[n] for n in names]
        made = [self._place(tree, node, group, vector, scale, seed)
                for node, group in zip(sources, mode.groups(self, result, sources), strict=True)]
        mode.link(self, tree, made, result)
        for node in tree.nodes:
            node.select = False
        made[0].select = True
        tree.nodes.active = made[0]
        return (f"Break Repetition: {len(made)} map(s) {mode.DONE}: "
                + ", ".join(f"'{n.node_tree.name}'" for n in made))

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
