"""The time budget: every method predicts its run time, and a prediction over budget is refused
before any work with a message naming the time and what to change."""

import numpy as np
import pytest

import texsynth
from texsynth import budget


@pytest.mark.parametrize("method", texsynth.methods(), ids=lambda m: m.name)
def test_every_method_predicts_more_time_for_more_pixels(method):
    params = method.resolve({})
    small = method.cost((64, 64, 3), 64, 64, params)
    large = method.cost((64, 64, 3), 1024, 1024, params)
    assert 0 < small < large and np.isfinite(large)


def test_the_machine_factor_is_measured_once_and_bounded():
    first = budget.machine_factor()
    assert 0.1 <= first <= 100 and budget.machine_factor() == first


@pytest.mark.parametrize("seconds, text", [(0.42, "0.4 s"), (42, "42 s"), (420, "7 min"),
                                          (4.2 * 3600, "4.2 h"), (5 * 86400, "5.0 days")])
def test_durations_read_as_people_say_them(seconds, text):
    assert budget.describe(seconds) == text


def test_a_prediction_over_budget_is_refused_naming_time_and_remedies(monkeypatch):
    monkeypatch.setenv("TEXSYNTH_TIME_BUDGET", "60")
    budget.check_time(59, "this run")
    with pytest.raises(ValueError, match="this run is predicted to take about 2 min, over the "
                                         "time budget of 60 s; choose a smaller size, .*"
                                         "TEXSYNTH_TIME_BUDGET"):
        budget.check_time(120, "this run")


@pytest.mark.parametrize("value", ["-1", "0", "nan", "an hour"])
def test_a_bad_budget_setting_is_named(monkeypatch, value):
    monkeypatch.setenv("TEXSYNTH_TIME_BUDGET", value)
    with pytest.raises(ValueError, match="TEXSYNTH_TIME_BUDGET must be"):
        budget.time_budget()


def test_efros_leung_counts_the_batches_of_a_strip():
    """A strip grows through two short fronts, a few pixels a batch: much of its run is the
    batches' fixed cost, which a model of pixels alone under-predicted 4x (16384 x 16 from 32 x
    32: 9 s predicted, 36 s run). The same pixels as a rectangle cost far less."""
    method = texsynth.get_method("efros_leung")
    params = method.resolve({})
    rectangle = method.cost((32, 32, 3), 512, 256, params)
    strip = method.cost((32, 32, 3), 16384, 8, params)
    assert strip > 1.5 * rectangle
