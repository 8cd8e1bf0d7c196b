"""`bumpbake bake ... --scheduler ADDRESS` on the Python side: the C
program checks and plans the command, then hands it over (the library's
bb_command_handover, in an inherited descriptor) and execs Python, which
sets it up again through the library (bb_command_from_handover: the same
parsers and checks, so no option means anything here that it does not
mean there) and runs it on the cluster: a batch (--out-dir) as
bake_files, one map as bake_big, its trace split over the workers. The
files record the command as the CLI records it without --scheduler (the
record travels with the command), so they are the bytes the same command
writes on one machine. It prints what the CLI prints, by the library's
lines of each report the cluster sends back and of the batch's summary
(bb_job_report_lines, bb_job_summary_lines: the C program's too), and
exits as it does: 0, 1 when an input failed, 2 for a usage error."""

import json
import os
import sys

from .._command import Command
from .._common import (ArgumentError, Error, _check, _check_notes, _ffi, _lib, _path,
                       _text)
from .._jobs import _OUTCOMES, BakeJob


class CommandJob(BakeJob):
    """A BakeJob planned from a handed-over command (bb_command_plan), not
    from keyword arguments: the library reads every option. Runs, reports
    and notes as BakeJob's."""

    def __init__(self, data, inputs=None, *, notes="warn", threads=None, unforced=False,
                 _trace=None):
        self._notes_policy = _check_notes(notes)
        self._trace = _trace
        self._cmd = command = Command.from_handover(data, inputs)
        if threads is not None:  # the library's threads per bake, unless --threads
            command.default("threads", str(threads))
        if unforced:  # the command without --force (a flag set to "0" is unset)
            err = _ffi.new("bb_error *")
            _check(_lib.bb_command_set(command.handle, b"force", b"0", err), err)
            _check(_lib.bb_command_check(command.handle, err), err)
        self._args = dict(out_dir=command.job_text("out_dir"),
                          keep_going=command.value("keep-going") == "1",
                          force=command.value("force") == "1",
                          depfile=command.job_text("depfile"))
        self._single = False  # the command line's single bake always bakes
        hooks = _ffi.new("bb_command_hooks *")
        if _trace is not None:
            hooks.trace = _trace

        def plan(note, out, err):
            hooks.note = note
            return _lib.bb_command_plan(command.handle, hooks, out, err)
        self._adopt(plan)

    def __reduce__(self):
        return (CommandJob, (self._cmd.data, self.inputs))


# ----------------------------------------------------------------- the run


_OUTCOME = {name: outcome for outcome, name in _OUTCOMES.items()}  # status -> outcome


def _printed(text):
    """Prints the library's lines (bb_job_report_lines, bb_job_summary_lines)."""
    if text == _ffi.NULL:
        raise MemoryError("bumpbake: out of memory")
    try:
        sys.stdout.write(_text(text))
    finally:
        _lib.free(text)
    sys.stdout.flush()


def _print_report(command, report, batch):
    """What the C program prints of a report, by the library's lines: the
    report (a worker's, sent back) as a bb_job_report again."""
    if report.status == "failed":
        print(f"bumpbake: {report.error}", file=sys.stderr)
    r = _ffi.new("bb_job_report *")
    _ffi.memmove(r, report._bytes, min(len(report._bytes), _ffi.sizeof(r[0])))
    keep = [_ffi.new("char[]", _path(report.input))]
    r.input = keep[0]
    r.outcome = _OUTCOME[report.status]
    r.output_count = len(report.outputs)
    for k, (kind, path) in enumerate(report.outputs.items()):
        keep += [_ffi.new("char[]", kind.encode()), _ffi.new("char[]", _path(path))]
        r.outputs[k].kind, r.outputs[k].path = keep[-2], keep[-1]
    extra = _ffi.NULL
    if report.cluster:  # where bake_big's trace ran
        extra = b'"cluster":' + json.dumps(report.cluster, separators=(",", ":")).encode()
    _printed(_lib.bb_job_report_lines(command.handle, r, batch, extra))


def _summary(command, reports):
    counts = _ffi.new("int[5]")
    for r in reports:
        counts[_OUTCOME[r.status]] += 1
    _printed(_lib.bb_job_summary_lines(command.handle, counts, len(reports)))


def _note(line):
    """A note as the C program prints it (cli_note)."""
    print(f"bumpbake: {line.split(': ', 1)[0]}: note: {line.split(': ', 1)[-1]}"
          if ": " in line else f"bumpbake: note: {line}", file=sys.stderr)


def run(command):
    """Runs a handed-over bake command on its cluster; the exit code."""
    from . import bake_big, bake_files
    from ._connect import connect
    with connect(command.value("scheduler"), quiet=True) as client:
        if command.job_text("out_dir") is not None:
            reports = bake_files(None, None, client=client, check=False, notes=_note,
                                 _command=command, _ask_notes=False)
            for r in reports:
                _print_report(command, r, batch=True)
            _summary(command, reports)
            return 1 if any(r.status == "failed" for r in reports) else 0
        report = bake_big(None, client=client, check=False, notes=_note, _command=command,
                          _ask_notes=False)
        _print_report(command, report, batch=False)
        return 1 if report.status == "failed" else 0


def main(fd):
    """The command handed over in descriptor fd, run; the exit code."""
    try:
        with os.fdopen(fd, "rb") as f:
            data = f.read()
        return run(Command.from_handover(data))
    except ArgumentError as e:
        print(f"bumpbake bake: {e}", file=sys.stderr)
        return 2
    except Error as e:
        print(f"bumpbake: {e}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        return 130
