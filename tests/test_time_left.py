"""The time left (texsynth.progress.TimeLeft) on a fake clock: the prediction first, then the
observed rate; the command line's bar tells it."""

import io

import pytest

from texsynth.cli import Bar
from texsynth.progress import TimeLeft


class Clock:
    def __init__(self):
        self.now = 1000.0

    def __call__(self):
        return self.now


@pytest.mark.parametrize("predicted", [50.0, 100.0, 200.0])
def test_a_time_linear_run_is_told_within_1_5x_from_a_tenth_whatever_the_prediction(predicted):
    clock = Clock()
    left = TimeLeft(predicted, clock)  # a 100 s run, predicted 2x too fast to 2x too slow
    for f in (0.1, 0.5, 0.9):
        clock.now = 1000.0 + 100.0 * f
        assert 1 / 1.5 <= left.seconds(f) / (100.0 * (1 - f)) <= 1.5


def test_the_prediction_alone_at_the_start_and_no_guess_without_one():
    clock = Clock()
    left, blind = TimeLeft(60.0, clock), TimeLeft(None, clock)
    clock.now += 15.0
    assert left.seconds(0.0) == 45.0 and blind.seconds(0.0) is None
    assert blind.seconds(0.005) is None and blind.seconds(0.25) == pytest.approx(45.0)
    assert left.seconds(1.0) == 0.0 == blind.seconds(1.0)
    clock.now += 100.0
    assert left.seconds(0.0) == 0.0  # overdue: the count-down stops at zero


def test_restart_and_an_explicit_now():
    clock = Clock()
    left = TimeLeft(None, clock)
    clock.now += 50.0
    left.restart()
    assert left.seconds(0.5, now=clock.now + 10.0) == pytest.approx(10.0)


def test_the_bar_shows_the_prediction_before_the_first_fraction():
    out = io.StringIO()
    bar = Bar(out, tty=False, predicted=125.0)
    bar(0.0, "start")
    assert out.getvalue().startswith("  0% (2:05 left) start")
