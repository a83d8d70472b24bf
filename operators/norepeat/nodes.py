"""Node-group building shared by the modes of ``texsynth.break_repetition``: a builder that
adds nodes left to right, new groups tagged with the layout's version, and the lookup of a
shared group a file already holds.

A group built here carries the custom property ``TAG`` = ``VERSION``; a file's shared group
(the grid, the blend, the cells) is reused only when it carries this version, so a group the
user renamed or edited under that name, or one an older layout built, is left alone and a new
one made. Raise ``VERSION`` whenever a shared group's layout changes.
"""

import bpy

#: Custom property marking a group as built by this wing, with the layout's version.
TAG, VERSION = "texsynth_norepeat", 4


class Builder:
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


def new_group(name, inputs, outputs):
    """An empty shader group with the named sockets ((name, type, default) / (name, type)),
    tagged; its builder and its Group Input's outputs."""
    group = bpy.data.node_groups.new(name, "ShaderNodeTree")
    group[TAG] = VERSION
    for socket_name, kind, *default in inputs:
        socket = group.interface.new_socket(socket_name, in_out="INPUT",
                                            socket_type=f"NodeSocket{kind}")
        if default:
            socket.default_value = default[0]
    for socket_name, kind in outputs:
        group.interface.new_socket(socket_name, in_out="OUTPUT", socket_type=f"NodeSocket{kind}")
    b = Builder(group)
    return group, b, b.node("NodeGroupInput").outputs


def finish_group(b, values):
    """The group's Group Output, fed ``values`` in the order of its sockets."""
    out = b.node("NodeGroupOutput")
    for socket, value in zip(out.inputs, values, strict=False):
        b.tree.links.new(value, socket)


def shared_group(name, build):
    """The shared group ``name``: the file's own if built by this version, else ``build()``'s
    new one."""
    for group in bpy.data.node_groups:
        if group.name.startswith(name) and group.get(TAG) == VERSION \
                and group.bl_idname == "ShaderNodeTree":
            return group
    return build()


def opaque_alpha(b):
    """A Value node's output of 1: the Alpha of an opaque map."""
    one = b.node("ShaderNodeValue")
    one.outputs[0].default_value = 1.0
    return one.outputs[0]


def stem(image):
    """An image's name without its extension: the new datablocks' prefix."""
    return image.name.rsplit(".", 1)[0]
