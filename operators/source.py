"""Which image to work on (a named image, or the active Image Texture node's), and the other
maps of its material that follow it (the selected Image Texture nodes)."""

from dataclasses import dataclass

import bpy
import numpy as np

from . import pixels


@dataclass(frozen=True)
class Source:
    """The source image, and the material and node holding it (names: safe across undo)."""

    image: str
    material: str = ""  # empty when the image was named directly: no node is added
    node: str = ""


def find_source(context, image_name: str = "") -> Source:
    """The image named ``image_name``, else the active Image Texture node's image (with its
    material and node); ``ValueError`` saying what to select when there is none."""
    if image_name:
        if image_name not in bpy.data.images:
            raise ValueError(f"No image named '{image_name}'")
        return Source(image_name)
    obj = context.active_object
    if obj is None:
        raise ValueError("No active object: select the object whose material holds the image")
    material = obj.active_material
    if material is None:
        raise ValueError(f"Object '{obj.name}' has no active material")
    if material.node_tree is None:
        raise ValueError(f"Material '{material.name}' has no shader nodes")
    node = material.node_tree.nodes.active
    if node is None:
        raise ValueError(f"Material '{material.name}' has no active node: click the Image "
                         "Texture node to synthesize from")
    if node.bl_idname != "ShaderNodeTexImage":
        raise ValueError(f"The active node '{node.name}' is a {node.bl_label} node, "
                         "not an Image Texture node")
    if node.image is None:
        raise ValueError(f"Image Texture node '{node.name}' has no image")
    return Source(node.image.name, material.name, node.name)


def source_node(source: Source):
    """The source's material node tree and node, or (None, None) if gone or not wanted."""
    material = bpy.data.materials.get(source.material)
    tree = material.node_tree if material else None
    node = tree.nodes.get(source.node) if tree else None
    return (tree, node) if node else (None, None)


def follower_nodes(context, src: Source):
    """The selected Image Texture nodes with an image, other than the source node."""
    tree = bpy.data.materials[src.material].node_tree
    return [n for n in tree.nodes if n.select and n.bl_idname == "ShaderNodeTexImage"
            and n.name != src.node and n.image is not None]


def read_maps(context, src: Source, followers: bool = True) -> list:
    """``(node name, image, pixels, encoding)`` of the source image, then (``followers``) of
    each follower node's image: the one place the maps of a material are read and checked.

    Raises ``ValueError`` naming the image and node when a map holds NaN or infinite values
    (a follower's values are copied as they are, so they would be written into the result) or
    its size differs from the source's.
    """
    nodes = [(src.node, bpy.data.images[src.image])]
    if followers:
        nodes += [(n.name, n.image) for n in follower_nodes(context, src)]
    maps = []
    for node_name, image in nodes:
        values, encoding = pixels.read_exemplar(image)
        if not np.isfinite(values).all():
            raise ValueError(f"Image '{image.name}' of node '{node_name}' contains NaN or "
                             "infinite values; repair or clamp that map first")
        if maps and values.shape[:2] != maps[0][2].shape[:2]:
            h, w = maps[0][2].shape[:2]
            raise ValueError(f"Image '{image.name}' of node '{node_name}' is "
                             f"{values.shape[1]} x {values.shape[0]}, not {w} x {h} like "
                             f"'{src.image}': the maps of a material must have one size")
        maps.append((node_name, image, values, encoding))
    return maps
