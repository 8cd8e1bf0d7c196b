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

from .._common import (ArgumentError, Error, _check, _check_notes, _ffi, _lib, _path,
                       _text)
from .._jobs import BakeJob


class Command:
    """A command handed over by the C program, set up and checked by the
    library; pickles as its hand-over bytes. inputs: a part of the batch
    in place of its inputs (a chunk, planned on a worker)."""

    def __init__(self, data, inputs=None):
        self.data = bytes(data)
        keep = [_ffi.new("char[]", _path(p, "input")) for p in inputs or ()]
        c_inputs = _ffi.new("char *[]", keep) if inputs is not None else _ffi.NULL
        out = _ffi.new("bb_command **")
        err = _ffi.new("bb_error *")
        _check(_lib.bb_command_from_handover(self.data, len(self.data), c_inputs,
                                             len(keep), out, err), err)
        self.c = _ffi.gc(out[0], _lib.bb_command_free)

    def __reduce__(self):
        return (Command, (self.data,))

    def default(self, name, text):
        """Sets option name from text unless the command gave it (a
        cluster's choice where the user made none: threads per task)."""
        if not _lib.bb_command_given(self.c, name.encode()):
            err = _ffi.new("bb_error *")
            _check(_lib.bb_command_set(self.c, name.encode(), text.encode(), err), err)
            _check(_lib.bb_command_check(self.c, err), err)

    @property
    def options(self):
        """The command's bb_command_options (owned by the command)."""
        return _lib.bb_command_options_of(self.c)

    def text(self, name):
        """The text of a string option of the job's, or None."""
        value = getattr(self.options.job, name)
        return None if value == _ffi.NULL else _text(value)


class CommandJob(BakeJob):
    """A BakeJob planned from a handed-over command (bb_command_plan), not
    from keyword arguments: the library reads every option. Runs, reports
    and notes as BakeJob's."""

    def __init__(self, data, inputs=None, *, notes="warn", threads=None, unforced=False,
                 _trace=None):
        self._notes_policy = _check_notes(notes)
        self._trace = _trace
        self._data = bytes(data)
        self._command = Command(data, inputs)
        if threads is not None:  # the library's threads per bake, unless --threads
            self._command.default("threads", str(threads))
        if unforced:  # the command without --force (a flag set to "0" is unset)
            err = _ffi.new("bb_error *")
            _check(_lib.bb_command_set(self._command.c, b"force", b"0", err), err)
            _check(_lib.bb_command_check(self._command.c, err), err)
        job = self._command.options.job
        self._args = dict(out_dir=self._command.text("out_dir"), keep_going=bool(job.keep_going),
                          force=bool(job.force), depfile=self._command.text("depfile"))
        self._single = False  # the command line's single bake always bakes
        hooks = _ffi.new("bb_command_hooks *")
        if _trace is not None:
            hooks.trace = _trace

        def plan(note, out, err):
            hooks.note = note
            return _lib.bb_command_plan(self._command.c, hooks, out, err)
        self._adopt(plan)

    def __reduce__(self):
        return (CommandJob, (self._data, self.inputs))

    def command_text(self, i=0):
        """The command input i's outputs record (bb_command_text)."""
        text = _lib.bb_command_text(self._command.c, self._raw(i).input,
                                    _lib.BB_OPTION_RECORDED)
        if text == _ffi.NULL:
            raise MemoryError("bb_command_text")
        try:
            return _text(text)
        finally:
            _lib.free(text)


# ----------------------------------------------------------------- the run


_OUTCOME = {"pending": _lib.BB_JOB_PENDING, "baked": _lib.BB_JOB_BAKED,
            "up to date": _lib.BB_JOB_CURRENT, "failed": _lib.BB_JOB_FAILED,
            "not run": _lib.BB_JOB_NOT_RUN}


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
    _printed(_lib.bb_job_report_lines(command.options, r, batch, extra))


def _summary(command, reports):
    counts = _ffi.new("int[5]")
    for r in reports:
        counts[_OUTCOME[r.status]] += 1
    name = _lib.bb_command_describe(command.c).name
    _printed(_lib.bb_job_summary_lines(command.options, name, counts, len(reports)))


def _note(line):
    """A note as the C program prints it (cli_note)."""
    print(f"bumpbake: {line.split(': ', 1)[0]}: note: {line.split(': ', 1)[-1]}"
          if ": " in line else f"bumpbake: note: {line}", file=sys.stderr)


def run(command):
    """Runs a handed-over bake command on its cluster; the exit code."""
    from . import bake_big, bake_files
    from ._connect import connect
    with connect(_text(command.options.scheduler), quiet=True) as client:
        if command.text("out_dir") is not None:
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
        return run(Command(data))
    except ArgumentError as e:
        print(f"bumpbake bake: {e}", file=sys.stderr)
        return 2
    except Error as e:
        print(f"bumpbake: {e}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        return 130
