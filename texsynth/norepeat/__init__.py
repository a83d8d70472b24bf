"""Render-time anti-repetition: what a renderer needs so that a texture never repeats.

- :mod:`.gaussian`: the Gaussianised texture (PCA colour when asked) and its inverse table
  (Heitz & Neyret 2018; Deliot & Heitz 2019; Burley 2019's truncated Gaussian);
- :mod:`.blend`: tiling and blending itself in numpy (the triangle grid, the hashed vertex
  offsets, the variance-preserving blend, the look-up), the reference for the Blender node group
  and a writer of never-repeating images for any engine;
- :mod:`.tiles`: a Wang tile set made from the photo (Cohen et al. 2003), its atlas with
  gutters and position map, and the tiling a renderer lays from hashed edge colours;
- :mod:`.hex`: hex tiling (Mikkelsen 2022) in numpy: randomly offset and turned copies on
  hexagonal cells, blended with luminance-weighted sharpened weights, normal maps turned too;
  the reference for the Blender node group;
- :mod:`.measure`: how much a rendered surface still repeats.
"""

from .blend import GRID_SCALE, predict_blend_memory, tile_and_blend, triangle_grid, vertex_offsets
from .gaussian import Gaussianized, gaussianize, predict_memory
from .hex import hex_tile, hex_weights, predict_hex_memory, rotation_symmetry
from .measure import anisotropy, period_correlation, repetition_peak
from .tiles import (
    WangTiles,
    edge_colours,
    photo_use,
    predict_tiles_memory,
    wang_tiles,
    wang_tiling,
    wang_tiling_positions,
)

__all__ = ["Gaussianized", "gaussianize", "predict_memory", "tile_and_blend",
           "predict_blend_memory", "triangle_grid", "vertex_offsets", "period_correlation",
           "GRID_SCALE", "WangTiles", "wang_tiles", "wang_tiling", "wang_tiling_positions",
           "edge_colours", "photo_use", "predict_tiles_memory", "hex_tile", "hex_weights",
           "predict_hex_memory", "rotation_symmetry", "repetition_peak", "anisotropy"]
