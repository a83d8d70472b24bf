"""texsynth batch, the Dask side: Dask's logs kept from the user, the scheduler address checked
before any work and answered within seconds, failures one line each, Ctrl+C.

One local cluster is started for the module (a shared ``Client``), and one more by the command
that is interrupted; the other tests start none.
"""

import os
import signal
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import texsynth
from texsynth import batch
from texsynth.io import write_exr, write_png
from texsynth.io.files import TEMP_PREFIX

from _images import ramp_photo

distributed = pytest.importorskip("distributed")

CHECKOUT = Path(texsynth.__file__).resolve().parents[1]
SIZE = 48


def _photos(folder, sides):
    folder.mkdir(parents=True, exist_ok=True)
    for k, side in enumerate(sides):
        write_png(folder / f"photo{k}.png", ramp_photo((side, side), seed=k))
    return folder


def _jobs(tmp_path, sides, method="heeger_bergen", size=SIZE):
    return batch.plan(_photos(tmp_path / "in", sides), tmp_path / "out",
                      batch.Defaults(size=(size, size), method=method))


def _dask_lines(text):
    return [line for line in text.splitlines() if "Traceback" in line or "distributed." in line]


@pytest.fixture(scope="module")
def cluster_client(tmp_path_factory):
    """The batch's own local cluster (one worker), its workers' stderr and Dask log in files.

    Worker processes start with this process's sys.path, where pytest puts the checkout's
    parent first (see test_batch.py's workers_import_this_checkout); their stderr is the file
    descriptor 2 they inherit, which capfd does not see: it is a file here."""
    folder = tmp_path_factory.mktemp("cluster")
    stderr, log = folder / "workers.stderr", folder / "workers.log"
    with pytest.MonkeyPatch.context() as patch:
        patch.syspath_prepend(str(CHECKOUT))
        saved = os.dup(2)
        with open(stderr, "w") as f:
            os.dup2(f.fileno(), 2)
        try:
            cluster = batch.local_cluster(1, log)
        finally:
            os.dup2(saved, 2)
            os.close(saved)
        with cluster, distributed.Client(cluster) as client:
            yield client, stderr, log


def test_a_failed_task_is_one_line_and_dask_logs_reach_no_terminal(tmp_path, cluster_client,
                                                                     capfd):
    client, workers_stderr, workers_log = cluster_client
    photos = _photos(tmp_path / "in", [64])
    damaged = ramp_photo((64, 64))
    damaged[3, 3] = np.nan  # a header that reads: refused by the task, not by the plan
    write_exr(photos / "photo1.exr", damaged)
    jobs = batch.plan(photos, tmp_path / "out", batch.Defaults(size=(SIZE, SIZE),
                                                               method="heeger_bergen"))
    summary = batch.run(jobs, client=client)
    assert summary.done == 1 and len(summary.failed) == 1
    (line,) = summary.failed
    assert line.startswith("photo1_heeger_bergen_48x48_s0.exr: InputError: ") and "\n" not in line
    out, err = capfd.readouterr()
    assert not _dask_lines(err) and not _dask_lines(out), err
    assert not _dask_lines(workers_stderr.read_text()), workers_stderr.read_text()
    assert "Compute Failed" in workers_log.read_text()  # routed, not lost
    assert not [p for p in (tmp_path / "out").rglob("*") if p.name.startswith(TEMP_PREFIX)]


def test_a_worker_runs_texsynth_already_imported_keeps_its_heap_and_its_cores(cluster_client):
    client, _, _ = cluster_client
    (state,) = client.run(lambda: ("texsynth.batch" in sys.modules,
                                   os.environ.get("MALLOC_TRIM_THRESHOLD_"),
                                   os.environ.get("MALLOC_MMAP_THRESHOLD_"),
                                   *map(os.environ.get, batch.THREAD_VARIABLES),
                                   sys.modules["texsynth.blocks.parallel"].WORKERS)).values()
    assert state[:3] == (True, *(batch.WORKER_MALLOC[n] for n in ("MALLOC_TRIM_THRESHOLD_",
                                                                   "MALLOC_MMAP_THRESHOLD_")))
    # one worker: BLAS and the pool get every core, not Dask's 1 (unless this process sets
    # its own)
    cores = str(batch.CORES)
    assert state[3:-1] == tuple(os.environ.get(n, cores) for n in batch.THREAD_VARIABLES)
    assert state[-1] == int(os.environ.get("TEXSYNTH_THREADS", cores))
    assert "MALLOC_MMAP_THRESHOLD_" not in os.environ  # the nanny's setting stays in the worker


def test_a_killed_worker_is_one_line(tmp_path, monkeypatch):
    """A task whose workers all died (Dask's KilledWorker, a paragraph) is one short line."""
    from distributed.scheduler import KilledWorker

    (job,) = _jobs(tmp_path, [64])

    class Failed:
        status = "error"

        def __init__(self, key):
            self.key = key

        def exception(self):
            return KilledWorker("texsynth-x", "tcp://127.0.0.1:1", allowed_failures=3)

    class Client:
        def map(self, function, todo, job_keys, key, pure):
            assert function is batch.run_job
            return [Failed(k) for k in key]

    monkeypatch.setattr(distributed, "as_completed", lambda futures: futures)
    summary = batch.run([job], client=Client())
    (line,) = summary.failed
    assert line.startswith("photo0_heeger_bergen_48x48_s0.png: KilledWorker: its worker ")
    assert "\n" not in line and len(line) < 200


@pytest.mark.parametrize("address", ["bogus", "tcp://render-01", "http://127.0.0.1:8787/status",
                                     "inproc://10.0.0.1/1/2", "tcp://:8786", "host:99999"])
def test_a_bad_scheduler_address_is_refused_before_any_work(tmp_path, address):
    jobs = _jobs(tmp_path, [64])
    start = time.monotonic()
    with pytest.raises(ValueError, match="scheduler .*(tcp://HOST:PORT|port 8786)") as error:
        batch.run(jobs, scheduler=address)
    assert time.monotonic() - start < 2 and "\n" not in str(error.value)
    assert not any((tmp_path / "out").iterdir())  # plan made the folder; nothing is in it


def _server(reply):
    """A TCP server on the loopback that accepts and answers ``reply`` (or keeps silent)."""
    server = socket.create_server(("127.0.0.1", 0))
    held = []

    def serve():
        while True:
            try:
                conn, _ = server.accept()
            except OSError:
                return
            held.append(conn)
            if reply:
                try:
                    conn.recv(4096)
                    conn.sendall(reply)
                except OSError:
                    pass

    threading.Thread(target=serve, daemon=True).start()
    return server, held


@pytest.mark.parametrize("reply", [b"HTTP/1.1 400 Bad Request\r\nContent-Length: 0\r\n\r\n",
                                   b""], ids=["web server", "silent"])
def test_no_scheduler_there_is_a_connection_error_within_seconds(tmp_path, monkeypatch, reply):
    monkeypatch.setattr(batch, "CONNECT_TIMEOUT", 3.0)
    server, held = _server(reply)
    address = f"tcp://127.0.0.1:{server.getsockname()[1]}"
    jobs = _jobs(tmp_path, [64])
    start = time.monotonic()
    try:
        with pytest.raises(ConnectionError, match=f"{address}: no Dask scheduler answers there"):
            batch.run(jobs, scheduler=address)
    finally:
        server.close()
        for conn in held:
            conn.close()
    assert time.monotonic() - start < batch.CONNECT_TIMEOUT + 5


def test_a_closed_port_is_a_connection_error_at_once(tmp_path):
    with socket.create_server(("127.0.0.1", 0)) as probe:
        port = probe.getsockname()[1]  # free once closed
    start = time.monotonic()
    with pytest.raises(ConnectionError, match="connection refused|Connection refused"):
        batch.run(_jobs(tmp_path, [64]), scheduler=f"127.0.0.1:{port}")
    assert time.monotonic() - start < 2


def test_ctrl_c_closes_the_cluster_and_leaves_nothing_half_written(tmp_path):
    """Ctrl+C in a terminal reaches the whole process group: the command and its workers."""
    photos = _photos(tmp_path / "in", [64] * 4)
    out = tmp_path / "out"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(CHECKOUT),
                                                        os.environ.get("PYTHONPATH", "")])}
    command = subprocess.Popen(
        [sys.executable, "-m", "texsynth", "-q", "batch", str(photos), "-o", str(out),
         "--size", "192", "--method", "multiscale_mrf"], cwd=CHECKOUT, env=env,
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))  # as in a terminal
    try:
        deadline = time.monotonic() + 120
        while not list(out.glob("*.png")) and command.poll() is None:
            assert time.monotonic() < deadline, "no task finished in 120 s"
            time.sleep(0.05)
        os.killpg(command.pid, signal.SIGINT)
        stdout, stderr = command.communicate(timeout=60)
    finally:
        if command.poll() is None:
            os.killpg(command.pid, signal.SIGKILL)
    assert command.returncode == 130, stderr
    assert "interrupted" in stderr and not _dask_lines(stderr) and not _dask_lines(stdout), stderr
    assert not [p for p in out.rglob("*") if p.name.startswith(TEMP_PREFIX)]
    deadline = time.monotonic() + 10
    while _group(command.pid) and time.monotonic() < deadline:
        time.sleep(0.2)
    assert not _group(command.pid), _group(command.pid)  # no worker outlives the command



def test_the_local_workers_never_take_a_terminals_ctrl_c_and_are_killed_on_one(tmp_path):
    """Started with SIGINT blocked (a Ctrl+C while they import printed their tracebacks), and
    killed when the batch is interrupted (closing waited for their running tasks)."""
    starter = batch._Start(None, 1, tmp_path / "batch.log")
    client = starter.client()
    (pid,) = client.run(os.getpid).values()
    blocked = int(next(line for line in Path(f"/proc/{pid}/status").read_text().splitlines()
                       if line.startswith("SigBlk:")).split()[1], 16)
    assert blocked & (1 << (signal.SIGINT - 1))
    task = client.submit(time.sleep, 60)
    deadline = time.monotonic() + 30
    while not any(client.processing().values()) and time.monotonic() < deadline:
        time.sleep(0.05)
    start = time.monotonic()
    starter.close(interrupted=True)
    assert time.monotonic() - start < 20 and task.status != "finished"
    assert not Path(f"/proc/{pid}").exists()


def _group(pgid):
    """The command lines of the processes still in process group ``pgid``."""
    found = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
            if int(fields[2]) == pgid and fields[0] != "Z":
                found.append((stat.parent / "cmdline").read_text().replace("\0", " "))
        except (OSError, IndexError, ValueError):
            pass
    return found


def test_a_second_cluster_beside_one_on_the_dashboard_port_starts_without_a_warning(recwarn):
    """Dask serves its HTTP routes on 8787 even with the dashboard off: two batches at once
    printed "Port 8787 is already in use ... Hosting the HTTP server on port ... instead"."""
    taken = socket.socket()
    taken.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    try:
        taken.bind(("", 8787))
        taken.listen()
    except OSError:
        pass  # another program holds it: the same case
    try:
        with batch.local_cluster(1):
            pass
    finally:
        taken.close()
    assert not [w for w in recwarn if "already in use" in str(w.message)]
