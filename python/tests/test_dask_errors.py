"""bumpbake.dask when the cluster is not what it should be: a malformed
--scheduler is a usage error (one line, exit 2) found before connecting; a
refused connection is one line at once; a scheduler or the only worker lost
in the middle of a batch is one line, within a bound, files whole and no
temporaries; Ctrl-C on the client leaves the batch's later inputs
untouched. A scheduler and a worker run as subprocesses (dask-scheduler,
dask-worker without a nanny), as a user starts them, so they can be
killed."""

import os
import re
import signal
import socket
import subprocess
import sys
import time

import pytest

import bumpbake

distributed = pytest.importorskip(
    "distributed", reason="python3-distributed is not installed (make deps installs it)")
import bumpbake.dask  # noqa: E402
from bumpbake.dask import _connect  # noqa: E402

from test_dask import heights  # noqa: E402

PYTHON_DIR = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# Seconds before a wait counts as a hang: a guard, never a bound on speed
# (no load makes a start, a batch's first files or a lost cluster take
# this long). The bounds on time themselves are make hostile's (32.6, 32.7).
HANG_GUARD = 600


def _free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Cluster:
    """dask-scheduler and one dask-worker (one thread, no nanny: killed, it
    stays dead) as subprocesses on 127.0.0.1. The scheduler picks its own
    port and says it in a scheduler file: a port found free beforehand may
    be taken by another program before the scheduler binds it, and the
    client then waits on a stranger."""

    def __init__(self, directory, package=True):
        env = dict(os.environ, PYTHONPATH=PYTHON_DIR)
        if not package:  # a worker that cannot import bumpbake
            del env["PYTHONPATH"]
        quiet = dict(stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env,
                     cwd=directory)
        scheduler_file = os.path.join(directory, ".scheduler.json")
        self.scheduler = subprocess.Popen(
            [sys.executable, "-m", "distributed.cli.dask_scheduler", "--host", "127.0.0.1",
             "--port", "0", "--scheduler-file", scheduler_file, "--no-dashboard"], **quiet)
        deadline = time.monotonic() + HANG_GUARD
        while not os.path.exists(scheduler_file):
            assert self.scheduler.poll() is None, "dask-scheduler exited"
            assert time.monotonic() < deadline, "dask-scheduler did not start"
            time.sleep(0.05)
        self.client = distributed.Client(scheduler_file=scheduler_file, timeout=HANG_GUARD,
                                         set_as_default=False)
        self.address = self.client.scheduler.address
        self.worker = subprocess.Popen(
            [sys.executable, "-m", "distributed.cli.dask_worker", self.address, "--nthreads",
             "1", "--no-nanny", "--memory-limit", "0", "--no-dashboard"], **quiet)
        self.client.wait_for_workers(1, timeout=HANG_GUARD)

    def close(self):
        self.client.close(timeout=10)
        for p in (self.worker, self.scheduler):
            if p.poll() is None:
                p.kill()
            p.wait()


@pytest.fixture
def cluster(tmp_path):
    c = Cluster(tmp_path)
    try:
        yield c
    finally:
        c.close()


def _one_line(err):
    assert err.count("\n") == 1 and "Traceback" not in err, err
    return err


# ------------------------------------------------------------ the address

BAD_ADDRESSES = ["garbage", "", "tcp://[::1", "inproc://x", "tcp://127.0.0.1:8786/path"]
MORE_BAD = ["tcp://127.0.0.1:99999", "tcp://127.0.0.1:0", "tcp://::1:8786", "tcp://host:port",
            "http://127.0.0.1:8786", "tcp://a b:1", "tcp://[nohost]:1", "tcp://h:1\x1b[2J",
            "tcp://user@h:1"]


@pytest.mark.parametrize("address", BAD_ADDRESSES)
def test_a_malformed_scheduler_is_a_usage_error_in_one_line(tmp_path, monkeypatch, cli,
                                                            address):
    monkeypatch.chdir(tmp_path)
    heights(".", 1, side=16)
    out = cli("bake", "h00.png", "--scale", "16", "-o", "m", "--scheduler", address,
              check=False)
    assert out.returncode == 2, out.stderr
    assert _one_line(out.stderr).startswith("bumpbake bake: --scheduler")
    assert sorted(os.listdir(".")) == ["h00.png"]


def test_more_malformed_addresses_are_one_line():
    for address in MORE_BAD:
        with pytest.raises(bumpbake.ArgumentError, match="^--scheduler") as e:
            _connect.scheduler_address(address)
        assert str(e.value).isprintable(), str(e.value)


def test_good_addresses_are_taken():
    for typed, port in (("tcp://10.0.0.1:8786", 8786), ("127.0.0.1:1", 1),
                        ("tls://sched.example.org:8786", 8786), ("tcp://[::1]:65535", 65535),
                        ("TCP://node-7:8786", 8786)):
        address, _, got = _connect.scheduler_address(typed)
        assert got == port and "://" in address


def test_a_refused_connection_is_one_line_at_once(tmp_path, monkeypatch, cli):
    """Nothing listens on the port: refused, said at once (it took Dask's
    30 s connect timeout and a traceback)."""
    monkeypatch.chdir(tmp_path)
    heights(".", 1, side=16)
    address = f"tcp://127.0.0.1:{_free_port()}"
    out = cli("bake", "h00.png", "--scale", "16", "-o", "m", "--scheduler", address,
              check=False)
    assert out.returncode == 1
    assert "connection refused" in _one_line(out.stderr), out.stderr
    assert sorted(os.listdir(".")) == ["h00.png"]


def test_an_unanswered_connection_is_reported_within_the_timeout():
    """A port that accepts and never speaks Dask (a listening socket that
    is never served): the bound given fires (Dask says which: "after 1 s"),
    not Dask's own 30 s. How long it takes is make hostile's (32.6h)."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        s.listen(1)
        address = f"tcp://127.0.0.1:{s.getsockname()[1]}"
        with pytest.raises(bumpbake.Error, match="cannot reach the Dask scheduler") as e:
            _connect.connect(address, timeout=1)
        assert "within 1 s" in str(e.value), str(e.value)
        assert re.search(r"after 1(\.0)? ?s\b", str(e.value)), str(e.value)  # Dask's words
        assert "\n" not in str(e.value)


def test_a_python_without_distributed_or_numpy_names_the_package(tmp_path):
    for hidden, package in (("distributed", "python3-distributed"), ("numpy", "python3-numpy")):
        out = subprocess.run(
            [sys.executable, "-c", f"import sys; sys.modules[{hidden!r}] = None\n"
             "import bumpbake.dask"], capture_output=True, text=True, cwd=tmp_path,
            env=dict(os.environ, PYTHONPATH=PYTHON_DIR))
        assert out.returncode == 1
        assert package in out.stderr.splitlines()[-1], out.stderr


def test_a_worker_without_the_package_is_one_line(tmp_path, monkeypatch, cli):
    monkeypatch.chdir(tmp_path)
    heights("in", 2, side=16)
    os.makedirs("empty")
    cluster = Cluster(tmp_path / "empty", package=False)
    try:
        out = cli("bake", "in", "--out-dir", "out", "--scale", "16", "--scheduler",
                  cluster.address, check=False)
        assert out.returncode == 1
        assert "a Dask worker cannot import bumpbake: install" in _one_line(out.stderr)
    finally:
        cluster.close()


# ------------------------------------------------------- a cluster lost

def _whole(directory):
    """Every output is whole (bumpbake reads it) and no temporary is left."""
    names = os.listdir(directory) if os.path.isdir(directory) else []
    assert not [n for n in names if n.startswith(".bb-tmp-")], names
    for n in names:
        bumpbake.read(os.path.join(directory, n))
    return names


def _wait_for_files(directory, count, process, deadline):
    while len(os.listdir(directory) if os.path.isdir(directory) else ()) < count:
        assert process.poll() is None, process.communicate()
        assert time.monotonic() < deadline, "the batch did not start"
        time.sleep(0.05)


def test_the_scheduler_killed_in_a_batch_is_one_line(tmp_path, monkeypatch, cli, cluster):
    monkeypatch.chdir(tmp_path)
    heights("in", 40, side=96)
    bake = cli.start("bake", "in", "--scale", "16", "--out-dir", "out", "--maps",
                     "normal,ssbump,ao", "-q", "--scheduler", cluster.address)
    _wait_for_files("out", 3, bake, time.monotonic() + HANG_GUARD)
    cluster.scheduler.kill()
    _, err = bake.communicate(timeout=HANG_GUARD)
    assert bake.returncode == 1, err
    # the connection's close was seen (35 s and a traceback before), not
    # the wait for workers; how soon is make hostile's (32.7a)
    assert re.search(r"the Dask cluster was lost: the connection to the scheduler \S+ closed$",
                     _one_line(err).rstrip("\n")), err
    cluster.worker.wait(timeout=HANG_GUARD)  # its chunk ended: nothing more comes
    assert len(_whole("out")) < 120


def test_the_only_worker_killed_is_lost_within_a_bound(tmp_path, monkeypatch, cluster):
    """It waited for ever for a worker; now WORKERLESS_WAIT seconds, and the
    message says that this wait fired (how soon: make hostile's 32.7b)."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(_connect, "WORKERLESS_WAIT", 2)
    heights("in", 30, side=96)
    killed = []

    def kill_the_worker(done, total):
        if done >= 3 and not killed:
            cluster.worker.kill()
            killed.append(done)

    with pytest.raises(_connect.ClusterLost, match=r"no worker left on \S+ for 2 s$") as e:
        bumpbake.dask.bake_files("in", "out", client=cluster.client, scale=16,
                                 maps=("normal", "ao"), chunk_size=1, progress=kill_the_worker)
    assert killed and "\n" not in str(e.value)
    assert len(_whole("out")) < 60


def test_a_result_lost_with_the_only_worker_is_lost_within_a_bound(monkeypatch, cluster):
    """A task finished on the only worker, which dies between the wait that
    saw it finish and the fetch of its result: the scheduler waits for a
    worker to compute it again, and the fetch waited with it for ever (seen
    once in make test); now WORKERLESS_WAIT seconds."""
    import concurrent.futures
    monkeypatch.setattr(_connect, "WORKERLESS_WAIT", 2)
    alive = _connect.alive

    def kill_then_alive(client):  # the first look after the wait: kill the worker there
        if cluster.worker.poll() is None:
            cluster.worker.kill()
            cluster.worker.wait(timeout=HANG_GUARD)
            deadline = time.monotonic() + HANG_GUARD
            while client.scheduler_info()["workers"]:
                assert time.monotonic() < deadline
                time.sleep(0.05)
        return alive(client)

    monkeypatch.setattr(_connect, "alive", kill_then_alive)
    f = cluster.client.submit(sum, [1, 2, 3], pure=False)
    pool = concurrent.futures.ThreadPoolExecutor(1)
    run = pool.submit(lambda: list(_connect.completed(cluster.client, [f])))
    try:
        with pytest.raises(_connect.ClusterLost, match=r"no worker left on \S+ for 2 s$"):
            run.result(timeout=HANG_GUARD)
    finally:
        pool.shutdown(wait=False)


# ---------------------------------------------------------------- Ctrl-C

def test_ctrl_c_on_the_client_leaves_later_inputs_untouched(tmp_path, monkeypatch, cli,
                                                           cluster):
    """SIGINT to `bake DIR --out-dir --scheduler --keep-going`: exit 130, and
    nothing is written after it: the bake running on the worker is
    cancelled (it looks at the batch's stop variable as it traces), the
    chunks not started are cancelled. The running bake went on and wrote
    after the client had gone."""
    monkeypatch.chdir(tmp_path)
    heights("in", 12, side=400)  # seconds an input on one loaded thread
    bake = cli.start("bake", "in", "--scale", "16", "--slices", "32", "--out-dir", "out",
                     "--maps", "ao", "-q", "--keep-going", "--scheduler", cluster.address)
    _wait_for_files("out", 1, bake, time.monotonic() + HANG_GUARD)
    bake.send_signal(signal.SIGINT)
    _, err = bake.communicate(timeout=HANG_GUARD)
    assert bake.returncode == 130, err
    at_exit = sorted(os.listdir("out"))

    def busy():
        return [k for keys in cluster.client.run(lambda dask_worker: list(
            dask_worker.active_threads.values())).values() for k in keys]

    deadline = time.monotonic() + HANG_GUARD
    while busy():
        assert time.monotonic() < deadline, busy()
        time.sleep(0.1)
    assert sorted(_whole("out")) == at_exit, "written after the client had gone"
    assert not any(cluster.client.processing().values()), "tasks left queued"
