"""The new Image Texture node: beside the source node, taking over its links."""

# Below the source node: an Image Texture node is about 270 units tall.
NODE_OFFSET_Y = 300.0
COPIED_SETTINGS = ("interpolation", "projection", "projection_blend")


def add_result_node(tree, source, image):
    """A new Image Texture node showing ``image``, wired like ``source`` and made active.

    The source node stays where it is, its inputs still linked; every socket its outputs fed
    is fed by the new node instead (an input takes one link, so the new link replaces the old).
    """
    node = tree.nodes.new("ShaderNodeTexImage")
    node.parent = source.parent
    node.location = (source.location.x, source.location.y - NODE_OFFSET_Y)
    node.image = image
    for name in COPIED_SETTINGS:
        setattr(node, name, getattr(source, name))
    node.extension = "REPEAT"  # the texture tiles
    for link in list(tree.links):
        if link.to_node == source:
            tree.links.new(link.from_socket, _socket(node.inputs, link.to_socket))
        elif link.from_node == source:
            tree.links.new(_socket(node.outputs, link.from_socket), link.to_socket)
    for other in tree.nodes:
        other.select = False
    node.select = True
    tree.nodes.active = node
    return node


def _socket(sockets, like):
    return next(s for s in sockets if s.identifier == like.identifier)
