"""The shared pool: results in order, progress as they come in, a cancel drops what is left."""

import threading
import time

import pytest

from texsynth.blocks import parallel


@pytest.mark.parametrize("workers", [1, 2])
def test_run_keeps_order_and_ticks_once_per_item(monkeypatch, workers):
    monkeypatch.setattr(parallel, "WORKERS", workers)
    ticks = []
    assert parallel.run(lambda x: x * x, range(7), lambda: ticks.append(1)) == [
        0, 1, 4, 9, 16, 25, 36]
    assert len(ticks) == 7


@pytest.mark.parametrize("workers", [1, 2])
def test_a_cancel_in_a_tick_propagates_and_drops_the_items_not_started(monkeypatch, workers):
    monkeypatch.setattr(parallel, "WORKERS", workers)
    started, release = [], threading.Event()

    def work(x):
        started.append(x)
        if x == 1:
            release.wait(5)              # holds one thread while the first tick cancels
        time.sleep(0.01)                 # the others take a while, as real items do
        return x

    def tick():
        raise KeyboardInterrupt("cancelled")

    with pytest.raises(KeyboardInterrupt):
        parallel.run(work, range(50), tick)
    release.set()
    time.sleep(0.8)                      # what was not dropped would have started by now
    assert len(started) < 10
