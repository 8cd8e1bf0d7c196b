"""The connection to a Dask cluster and what happens when it goes: a
scheduler address checked before any connection (a usage error in one
line), a connection refused or unanswered reported within a bound, and
results waited for under a watch that says, in one line, when the
scheduler or every worker was lost, instead of a traceback or a wait for
ever."""

import logging
import socket
import time

import distributed

from .._common import Error, _argument_error, _c_text, _check, _ffi, _lib, _message

# Seconds a connection to the scheduler may take (the TCP connection, then
# Dask's handshake); also how long the client tries to reconnect to a
# scheduler it lost before giving up.
CONNECT_TIMEOUT = 10
# Seconds a bake waits for a worker when the cluster has none left (a
# nanny restarting a killed worker takes a few seconds).
WORKERLESS_WAIT = 20
# Seconds between looks at the cluster while waiting for results.
_POLL = 0.5
_WORKERS_EVERY = 2.0



class ClusterLost(Error):
    """The scheduler, or every worker, went away during a bake."""

    def __init__(self, message):
        super().__init__(message, "i/o error")


def scheduler_address(text):
    """(address, host, port) of a scheduler address as typed: PROTOCOL://HOST:PORT
    or HOST:PORT (tcp), the host a name, an IPv4 address or [an IPv6 one].
    ArgumentError, one line, for anything else: the library's check of
    `bumpbake bake --scheduler` (checked before connecting)."""
    if not isinstance(text, str):
        raise _argument_error(f"--scheduler: the address must be a string (got {text!r})")
    err = _ffi.new("bb_error *")
    command = _ffi.new("bb_command **")
    _check(_lib.bb_command_new(b"bake", command, err), err)
    try:
        st = _lib.bb_command_set(command[0], b"scheduler", _c_text(text, "--scheduler"), err)
        if st != _lib.BB_OK:
            raise _argument_error(_message(err, st))
    finally:
        _lib.bb_command_free(command[0])
    scheme, sep, rest = text.partition("://")
    if not sep:
        scheme, rest = "tcp", text
    if rest.startswith("["):
        host, port = rest[1:rest.index("]")], rest[rest.index("]") + 2:]
    else:
        host, _, port = rest.rpartition(":")
    return f"{scheme.lower()}://{rest}", host, int(port)


def connect(text, timeout=None, quiet=False):
    """A distributed.Client of the scheduler at text (checked first by
    scheduler_address): a refused connection is reported at once, one that
    is not answered after timeout seconds (CONNECT_TIMEOUT) then, as
    bumpbake.Error, one line. quiet: no log lines of Dask's in this process
    (a command line, which prints its own one-line errors)."""
    timeout = CONNECT_TIMEOUT if timeout is None else timeout
    address, host, port = scheduler_address(text)
    cannot = f"cannot reach the Dask scheduler {address}"
    try:
        socket.create_connection((host, port), timeout=timeout).close()
    except socket.gaierror as e:
        raise Error(f"{cannot}: unknown host '{host}' ({e.strerror})", "i/o error") from None
    except ConnectionRefusedError:
        raise Error(f"{cannot}: connection refused (no scheduler listens there: "
                    "dask-scheduler prints its address)", "i/o error") from None
    except (socket.timeout, TimeoutError):
        raise Error(f"{cannot}: no answer within {timeout:g} s", "i/o error") from None
    except OSError as e:
        raise Error(f"{cannot}: {e.strerror or e}", "i/o error") from None
    if quiet:  # Dask logs a lost scheduler with tracebacks
        logging.disable(logging.CRITICAL)
    try:
        return distributed.Client(address, timeout=timeout, set_as_default=False)
    except (OSError, TimeoutError) as e:
        raise Error(f"{cannot}: no Dask scheduler answered within {timeout:g} s "
                    f"({str(e).splitlines()[0] if str(e) else type(e).__name__})",
                    "i/o error") from None


def alive(client):
    """Whether client still talks to its scheduler."""
    return client.status == "running"


def completed(client, futures, each_poll=None):
    """Yields (future, its result) as the futures finish, watching the
    cluster meanwhile (and calling each_poll(), when given, at every look):
    raises ClusterLost when the client lost its scheduler (also when it
    goes between a task's end and the fetch of its result), or when no
    worker was left for WORKERLESS_WAIT seconds; a task whose workers kept
    dying, or that a worker cannot load (bumpbake not installed there), is
    one bumpbake.Error too. A task that failed otherwise raises its own
    error here."""
    pending = set(futures)
    workers = _WorkerWatch(client)
    while pending:
        if each_poll is not None:
            each_poll()
        try:
            # distributed.wait, with this client rather than the default one
            done = client.sync(distributed.client._wait, list(pending), timeout=_POLL,
                               return_when="FIRST_COMPLETED").done
        except TimeoutError:
            done = set()
        except Exception:  # noqa: BLE001: the comm went away under the wait
            if not alive(client):
                raise _lost(client) from None
            raise
        for f in done:
            pending.discard(f)
            if f.status == "cancelled" or not alive(client):
                raise _lost(client)
            if f.status == "error":
                _raise_cluster_error(f.exception())
                f.result()  # raises the task's own error
            yield f, _result(client, f, workers, each_poll)
        if not alive(client):
            raise _lost(client)
        if pending:
            workers.look()


class _WorkerWatch:
    """Raises ClusterLost at a look when no worker was left for
    WORKERLESS_WAIT seconds; looks at most every _WORKERS_EVERY seconds."""

    def __init__(self, client):
        self.client = client
        self.workerless_since = None
        self.next_look = 0.0

    def look(self):
        now = time.monotonic()
        if now < self.next_look:
            return
        self.next_look = now + _WORKERS_EVERY
        try:
            workers = len(self.client.scheduler_info()["workers"])
        except Exception:  # noqa: BLE001
            if not alive(self.client):
                raise _lost(self.client) from None
            raise
        if workers:
            self.workerless_since = None
        elif self.workerless_since is None:
            self.workerless_since = now
        elif now - self.workerless_since >= WORKERLESS_WAIT:
            raise ClusterLost(f"the Dask cluster was lost: no worker left on "
                              f"{self.client.scheduler.address} for {WORKERLESS_WAIT:g} s")


def _result(client, f, workers, each_poll):
    """A finished future's result, fetched a _POLL at a time: when the worker
    holding it dies before the fetch, the scheduler computes the task again
    on another worker, or waits for one for ever; the watch bounds that wait
    as it bounds the tasks'."""
    while True:
        try:
            return f.result(timeout=_POLL)
        except TimeoutError:  # (before OSError, of which it is a subclass)
            pass
        except OSError:  # the result comes over the scheduler's connection
            raise _lost(client) from None
        if not alive(client) or f.status == "cancelled":
            raise _lost(client)
        if f.status == "error":
            _raise_cluster_error(f.exception())
            f.result()  # raises the task's own error
        if each_poll is not None:
            each_poll()
        workers.look()


def _lost(client):
    address = getattr(client.scheduler, "address", None) or "(its address)"
    return ClusterLost(f"the Dask cluster was lost: the connection to the scheduler "
                       f"{address} closed")


_MISSING = {"bumpbake": "bumpbake (make install on every worker, or PYTHONPATH=TREE/python "
                        "in the workers' environment)",
            "numpy": "numpy (Debian's python3-numpy)",
            "cffi": "cffi (Debian's python3-cffi)"}


def _raise_cluster_error(e):
    if isinstance(e, distributed.KilledWorker):
        raise ClusterLost(f"the Dask cluster lost the workers running a task several times "
                          f"over (each died: {e})") from None
    if isinstance(e, ImportError):
        name = (e.name or "").split(".")[0]
        if name in _MISSING:
            raise Error(f"a Dask worker cannot import {name}: install {_MISSING[name]}",
                        "i/o error") from None


def settle(client, call):
    """call() when the scheduler is still there (a cleanup), ignoring what
    a scheduler lost meanwhile raises."""
    if not alive(client):
        return
    try:
        call()
    except Exception:  # noqa: BLE001: the first error is the one reported
        if alive(client):
            raise
