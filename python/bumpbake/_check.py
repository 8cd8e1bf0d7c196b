"""A suite of maps against their goldens (bb_check_*): what `bumpbake check`
does, with the same cases, verdicts, updates and reports."""

import collections.abc
import dataclasses
import math
import os
import typing

from ._command import Command
from ._common import (_argument_error, _check, _check_notes, _dispatch_notes, _ffi, _lib,
                      _note_text, _path, _progress_hook, _taken_bytes, _text)

# The keywords of limits in a rule, as idiff's options are named.
_LIMITS = ("fail", "failpercent", "hardfail", "allowfailures", "warn", "warnpercent",
           "hardwarn")


@dataclasses.dataclass
class CheckCase:
    """One map and its golden (bumpbake.check)."""
    name: str              # the golden's path relative to the golden tree
    golden: str            # the golden's path
    new: typing.Optional[str]  # the new file, or the height a bake made it from
    kind: str              # the map's kind ("normal"; "" when unknown)
    result: str            # "PASS", "WARNING", "FAILURE", "DIFFERENT SIZE",
                           # "UNREADABLE", "MISSING", "EXTRA"
    exit_code: int         # idiff's: 0 to 4 (MISSING and EXTRA 2)
    limits: dict           # the limits it was judged by, by idiff's names
    golden_shape: tuple    # (height, width, channels); (0, 0, 0): not read
    new_shape: tuple
    pixels: int
    mean_abs: float
    rms: float
    max_abs: float
    worst: typing.Optional[tuple]  # (x, y, channel) of max_abs, None when 0
    over_fail: int
    over_warn: int
    provenance_diff: typing.Optional[list]  # "key: golden -> new" lines, None:
                                            # not compared
    message: str           # why UNREADABLE, MISSING or EXTRA; else ""
    updated: bool          # the golden was written (update)
    update_error: typing.Optional[str]
    seconds: float

    @property
    def passed(self):
        return self.exit_code == 0 or self.updated


@dataclasses.dataclass
class CheckResult:
    """A suite checked (bumpbake.check): every case, and what the command
    line would exit with."""
    cases: list
    exit_code: int         # the worst case's (an updated one counts as a pass)
    summary: str           # the command line's summary line
    lines: str             # what the command line prints of the cases that do not pass

    @property
    def passed(self):
        return self.exit_code == 0

    def __bool__(self):
        return self.passed

    @property
    def failed(self):
        """The cases that did not pass (and were not updated)."""
        return [c for c in self.cases if not c.passed]


def _case(k):
    s = k.stats
    compared = k.status <= _lib.BB_CHECK_FAILURE and k.width
    diff = _text(k.provenance_diff) if k.provenance_diff != _ffi.NULL else None
    lim = k.limits
    return CheckCase(
        name=_text(k.name), golden=_text(k.golden),
        new=_text(k.fresh) if k.fresh != _ffi.NULL else None, kind=_text(k.kind),
        result=_text(_lib.bb_report_word(b"result", k.status)), exit_code=k.exit_code,
        limits=dict(zip(_LIMITS, (lim.fail, lim.fail_percent, lim.hard_fail,
                                  lim.allow_failures, lim.warn, lim.warn_percent,
                                  lim.hard_warn))),
        golden_shape=(k.height, k.width, k.channels),
        new_shape=(k.new_height, k.new_width, k.new_channels),
        pixels=s.pixels if compared else 0, mean_abs=s.mean_abs, rms=s.rms,
        max_abs=s.max_abs,
        worst=(s.worst_x, s.worst_y, s.worst_channel) if compared and s.max_abs > 0 else None,
        over_fail=s.over_fail, over_warn=s.over_warn,
        provenance_diff=diff.splitlines() if diff is not None else None,
        message=_text(k.message), updated=bool(k.updated),
        update_error=_text(k.update_error) if k.update_error != _ffi.NULL else None,
        seconds=k.seconds)


def _number(value):
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise TypeError
    return "inf" if math.isinf(value) and value > 0 else repr(value)


def limits_text(limits):
    """--limits' text of a mapping {kind or pattern: {limit: value}}
    ("ao": {"fail": 1e-3}), or of a str as it is."""
    if limits is None or isinstance(limits, str):
        return limits
    if not isinstance(limits, collections.abc.Mapping):
        raise TypeError(f"check: limits must be a str or a dict (got {limits!r})")
    rules = []
    for selector, values in limits.items():
        if not isinstance(selector, str) or not isinstance(values, collections.abc.Mapping):
            raise TypeError(f"check: limits: {selector!r} must map a kind or pattern to a "
                            f"dict of limits")
        words = []
        for key, value in values.items():
            if key not in _LIMITS:
                raise _argument_error(f"check: limits: {key!r} is not one of idiff's limits "
                                      f"({', '.join(_LIMITS)})")
            try:
                words.append(f"-{key} {_number(value)}")
            except TypeError:
                raise TypeError(f"check: limits: {selector}: {key} must be a number "
                                f"(got {value!r})") from None
        rules.append(f"{selector}: {' '.join(words)}")
    return "; ".join(rules)


def command(golden, new=None, *, heights=None, limits=None, **options):
    """The library's `check` command of check()'s arguments, checked."""
    if "bake" in options:
        raise TypeError("check: heights= bakes them (the command line's --bake)")
    if (new is None) == (heights is None):
        raise TypeError("check: give new (a tree or file to compare) or heights (to bake), "
                        "not both")
    c = Command("check", "check")
    c.add_input(_path(golden, "golden"))
    if heights is not None:
        if isinstance(heights, (str, bytes, os.PathLike)):
            heights = [heights]
        for h in heights:
            c.add_input(_path(h, "height"))
        options["bake"] = True
    else:
        c.add_input(_path(new, "new"))
    options["limits"] = limits_text(limits)
    c.set_all(options, skip_default=True)
    c.check()
    return c


class Check:
    """A planned check (bb_check_plan) and its cases as they are decided."""

    def __init__(self, cmd, notes="warn"):
        self._notes_policy = _check_notes(notes)
        self.notes = []
        self._note = _ffi.callback("bb_note_fn", self._on_note)
        self.command = cmd
        hooks = _ffi.new("bb_command_hooks *")
        hooks.note = self._note
        out = _ffi.new("bb_check **")
        err = _ffi.new("bb_error *")
        _check(_lib.bb_check_plan(cmd.handle, hooks, out, err), err)
        self._c = _ffi.gc(out[0], _lib.bb_check_free)

    def _on_note(self, user, path, text):
        self.notes.append(_note_text(_text(path), _text(text)))

    @property
    def inputs(self):
        return [_text(_lib.bb_check_input(self._c, i))
                for i in range(_lib.bb_check_input_count(self._c))]

    def run(self, inputs=None, rest=True, progress=None, each=None):
        """Decides the cases of the inputs (indices; None: all) and, with
        rest, the others (two trees' pairs, goldens no input makes)."""
        raised = []
        cb = _progress_hook(progress, raised)
        err = _ffi.new("bb_error *")

        def on_case(user, k):
            if each is not None:
                each(_case(k))
        case_cb = _ffi.callback("bb_check_case_fn", on_case)
        count = _lib.bb_check_input_count(self._c)
        for i in range(count) if inputs is None else inputs:
            st = _lib.bb_check_run_input(self._c, i, cb, _ffi.NULL, case_cb, _ffi.NULL, err)
            if raised:
                raise raised[0]
            _check(st, err)
        if rest:
            _check(_lib.bb_check_run_rest(self._c, case_cb, _ffi.NULL, err), err)

    def cases(self):
        return [_case(_lib.bb_check_case_get(self._c, i))
                for i in range(_lib.bb_check_case_count(self._c))]

    def export(self, first=0):
        """The cases from first on as bytes (bb_check_export)."""
        size = _ffi.new("size_t *")
        raw = _lib.bb_check_export(self._c, first, size)
        return _taken_bytes(raw, size[0], "bb_check_export")

    def import_cases(self, data):
        err = _ffi.new("bb_error *")
        _check(_lib.bb_check_import(self._c, data, len(data), err), err)

    def write_reports(self):
        err = _ffi.new("bb_error *")
        _check(_lib.bb_check_write_reports(self._c, err), err)

    def _lines(self, raw):
        if raw == _ffi.NULL:
            raise MemoryError("bumpbake: out of memory")
        try:
            return _text(raw)
        finally:
            _lib.free(raw)

    def result(self):
        """The CheckResult of the cases so far."""
        lines = "".join(self._lines(_lib.bb_check_case_lines(
            self._c, _lib.bb_check_case_get(self._c, i)))
            for i in range(_lib.bb_check_case_count(self._c)))
        return CheckResult(cases=self.cases(), exit_code=_lib.bb_check_exit_code(self._c),
                           summary=self._lines(_lib.bb_check_summary_lines(self._c)).strip(),
                           lines=lines)

    def dispatch_notes(self, stacklevel):
        _dispatch_notes(self.notes, self._notes_policy, stacklevel + 1)


def check(golden, new=None, *, heights=None, limits=None, update=False, junit=None,
          html=None, progress=None, notes="warn", **options):
    """Checks a suite of maps against their goldens as `bumpbake check` does,
    and returns a CheckResult (one CheckCase per map; passed when the
    command line would exit 0):

        bumpbake.check("goldens", "out")                      # two trees
        bumpbake.check("goldens", heights=["heights/"], scale=32, maps=("normal", "ao"))

    Two trees (or files) are paired by relative name: a golden without a new
    file is MISSING, a new file without a golden EXTRA (failures). With
    heights, they are baked in memory as bake_files(heights, golden, ...)
    would bake them (bake options: scale, rays, maps, name, ...) and each
    map compared with the file it would write; nothing is written.

    Tolerances are idiff's, as compare()'s keywords (fail, failpercent,
    hardfail, allowfailures, warn, warnpercent, hardwarn), and limits sets
    them per map kind or file pattern: {"ao": {"fail": 1e-3},
    "*_normal.png": {"fail": 0.004}} (or --limits' text); the last rule
    that selects a map wins. update: write the goldens of the maps that do
    not pass, and only those. junit: a JUnit XML file to write; html: a
    folder for the HTML report. progress(done, total) follows each bake and
    may return True to cancel (Error "cancelled"). notes: as bake_files'.
    Raises ArgumentError for bad arguments, Error when the goldens or the
    new tree are not there."""
    cmd = command(golden, new, heights=heights, limits=limits, update=update, junit=junit,
                  html=html, **options)
    c = Check(cmd, notes)
    try:
        c.run(progress=progress)
    finally:
        c.write_reports()
    c.dispatch_notes(stacklevel=2)
    return c.result()
