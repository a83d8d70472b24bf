"""Break Repetition's **Tile Set** mode: the precomputation, the atlas images and the node
groups, built by code; ``texsynth.norepeat.tiles`` is the numpy reference.

Wang tiles (Cohen et al. 2003; Wei 2004's complete set picked per cell from hashed edge
colours): ``texsynth.norepeat.wang_tiles`` cuts ``colours**4`` tiles from the photo into one
atlas with gutters and gives its position map, which makes the followers' atlases (roughness,
normal) from the same photo pixels. In the shader, texture space is cut into square cells;
every cell edge carries a colour hashed from the edge's integer coordinates and the seed, and
each cell shows the atlas tile whose north, east, south and west colours are its edges'.
Neighbours share an edge, so their tiles match along it, with no blending.

* **TexSynth Wang Cells** (Vector, Scale, Seed, Aspect, Colours -> Position, Row, Column),
  shared by every material: ``texsynth.norepeat.wang_tiling`` in nodes. Cell ``(X, Y) =
  floor(u Scale, v Scale Aspect)`` (``v`` up); its edge colours south ``h(X, Y)``, north
  ``h(X, Y + 1)``, west ``g(X, Y)``, east ``g(X + 1, Y)``, where ``h`` and ``g`` are the R and
  G channels of the White Noise texture at ``(X, Y, Seed)`` times ``Colours``, floored; the
  tile's atlas slot row ``n Colours + s`` and column ``w Colours + e``
  (``WangTiles.slot``), and the position ``(frac u, 1 - frac v)`` in the tile, rows down;
* **TexSynth Wang <image>** per map (Vector, Scale, Seed -> Color, Alpha): the cells and one
  read of the map's atlas inside the slot (the gutters serve linear and cubic reads).

Only Math, Separate/Combine XYZ, White Noise and Image Texture nodes: Cycles and EEVEE both
run them. Deviation: Blender's White Noise hash, not the core's integer hash
(``texsynth.norepeat.edge_colours``): the same tiling law, other colours per edge (the tests
compute White Noise's hash in numpy to compare a render with ``wang_tiling``).
"""

import bpy
import numpy as np

from ... import texsynth
from ...texsynth.norepeat import predict_tiles_memory, wang_tiles
from ...texsynth.norepeat.tiles import COLOURS, MIN_TILE, default_tile
from .. import pixels
from ..job import Task
from .maps import check_opaque
from .nodes import finish_group, new_group, opaque_alpha, shared_group, stem

#: The mode's enum item, the operator settings its redo panel shows and its report's verb.
ITEM = ("TILE_SET", "Tile Set",
        "Wang tiles cut from the photo, picked per cell so that neighbours always match, no "
        "blending: for regular and structured textures (bricks, pavers, setts)")
SETTINGS = ("colours", "seed")
DONE = "set with Wang tiles"
CELLS = "TexSynth Wang Cells"
GUTTER = 8  # atlas gutter in pixels (at most a quarter of the tile)
SUFFIX = "wang_atlas"


def prepare(op, src, nodes):
    """The job that cuts the tiles: every map of one size, opaque; the stored values (no
    colour conversion: the atlas is read as the source image is)."""
    w, h = nodes[0].image.size
    for node in nodes[1:]:
        if tuple(node.image.size) != (w, h):
            raise ValueError(f"Image '{node.image.name}' of node '{node.name}' is "
                             f"{node.image.size[0]} x {node.image.size[1]}, not {w} x {h} "
                             f"like '{src.image}': Tile Set needs the maps of one size")
    check(nodes[0].image, len(nodes), op.colours)
    maps = [check_opaque(node.image, pixels.read_exemplar(node.image)[0]) for node in nodes]
    return Task(precompute, maps, colours=op.colours, seed=op.seed)


def check(image, maps, colours):
    """``ValueError`` unless ``image`` is large enough for tiles and its tiles and ``maps``
    atlases (float32 RGBA in numpy and in Blender) fit the memory budget."""
    width, height = image.size
    if default_tile((height, width), colours, GUTTER) < MIN_TILE:
        side = next(s for s in range(MIN_TILE, 4 * MIN_TILE + 4 * GUTTER)
                    if default_tile((s, s), colours, GUTTER) >= MIN_TILE)
        raise ValueError(f"Image '{image.name}' is {width} x {height} pixels; Tile Set needs "
                         f"at least {side} x {side}")
    side = colours ** 2 * (default_tile((height, width), colours, GUTTER) + 2 * GUTTER)
    need = predict_tiles_memory((height, width, 3), colours=colours, gutter=GUTTER) \
        + maps * side * side * 16 * 2.0
    texsynth.validation.check_memory(need, "Break Repetition (Tile Set)", "use smaller images")


def precompute(maps, colours=COLOURS, seed=0, progress=None):
    """The Wang tiles of ``maps[0]`` (H, W, C) and every map's atlas (the followers' by the
    tiles' position map): ``(tiles, atlases)``, numpy only (the job's work)."""
    tiles = wang_tiles(maps[0], colours=colours, gutter=GUTTER, seed=seed, progress=progress)
    atlases = [tiles.atlas] + [texsynth.apply_positions(tiles.positions, m) for m in maps[1:]]
    return tiles, atlases


def scale(op, result):
    """The Scale node's value, so that texels keep their size: cells per texture tile along u
    (the photo's width over the tile side)."""
    tiles, _ = result
    return tiles.photo_shape[1] / tiles.tile


def groups(op, result, nodes):
    """One new atlas image and group per source node (same order)."""
    tiles, atlases = result
    return [map_group(f"TexSynth Wang {stem(node.image)}", atlas_image(node.image, atlas), tiles,
                      node.interpolation) for node, atlas in zip(nodes, atlases, strict=True)]


def link(op, tree, made, result):
    """Nothing to set on the placed nodes: Vector, Scale and Seed are all they take."""


def atlas_image(source, atlas):
    """A new packed image of ``atlas`` (A, A, C, top row first) stored as ``source`` is (byte or
    float, its colour space), so the shader reads the atlas exactly as it read the photo."""
    h, w, c = atlas.shape
    rgba = np.ones((h, w, 4), np.float32)
    rgba[:, :, :3] = atlas[:, :, :3] if c >= 3 else atlas[:, :, :1]
    image = bpy.data.images.new(f"{stem(source)}_{SUFFIX}", w, h, alpha=True,
                                float_buffer=bool(source.is_float))
    image.colorspace_settings.name = source.colorspace_settings.name
    image.alpha_mode = "NONE"
    image.pixels.foreach_set(np.ascontiguousarray(rgba[::-1]).ravel())
    image.pack()
    return image


def _build_cells():
    group, b, i = new_group(CELLS, [("Vector", "Vector"), ("Scale", "Float", 2.0),
                                     ("Seed", "Float", 0.0), ("Aspect", "Float", 1.0),
                                     ("Colours", "Float", 2.0)],
                             [("Position", "Vector"), ("Row", "Float"), ("Column", "Float")])
    u, v, _ = b.separate(i["Vector"])
    x = b.math("MULTIPLY", u, i["Scale"])
    y = b.math("MULTIPLY", b.math("MULTIPLY", v, i["Scale"]), i["Aspect"])
    cx, cy = b.math("FLOOR", x), b.math("FLOOR", y)
    position = b.combine(b.math("SUBTRACT", x, cx),
                         b.math("SUBTRACT", 1.0, b.math("SUBTRACT", y, cy)), 0.0)
    last = b.math("SUBTRACT", i["Colours"], 1.0)

    def edges(dx, dy):
        """(h, g) of lattice point (X + dx, Y + dy): the R and G of White Noise, coloured."""
        point = b.combine(b.math("ADD", cx, dx), b.math("ADD", cy, dy), i["Seed"])
        noise = b.node("ShaderNodeTexWhiteNoise", (point,), noise_dimensions="3D")
        r, g, _ = b.separate(noise.outputs["Color"])
        return [b.math("MINIMUM", b.math("FLOOR", b.math("MULTIPLY", c, i["Colours"])), last)
                for c in (r, g)]

    (south, west), (north, _), (_, east) = edges(0.0, 0.0), edges(0.0, 1.0), edges(1.0, 0.0)
    row = b.math("MULTIPLY_ADD", north, i["Colours"], south)
    column = b.math("MULTIPLY_ADD", west, i["Colours"], east)
    finish_group(b, [position, row, column])
    return group


def map_group(name, atlas, tiles, interpolation):
    """A new group (Vector, Scale, Seed -> Color, Alpha) laying ``tiles`` (``WangTiles``) from
    the ``atlas`` image (Blender's rows, bottom first)."""
    group, b, i = new_group(name, [("Vector", "Vector"), ("Scale", "Float", 2.0),
                                    ("Seed", "Float", 0.0)],
                             [("Color", "Color"), ("Alpha", "Float")])
    cells = b.node("ShaderNodeGroup", node_tree=shared_group(CELLS, _build_cells))
    for socket in ("Vector", "Scale", "Seed"):
        b.tree.links.new(i[socket], cells.inputs[socket])
    h, w = tiles.photo_shape
    cells.inputs["Aspect"].default_value = h / w
    cells.inputs["Colours"].default_value = float(tiles.colours)
    t, step, g = float(tiles.tile), float(tiles.step), float(tiles.gutter)
    width, height = atlas.size
    fx, fy, _ = b.separate(cells.outputs["Position"])
    # atlas pixels (column right, row down from the top) -> the image's uv (v up)
    px = b.math("MULTIPLY_ADD", cells.outputs["Column"], step, b.math("MULTIPLY_ADD", fx, t, g))
    py = b.math("MULTIPLY_ADD", cells.outputs["Row"], step, b.math("MULTIPLY_ADD", fy, t, g))
    uv = b.combine(b.math("DIVIDE", px, float(width)),
                   b.math("SUBTRACT", 1.0, b.math("DIVIDE", py, float(height))), 0.0)
    read = b.node("ShaderNodeTexImage", (uv,), image=atlas, interpolation=interpolation,
                  extension="EXTEND")
    finish_group(b, [read.outputs["Color"], opaque_alpha(b)])
    return group
