"""The courses' period that make_tileable phases its band with, and the "no courses" answer
that leaves stochastic photos on the old path."""

import numpy as np
import pytest

from texsynth.blocks.rhythm import bond, course_period

from _images import running_bond, smooth_noise


def _wall(shape, course, brick):
    return running_bond(shape, 0, course=course, brick=brick, joint=3, tint=(0.9, 0.5, 0.4),
                        shade=(0.5, 0.3), grain=0.1, mortar=(0.15, 0.15, 0.15),
                        speckle=0.04)[0]


@pytest.mark.parametrize(("course", "brick"), [(16, 40), (24, 64), (32, 64)])
def test_a_walls_courses_are_found_whatever_its_size(course, brick):
    wall = _wall((200 + course // 3, 232), course, brick)[course // 3:]  # not whole courses
    period = course_period(wall)  # a whole number of courses (shades may alternate)
    assert period in (course, 2 * course)


@pytest.mark.parametrize("seed", range(4))
def test_noise_and_a_ramp_have_no_courses(seed):
    noise = smooth_noise((256, 320), seed=seed, sigma=4)
    assert course_period(noise) is None
    assert course_period(noise + np.linspace(0, 1, 256)[:, None, None]) is None


@pytest.mark.parametrize(("course", "brick"), [(24, 64), (48, 112)])
def test_a_running_bonds_head_joints_are_found_a_brick_on_and_half_a_brick_a_course_on(
        course, brick):
    wall = _wall((240, 300), course, brick)
    assert bond(wall, course) == (brick, brick // 2)


def test_elements_out_of_line_have_no_bond():
    """Courses whose head joints fall anywhere (random bond, like setts) read as no lattice."""
    rng = np.random.default_rng(0)
    wall = _wall((240, 320), 24, 64)
    for k in range(10):  # each course moved along by its own shift
        wall[24 * k:24 * k + 24] = np.roll(wall[24 * k:24 * k + 24], rng.integers(64), axis=1)
    assert bond(wall, 24) is None
    assert bond(smooth_noise((256, 320), seed=0, sigma=4), 24) is None
