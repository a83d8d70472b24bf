"""The multiscale MRF keeps bricks in rows (issue 25: on the brick wall at 2048, copied regions
met with their courses half a course apart, the rows stepping several times a 512 crop)."""

import numpy as np
import pytest

import texsynth
from texsynth.algorithms import multiscale_mrf as method
from texsynth.metrics import course_steps

from _images import running_bond

COURSE, BRICK, MORTAR = 12, 28, 2  # course height, brick length, mortar thickness (pixels)
STRIP = 16  # column strips whose bed joints are compared


def wall(seed=0):
    """Courses 12 px tall of bricks 28 px long, each course shifted half a brick, 2 px dark
    mortar, each brick its own red with grain (120 x 120)."""
    return running_bond((120, 120), seed, course=COURSE, brick=BRICK, joint=MORTAR,
                        tint=(0.95, 0.55, 0.45), shade=(0.5, 0.3), grain=0.1,
                        mortar=(0.12, 0.12, 0.12), speckle=0.04)[0]


def test_the_measure_sees_a_step_of_half_a_course():
    ex = wall()
    assert course_steps(ex, COURSE, STRIP, wrap=False) == 0
    stepped = np.concatenate([ex[:, :64], np.roll(ex[:, 64:], COURSE // 2, axis=0)], axis=1)
    assert course_steps(stepped, COURSE, STRIP, wrap=False) > 0.1  # one strip pair in 6


@pytest.mark.parametrize("seed", [0, 1])
def test_courses_run_straight_across_the_output(seed):
    """A 120 px wall to 192 px: the courses step at under 5 % of the places (strip pairs and
    windows; 0 and 0.6 % for seeds 0 and 1), where without the copies slid into phase
    (``ALIGN_PIXELS`` 0, as before) they stepped at 8 and 15 %."""
    ex = wall(seed=seed)
    out = texsynth.synthesize(ex, 192, 192, method="multiscale_mrf", seed=seed)
    assert course_steps(out, COURSE, STRIP) < 0.05


def test_without_the_alignment_the_courses_step(monkeypatch):
    """The test above can fail: the same run without the alignment (and without the joints'
    channels, which keep courses too: 0.051 with them) steps more often."""
    monkeypatch.setattr(method, "ALIGN_PIXELS", 0)
    out = texsynth.synthesize(wall(), 192, 192, method="multiscale_mrf", seed=0,
                              feature_weight=0.0)
    assert course_steps(out, COURSE, STRIP) > 0.06
