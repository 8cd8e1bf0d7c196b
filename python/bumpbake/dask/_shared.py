"""What bumpbake's Dask tasks share: the client to use, the client's
directory on the workers, and thread counts."""

import asyncio
import contextlib
import os
import threading

import distributed

from .._common import _argument_error


def client_of(client):
    """The distributed.Client to submit to: client, or the current one."""
    if client is not None:
        if not isinstance(client, distributed.Client):
            raise TypeError(f"client must be a distributed.Client (got {client!r})")
        return client
    try:
        return distributed.get_client()
    except ValueError:
        raise _argument_error(
            "bumpbake.dask: no Dask client: pass client=distributed.Client(ADDRESS) "
            "(the scheduler's address, e.g. tcp://host:8786), or create one first") from None


def worker_threads(client):
    """Threads of every worker of the cluster, together (at least 1)."""
    return max(1, sum(client.nthreads().values()))


# ------------------------------------------------- the client's directory

# Paths are the client's: relative ones are relative to its current
# directory, and the outputs record them as given (the provenance's
# "command"). A worker runs the tasks that open them in that directory, so
# it opens the same files and records the same text, whatever directory it
# was started in. One directory at a time per worker process: a task for
# another waits until the tasks in this one are done.
_directory = threading.Condition()
_directory_users = 0
_directory_path = None


@contextlib.contextmanager
def client_directory(path):
    """Runs the body in the client's directory `path` (an absolute path that
    the worker must see at the same place: shared storage)."""
    global _directory_users, _directory_path
    with _directory:
        while _directory_users and _directory_path != path:
            _directory.wait()
        if not _directory_users:
            try:
                os.chdir(path)
            except OSError as e:
                worker = _worker_address()
                raise _argument_error(
                    f"bumpbake.dask: worker {worker} cannot enter the client's directory "
                    f"{path} ({e.strerror}): the workers must see the client's files at the "
                    "same paths (shared storage)") from None
            _directory_path = path
        _directory_users += 1
    try:
        yield
    finally:
        with _directory:
            _directory_users -= 1
            _directory.notify_all()


def _worker_address():
    try:
        return distributed.get_worker().address
    except ValueError:
        return "(not a worker)"


def this_worker_threads(default=1):
    """The thread slots of the worker running the calling task."""
    try:
        return max(1, int(distributed.get_worker().state.nthreads))
    except ValueError:
        return default


# How long a task waits for a bake's distributed.Variable that is not there:
# one that exists answers at once, so only a variable deleted when its bake
# ended waits this long.
_VARIABLE_WAIT = 5


def variable_value(name, gone, client=None):
    """The value of the distributed.Variable name, or gone when it no longer
    exists: its bake is over, and the task reading it (run again by Dask
    after a worker was lost, for a future somebody still held) must do
    nothing. Variable.get without a timeout would wait for ever."""
    try:
        return distributed.Variable(name, client=client).get(timeout=_VARIABLE_WAIT)
    except (TimeoutError, asyncio.TimeoutError):
        return gone
