"""Source images and materials for the Blender tests, and a fingerprint of the whole file."""

import bpy
import numpy as np


def noise(h=48, w=64, channels=3, seed=0, low=0.1, high=0.9):
    """Values in [low, high]: a small exemplar with some structure at every scale."""
    rng = np.random.default_rng(seed)
    return (low + (high - low) * rng.random((h, w, channels))).astype(np.float32)


def rgba(a):
    """(H, W, C) as (H, W, 4), grey repeated and alpha opaque when missing."""
    a = np.asarray(a, np.float32)
    rgb = np.repeat(a[:, :, :1], 3, 2) if a.shape[2] < 3 else a[:, :, :3]
    alpha = a[:, :, 3:] if a.shape[2] == 4 else np.ones(a.shape[:2] + (1,), np.float32)
    return np.concatenate([rgb, alpha], axis=2)


def generated_image(pixels, name="source", float_buffer=False, colorspace=None):
    """A generated image (no file) holding ``pixels`` (H, W, C), top row first."""
    h, w = pixels.shape[:2]
    image = bpy.data.images.new(name, w, h, alpha=True, float_buffer=float_buffer)
    if colorspace:
        image.colorspace_settings.name = colorspace
    image.pixels.foreach_set(rgba(pixels)[::-1].ravel())
    return image


def pixels_of(image):
    """The image's pixels as (H, W, channels), top row first."""
    w, h = image.size
    buffer = np.empty(len(image.pixels), np.float32)
    image.pixels.foreach_get(buffer)
    return buffer.reshape(h, w, -1)[::-1]


def material_with(image):
    """A plane whose material feeds ``image`` through an active Image Texture node into Base
    Color, its Vector input fed by a Texture Coordinate node. Returns the node tree."""
    mesh = bpy.data.meshes.new("plane")
    obj = bpy.data.objects.new("plane", mesh)
    bpy.context.scene.collection.objects.link(obj)
    bpy.context.view_layer.objects.active = obj
    material = bpy.data.materials.new("material")
    if material.node_tree is None:
        material.use_nodes = True
    mesh.materials.append(material)
    tree = material.node_tree
    shader = next(n for n in tree.nodes if n.bl_idname == "ShaderNodeBsdfPrincipled")
    coords = tree.nodes.new("ShaderNodeTexCoord")
    node = tree.nodes.new("ShaderNodeTexImage")
    node.name = "source node"
    node.image = image
    tree.links.new(coords.outputs["UV"], node.inputs["Vector"])
    tree.links.new(node.outputs["Color"], shader.inputs["Base Color"])
    tree.links.new(node.outputs["Alpha"], shader.inputs["Alpha"])
    tree.nodes.active = node
    return tree


def links(tree):
    return sorted((link.from_node.name, link.from_socket.identifier, link.to_node.name,
                   link.to_socket.identifier) for link in tree.links)


def _image_state(image):
    size = tuple(image.size)  # loads the pixels if needed
    data = pixels_of(image).tobytes() if image.has_data else b""
    return image.name, image.filepath, size, image.colorspace_settings.name, data


def fingerprint():
    """Everything a failed run must leave as it was: datablocks, nodes, links, source pixels."""
    return {
        "images": sorted(_image_state(i) for i in bpy.data.images),
        "objects": sorted(o.name for o in bpy.data.objects),
        "materials": {m.name: (sorted(n.name for n in m.node_tree.nodes), links(m.node_tree),
                               m.node_tree.nodes.active.name if m.node_tree.nodes.active else None)
                      for m in bpy.data.materials if m.node_tree},
    }


def synthesize(**properties):
    """Run the operator and return the one image it made."""
    before = set(bpy.data.images)
    assert bpy.ops.texsynth.synthesize(**properties) == {"FINISHED"}
    (image,) = set(bpy.data.images) - before
    return image
