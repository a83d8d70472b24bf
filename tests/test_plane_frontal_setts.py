"""Frontal setts read from their courses' spacing (issue 42): granite setts photographed square
to the surface read slant 54 to 62 deg at confidence 0.98 with the focal length from the EXIF.
The courses are curved and broken into pieces, about six periods across: a horizon that
chirps the period fitted their uneven positions a little better than the frontal view did,
and the periodicity peak's half-height width was stated as the whole uncertainty. The frontal
view, not ruled out by the spacing's own likelihood, must stay within its two sigmas."""

import math

import numpy as np
import pytest

from texsynth.plane.lines import Segments, horizon_through, spaced_horizon

pytestmark = pytest.mark.filterwarnings("error::RuntimeWarning")

SIDE = 320.0


def bowed_courses(seed=2, courses=7, pieces=12, bow=4.0, jitter=4.0):
    """Segments of ``courses`` frontal courses (centred y-up pixels) about 34 pixels apart,
    each placed off the equal spacing by ``jitter`` pixels (sd), bowed by up to ``bow`` pixels
    across the image and found as ``pieces`` pieces 12 to 30 pixels long, as setts' bed joints
    are laid by hand."""
    rng = np.random.default_rng(seed)
    period = 240.0 / courses
    m, d, length = [], [], []
    for k in range(courses):
        y0 = -100.0 + k * period + rng.normal(0.0, jitter)
        b = rng.uniform(-bow, bow)
        for x in np.linspace(-140.0, 140.0, pieces) + rng.uniform(-8.0, 8.0, pieces):
            m.append((x, y0 + b * (x / 140.0) ** 2 + rng.normal(0.0, 1.0)))
            a = math.atan(2.0 * b * x / 140.0 ** 2 + rng.normal(0.0, 0.02))
            d.append((math.cos(a), math.sin(a)))
            length.append(rng.uniform(12.0, 30.0))
    return Segments(np.array(m), np.array(d), np.array(length))


def test_the_frontal_view_stays_within_the_spacing_s_two_sigmas():
    """Main found a spacing whose horizon lay 6.6 of its sigmas from the frontal view's."""
    family = bowed_courses()
    found = spaced_horizon(family, horizon_through(family, SIDE), SIDE)
    assert found is not None
    v, cov = found
    assert np.linalg.norm(v) <= 2.0 * math.sqrt(np.trace(cov)) + 1e-4  # v = 0 within 2 sigmas


def test_equal_courses_still_give_a_sharp_horizon():
    """Twelve courses equally spaced on a plane receding at v = (0, 1/300), in ten pieces
    each: the frontal view is ruled out, and the horizon is told within a tenth of its distance."""
    v_y = 1.0 / 300.0
    plane_rows = -100.0 + 20.0 * np.arange(12)
    rows = plane_rows / (1.0 + v_y * plane_rows)
    x = np.linspace(-140.0, 140.0, 10)
    m = np.array([(xi, y) for y in rows for xi in x])
    family = Segments(m, np.tile([1.0, 0.0], (len(m), 1)), np.full(len(m), 20.0))
    v, cov = spaced_horizon(family, horizon_through(family, SIDE), SIDE)
    assert abs(v[1] - v_y) < 0.1 * v_y
    assert 2.0 * math.sqrt(np.trace(cov)) < 0.5 * v_y


def test_a_horizon_interval_that_reaches_the_frontal_view_is_a_slant_interval_to_0():
    """The setts' spacing, focal length known: a horizon at slant 56 deg whose two sigmas reach
    the frontal view. Linearised at the fit its slant sigma read 13 deg; the interval's ends,
    mapped exactly (56 deg to the frontal end, 15 to the far one), give 21."""
    from texsynth.plane.fit import _spacing_covariance
    from texsynth.plane.geometry import angles_from_gradient

    f = 231.0
    v = np.array([0.0065, 0.0])
    cov = _spacing_covariance(f * v, (v, np.diag([(0.0065 / 2) ** 2, 0.0])), f)
    slant = angles_from_gradient(f * v)[0]
    assert math.sqrt(cov[0, 0]) >= slant / 3
