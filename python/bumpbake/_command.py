"""The generic driver over the library's descriptions of its commands
(bb_command_*, bb_option_*): every Python function that does what a
`bumpbake` command does takes that command's options as keyword arguments,
named as the command line's long options with '_' for '-' (filter_radius
for --filter-radius). A keyword is set through the library's parser for
its option (bb_command_set) and checked by the library with the other
options (bb_command_check): ranges, defaults and the rules between options
have their one home there, and a refusal carries the library's words. A
mistyped keyword gives the library's nearest option ("did you mean").

Python values become the option's text by its type: a flag takes True
(False or None: not given), numbers are spelled exactly (repr), a word
list or several numbers take a sequence, a path str, bytes or
os.PathLike (a map's file option a list of them: one bake, one file each).
"""

import numbers
import os

import numpy as np

from ._common import (_argument_error, _c_bytes, _c_text, _check, _exception, _ffi, _lib,
                      _message, _path, _shown, _taken_bytes, _text)


# What Python offers for an option of the command line's own
# (BB_OPTION_CLIENT) besides the reports and exceptions it returns.
_CLIENT_ONLY = {
    "scheduler": "from Python, bumpbake.dask.bake_files(client=...) runs a batch on a cluster",
}


def _info(command):
    info = _lib.bb_command_info_find(command.encode())
    if info == _ffi.NULL:
        raise ValueError(f"no command {command!r}")
    return info


def options(command):
    """The options of a command, in the order of its --help: a list of
    bb_option_info (cdata, static)."""
    info = _info(command)
    return [_lib.bb_command_option(info, i) for i in range(info.option_count)]


def keyword(option):
    """The Python keyword of an option (bb_option_info): its long name with
    '_' for '-'."""
    return _text(option.name).replace("-", "_")


def keywords(command, client=False, files=True):
    """The keywords of a command's options, in --help order: without the
    command line's own ones (--help, -q, --json: BB_OPTION_CLIENT) unless
    client, and without those about files (BB_OPTION_FILES: names, formats,
    batches) when files is False (a function on arrays)."""
    out = []
    for o in options(command):
        if o.flags & _lib.BB_OPTION_CLIENT and not client:
            continue
        if o.flags & _lib.BB_OPTION_FILES and not files:
            continue
        out.append(keyword(o))
    return tuple(out)


def _spell_number(value, integer):
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError
    if isinstance(value, numbers.Integral):
        return str(int(value))
    if integer:
        raise TypeError
    return repr(float(value))


def _spell(option, value, what):
    """The text bb_command_set takes for value, by the option's type."""
    kind = option.type
    try:
        if kind == _lib.BB_OPTION_FLAG:
            return None  # (its type checked by set)
        if kind == _lib.BB_OPTION_PATH:
            if isinstance(value, bytes):
                return _c_bytes(value, what)
            if isinstance(value, (str, os.PathLike)):
                return _c_bytes(os.fsencode(value), what)
            raise TypeError
        if isinstance(value, str) and kind != _lib.BB_OPTION_INT:
            return _c_text(value, what)
        if kind in (_lib.BB_OPTION_INT, _lib.BB_OPTION_NUMBER):
            return _spell_number(value, kind == _lib.BB_OPTION_INT).encode()
        if kind in (_lib.BB_OPTION_TEXT, _lib.BB_OPTION_WORD):  # 7.3, flags 4, depth 16
            return _spell_number(value, isinstance(value, numbers.Integral)).encode()
        if kind == _lib.BB_OPTION_WORDS:
            words = list(value)
            if not all(isinstance(w, str) for w in words):
                raise TypeError
            return _c_text(",".join(words), what)
        if kind == _lib.BB_OPTION_NUMBERS:
            sep = " " if option.values > 1 else ","
            return sep.join(_spell_number(v, False) for v in value).encode()
        raise TypeError
    except TypeError:
        raise TypeError(f"{what} must be {_expected(option)} (got {_shown(value)})") from None


def _expected(option):
    kind = option.type
    if kind == _lib.BB_OPTION_FLAG:
        return "True or False"
    if kind == _lib.BB_OPTION_PATH:
        return "a path (str, bytes or os.PathLike)"
    if kind == _lib.BB_OPTION_WORDS:
        return "a str or a sequence of str"
    if kind == _lib.BB_OPTION_NUMBERS:
        return f"a str or a sequence of {option.count} numbers"
    if kind in (_lib.BB_OPTION_INT, _lib.BB_OPTION_NUMBER, _lib.BB_OPTION_TEXT):
        return "an integer" if kind == _lib.BB_OPTION_INT else "a number or a str"
    return "a str"


class Command:
    """One use of a library command (bb_command): keywords set, inputs
    added, checked, then planned, run or drawn by the library. Or, by
    from_handover, the command the C program handed over (`bumpbake bake
    --scheduler`), set up and checked by the library; that one pickles as
    its hand-over bytes (data)."""

    def __init__(self, name, function=None, _handle=None):
        self.name = name
        self.function = function or name  # how messages name the Python call
        self.data = None  # the hand-over bytes (from_handover)
        if _handle is None:
            err = _ffi.new("bb_error *")
            out = _ffi.new("bb_command **")
            _check(_lib.bb_command_new(name.encode(), out, err), err)
            _handle = out[0]
            # its refusals name the options as this package's keywords
            _lib.bb_command_set_spelling(_handle, _lib.BB_SPELLING_KEYWORDS)
        self._c = _ffi.gc(_handle, _lib.bb_command_free)
        self._info = _lib.bb_command_describe(self._c)

    @classmethod
    def from_handover(cls, data, inputs=None):
        """The command of bb_command_handover's bytes (bb_command_from_handover:
        the same parsers and checks as the C program's). inputs: a part of
        the batch in place of its inputs (a chunk, planned on a worker)."""
        data = bytes(data)
        keep = [_ffi.new("char[]", _path(p, "input")) for p in inputs or ()]
        c_inputs = _ffi.new("char *[]", keep) if inputs is not None else _ffi.NULL
        out = _ffi.new("bb_command **")
        err = _ffi.new("bb_error *")
        _check(_lib.bb_command_from_handover(data, len(data), c_inputs, len(keep), out, err),
               err)
        command = cls(_text(_lib.bb_command_describe(out[0]).name), _handle=out[0])
        command.data = data
        return command

    def __reduce__(self):
        if self.data is None:
            raise TypeError("a Command pickles only when handed over (from_handover)")
        return (Command.from_handover, (self.data,))

    def default(self, name, text):
        """Sets option name (its long name) from text unless the command
        gave it (a cluster's choice where the user made none: threads per
        task), and checks the command again."""
        if not self.given(name):
            err = _ffi.new("bb_error *")
            _check(_lib.bb_command_set(self._c, name.encode(), text.encode(), err), err)
            _check(_lib.bb_command_check(self._c, err), err)

    def job_text(self, name):
        """The text of a file option of the job's (out-dir), or None when
        not given."""
        return self.value(name) or None

    def option(self, key):
        """The option of keyword key; TypeError naming the nearest when none."""
        if not isinstance(key, str) or "-" in key:
            o = _ffi.NULL
        else:
            o = _lib.bb_option_find(self._info, key.encode(), 0)
        # "bake()", "run('bake')": how Python names the call
        call = self.function if self.function.endswith(")") else self.function + "()"
        if o != _ffi.NULL and o.flags & _lib.BB_OPTION_CLIENT:
            name = _text(o.name)
            raise TypeError(f"{call} got an unexpected keyword argument {key!r} "
                            f"(--{name} is the command line's own: "
                            f"{_CLIENT_ONLY.get(name, 'Python returns reports and raises')})")
        if o == _ffi.NULL:
            near = _lib.bb_option_nearest(self._info, str(key).encode(), 0)
            hint = ""
            if near != _ffi.NULL and not near.flags & _lib.BB_OPTION_CLIENT:
                hint = f" (did you mean {keyword(near)!r}?)"
            raise TypeError(f"{call} got an unexpected keyword argument {key!r}{hint}")
        return o

    def set(self, key, value, skip_default=False):
        """Sets keyword key (None: left at its default; a flag False: not
        given) through the library's parser. skip_default: a value spelled
        as the option's default is left ungiven (a file bake's provenance
        then records what the command line typed without it records)."""
        o = self.option(key)
        if value is None:
            return
        if o.type == _lib.BB_OPTION_FLAG:
            if not isinstance(value, (bool, numbers.Integral, np.bool_)) or value not in (0, 1):
                raise TypeError(f"{self.function}: {key} must be True or False (got {_shown(value)})")
            if not value:
                return
        if o.type == _lib.BB_OPTION_PATH and isinstance(value, (list, tuple)) and value:
            # several files: the option given once per file, as the command
            # line gives it (a map written to each; the library refuses a
            # second file where an option names one)
            for one in value:
                if isinstance(one, (list, tuple)):
                    raise TypeError(f"{self.function}: {key} must be a path or a list of "
                                    f"paths (got {_shown(value)})")
                self.set(key, one, skip_default)
            return
        text = _spell(o, value, f"{self.function}: {key}")
        if skip_default and text is not None:
            buf = _ffi.new("char[256]")
            _lib.bb_option_default_text(self._info, o, buf, 256)
            if _ffi.string(buf) == text:
                return
        err = _ffi.new("bb_error *")
        st = _lib.bb_command_set(self._c, o.name, _ffi.NULL if text is None else text, err)
        if st != _lib.BB_OK:
            raise _exception(st, self.prefixed(_message(err, st)))

    def prefixed(self, message):
        """The library's message (its options spelled as keywords by the
        library, bb_command_set_spelling) after the function's name, once."""
        return message if message.startswith(self.name + ":") else \
            f"{self.function}: {message}"

    def set_all(self, values, skip_default=False):
        for key, value in values.items():
            self.set(key, value, skip_default)

    def add_input(self, value):
        err = _ffi.new("bb_error *")
        if not isinstance(value, bytes):
            value = os.fsencode(value)
        _check(_lib.bb_command_add_input(self._c, _c_bytes(value, "input"), err), err)

    def in_memory(self, maps=0):
        """For images in memory (arrays): options about files are refused."""
        _lib.bb_command_set_in_memory(self._c, maps)

    def check(self):
        err = _ffi.new("bb_error *")
        st = _lib.bb_command_check(self._c, err)
        if st != _lib.BB_OK:
            message = self.prefixed(_message(err, st))
            if any(o.flags & _lib.BB_OPTION_REQUIRED and not self.given(_text(o.name))
                   and keyword(o) + " is required" in message
                   for o in options(self.name)):
                raise TypeError(message)  # a missing argument, as Python says it
            raise _exception(st, message)

    def given(self, key):
        return bool(_lib.bb_command_given(self._c, key.encode()))

    @property
    def options(self):
        """The checked options, as the runs read them (_Options)."""
        return _Options(self)

    def value(self, name):
        """The value of option name (its long name) as the command holds it,
        spelled as the option takes it (bb_command_value): "" for a file
        not given, "0" or "1" for a flag."""
        out = _ffi.new("char[]", 4096)
        err = _ffi.new("bb_error *")
        _check(_lib.bb_command_value(self._c, name.encode(), out, len(out), err), err)
        return _text(out)

    def numbers(self, name):
        """The numbers of option name as the command holds them, read back by
        the option's own parser (bb_command_numbers): a tuple of floats."""
        option = _lib.bb_option_find(self._info, name.encode(), 0)
        n = option.count if option != _ffi.NULL else 1
        out = _ffi.new("double[]", max(n, 1))
        count = _ffi.new("int *")
        err = _ffi.new("bb_error *")
        _check(_lib.bb_command_numbers(self._c, name.encode(), out, len(out), count, err), err)
        return tuple(out[k] for k in range(count[0]))

    def word(self, name):
        """The value of word option name as the library's enum value
        (bb_option_parse of its value: bb_map_kind for --kind)."""
        option = _lib.bb_option_find(self._info, name.encode(), 0)
        value = _ffi.new("long long *")
        err = _ffi.new("bb_error *")
        _check(_lib.bb_option_parse(option, self.value(name).encode(), value, err), err)
        return value[0]

    def text(self, input=None, recorded=True):
        """The command as bb_command_text spells it (recorded: the options
        that determine what is made, as provenance records them)."""
        flags = _lib.BB_OPTION_RECORDED if recorded else 0
        if input is not None and not isinstance(input, bytes):
            input = os.fsencode(input)
        raw = _lib.bb_command_text(self._c, input if input is not None else _ffi.NULL, flags)
        if raw == _ffi.NULL:
            raise MemoryError("bb_command_text")
        try:
            return _text(raw)
        finally:
            _lib.free(raw)

    def record(self, line=None, options=None):
        err = _ffi.new("bb_error *")
        for what, value in (("command", line), ("command_options", options)):
            if value is not None and not isinstance(value, str):
                raise TypeError(f"{self.function}: {what} must be a str (got {_shown(value)})")
        _check(_lib.bb_command_set_record(
            self._c, _ffi.NULL, _c_text(line, "command") if line is not None else _ffi.NULL,
            _c_text(options, "command_options") if options is not None else _ffi.NULL, err),
            err)

    def set_basis(self, basis):
        """A basis of vectors (a bb_basis *, bb_basis_from_vectors), which no
        --basis spells, for the checked command's bake (bb_command_set_basis)."""
        err = _ffi.new("bb_error *")
        st = _lib.bb_command_set_basis(self._c, basis, err)
        if st != _lib.BB_OK:
            raise _exception(st, self.prefixed(_message(err, st)))

    def handover(self):
        """The command as bytes another process sets up again
        (bb_command_handover; from_handover reads them)."""
        size = _ffi.new("size_t *")
        raw = _lib.bb_command_handover(self._c, size)
        return _taken_bytes(raw, size[0], "bb_command_handover")

    @property
    def handle(self):
        return self._c


def option_table(command):
    """[(keyword, type, value, default, range, help)] of a command's options,
    as the library describes them (docs, tests)."""
    info = _info(command)
    rows = []
    buf = _ffi.new("char[512]")
    for o in options(command):
        _lib.bb_option_value_text(o, buf, 512)
        value = _text(buf)
        _lib.bb_option_default_text(info, o, buf, 512)
        default = _text(buf)
        _lib.bb_option_range_text(o, buf, 512)
        rows.append((keyword(o), _text(_lib.bb_option_type_name(o.type)), value, default, _text(buf),
                     _text(o.help)))
    return rows


def argument_error(command, message):
    return _argument_error(f"{command}: {message}")


def doc(command, files=True, skip=()):
    """The keyword arguments of a command as a docstring's lines, from the
    library's descriptions: "keyword: help (default D; R)"."""
    import textwrap
    lines = []
    for key, _, value, default, range_text, help in option_table(command):
        o = _lib.bb_option_find(_info(command), key.encode(), 0)
        if key in skip or o.flags & _lib.BB_OPTION_CLIENT or (
                not files and o.flags & _lib.BB_OPTION_FILES):
            continue
        extra = "; ".join(x for x in (default and f"default {default}", range_text) if x)
        text = f"{key}: {help}" + (f" ({extra})" if extra else "")
        lines += textwrap.wrap(text, 76, initial_indent="    ", subsequent_indent="        ")
    return "\n".join(lines) + "\n"


class _Options:
    """What the runs read of a checked command after bb_command_check that
    no keyword's value gives as it is; every option is read by name through
    the library (value, numbers, word)."""

    def __init__(self, command):
        self._command = command

    @property
    def maps_normal_y_up(self):
        """--normal-y up: the normal maps read (or written) are OpenGL-style."""
        return int(self._command.value("normal-y") == "up")
