"""Plane orientation from texture (shape from texture), rectification and camera pose.

Forsyth & Ponce, Computer Vision: A Modern Approach, sec. 11.4.1 ("Shape from texture for
planes"). The modules, in the order a photo goes through them:

- :mod:`~texsynth.plane.geometry`: conventions, normals and angles, the maps image <-> plane;
- :mod:`~texsynth.plane.spectra`: the textured part of the photo, windowed spectra, and the
  isotropy and homogeneity criterion;
- :mod:`~texsynth.plane.lines`: straight segments, their families and vanishing points;
- :mod:`~texsynth.plane.fit`: the search, its uncertainty, :func:`estimate_plane`, combining the
  texture with the lines (:mod:`~texsynth.plane.combine`);
- :mod:`~texsynth.plane.verdict`: a measurement or a guess, and why, in a user's words;
- :mod:`~texsynth.plane.rectangle`: the plane from a rectangle the user marks on it, where the
  estimate cannot be trusted;
- :mod:`~texsynth.plane.rectify`: the frontal view of the texture;
- :mod:`~texsynth.plane.camera`: Blender's lens and sensor fit, the camera pose;
- :mod:`~texsynth.plane.exif`: the focal length a camera wrote into the photo's file.
"""

from .camera import camera_pose, focal_px_from_lens, lens_from_focal_px
from .exif import focal_px_from_file
from .fit import ESTIMATE_METHODS, PlaneEstimate, estimate_plane
from .geometry import angles_from_normal, image_to_plane, normal_from_angles, plane_to_image
from .rectangle import from_rectangle
from .rectify import rectify
from .verdict import Verdict, verdict

__all__ = [
    "PlaneEstimate",
    "estimate_plane",
    "from_rectangle",
    "rectify",
    "camera_pose",
    "normal_from_angles",
    "angles_from_normal",
    "image_to_plane",
    "plane_to_image",
    "focal_px_from_lens",
    "lens_from_focal_px",
    "focal_px_from_file",
    "ESTIMATE_METHODS",
    "Verdict",
    "verdict",
]
