"""From a photo to a whole material (issue 43): delight, heal, derive the maps, and the
pipeline over them (rectify, heal, delight, tile, maps) with its files.

    texsynth.material.delight(photo) -> the photo with the light taken out
    texsynth.material.heal(photo, mask) -> the masked pixels re-synthesized from the rest
    texsynth.material.derive_maps(colour) -> Maps(normal, height, roughness, ao)
    texsynth.material.photo_to_material(photo, size=None, ...) -> Material
    texsynth.material.write_material(material, folder, stem) -> the ambientCG-named files
"""

from .delight import delight
from .heal import heal
from .maps import Maps, derive_maps
from .pipeline import Material, photo_to_material, write_material

__all__ = ["delight", "heal", "derive_maps", "Maps", "Material", "photo_to_material",
           "write_material"]
