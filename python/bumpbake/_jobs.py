"""Bakes of files and batches (bb_job_*): what `bumpbake bake` does, with
the same files, provenance, up-to-date decisions and depfiles."""

import collections.abc
import dataclasses
import os
import typing

from ._bake import OUTPUTS, _basis
from ._command import Command
from ._common import (_argument_error, _check, _check_notes, _dispatch_notes, _exception, _ffi,
                      _lib, _message, _note_text, _path, _progress_hook, _status_name, _shown, _text)

# A report's status: the library's name of its outcome ("up to date", ...).
_OUTCOMES = {k: _text(_lib.bb_report_word(b"outcome", k))
             for k in (_lib.BB_JOB_PENDING, _lib.BB_JOB_BAKED, _lib.BB_JOB_CURRENT,
                       _lib.BB_JOB_FAILED, _lib.BB_JOB_NOT_RUN)}

_SECONDS = ("load", "smooth", "pyramid", "trace", "derive", "compress", "write")


@dataclasses.dataclass
class BakeReport:
    """What became of one input of a bake (bumpbake.bake_files, BakeJob)."""
    input: str             # the path as planned (a directory's file: DIR/NAME)
    status: str            # "pending", "baked", "up to date", "failed", "not run"
    outputs: dict          # {kind: path} it writes ("normal", ..., "slope", "slope_lit");
                           # a map written to several files: {kind: [path, ...]}
    error: typing.Optional[str] = None         # why it failed: "PATH: reason"
    error_status: typing.Optional[str] = None  # the bb_status name of the failure
    reason: typing.Optional[str] = None  # why its outputs were not up to date
    width: typing.Optional[int] = None   # once baked: the height's size,
    height: typing.Optional[int] = None
    channel: typing.Optional[str] = None  # the channel the height came from
    threads: typing.Optional[int] = None  # threads the stages ran on
    slices: typing.Optional[int] = None   # azimuth slices traced (0: none)
    rayset: typing.Optional[str] = None   # the traced scheme's id, None when not traced
    horizons: typing.Optional[float] = None  # texels x slices
    seconds: dict = dataclasses.field(default_factory=dict)  # load, smooth, ..., write
    notes: list = dataclasses.field(default_factory=list)    # "PATH: text" lines
    cluster: typing.Optional[dict] = None  # bumpbake.dask.bake_big: where the trace ran
    _code: int = dataclasses.field(default=0, repr=False, compare=False)  # bb_status
    # the bb_job_report's bytes (its pointers stale), for the library's
    # lines of it (bumpbake bake --scheduler prints them: bb_job_report_lines)
    _bytes: bytes = dataclasses.field(default=b"", repr=False, compare=False)

    @property
    def ok(self):
        """True when baked or up to date."""
        return self.status in ("baked", "up to date")


def _report(r, status=None):
    outputs = {}
    for k in range(r.output_count):  # a map written to several files: a list of them
        kind, path = _text(r.outputs[k].kind), _text(r.outputs[k].path)
        was = outputs.get(kind)
        if was is None:
            outputs[kind] = path
        else:
            outputs[kind] = (was if isinstance(was, list) else [was]) + [path]
    out = BakeReport(input=_text(r.input), status=status or _OUTCOMES[r.outcome],
                     outputs=outputs, _bytes=bytes(_ffi.buffer(r)))
    out.reason = _text(r.reason) or None
    if r.outcome == _lib.BB_JOB_FAILED:
        out.error = _message(r.error, r.status)
        out.error_status = _status_name(r.status)
        out._code = r.status
    if r.outcome == _lib.BB_JOB_BAKED:
        out.width, out.height = r.width, r.height
        out.channel = _text(_lib.bb_height_source_channel(_ffi.addressof(r, "source")))
        out.threads, out.slices, out.horizons = r.threads, r.slices, r.horizons
        out.rayset = _text(r.rayset_id) or None
        out.seconds = {k: getattr(r, "seconds_" + k) for k in _SECONDS}
    return out


class BakeJob:
    """A planned bake of files (bb_command_plan): every option, input and output
    path checked, out_dir and its subfolders made, nothing baked yet.

        job = bumpbake.BakeJob(["heights/"], out_dir="maps", scale=16)
        for i in range(len(job)):
            report = job.run(i)     # up to date: skipped; else baked and written
        job.write_depfile()

    Arguments are bake_files()'s, and bake_file()'s outputs, prefix, slope,
    lit, vmt, materials and basetexture. `reports` lists one BakeReport per input, in order (a
    directory's images sorted by name). run(i) is what bake_files() does
    for one input; items of one job run one at a time (a job is not
    thread-safe), on the calling thread, without the GIL.

    A job pickles as its plan (the inputs as expanded, and the options) and
    is planned again where it is unpickled: a client can plan, send the job
    to workers that each run(i) some inputs, then, once they are done, run
    every input itself (each is then up to date: a header check, no bake)
    and write_depfile().
    """

    # The keywords Python reads itself; every other keyword is the `bake`
    # command's option of that name (maps, name, scale, depfile, vmt...),
    # spelled, checked and refused by the library's option rows.
    def __init__(self, inputs, out_dir=None, *, outputs=None, prefix=None, force=False,
                 keep_going=False, notes="warn", command=None, command_options=None,
                 _trace=None, **options):
        self._args = dict(out_dir=out_dir, outputs=outputs, prefix=prefix, force=force,
                          keep_going=keep_going, notes=notes, command=command,
                          command_options=command_options, **options)
        self._notes_policy = _check_notes(notes)
        self._trace = _trace  # a bb_trace_fn callback, kept alive with the job
        if isinstance(inputs, (str, bytes, os.PathLike)):
            inputs = [inputs]
        elif not isinstance(inputs, (list, tuple)):
            raise TypeError(f"bake: inputs must be a path or a list of paths (got {_shown(inputs)})")
        self._plan([_path(p, "input") for p in inputs], self._args)

    def _command(self, inputs, a):
        """The library's `bake` command of the arguments: each keyword set
        as the command line's option of that name (prefix is -o), checked
        by the library."""
        c = Command("bake")
        for p in inputs:
            c.add_input(p)
        outputs = a["outputs"]
        if outputs is not None and not isinstance(outputs, collections.abc.Mapping):
            raise TypeError(f"bake: outputs must be a dict {{kind: path}} (got {_shown(outputs)})")
        for kind in outputs or {}:
            if kind not in OUTPUTS:
                raise _argument_error(f"bake: unknown map {kind!r} in outputs "
                                      f"(one of {', '.join(OUTPUTS)})")
        options = {k: v for k, v in a.items()
                   if k not in ("outputs", "prefix", "notes", "command", "command_options",
                                "force", "basis")}
        options.update(outputs or {})
        options["output"] = a["prefix"]
        # A single bake always bakes (the command line's); force=False asks
        # for the up-to-date check first (run()).
        options["force"] = a["force"] if a["out_dir"] is not None else None
        basis = a.get("basis")
        vectors = None
        if basis is not None and not isinstance(basis, (str, bytes, os.PathLike)):
            vectors = _basis(basis)[0]  # an array of directions: no command-line spelling
        else:
            options["basis"] = basis
        c.set_all(options, skip_default=True)
        c.record(a["command"], a["command_options"])
        c.check()
        if vectors is not None:
            c.set_basis(vectors)
        return c

    def _plan(self, inputs, a):
        self._cmd = self._command(inputs, a)
        self._single = a["out_dir"] is None

        def plan(note, job, err):
            hooks = _ffi.new("bb_command_hooks *")
            hooks.note = note
            if self._trace is not None:
                hooks.trace = self._trace
            return _lib.bb_command_plan(self._cmd.handle, hooks, job, err)
        self._adopt(plan)

    def _adopt(self, plan):
        """Plans the job through plan(note, job, err) (bb_command_plan of
        this job's command, or of a handed-over one), with the notes hook."""
        # Notes are handed out as they come, on the caller's terms (a
        # warning, a callable), and kept for the report. One the caller
        # turns into an exception cannot raise through C: it is kept, the
        # progress callback cancels the bake at its next call (the library
        # makes one as soon as the input's notes are given, before baking),
        # and it is raised once the library has stopped.
        self._pending = []
        self._note_raised = []
        self._note_stacklevel = None
        self._note = _ffi.callback("bb_note_fn", self._on_note)
        err = _ffi.new("bb_error *")
        job = _ffi.new("bb_job **")
        _check(plan(self._note, job, err), err)
        self._job = _ffi.gc(job[0], _lib.bb_job_free)
        self._count = _lib.bb_job_count(self._job)
        self._status = [None] * self._count  # "not run", "up to date" overrides
        self._notes = [[] for _ in range(self._count)]

    def _on_note(self, user, path, text):
        line = _note_text(_text(path), _text(text))
        self._pending.append(line)
        if self._note_stacklevel is None or self._note_raised:
            return
        try:
            # (frames: _dispatch_notes, this callback, then _run's caller's)
            _dispatch_notes([line], self._notes_policy, self._note_stacklevel + 1)
        except BaseException as e:  # noqa: B036: raised again after the call
            self._note_raised.append(e)

    # ------------------------------------------------------------ pickling

    def __reduce__(self):
        inputs = [r.input for r in self.reports]
        return (_replan, (inputs, self._args))

    # -------------------------------------------------------------- access

    def __len__(self):
        return self._count

    def _raw(self, i):
        if not 0 <= i < self._count:
            raise IndexError(f"input {i} of a job of {self._count}")
        return _lib.bb_job_report_get(self._job, i)

    def report(self, i):
        """Input i's BakeReport as things stand."""
        r = _report(self._raw(i), self._status[i])
        r.notes = list(self._notes[i])
        return r

    @property
    def reports(self):
        """Every input's BakeReport, in order."""
        return [self.report(i) for i in range(self._count)]

    @property
    def inputs(self):
        return [_text(self._raw(i).input) for i in range(self._count)]

    def command_text(self, i=0):
        """The command input i's outputs record in their provenance (key
        "command"): `bumpbake bake INPUT` and the options given that
        determine the output, as bb_command_text spells them. Typing this
        command gives byte-identical files."""
        return self._cmd.text(_ffi.string(self._raw(i).input))

    # ---------------------------------------------------------------- work

    def check_current(self, i):
        """Whether every output of input i is what baking it now would
        write, from the files' headers (no pixel is decoded; the input's
        bytes are hashed): True or False, the report's reason saying why
        not. Raises Error when the input cannot be read."""
        current = _ffi.new("int *")
        err = _ffi.new("bb_error *")
        self._raw(i)
        _check(_lib.bb_job_check_current(self._job, i, current, err), err)
        return bool(current[0])

    def run(self, i, progress=None):
        """Runs input i (bb_job_run_item): skipped when its outputs are up to
        date and the job is not forced, else read, baked and its maps
        written all or nothing with provenance. Returns its BakeReport; a
        failure is in the report, not raised. progress(done, total), when
        given, follows the trace and may return True to cancel it (the
        input then fails, "cancelled", and nothing of it is written); an
        exception it raises (KeyboardInterrupt from Ctrl-C included)
        cancels too and is raised again once the library has stopped."""
        return self._run(i, progress, stacklevel=3)

    def _run(self, i, progress, stacklevel):
        self._raw(i)
        if self._single and not self._args["force"] and self.check_current(i):
            self._status[i] = "up to date"
            self._notes[i] = []
            return self.report(i)
        raised = []
        # Always there: a Ctrl-C during a long trace lands in this Python
        # callback (it runs on the calling thread), which cancels the bake;
        # so does a note the caller made an error (nothing is written).
        cb = _progress_hook(progress, raised, stop=lambda: bool(self._note_raised))
        self._pending = []
        self._note_raised = []
        self._note_stacklevel = stacklevel
        self._status[i] = None
        try:
            _lib.bb_job_run_item(self._job, i, cb, _ffi.NULL)  # without the GIL
        finally:
            notes, self._pending = self._pending, []
            self._notes[i] = notes
            self._note_stacklevel = None
        if self._note_raised:
            raise self._note_raised[0]
        if raised:
            raise raised[0]
        return self.report(i)

    def run_all(self, progress=None):
        """Runs every input in order as bb_job_run does: stopping at the
        first failure unless keep_going (the rest are then "not run"), then
        writes the depfile. Returns the reports; failures are in them.
        Raises Error when the depfile cannot be written."""
        reports, depfile_error = self._run_all(progress, stacklevel=3)
        if depfile_error:
            raise depfile_error
        return reports

    def _run_all(self, progress, stacklevel):
        """(reports, the depfile's error or None)."""
        failed = False
        for i in range(self._count):
            if failed and not self._args["keep_going"]:
                self._status[i] = "not run"
                continue
            failed |= self._run(i, progress, stacklevel + 1).status == "failed"
        try:
            self.write_depfile()
            depfile_error = None
        except Exception as e:  # reported after the inputs' own failures
            depfile_error = e
        return self.reports, depfile_error

    def write_depfile(self):
        """Writes the depfile of the inputs run so far that were baked or up
        to date (all or nothing); nothing without a depfile. A single
        input's depfile is written with its maps. Raises Error when it
        cannot be written."""
        err = _ffi.new("bb_error *")
        _check(_lib.bb_job_write_depfile(self._job, err), err)


def _replan(inputs, args):
    args = dict(args)
    return BakeJob(inputs, args.pop("out_dir"), **args)


def _raise_failures(reports, depfile_error):
    """The first input's failure as the library's error (with every report
    in e.reports), else the depfile's, else nothing: bb_job_run's order."""
    for r in reports:
        if r.status == "failed":
            e = _exception(r._code, r.error)
            e.reports = reports
            raise e
    if depfile_error:
        depfile_error.reports = reports
        raise depfile_error


def bake_files(inputs, out_dir, *, maps=None, name=None, force=False, keep_going=False,
               depfile=None, check=True, progress=None, notes="warn", **options):
    """Bakes height files and directories of them into out_dir, as
    `bumpbake bake INPUT... --out-dir OUT_DIR` does, and returns one
    BakeReport per input.

    inputs: a path or a list of paths: files, and directories, which give
    the image files in them (not below), sorted by name, leaving out names
    starting with '.' and maps bumpbake baked (so a directory can be its own
    out_dir). out_dir is created when missing. maps: the kinds to write,
    from OUTPUTS (default normal, ssbump, ao); name: the file name template,
    "{stem}_{kind}.png" by default ({stem}, {kind}, {ext}; "{kind}/{stem}.png"
    makes subfolders). Every path is checked before any bake.
    An input whose outputs are up to date (their provenance names the same
    input bytes, parameters and bumpbake version) is skipped unless force.
    keep_going: go on after an input fails (default: stop; the rest are
    "not run"). depfile: a Make/Ninja depfile to write. Options: scale
    (required) and bake()'s parameters, channel, depth (None, 8, 16, "half",
    "float") and mips, and the settings of .vtf and .dds outputs, as write()
    takes them (texture_format, vtf_version, vtf_flags, nomip,
    fast_compression), each map's flags and default format following its
    kind. A VTF 7.2 or DDS output holds no provenance, so it is never up
    to date: it is baked again every time (VTF 7.3 and up hold it).

    check (default True): when an input failed, raise its error once the
    run is over (ArgumentError for a bad argument, Error otherwise), with
    every report in e.reports; False returns the reports with the failure
    in them. Errors found before any bake (an option, a name clash, an
    output over an input) are raised either way. progress: as
    BakeJob.run's. notes: "warn" (default: each note is a NoteWarning),
    "ignore", or a callable taking the note's line; every report keeps its
    notes either way.
    """
    job = BakeJob(inputs, out_dir, maps=maps, name=name, force=force, keep_going=keep_going,
                  depfile=depfile, notes=notes, **options)
    reports, depfile_error = job._run_all(progress, stacklevel=3)
    if check:
        _raise_failures(reports, depfile_error)
    elif depfile_error:
        raise depfile_error
    return reports


def bake_file(input, outputs=None, *, prefix=None, slope=None, lit=None, depfile=None,
              force=True, check=True, progress=None, notes="warn", **options):
    """Bakes one height file into the files named, as `bumpbake bake INPUT
    --normal FILE ...` does, and returns its BakeReport.

    outputs: {kind: path} for kinds of OUTPUTS (a list of paths: the map
    written to each, in its format, from the one bake); prefix: also PREFIX_normal.png,
    PREFIX_ssbump.png and PREFIX_ao.png where not named (bake's -o);
    slope: flipcode's slope map (8-bit .png .tga .tif) and lit=(azimuth,
    elevation) its lit preview, written as SLOPE_lit.EXT. force (default
    True, as the command line's single bake): bake even when every output
    is up to date. vmt: also a Source material (.vmt) naming the ssbump
    .vtf (with $ssbump 1), else the normal map's .vtf, relative to
    materials (None: the folder named "materials" above it), with
    basetexture (a .vtf) as $basetexture when given. Other arguments as
    bake_files()'s. Every file is written all or nothing, with provenance.
    """
    job = BakeJob(input, None, outputs=outputs, prefix=prefix, slope=slope, lit=lit,
                  depfile=depfile, force=force, notes=notes, **options)
    reports, depfile_error = job._run_all(progress, stacklevel=3)
    if check:
        _raise_failures(reports, depfile_error)
    return reports[0]
