"""texsynth: example-based, seamless (periodic) texture synthesis with numpy and scipy.

The core never imports Blender. This module only gathers the public API; each name lives in
the module that says what it is (see docs/ARCHITECTURE.md)::

    texsynth.synthesize(exemplar, width, height, method="heeger_bergen", seed=0,
                        progress=None, **params) -> float32 (height, width, C)
    texsynth.methods() -> tuple of Method records (name, label, description, params)
    texsynth.make_tileable(photo, band=None, seed=0) -> float32, the photo's size, made to tile

Every method returns a periodic image: tiled 2 x 2 it shows no seam.
"""

from __future__ import annotations

from . import interrupts

# ruff: noqa: I001  (algorithms first: importing it registers every method, in panel order)
with interrupts.while_starting(active=interrupts.starting_command()):  # the command's start
    from . import algorithms, budget, validation
    from .algorithms import composite, cooccurrence
    from .algorithms.composite import segmentation
    from . import material
    from .api import synthesize, synthesize_positions
    from .plane import PlaneEstimate, camera_pose, estimate_plane, focal_px_from_file, rectify
    from .positions import apply_positions, positions_image
    from .progress import Cancelled, Progress
    from .registry import Method, Param, get_method, methods
    from .stack import synthesize_stack
    from .tileable import make_tileable, make_tileable_positions
    from .validation import MAX_SIDE, memory_budget

__all__ = [
    "synthesize",
    "synthesize_positions",
    "apply_positions",
    "positions_image",
    "synthesize_stack",
    "algorithms",
    "make_tileable",
    "make_tileable_positions",
    "budget",
    "validation",
    "cooccurrence",
    "composite",
    "segmentation",
    "material",
    "methods",
    "get_method",
    "Cancelled",
    "Progress",
    "Method",
    "Param",
    "MAX_SIDE",
    "memory_budget",
    "estimate_plane",
    "rectify",
    "camera_pose",
    "focal_px_from_file",
    "PlaneEstimate",
]
