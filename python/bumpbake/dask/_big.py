"""bake_big: one map whose trace is split over the workers of a Dask
cluster, bit for bit the single machine's bake.

One task, the driver, runs the bake itself on a worker (a BakeJob: read,
smooth, normals, derive, write with provenance, all or nothing); its trace
is a hook (bb_trace_options.trace) that sends the slices to horizon tasks,
two slices each (a slice and its opposite share their sweeps), and adds
what comes back in the order the single machine adds it
(bb_trace_accumulate by rank), as each group arrives. A horizon task builds
what the bake traces from the bake's command, handed over
(bb_command_trace_input: read, smooth, scale, pyramid), once per worker
process and bake, and finds its slices' horizons (bb_trace_horizons). The
driver's own worker uses the driver's pyramid.
"""

import collections
import concurrent.futures
import inspect
import os
import threading
import time
import uuid

import distributed
import numpy as np

from .._bake import _basis
from .._common import Error, _check, _dispatch_notes, _exception, _ffi, _lib, _text
from .._jobs import BakeJob, _raise_failures
from ._batch import sweep_temporaries
from .._command import Command
from ._command import CommandJob
from ._connect import ClusterLost, completed, settle
from ._shared import (NoteDesk, client_directory, client_of, notes_can_raise,
                      this_worker_threads, variable_value, worker_threads)

# Groups of slices whose horizons are fetched ahead of the one being added
# up (each holds 8 bytes a texel while it waits).
_AHEAD = 2
# Threads adding the horizons up on the driver: all its machine's cores
# (0); the sums are the same bits for any count.
_DRIVER_THREADS = 0
# Seconds between the driver's looks at the client's stop variable.
_LOOK_EVERY = 0.5

# -------------------------------------------------- a worker's trace inputs


class _Entry:
    def __init__(self, pyramid, rays, owned):
        self.pyramid, self.rays, self.owned = pyramid, rays, owned
        self.users = 0
        self.dropped = False

    def free(self):
        if self.owned:
            _lib.bb_pyramid_free(self.pyramid)
            _lib.bb_rayset_free(self.rays)
        self.pyramid = self.rays = None


# What this worker process holds for each bake it helps: the pyramid and
# ray set, built once (by the first of its tasks) and shared by the others,
# read-only, until the driver drops them. The driver's own worker borrows
# the driver's (_lend), which the bake frees once the loan ends (_take_back).
_inputs = {}
_building = set()
_inputs_changed = threading.Condition()
# Bakes whose inputs were dropped here, the newest last: a horizon task that
# starts after its bake ended (cancelled, but begun before the cancel
# arrived) must not build a pyramid nobody would free.
_ended = collections.OrderedDict()
_ENDED_KEPT = 1024


class _Ended(Exception):
    status = "cancelled"


def _acquire(key, build):
    with _inputs_changed:
        while True:
            if key in _ended:
                raise _Ended(f"bake {key} is over")
            entry = _inputs.get(key)
            if entry is not None:
                entry.users += 1
                return entry
            if key not in _building:
                _building.add(key)
                break
            _inputs_changed.wait()
    try:
        pyramid, rays = build()
    except BaseException:
        with _inputs_changed:
            _building.discard(key)
            _inputs_changed.notify_all()
        raise
    with _inputs_changed:
        _building.discard(key)
        _inputs_changed.notify_all()
        if key in _ended:  # dropped while it was built
            _lib.bb_pyramid_free(pyramid)
            _lib.bb_rayset_free(rays)
            raise _Ended(f"bake {key} is over")
        entry = _inputs[key] = _Entry(pyramid, rays, owned=True)
        entry.users = 1
    return entry


def _release(entry):
    with _inputs_changed:
        entry.users -= 1
        if entry.dropped and entry.users == 0:
            entry.free()
        _inputs_changed.notify_all()


def _drop(key):
    """Frees this worker's inputs of a bake once no task uses them (run on
    every worker by the driver at the end); no task of the bake starts here
    after it. The driver's loan is left to _take_back."""
    with _inputs_changed:
        _ended[key] = True
        while len(_ended) > _ENDED_KEPT:
            _ended.popitem(last=False)
        entry = _inputs.get(key)
        if entry is not None and entry.owned:
            del _inputs[key]
            entry.dropped = True
            if entry.users == 0:
                entry.free()
    return entry is not None


def _lend(key, pyramid, rays):
    with _inputs_changed:
        entry = _inputs[key] = _Entry(pyramid, rays, owned=False)
    return entry


def _take_back(key, entry):
    """Ends the loan of the driver's pyramid (entry): waits until no task
    uses it, since the bake frees it next."""
    with _inputs_changed:
        if _inputs.get(key) is entry:
            del _inputs[key]
        while entry.users:
            _inputs_changed.wait()


def _task_command(task):
    """task's bake command, handed over and set up again by the library in
    the client's directory (a basis file is named relative to it), reading
    the input the driver planned; with the basis of vectors it was given
    (which no option spells)."""
    with client_directory(task["directory"]):
        command = Command.from_handover(task["command"], [task["path"]])
    if task.get("basis") is not None:
        command.set_basis(_basis(task["basis"])[0])
    return command


def _build(task, threads):
    """The trace's input of task's bake on this worker, built by the
    library from the bake's command (bb_command_trace_input): the height
    read as the driver read it (the same bytes: their hash is checked),
    smoothed, scaled, its pyramid, and the ray set."""
    command = _task_command(task)
    pyramid = _ffi.new("bb_pyramid **")
    rays = _ffi.new("bb_rayset **")
    err = _ffi.new("bb_error *")
    _check(_lib.bb_command_trace_input(command.handle, threads, task["file_hash"], pyramid,
                                       rays, err), err)
    if _text(_lib.bb_rayset_id(rays[0])) != task["rayset"]:
        _lib.bb_pyramid_free(pyramid[0])
        _lib.bb_rayset_free(rays[0])
        raise Error(f"{task['path']}: a worker's ray set is not the bake's "
                    "(another bumpbake version?)", "bad argument")
    return pyramid[0], rays[0]


def _owned_array(img):
    """A numpy view of a bb_image's pixels that frees them when it goes."""
    n = img.width * img.height * img.channels
    pixels = _ffi.gc(_ffi.cast("float *", img.pixels), _lib.free)
    img.pixels = _ffi.NULL
    return np.frombuffer(_ffi.buffer(pixels, 4 * n), dtype=np.float32).reshape(
        img.height, img.width)


def _horizons(task, slices, threads):
    """On a worker: (its address, the horizons of slices: {slice: float32
    (H, W)}) of task's bake, found by the sweeps the single machine runs."""
    entry = _acquire(task["key"], lambda: _build(task, threads))
    try:
        o = _ffi.new("bb_trace_options *")  # the bake's, as the driver's trace has them
        o.bias_texels = task["bias"]
        o.threads = threads
        c_slices = _ffi.new("int[]", slices)
        images = _ffi.new("bb_image[]", len(slices))
        err = _ffi.new("bb_error *")
        _check(_lib.bb_trace_horizons(entry.pyramid, entry.rays, o, c_slices, len(slices),
                                      images, err), err)
        return (distributed.get_worker().address,
                {s: _owned_array(images[k]) for k, s in enumerate(slices)})
    finally:
        _release(entry)


# ------------------------------------------------------------- the driver


class _SplitTrace:
    """The bake's trace hook on the driver (bb_trace_fn): horizon tasks
    for every slice, added up here by rank as they arrive."""

    def __init__(self, task, lib_threads):
        self.task = task
        self.lib_threads = lib_threads
        self.job = None
        self.raised = None
        self.stats = {}
        self.started = None  # when the trace began (time.monotonic())

    def __call__(self, user, pyramid, rays, options, vis, err):
        # Nothing may raise through C: the exception is kept for the driver
        # and the bake fails with its message.
        try:
            return self._trace(pyramid, rays, options, vis, err)
        except BaseException as e:  # noqa: B902 (KeyboardInterrupt included)
            self.raised = e
            message = f"trace on the cluster: {e}".encode("utf-8", "replace")[:500]
            _ffi.memmove(err.message, message + b"\0", len(message) + 1)
            return _lib.BB_ERR_CANCELLED if getattr(e, "status", None) == "cancelled" \
                else _STATUS.get(getattr(e, "status", None), _lib.BB_ERR_IO)

    def _trace(self, pyramid, rays, options, vis, err):
        t0 = self.started = time.monotonic()
        n = _lib.bb_rayset_slice_count(rays)
        lobes = _lib.bb_rayset_lobe_count(rays)
        order = _ffi.new("int[]", n)
        _check(_lib.bb_trace_slice_order(rays, order, err), err)
        task = dict(self.task, rayset=_text(_lib.bb_rayset_id(rays)),
                    file_hash=self.job._raw(0).source.file_hash, bias=options.bias_texels)
        # A slice and the next in the order (its opposite, when it has one)
        # go together: bb_trace_horizons sweeps them once.
        groups = [list(range(k, min(k + 2, n))) for k in range(0, n, 2)]
        here = distributed.get_worker()
        me = here.address
        loan = _lend(task["key"], pyramid, rays)
        moved = received = 0
        ran = {}
        # Where the driver's time goes: waiting for horizons, fetching them
        # (on the fetch threads, overlapping the rest), adding them up.
        waited = fetching = adding = 0.0
        cpu0 = _cpu()
        try:
            with distributed.worker_client() as client:
                lib_threads = self.lib_threads
                if lib_threads is None:  # the cluster's threads over the tasks
                    lib_threads = max(1, worker_threads(client) // len(groups))
                futures = [client.submit(_horizons, task, [order[r] for r in g], lib_threads,
                                         key=f"bumpbake-horizons-{task['key']}-{k}", pure=False)
                           for k, g in enumerate(groups)]
                # The next groups' horizons come over (and who ran them is
                # asked) on other threads while this one adds a group up.
                fetcher = concurrent.futures.ThreadPoolExecutor(_AHEAD)

                def fetch(future):
                    distributed.wait(future)
                    t = time.monotonic()
                    (worker, got), = _gather(client, future, here)
                    return got, worker, time.monotonic() - t

                fetched = [fetcher.submit(fetch, f) for f in futures[:_AHEAD]]
                next_look = 0.0
                try:
                    for k, (g, future) in enumerate(zip(groups, futures)):
                        t = time.monotonic()
                        got, worker, seconds = fetched[k].result()
                        waited += time.monotonic() - t
                        fetching += seconds
                        if k + _AHEAD < len(futures):
                            fetched.append(fetcher.submit(fetch, futures[k + _AHEAD]))
                        ran[worker] = ran.get(worker, 0) + len(g)
                        size = sum(a.nbytes for a in got.values())
                        received += size
                        if worker != me:
                            moved += size
                        if k == 0:
                            h, w = got[order[0]].shape
                            _check(_lib.bb_image_alloc(vis, w, h, 1 + lobes, err), err)
                        t = time.monotonic()
                        for r in g:
                            self._accumulate(rays, r, got[order[r]], vis, err)
                        adding += time.monotonic() - t
                        del got
                        future.release()
                        if options.progress != _ffi.NULL and options.progress(
                                options.progress_user, g[-1] + 1, n):
                            raise _exception(_lib.BB_ERR_CANCELLED,
                                             "trace: cancelled by the progress callback")
                        if time.monotonic() >= next_look:  # a round trip: not every group
                            next_look = time.monotonic() + _LOOK_EVERY
                            if variable_value(task["stop"], 1, client=client):
                                raise _exception(_lib.BB_ERR_CANCELLED,
                                                 "trace: cancelled by the client")
                    t = time.monotonic()
                    _check(_lib.bb_trace_finish(rays, vis, _DRIVER_THREADS, err), err)
                    adding += time.monotonic() - t
                finally:
                    fetcher.shutdown(wait=False, cancel_futures=True)
                    client.cancel([f for f in futures if not f.done()])
                    for f in futures:  # none left for Dask to run again
                        f.release()
                    client.run(_drop, task["key"])
        finally:
            _take_back(task["key"], loan)
        self.stats = {"slices": n, "tasks": len(groups), "slices_by_worker": ran,
                      "bytes_received": received, "bytes_moved": moved,
                      "driver": me, "seconds_trace": time.monotonic() - t0,
                      "seconds_waiting": waited, "seconds_fetching": fetching,
                      "seconds_adding": adding, "cpu_seconds_trace": _cpu() - cpu0}
        return _lib.BB_OK

    def _accumulate(self, rays, rank, horizon, vis, err):
        img = _ffi.new("bb_image *")
        img.width, img.height, img.channels = horizon.shape[1], horizon.shape[0], 1
        # aligned: what comes back from a worker may sit at any offset of its frame
        keep = _ffi.from_buffer("float[]", np.require(horizon, dtype=np.float32,
                                                      requirements=("C", "A")))
        img.pixels = keep
        _check(_lib.bb_trace_accumulate(rays, rank, img, vis, _DRIVER_THREADS, err), err)


def _gather(client, future, here):
    """[future's result], taken from the memory of the worker here when it
    holds it (a group traced on the driver's own worker: the arrays as
    they are), else fetched from the worker that does. future.result()
    fetches even a result held here over a socket, serialised and copied:
    4 bytes a texel a slice. (Client._gather's local_worker is Dask's own
    way for a worker's client; a Dask without it fetches as before.)"""
    if _LOCAL_GATHER:
        return client.sync(client._gather, [future], local_worker=here)
    return [future.result()]


_LOCAL_GATHER = "local_worker" in inspect.signature(distributed.Client._gather).parameters


def _cpu():
    """CPU seconds (user and system) of this process so far."""
    t = os.times()
    return t.user + t.system


def _drive(directory, input, args, task):
    """On a worker: the bake of input with its trace split over the
    cluster; returns (BakeReport, what the split did)."""
    t0, cpu0 = time.monotonic(), _cpu()
    with client_directory(directory):
        own = this_worker_threads()
        lib_threads = task.pop("horizon_threads")
        notes = task.pop("notes")  # "ignore", or the client's NoteDesk asker
        if isinstance(args, Command):  # handed over by the CLI: planned by the library
            hook = _SplitTrace(task, lib_threads)
            callback = _ffi.callback("bb_trace_fn", hook, error=_lib.BB_ERR_IO)
            job = CommandJob(args.data, notes=notes, threads=own, _trace=callback)
        else:
            args = dict(args)
            if args.get("threads") is None:
                args["threads"] = own
            hook = _SplitTrace(task, lib_threads)
            callback = _ffi.callback("bb_trace_fn", hook, error=_lib.BB_ERR_IO)
            job = BakeJob(input, None, notes=notes, _trace=callback,
                          **{k: v for k, v in args.items() if k not in ("out_dir", "notes")})
        hook.job = job
        report = job.run(0)
        if hook.raised is not None and not isinstance(hook.raised, Error):
            raise hook.raised  # the cluster's (a lost worker, a cancel), not the bake's
        hook.stats.update(seconds_driver=time.monotonic() - t0, cpu_seconds_driver=_cpu() - cpu0)
        if hook.started is not None:
            hook.stats["seconds_before_trace"] = hook.started - t0
        return report, hook.stats


def bake_big(input, outputs=None, *, client=None, prefix=None, slope=None, lit=None,
             depfile=None, force=True, check=True, notes="warn", command=None,
             horizon_threads=None, _command=None, _ask_notes=None, **options):
    """Bakes one height file into the files named, as bumpbake.bake_file
    (and `bumpbake bake INPUT --normal FILE ...`) does, with its trace
    split over the workers of a Dask cluster; returns its BakeReport. The
    files are a single machine's bake's, bit for bit.

    The job is planned (every path checked) here, on the client. The bake
    then runs on one worker, the driver: it reads, smooths and writes as
    one machine does; its trace goes out as tasks of two slices each (A/2
    tasks for A slices), which every worker runs on the map's pyramid,
    built once per worker process, and the horizons they send back are
    added up on the driver in the single machine's fixed order. So: the
    driver holds what a single bake holds but for the trace's pyramid
    (docs/cluster.md has the bytes per texel), each other worker the
    smoothed height's pyramid (about 9.3 bytes a texel) and the horizons of
    the slices it is working on (4 bytes a texel a slice); what moves is
    4 bytes a texel for every slice traced away from the driver, and the
    input file, read by every worker from shared storage.

    The report's `cluster` says where the slices ran, what moved and
    where the driver's time went: {"slices", "tasks", "slices_by_worker",
    "bytes_received", "bytes_moved", "driver", "seconds_trace",
    "seconds_waiting" (for horizons), "seconds_fetching" (them, on threads
    beside the adding), "seconds_adding" (them up, and finishing),
    "cpu_seconds_trace", "seconds_driver", "cpu_seconds_driver" (of the
    driver's worker process, with the horizon tasks it ran),
    "seconds_before_trace" (reading, smoothing, the pyramid)}.
    horizon_threads: the
    library's threads in each horizon task (default: the cluster's threads
    over the tasks, at least 1). Other arguments as bumpbake.bake_file's
    (force defaults to True, as there: bake even when up to date).
    """
    client = client_of(client)
    directory = os.getcwd()
    if _command is not None:  # the CLI's command (bumpbake bake --scheduler): always baked
        job = CommandJob(_command.data, notes=notes)
        args, force, handed = _command, True, _command.data
    else:
        job = BakeJob(input, None, outputs=outputs, prefix=prefix, slope=slope, lit=lit,
                      depfile=depfile, force=force, notes=notes, command=command, **options)
        args = dict(job._args, force=True)
        handed = job._cmd.handover()  # the command the workers' trace inputs are built of
    if not force and job.check_current(0):
        report = job.report(0)
        report.status = "up to date"
        return report
    planned = job.inputs[0]
    task = {"key": uuid.uuid4().hex, "path": os.path.join(directory, planned),
            "command": handed, "directory": directory}
    basis = options.get("basis")
    if _command is None and basis is not None and \
            not isinstance(basis, (str, bytes, os.PathLike)):
        task["basis"] = np.asarray(basis, dtype=np.float64)  # vectors: no option spells them
    # (None: the driver's trace gives each task the cluster's threads over the tasks)
    task["horizon_threads"] = None if horizon_threads is None else int(horizon_threads)
    # Set when the client gives up (Ctrl-C): the driver stops at the next
    # group of slices, writing nothing (a running task cannot be killed).
    task["stop"] = f"bumpbake-big-stop-{task['key']}"
    stop = distributed.Variable(task["stop"], client=client)
    stop.set(0)
    # A note the caller may make an error is dispatched here before the
    # driver writes anything; the others once the bake is over.
    desk = None
    if notes_can_raise(notes) if _ask_notes is None else _ask_notes:
        desk = NoteDesk(client, task["key"], notes, stacklevel=4)
        task["notes"] = desk.asker(task["stop"], 1)
    else:
        task["notes"] = "ignore"
    future = client.submit(_drive, directory, planned, args, task, pure=False,
                           key=f"bumpbake-big-{task['key']}")
    try:
        (_, (report, stats)), = completed(client, [future], desk.serve if desk else None)
    except BaseException as e:
        settle(client, lambda: stop.set(1))  # left set: the driver may still read it
        settle(client, lambda: client.cancel([future]))
        if isinstance(e, ClusterLost):  # what the lost driver was writing
            sweep_temporaries({os.path.dirname(p) or "." for p in job.report(0).outputs.values()})
        raise
    finally:
        # Released at once: a future still held (by an exception's
        # traceback) makes Dask bake again when the driver's worker is lost.
        future.release()
        if desk is not None:
            settle(client, lambda: desk.queue.close())
    stop.delete()
    report.cluster = stats
    sweep_temporaries({os.path.dirname(p) or "." for p in report.outputs.values()})
    if desk is None:  # (else each was dispatched as the driver read it)
        _dispatch_notes(report.notes, job._notes_policy, stacklevel=2)
    if check:
        _raise_failures([report], None)
    return report


# bb_status by name ("i/o error", ...), for an exception's .status.
_STATUS = {_text(_lib.bb_status_name(code)): code for code in range(_lib.BB_ERR_CANCELLED + 1)}
