"""From a photo to a material: heal a blemish, take out the light, derive the maps.

One home for the capability (issue 43); each name lives in the module that says what it is::

    texsynth.material.heal(photo, mask, seed=0) -> the masked region re-synthesized
    texsynth.material.delight(photo) -> the photo with its light taken out
    texsynth.material.derive_maps(colour, wrap=True) -> Maps(normal, height, roughness, ao)
"""

from __future__ import annotations

from .delight import delight
from .heal import heal
from .maps import Maps, derive_maps

__all__ = ["delight", "heal", "derive_maps", "Maps"]
