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


def test_the_speed_is_measured_once_and_the_factor_is_finite():
    first = budget.speed()
    assert 0.1 <= first <= 100 and budget.speed() == first
    assert np.isfinite(budget.machine_factor()) and budget.machine_factor() >= first


@pytest.fixture
def loadavg(monkeypatch, tmp_path):
    """Writes a /proc/loadavg of its own for the budget, on a machine of 2 cores."""
    path = tmp_path / "loadavg"
    monkeypatch.setattr(budget, "LOADAVG", path)
    monkeypatch.setattr(budget, "CORES", 2)
    monkeypatch.setattr(budget, "PROC", tmp_path / "no-proc")  # the plain count
    monkeypatch.setattr(budget, "_load", None)

    def write(text):
        path.write_text(text)
        budget._load = None  # read again at once
    return write


@pytest.mark.parametrize("text, expected", [
    ("0.30 0.20 0.10 1/250 999\n", 1.0),     # idle: this task alone
    ("1.90 1.20 0.50 1/250 999\n", 1.0),     # a run that just ended still in the average
    ("7.50 6.00 3.00 9/300 999\n", 3.75),    # busy: 7.5 tasks a core pair
    ("9.00 6.00 3.00 3/300 999\n", 1.5),     # the average lags a load that has gone
    ("nonsense", 1.0),                       # nothing readable: the idle machine's speed
])
def test_the_factor_follows_the_tasks_that_want_a_core(loadavg, text, expected):
    loadavg(text)
    assert budget.contention() == expected
    assert budget.machine_factor() == budget.speed() * expected


def _task(root, pid, state, nice, group):
    """A task of a /proc of the test's own: its stat (state, nice) and its autogroup."""
    task = root / str(pid) / "task" / str(pid)
    task.mkdir(parents=True)
    fields = [state] + ["0"] * 15 + [str(nice)] + ["0"] * 30
    for stat in (task / "stat", root / str(pid) / "stat"):
        stat.write_text(f"{pid} (py) thon) " + " ".join(fields) + "\n")
    root.joinpath(str(pid), "autogroup").write_text(f"/autogroup-{group} nice 0\n")
    return root / str(pid)


@pytest.mark.parametrize("mine, expected", [(0, 1.7), (-19, 1.4)])
def test_niced_tasks_of_the_group_slow_a_run_by_their_share(loadavg, tmp_path, monkeypatch,
                                                               mine, expected):
    proc = tmp_path / "proc"
    own = _task(proc, 9, "R", mine, 4)
    (proc / "self").symlink_to(own)
    _task(proc, 10, "R", 15, 4)             # a background job, nice 15: its floor, 0.4
    _task(proc, 11, "R", 0, 4)              # a job at nice 0: a task; beside -19 its floor
    _task(proc, 12, "S", 0, 4)              # asleep: none
    _task(proc, 13, "R", 0, 1)              # another session's two tasks: one group
    _task(proc, 14, "R", 0, 1)
    monkeypatch.setattr(budget, "PROC", proc)
    loadavg("8.00 8.00 8.00 9/300 999\n")
    assert budget.contention() == pytest.approx(expected, abs=0.02)


def test_the_load_is_kept_for_a_while_then_read_again(loadavg):
    loadavg("0.10 0.10 0.10 1/250 999\n")
    assert budget.contention() == 1.0
    budget.LOADAVG.write_text("8.00 8.00 8.00 8/250 999\n")
    assert budget.contention() == 1.0  # the panel redraws often: no file read each time
    read_at, value = budget._load
    budget._load = (read_at - budget.REFRESH - 1, value)  # that reading is now too old
    assert budget.contention() == 4.0


def test_a_loaded_machine_refuses_a_run_that_fits_when_idle_naming_the_time(loadavg,
                                                                            monkeypatch):
    method = texsynth.get_method("multiscale_mrf")
    params = method.resolve({})
    loadavg("0.10 0.10 0.10 1/250 999\n")
    idle = budget.check_method(method, (64, 64, 3), 512, 512, params)
    monkeypatch.setenv("TEXSYNTH_TIME_BUDGET", str(2 * idle))
    loadavg("8.00 8.00 8.00 8/250 999\n")
    with pytest.raises(ValueError, match=r"512 x 512 with 'multiscale_mrf' is predicted to take "
                                         r"about [\d.]+ (s|min)"):
        budget.check_method(method, (64, 64, 3), 512, 512, params)


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


def test_efros_leung_memory_counts_a_batch_front_not_a_fixed_matrix():
    """A batch holds a front's pixels: 96 x 96 from 48 x 48 peaks at about 10 MiB resident; a
    fixed 128 MiB for the distances predicted 131 MiB (and refused it under a tight budget)."""
    seconds, peak = budget.forecast("efros_leung", (48, 48, 3), 96, 96)
    assert peak < 16 * 2**20
    _, strip = budget.forecast("efros_leung", (32, 32, 3), 16384, 16)
    assert strip < 48 * 2**20


@pytest.mark.parametrize("method", ["multiscale_mrf", "texture_optimization"])
def test_the_photo_at_hand_tells_whether_its_joints_are_counted(method):
    i, j = np.mgrid[:256, :256]
    wall = np.where((i % 24 < 4) | ((j + 24 * (i // 24 % 2)) % 48 < 4), 0.2, 0.7)
    wall = np.repeat(wall[:, :, None], 3, axis=2).astype(np.float32)
    gravel = np.random.default_rng(0).random((256, 256, 3)).astype(np.float32)
    shape_only = budget.forecast(method, (256, 256, 3), 512, 512)
    joints = budget.forecast(method, (256, 256, 3), 512, 512, exemplar=wall)
    assert joints[0] > shape_only[0] and joints[1] > shape_only[1]
    assert budget.forecast(method, (256, 256, 3), 512, 512, exemplar=gravel) == shape_only
    assert budget.forecast(method, (256, 256, 3), 512, 512, {"feature_weight": 0.0},
                           exemplar=wall) == shape_only
