"""Two line families checked against the first one's equal spacing (issue 27, rendered views of
real photos): a brick wall's head joints are short, and where their directions are off (a
real wall's joints are laid by hand) their vanishing point reads the wrong plane, while the
courses' spacing, measured along every course, still gives the right one."""

import numpy as np
import pytest
import scipy.ndimage as ndi
from _planes import brick_texture, normal_error, photograph

from texsynth.plane import estimate_plane

#: A NaN or an overflow in the estimate is garbage on its way out (issue 27): an error here.
pytestmark = pytest.mark.filterwarnings("error::RuntimeWarning")

FOCAL = 400.0


def fanned_brick_texture(seed=0, n=1024, brick=(96, 32), mortar=3, fan=1500.0):
    """Running-bond bricks whose straight, equally spaced courses are right but whose head
    joints fan out: each one points at a plane point ``fan`` pixels beyond the centre, up to 6
    deg off at the view's sides, as perspective would turn them. Centred on the plane's origin
    (the photographed region), with its seams ``n / 2`` away."""
    rng = np.random.default_rng(seed)
    bw, bh = brick
    rows, cols = np.mgrid[0:n, 0:n].astype(float)
    y = (rows + n / 2) % n - n / 2
    x = (cols + n / 2) % n - n / 2
    course = np.floor(y / bh).astype(int)
    along = x / (1.0 + y / fan) + (course % 2) * bw / 2  # straight lines through (0, -fan)
    per_course = 4 * (n // bw)  # more bricks than a fanned course holds
    index = (course - course.min()) * per_course + np.floor(along / bw).astype(int) + n // bw * 2
    shade = rng.uniform(-0.12, 0.12, index.max() + 1)[index]
    joint = ((y % bh) < mortar) | ((along % bw) < mortar)
    t = np.where(joint, -0.25, shade + 0.03 * rng.standard_normal((n, n)))
    return ndi.spline_filter(t, order=3, mode="grid-wrap")


@pytest.mark.parametrize("tilt", [90.0, 180.0])
def test_misleading_head_joints_give_way_to_the_courses_spacing(tilt):
    """With the focal length known, the two families' plane read 12.8 and 8.2 deg off (the
    fanned head joints' vanishing point); the courses' spacing reads 0.9 and 0.5."""
    slant = 30.0
    result = estimate_plane(photograph(fanned_brick_texture(), slant, tilt, FOCAL),
                            focal_px=FOCAL)
    assert normal_error((slant, tilt), (result.slant, result.tilt)) < 2.0
    assert result.line_families == 1  # the courses alone


def test_head_joints_that_agree_with_the_spacing_are_kept():
    """Bricks as laid on a plane: the families' plane and the courses' spacing agree, so both
    families stay in the estimate."""
    slant, tilt = 30.0, 90.0
    result = estimate_plane(photograph(brick_texture(brick=(96, 32)), slant, tilt, FOCAL),
                            focal_px=FOCAL)
    assert result.line_families == 2
    assert normal_error((slant, tilt), (result.slant, result.tilt)) < 2.0
