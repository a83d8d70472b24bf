"""From a photo to a material: heal a blemish, take out the light, derive the maps, and the
pipeline over them (rectify, heal, delight, tile, maps) with its files.

One home for the capability (issue 43); each name lives in the module that says what it is::

    texsynth.material.heal(photo, mask, seed=0) -> the masked region re-synthesized
    texsynth.material.delight(photo) -> the photo with its light taken out
    texsynth.material.derive_maps(colour, wrap=True) -> Maps(normal, height, roughness, ao)
    texsynth.material.photo_to_material(photo, size=None, ...) -> Material (pipeline.py)
    texsynth.material.write_material(material, folder, stem) -> the ambientCG-named files
"""

from __future__ import annotations

from .delight import delight
from .heal import heal
from .maps import Maps, derive_maps
from .pipeline import Material, photo_to_material, write_material

__all__ = ["delight", "heal", "derive_maps", "Maps", "Material", "photo_to_material",
           "write_material"]
