"""`bumpbake bake ... --scheduler ADDRESS` on the Python side: the C
program checks and plans the command, then hands it over (the library's
bb_command_handover, in an inherited descriptor) and execs Python, which
sets it up again through the library (bb_command_from_handover: the same
parsers and checks, so no option means anything here that it does not
mean there) and runs it on the cluster: a batch (--out-dir) as
bake_files, one map as bake_big, its trace split over the workers. The
files record the command as the CLI records it without --scheduler (the
record travels with the command), so they are the bytes the same command
writes on one machine. It prints what the CLI prints (wrote/up to date
lines, the batch's summary, --json lines) and exits as it does: 0, 1 when
an input failed, 2 for a usage error."""

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


def _print_report(report, as_json, quiet, batch):
    if report.status == "failed":
        print(f"bumpbake: {report.error}", file=sys.stderr)
    if report.status == "not run":
        return
    if as_json:
        line = {"input": report.input}
        if batch or report.status != "baked":
            line["status"] = report.status
        if report.status == "baked":
            line.update(width=report.width, height=report.height,
                        parameters={"slices": report.slices, "rayset": report.rayset,
                                    "channel": report.channel, "threads": report.threads},
                        seconds=report.seconds, horizons=report.horizons)
            if report.cluster:
                line["cluster"] = report.cluster
        elif report.status == "failed":
            line["exit_code"] = 1
        line["outputs"] = [{"kind": k, "path": p} for k, p in report.outputs.items()
                           if not k.startswith("slope") or report.status != "baked"]
        print(json.dumps(line, separators=(",", ":")))
    elif not quiet and report.status in ("baked", "up to date"):
        verb = "wrote" if report.status == "baked" else "up to date"
        for kind, path in report.outputs.items():
            print(f"{verb} {kind} {path}")
    sys.stdout.flush()


def _summary(reports, as_json, quiet):
    count = {s: sum(r.status == s for r in reports)
             for s in ("baked", "up to date", "failed", "not run")}
    if as_json:
        print(json.dumps({"summary": {"files": len(reports), "baked": count["baked"],
                                      "up_to_date": count["up to date"],
                                      "failed": count["failed"],
                                      "not_run": count["not run"]}}, separators=(",", ":")))
    elif not quiet:
        line = (f"bake: {len(reports)} file{'' if len(reports) == 1 else 's'}: "
                f"{count['baked']} baked, {count['up to date']} up to date, "
                f"{count['failed']} failed")
        if count["not run"]:
            line += (f", {count['not run']} not run (stopped at the first failure; "
                     "--keep-going goes on)")
        print(line)


def _note(line):
    """A note as the C program prints it (cli_note)."""
    print(f"bumpbake: {line.split(': ', 1)[0]}: note: {line.split(': ', 1)[-1]}"
          if ": " in line else f"bumpbake: note: {line}", file=sys.stderr)


def run(command):
    """Runs a handed-over bake command on its cluster; the exit code."""
    from . import bake_big, bake_files
    from ._connect import connect
    o = command.options
    as_json, quiet = bool(o.json), bool(o.quiet)
    with connect(_text(o.scheduler), quiet=True) as client:
        if command.text("out_dir") is not None:
            reports = bake_files(None, None, client=client, check=False, notes=_note,
                                 _command=command, _ask_notes=False)
            for r in reports:
                _print_report(r, as_json, quiet, batch=True)
            _summary(reports, as_json, quiet)
            return 1 if any(r.status == "failed" for r in reports) else 0
        report = bake_big(None, client=client, check=False, notes=_note, _command=command,
                          _ask_notes=False)
        _print_report(report, as_json, quiet, batch=False)
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
