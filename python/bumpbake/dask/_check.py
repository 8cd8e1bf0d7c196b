"""check_files on a Dask cluster: a golden suite baked and compared on the
workers as a batch is baked, reported by the client as one check."""

import os
import uuid

from .. import _check as check_module
from .._command import Command
from .._common import _argument_error
from ._batch import chunk_size_for
from ._connect import completed, settle
from ._shared import client_directory, client_of, worker_threads


def _check_chunk(directory, data, golden, heights):
    """On a worker: the client's check command planned again for these
    heights (the same options, read by the same parsers), each baked and
    its maps compared (their pictures written into the shared report
    folder); the cases as bb_check_export's bytes."""
    with client_directory(directory):
        cmd = Command.from_handover(data, [golden] + list(heights))
        c = check_module.Check(cmd, notes="ignore")
        c.run(rest=False)
        return c.export()


def check_files(golden, heights, *, client=None, limits=None, update=False, junit=None,
                html=None, progress=None, notes="warn", chunk_size=None, **options):
    """bumpbake.check(golden, heights=heights, ...) on a Dask cluster: the
    suite is planned on the client (every option and name checked, as
    bumpbake.check plans it), its heights baked and compared on the workers
    in chunks, each map against the file the batch would write, nothing
    written but --update's goldens and the report's pictures; the client
    gathers the cases in input order, finds the goldens no input makes, and
    writes the JUnit file and the HTML report of them all. Returns the
    CheckResult, the same cases one process finds.

    Workers open the client's paths (shared storage): the goldens, the
    heights, and the report's folder, where each writes the pictures of its
    cases. chunk_size: heights per task (default: about 20 chunks per worker
    thread, at most 32). progress(done, total): called as heights finish;
    True stops (the rest are not checked, and the reports say so by their
    absence). Other arguments as bumpbake.check's."""
    client = client_of(client)
    directory = os.getcwd()
    cmd = check_module.command(golden, heights=heights, limits=limits, update=update,
                               junit=junit, html=html, **options)
    c = check_module.Check(cmd, notes)
    inputs = c.inputs
    size = chunk_size or chunk_size_for(len(inputs), worker_threads(client))
    if not isinstance(size, int) or size < 1:
        raise _argument_error(f"bumpbake.dask: chunk_size must be a positive integer "
                              f"(got {chunk_size!r})")
    data = cmd.handover()
    token = uuid.uuid4().hex
    chunks = [inputs[i:i + size] for i in range(0, len(inputs), size)]
    futures = {}
    results = [None] * len(chunks)
    try:
        for n, chunk in enumerate(chunks):
            f = client.submit(_check_chunk, directory, data, os.fsdecode(golden), chunk,
                              key=f"bumpbake-check-{token}-{n}", pure=False)
            futures[f] = n
        done = 0
        for f, exported in completed(client, list(futures)):
            n = futures[f]
            results[n] = exported
            done += len(chunks[n])
            if progress is not None and progress(done, len(inputs)):
                break
    except BaseException:
        settle(client, lambda: client.cancel(list(futures)))
        raise
    finally:
        for f in futures:
            f.release()
    stopped = any(r is None for r in results)
    if stopped:
        settle(client, lambda: client.cancel(list(futures)))
    for exported in results:  # in input order, whoever finished first
        if exported is not None:
            c.import_cases(exported)
    if not stopped:
        c.run(inputs=[], rest=True)
    c.write_reports()
    c.dispatch_notes(stacklevel=2)
    return c.result()
