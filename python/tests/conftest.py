"""What the package's tests share: where the fixtures and the command line
are (BB_BIN, set by `make check-python`), and a way to run it."""

import os
import subprocess

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
FIXTURES = os.path.join(ROOT, "fixtures")
BIN = os.environ.get("BB_BIN") or os.path.join(ROOT, "build", "bumpbake")


@pytest.fixture
def fixtures():
    return FIXTURES


@pytest.fixture
def cli():
    """cli(*args, cwd=None, check=True) runs `bumpbake ARGS` and returns the
    CompletedProcess (text). cli.start(*args, cwd=None) starts it and
    returns the Popen, to run several at once. Skips without the binary."""
    if not os.access(BIN, os.X_OK):
        pytest.skip(f"{BIN} not built")

    def run(*args, cwd=None, check=True):
        out = subprocess.run([BIN, *map(str, args)], cwd=cwd, capture_output=True, text=True)
        if check and out.returncode != 0:
            raise AssertionError(f"bumpbake {' '.join(map(str, args))}: exit {out.returncode}\n"
                                 f"{out.stderr}")
        return out

    def start(*args, cwd=None):
        return subprocess.Popen([BIN, *map(str, args)], cwd=cwd, stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True)

    run.start = start
    return run


@pytest.fixture(scope="session")
def client():
    """A Dask client of a LocalCluster: two worker processes of one thread
    each, started the way a user would (processes, nannies that restart a
    worker that dies). One for the session: a cluster's start (a scheduler,
    two nannies, two workers, each a Python importing Dask) is what a test
    of a cluster need not repeat; a test that kills a worker waits until
    its nanny brings it back."""
    distributed = pytest.importorskip(
        "distributed", reason="python3-distributed is not installed (make deps installs it)")
    try:
        cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                           dashboard_address=None, silence_logs=40)
    except Exception as e:  # pragma: no cover: what this machine cannot do
        pytest.skip(f"dask cannot start a LocalCluster here: {e!r}")
    with cluster, distributed.Client(cluster) as c:
        c.wait_for_workers(2, timeout=60)
        yield c
