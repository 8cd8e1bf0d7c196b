"""What bumpbake's Dask tasks share: the client to use, the client's
directory on the workers, thread counts, and the notes the client
dispatches before a worker writes."""

import asyncio
import contextlib
import os
import threading
import uuid
import warnings

import distributed

from .._common import NoteWarning, _argument_error, _dispatch_notes


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


# ----------------------------------------------- notes made into errors

class NoteRefused(Exception):
    """On a worker: the client made a note about the input an error; the
    input is cancelled before anything of it is written."""

    status = "cancelled"


def notes_can_raise(policy):
    """Whether dispatching a note with policy may raise: a callable may; a
    warning may when a filter makes NoteWarning (or a class above it) an
    error; "ignore" never does."""
    if policy == "ignore":
        return False
    if callable(policy):
        return True
    return any(f[0] == "error" and issubclass(NoteWarning, f[2]) for f in warnings.filters)


class NoteDesk:
    """Notes of the inputs baked on the workers, dispatched on the client
    (a warning, the caller's callable) as they come and before anything of
    their input is written, as bake_file dispatches them: a worker that
    reads an input with a note asks here (a distributed.Queue) and waits
    for the answer (a distributed.Variable); a note the caller makes an
    error is raised here, and the worker cancels that input, writing
    nothing of it."""

    def __init__(self, client, token, policy, stacklevel):
        self.name = f"bumpbake-notes-{token}"
        self.queue = distributed.Queue(self.name, client=client)
        self.client, self.policy, self.stacklevel = client, policy, stacklevel

    def asker(self, stop, stopped_at):
        """The notes callable for the workers' jobs (picklable); stop: the
        name of the bake's stop variable, which holds stopped_at (or is
        gone) once the client gave up: no answer will come."""
        return _AskTheClient(self.name, stop, stopped_at)

    def serve(self):
        """Dispatches the notes asked so far and answers each; raises what
        the caller's policy raised (after telling the worker)."""
        for reply, line in self.queue.get(batch=True):
            try:
                _dispatch_notes([line], self.policy, self.stacklevel + 1)
            except BaseException:
                distributed.Variable(reply, client=self.client).set("refused")
                raise
            distributed.Variable(reply, client=self.client).set("go")


class _AskTheClient:
    def __init__(self, name, stop, stopped_at):
        self.name, self.stop, self.stopped_at = name, stop, stopped_at

    def __call__(self, line):
        reply = f"{self.name}-{uuid.uuid4().hex}"
        distributed.Queue(self.name).put((reply, line))
        while True:
            answer = variable_value(reply, None)
            if answer is not None:
                distributed.Variable(reply).delete()
                break
            stop = variable_value(self.stop, None)
            if stop is None or stop == self.stopped_at:  # the client gave up: no answer
                answer = "refused"
                break
        if answer != "go":
            raise NoteRefused(f"{line} (made an error by the caller)")
