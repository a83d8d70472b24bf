"""Setts laid in courses, the focal length known (issue 27, rendered views of the real granite
setts photo): the stones' sides lean every way and form no second family, and the stones are
as wide as a course, so the texture reads isotropic. The courses' joints are then the only
family, and their equal spacing gives the whole plane (p = f v) where the texture alone was off
by 7 to 9 deg."""

import numpy as np
import pytest
import scipy.ndimage as ndi
from _planes import noise_texture, normal_error, photograph

from texsynth.plane import estimate_plane
from texsynth.plane.geometry import gradient

#: A NaN or an overflow in the estimate is garbage on its way out (issue 27): an error here.
pytestmark = pytest.mark.filterwarnings("error::RuntimeWarning")

FOCAL = 400.0


def setts_texture(seed=0, n=512, courses=8, joint=4, lean=30.0, grain=0.1):
    """Periodic setts (n x n, prefiltered like ``_planes.noise_texture``): equal courses along
    x, about as many stones per course as courses, staggered at random from course to course,
    each side leaning up to ``lean`` deg either way (cut by hand), each stone a random shade
    with fine isotropic grain, dark joints."""
    rng = np.random.default_rng(seed)
    rows, cols = np.mgrid[0:n, 0:n].astype(float)
    height = n / courses
    course = np.floor(rows / height).astype(int)
    mid = (course + 0.5) * height
    index = np.zeros((n, n), int)
    side = np.zeros((n, n), bool)
    for r in range(courses):
        edges = (np.arange(courses) + rng.uniform(-0.2, 0.2, courses)) * n / courses
        edges += rng.uniform(0, n)
        slope = np.tan(np.radians(rng.uniform(-lean, lean, courses)))
        inside = course == r
        x, y = cols[inside], rows[inside] - mid[inside]
        # each side is the line x = edge + slope * y; a pixel lies in the stone of the nearest
        # side to its left (modulo n: the course wraps around)
        along = (x[:, None] - edges[None] - slope[None] * y[:, None]) % n
        index[inside] = r * courses + np.argmin(along, axis=1)
        side[inside] = along.min(axis=1) < joint
    bed = rows - np.floor(course * height) < joint
    shade = rng.uniform(-0.12, 0.12, courses * courses)[index]
    g = ndi.gaussian_filter(rng.standard_normal((n, n)), 1.5, mode="wrap")
    t = np.where(bed | side, -0.25, shade + grain * g / g.std())
    return ndi.spline_filter(t, order=3, mode="grid-wrap")


@pytest.mark.parametrize("tilt", [90.0, 135.0, 180.0])
def test_courses_spacing_gives_the_plane_of_isotropic_setts(tilt):
    """Main read these 6.9, 8.3 and 8.8 deg off from the texture alone (the lone family of
    courses was dropped on an isotropic texture); the courses' spacing reads 1.7, 0.6, 1.4."""
    slant = 45.0
    photo = photograph(setts_texture(), slant, tilt, FOCAL, size=384)
    result = estimate_plane(photo, focal_px=FOCAL)
    assert result.anisotropy <= 1.0  # isotropic by the estimate's own measure
    assert result.line_families == 1  # the courses
    assert normal_error((slant, tilt), (result.slant, result.tilt)) < 3.0


def test_courses_are_not_used_without_the_focal_length():
    """With the focal length unknown the spacing gives the vanishing line only, its slant still
    from the texture's isotropy: a lone family on an isotropic texture stays out."""
    photo = photograph(setts_texture(), 45.0, 135.0, FOCAL, size=384)
    assert estimate_plane(photo).line_families == 0


@pytest.mark.parametrize("tilt", [30.0, 200.0])
def test_a_spacing_that_recedes_the_wrong_way_is_ruled_out(tilt):
    """The gate on an isotropic texture's lone family: a chance period's chirp may point either
    way; the texture's homogeneity accepts the true receding direction and refuses its mirror."""
    from texsynth.plane import fit, spectra

    slant = 45.0
    photo = photograph(noise_texture(), slant, tilt, FOCAL)
    small, _ = spectra.downsample(spectra.luminance(photo))
    crit = spectra.Criterion(spectra.spectra(small, spectra.texture_mask(small), fit._MOMENT_W_MAX,
                                             fit._WINDOW)).band_limited(fit._W_MAX)
    v = gradient(slant, tilt) / FOCAL
    assert fit._recedes_with(crit, v, FOCAL)
    assert not fit._recedes_with(crit, -v, FOCAL)
