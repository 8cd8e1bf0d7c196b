"""bake_files on a Dask cluster: a batch planned once on the client, its
stale inputs baked on the workers in chunks, the same files as the CLI's
batch."""

import math
import os
import time
import uuid

import distributed

from .. import _common
from .._common import _argument_error, _check, _dispatch_notes, _ffi, _lib, _path
from .._jobs import BakeJob, _raise_failures
from .._command import Command
from ._command import CommandJob
from ._connect import ClusterLost, completed, settle
from ._shared import (NoteDesk, NoteRefused, client_directory, client_of, notes_can_raise,
                      variable_value, worker_threads)

# Inputs per chunk: enough chunks that the last ones end together (the
# scheduler hands a chunk to whichever worker thread is free), few enough
# that a task's cost (a few milliseconds: scheduling, a plan of the chunk)
# stays small against its bakes.
_CHUNKS_PER_THREAD = 20
_MAX_CHUNK = 32

# The stop variable's value when nothing failed: past every index.
_NO_STOP = 2**62


def chunk_size_for(pending, threads):
    """Inputs per chunk for `pending` inputs on `threads` worker threads."""
    return max(1, min(_MAX_CHUNK, math.ceil(pending / (_CHUNKS_PER_THREAD * threads))))


class _Stop:
    """Where a batch without keep_going stops: the index of its first failed
    input, kept by the scheduler (a distributed.Variable, lowered under a
    distributed.Lock) so every worker sees it before starting an input.
    Inputs after it that have not started are not run; those before it
    still run, as in the CLI's batch, which would have baked them first."""

    # Seconds between two looks at the variable during one input's bake.
    LOOK_EVERY = 0.5

    def __init__(self, name):
        self.name = name
        self.over = False  # the batch ended: this chunk is a re-run nobody waits for
        self._next_look = 0.0

    def abandoned(self, done=None, total=None):
        """During an input's bake (its progress callback): whether the
        client gave up (Ctrl-C, its own error: the variable is -1, or gone),
        looked at every LOOK_EVERY seconds. The bake is then cancelled and
        writes nothing: an input that failed stops only later inputs."""
        now = time.monotonic()
        if self.over or now < self._next_look:
            return self.over
        self._next_look = now + self.LOOK_EVERY
        stop = variable_value(self.name, None)
        self.over = stop is None or stop < 0
        return self.over

    def reached(self, index):
        if self.over:
            return True
        stop = variable_value(self.name, None)
        self.over = stop is None
        return self.over or index > stop

    def lower(self, index):
        with distributed.Lock(self.name + "-lock"):
            stop = variable_value(self.name, None)
            if stop is not None and index < stop:
                distributed.Variable(self.name).set(index)


def _bake_chunk(directory, inputs, indices, args, stop, stop_on_failure, notes="ignore"):
    """On a worker: bakes inputs (indices in the batch) of one chunk with
    the batch's arguments (a dict of keyword arguments, or the Command); returns [(index, BakeReport or None: not run)].
    stop (a _Stop or None) says which inputs no longer start; a failure
    lowers it when stop_on_failure. Each input is checked again (a chunk
    run a second time, after its worker died, skips what the first run
    finished) and written all or nothing, as bb_job_run_item does. notes:
    "ignore", or the client's NoteDesk asker: an input whose note the
    client makes an error is cancelled, nothing of it written, and
    reported not run."""
    out = []
    with client_directory(directory):
        if isinstance(args, Command):  # handed over by the CLI: planned by the library
            job = CommandJob(args.data, inputs, notes=notes, threads=1)
        else:
            job = BakeJob(inputs, args["out_dir"], notes=notes,
                          **{k: v for k, v in args.items() if k not in ("out_dir", "notes")})
        for k, index in enumerate(indices):
            if stop is not None and stop.reached(index):
                out.append((index, None))
                continue
            try:
                report = job.run(k, progress=stop.abandoned if stop is not None else None)
            except NoteRefused:
                out.append((index, None))
                continue
            if report.status == "failed" and stop_on_failure:
                stop.lower(index)
            out.append((index, report))
    return out


def _output_directories(reports):
    return sorted({os.path.dirname(p) or "." for r in reports for p in r.outputs.values()})


def sweep_temporaries(directories):
    """Removes what killed writers left in directories (bb_tempfiles_sweep);
    the number removed."""
    removed = 0
    for d in directories:
        n = _ffi.new("int *")
        err = _ffi.new("bb_error *")
        if os.path.isdir(d):
            _check(_lib.bb_tempfiles_sweep(_path(d), n, err), err)
            removed += n[0]
    return removed


def bake_files(inputs, out_dir, *, client=None, maps=None, name=None, force=False,
               keep_going=False, depfile=None, check=True, progress=None, notes="warn",
               chunk_size=None, command_options=None, _command=None, _ask_notes=None,
               **options):
    """Bakes height files and directories of them into out_dir on a Dask
    cluster, as `bumpbake bake INPUT... --out-dir OUT_DIR` does on one
    machine, and returns one BakeReport per input, in input order.

    The batch is planned here, on the client (bumpbake.BakeJob: every
    option and path checked, every name clash across the whole batch
    refused before anything is baked, out_dir made); inputs whose outputs
    are up to date are skipped here (their bytes hashed, the outputs'
    headers read); the rest go to the workers in chunks, so many that every
    worker thread stays busy to the end. Workers open the client's paths,
    relative ones in the client's current directory: they must see the
    same files at the same paths (shared storage). The files are the CLI
    batch's byte for byte when the CLI is typed as BakeJob.command_text
    spells the options (or give command_options, what follows `bumpbake
    bake INPUT` in each file's provenance, as the CLI's --scheduler does).

    A chunk whose worker dies is run again by Dask: what the first run
    finished is then up to date, the rest is baked, and once the batch is
    over the temporaries killed writers left in the output directories are
    removed (bb_tempfiles_sweep). A re-run of the batch bakes nothing.

    keep_going: go on after an input fails. Without it (the default, the
    CLI's) the batch stops at its first failure: no input after the first
    failed one (in input order) starts once the failure is known, and they
    are reported "not run"; inputs before it still run, as the CLI would
    have baked them first; inputs already being baked on other workers when
    it failed finish (each is written whole) and are reported as they
    ended. So more inputs may be baked than by the CLI, never fewer.

    client: a distributed.Client (default: the current one). chunk_size:
    inputs per task (default: about 20 chunks per worker thread, at most
    32 inputs). progress(done, total), called here as inputs finish, may
    return True to stop: no input starts after that, the rest are "not
    run". Other arguments as bumpbake.bake_files; threads (default 1: one
    per task, each worker thread runs a task) is the library's threads per
    bake and changes no byte. check: raise the first failure once the
    batch is over (its e.reports holds every report).
    """
    client = client_of(client)
    directory = os.getcwd()
    if _command is not None:  # the CLI's command (bumpbake bake --scheduler): its own options
        job = CommandJob(_command.data, notes=notes)
        force, keep_going, depfile = (job._args[k] for k in ("force", "keep_going", "depfile"))
    else:
        job = BakeJob(inputs, out_dir, maps=maps, name=name, force=force, keep_going=keep_going,
                      depfile=depfile, notes=notes, command_options=command_options, **options)
    count = len(job)
    reports = [None] * count
    pending = []
    for i in range(count):
        if not force and job.check_current(i):
            reports[i] = job.report(i)
            reports[i].status = "up to date"
        else:
            pending.append(i)
    if _command is not None:
        args = _command
    else:
        args = dict(job._args, depfile=None, keep_going=True)
        args.setdefault("threads", 1)
        if args["threads"] is None:
            args["threads"] = 1
    inputs_planned = job.inputs
    size = chunk_size or chunk_size_for(len(pending), worker_threads(client))
    if not isinstance(size, int) or size < 1:
        raise _argument_error(f"bumpbake.dask: chunk_size must be a positive integer "
                              f"(got {chunk_size!r})")
    token = uuid.uuid4().hex
    # Always there: a client that gives up (Ctrl-C, an exception) stops
    # every chunk before its next input, keep_going or not.
    stop = _Stop(f"bumpbake-stop-{token}")
    distributed.Variable(stop.name, client=client).set(_NO_STOP)
    # Notes the caller may make errors are dispatched here before the
    # worker writes anything of their input; the others once it is over.
    desk = None
    if notes_can_raise(notes) if _ask_notes is None else _ask_notes:
        desk = NoteDesk(client, token, notes, stacklevel=4)
        worker_notes = desk.asker(stop.name, -1)
    else:
        worker_notes = "ignore"
    chunks = [pending[c:c + size] for c in range(0, len(pending), size)]
    futures = {}

    def stop_all():
        distributed.Variable(stop.name, client=client).set(-1)

    try:
        for n, chunk in enumerate(chunks):
            f = client.submit(_bake_chunk, directory, [inputs_planned[i] for i in chunk], chunk,
                              args, stop, not keep_going, worker_notes,
                              key=f"bumpbake-chunk-{token}-{n}", pure=False)
            futures[f] = chunk
        done = count - len(pending)
        for _, result in completed(client, list(futures), desk.serve if desk else None):
            for index, report in result:
                reports[index] = report
                done += 1
            if progress is not None and progress(done, count):
                stop_all()
    except BaseException as e:
        # Nothing that has not started starts: the queued chunks are
        # cancelled, the running ones stop before their next input (a
        # running input is finished, whole: a task cannot be killed).
        settle(client, stop_all)
        settle(client, lambda: client.cancel(list(futures)))
        if isinstance(e, ClusterLost):
            # what the workers it lost were writing
            sweep_temporaries(_output_directories(job.report(i) for i in range(count)))
        raise
    finally:
        # Released now, not when the frame goes (an exception's traceback
        # keeps it): a future still held makes Dask run its chunk again
        # when a worker holding its result is lost.
        for f in futures:
            f.release()
        futures.clear()
        settle(client, lambda: distributed.Variable(stop.name, client=client).delete())
        if desk is not None:
            settle(client, lambda: desk.queue.close())
    for i in range(count):
        if reports[i] is None:
            reports[i] = job.report(i)
            reports[i].status = "not run"
    sweep_temporaries(_output_directories(reports))
    depfile_error = None
    if depfile is not None:
        # The client's job learns what the workers made: each baked input is
        # now up to date (its bytes hashed, its outputs' headers read). A
        # forced job would bake it again here: that one is planned unforced.
        depjob = job
        if force and _command is not None:
            depjob = CommandJob(_command.data, notes="ignore", unforced=True)
        elif force:
            depjob = BakeJob(job.inputs, out_dir, maps=maps, name=name, keep_going=keep_going,
                             depfile=depfile, notes="ignore", command_options=command_options,
                             **options)
        for i in range(count):
            if reports[i].ok:
                depjob.run(i)
        try:
            depjob.write_depfile()
        except _common.Error as e:
            depfile_error = e
    if desk is None:  # (else each was dispatched as its worker read it)
        for r in reports:
            _dispatch_notes(r.notes, job._notes_policy, stacklevel=2)
    if check:
        _raise_failures(reports, depfile_error)
    elif depfile_error:
        raise depfile_error
    return reports
