"""What every part of the package shares: the loaded library, its errors,
and numpy arrays to and from bb_image.

Arrays follow the library's conventions (include/bumpbake.h): row 0 is the
top row; (H, W) for one channel, (H, W, C) for more; float arrays are used
as they are and unsigned integer arrays as value / max code, as files are
read.
"""

import os
import warnings

try:
    import numpy as np
except ImportError as e:  # one line naming what to install, not a bare ImportError
    raise ModuleNotFoundError(f"bumpbake needs numpy ({e}): install Debian's python3-numpy",
                              name=e.name) from None

from . import _library

_ffi, _lib, library_path = _library.load()

_INT_MAX = 2**31 - 1


class Error(Exception):
    """A libbumpbake call failed. str(e) is the library's message; e.status
    is the bb_status name ("bad argument", "i/o error", ...)."""

    def __init__(self, message, status):
        super().__init__(message)
        self.status = status


class ArgumentError(Error, ValueError):
    """The library refused a parameter (BB_ERR_ARGUMENT) or, for functions
    on arrays, the array itself (a NaN or infinite value, an empty or
    oversized array)."""


class NoteWarning(UserWarning):
    """A remark of the library about an input that is not an error: which
    channel became the height, a lossy JPEG, 8-bit codes that terrace at
    the scale asked. `bumpbake bake` prints the same lines on stderr."""


# ------------------------------------------------------------------ notes

def _note_text(path, text):
    return f"{path}: {text}" if path else text


def _dispatch_notes(notes, policy, stacklevel):
    if policy == "ignore":
        return
    for line in notes:
        if policy == "warn":
            warnings.warn(line, NoteWarning, stacklevel=stacklevel + 1)
        else:
            policy(line)


class _NoteHooks:
    """bb_command_hooks whose notes gather in heard ("PATH: text"), for a
    call that dispatches them after (_dispatch_notes); keep it alive for
    the call (it holds its callback)."""

    def __init__(self):
        self.heard = []
        self.note = _ffi.callback(
            "bb_note_fn",
            lambda user, p, text: self.heard.append(_note_text(_text(p), _text(text))))
        self.hooks = _ffi.new("bb_command_hooks *")
        self.hooks.note = self.note


def _check_notes(notes):
    if notes not in ("warn", "ignore") and not callable(notes):
        raise _argument_error(f"notes must be 'warn', 'ignore' or a callable (got {_shown(notes)})")
    return notes


def _progress_hook(progress, raised, stop=None):
    """The bb_progress_fn every long call hands the library: progress(done,
    total) (may be None) may return True to cancel; an exception in it
    (KeyboardInterrupt from Ctrl-C included: the callback runs on the
    calling thread, so Python's signal handler raises there) cancels too and
    is kept in raised, to be raised once the library has stopped. stop():
    cancel when it says so. Keep the callback alive for the call."""

    def on_progress(user, done, total):
        if stop is not None and stop():
            return 1
        if progress is not None and total > 0:  # (0, 0): a checkpoint, not progress
            return 1 if progress(done, total) else 0
        return 0

    def on_error(exc_type, exc, tb):
        raised.append(exc)
        return 1  # cancel

    return _ffi.callback("bb_progress_fn", on_progress, onerror=on_error)


def _progress_hooks(progress, raised):
    """(bb_command_hooks * whose progress is _progress_hook(progress,
    raised), the callback): keep both alive for the call."""
    hooks = _ffi.new("bb_command_hooks *")
    cb = _progress_hook(progress, raised)
    hooks.progress = cb
    return hooks, cb


def _status_name(status):
    return _ffi.string(_lib.bb_status_name(status)).decode()


def _message(err, status):
    return _ffi.string(err.message).decode("utf-8", "replace") or _status_name(status)


def _exception(status, message, arrays=False):
    """The exception for a library status: ArgumentError for a bad argument
    (and, for calls on arrays, a bad value or size), Error otherwise."""
    argument = (_lib.BB_ERR_ARGUMENT,)
    if arrays:
        argument += (_lib.BB_ERR_VALUE, _lib.BB_ERR_SIZE)
    cls = ArgumentError if status in argument else Error
    return cls(message, _status_name(status))


def _check(status, err, arrays=False):
    """Raises the library's error when status is not BB_OK."""
    if status != _lib.BB_OK:
        raise _exception(status, _message(err, status), arrays)


def _argument_error(message):
    return ArgumentError(message, "bad argument")


def _text(value):
    """A C string of the library's, as str (None for NULL)."""
    if value == _ffi.NULL:
        return None
    return _ffi.string(value).decode("utf-8", "surrogateescape")


def _taken_bytes(raw, size, call):
    """The size bytes at raw, which call malloc'd (freed here), as bytes;
    MemoryError naming call when raw is NULL."""
    if raw == _ffi.NULL:
        raise MemoryError(call)
    try:
        return bytes(_ffi.buffer(raw, size))
    finally:
        _lib.free(raw)


def _c_bytes(value, what):
    """value (bytes) for a C string: an embedded NUL, where C would end it
    (a.png\\0.exr read as a.png), is ValueError, as os gives."""
    if b"\0" in value:
        raise ValueError(f"{what}: embedded null byte")
    return value


def _shown(value):
    """A value as a message shows it: its repr when short and on one line,
    else what it is (an array's shape and type: its repr spans lines)."""
    text = repr(value)
    if len(text) <= 80 and "\n" not in text:
        return text
    if isinstance(value, np.ndarray):
        return f"a numpy array of shape {value.shape} ({value.dtype})"
    return f"a {type(value).__module__}.{type(value).__qualname__}"


def _c_text(value, what):
    """A str for a C string, UTF-8, refusing an embedded NUL (_c_bytes);
    TypeError for anything else (bytes included: text is str)."""
    if not isinstance(value, str):
        raise TypeError(f"{what} must be a str (got {_shown(value)})")
    return _c_bytes(value.encode(), what)


def _path(value, what="path"):
    """A path (str, bytes or os.PathLike) as the bytes the library opens;
    ValueError for an embedded NUL."""
    if not isinstance(value, (str, bytes, os.PathLike)):
        raise TypeError(f"{what} must be a path (got {_shown(value)})")
    return _c_bytes(os.fsencode(value), what)


def _bake_option(name):
    """`bumpbake bake`'s option name (bb_option_info), whose words and parser
    the package's enum arguments share (bb_option_parse)."""
    return _lib.bb_option_find(_lib.bb_command_info_find(b"bake"), name.encode(), 0)


def _parse_raw(option, text, what):
    """(status, value, err) of text as bake's option reads it (bb_option_parse)."""
    out = _ffi.new("long long *")
    err = _ffi.new("bb_error *")
    st = _lib.bb_option_parse(_bake_option(option), _c_text(text, what), out, err)
    return st, out[0], err


def _parse(option, text, what):
    """The value text stands for as bake's option reads it (its enum's
    value), by the library's parser of the option; its message when refused."""
    if not isinstance(text, str):
        raise TypeError(f"{what} must be a str (got {_shown(text)})")
    st, value, err = _parse_raw(option, text, what)
    _check(st, err)
    return value


def _depth(depth):
    """bb_depth from None (the default), 8, 16, "8", "16", "half", "float"."""
    if depth is None:
        return _lib.BB_DEPTH_DEFAULT
    if isinstance(depth, int) and not isinstance(depth, bool):
        depth = str(depth)
    return _parse("depth", depth, "depth")


# -------------------------------------------------------- engine textures

# The texture settings of write(), bake_file(), bake_files() and BakeJob,
# named as the command line's options.
TEXTURE_PARAMETERS = ("texture_format", "vtf_version", "vtf_flags", "nomip",
                      "fast_compression")


def _vtf_text(command, name, value):
    """value as text for the library's parsers: str as given, an int in
    decimal, a float as Python spells it (7.3); else TypeError."""
    if isinstance(value, bool) or not isinstance(value, (str, int, float)):
        raise TypeError(f"{command}: {name} must be a str or a number (got {_shown(value)})")
    return value if isinstance(value, str) else repr(value)


def _vtf_version(command, value):
    """The VTF minor version of 3, "7.3", "3" or 7.3, as --vtf-version
    reads it (bb_option_parse)."""
    st, minor, err = _parse_raw("vtf-version", _vtf_text(command, "vtf_version", value),
                                "vtf_version")
    if st != _lib.BB_OK:
        raise _argument_error(f"{command}: vtf_version: {_text(err.message)}")
    return minor


def _vtf_flags(command, value):
    """TEXTUREFLAGS_* bits: an int, or text as --vtf-flags takes it ("0x4")
    (bb_option_parse)."""
    if isinstance(value, float):
        raise TypeError(f"{command}: vtf_flags must be an int or a str (got {_shown(value)})")
    st, flags, err = _parse_raw("vtf-flags", _vtf_text(command, "vtf_flags", value), "vtf_flags")
    if st != _lib.BB_OK:
        raise _argument_error(f"{command}: vtf_flags: {_text(err.message)}")
    return flags


def _texture_options(command, texture_format=None, vtf_version=None, vtf_flags=None,
                     nomip=False, fast_compression=False, out=None):
    """A bb_texture_options of the CLI-named settings (None: the library's
    default), filled into out (a bb_texture_options cdata) or a new one.
    Names are parsed by the library; the rest is checked where it is used
    (bb__texture_check), with its message."""
    o = out if out is not None else _ffi.new("bb_texture_options *")
    _lib.bb_texture_options_init(o)
    if texture_format is not None:
        o.format = _parse("texture-format", texture_format, "texture_format")
    if vtf_version is not None:
        o.vtf_version = _vtf_version(command, vtf_version)
    if vtf_flags is not None:
        o.vtf_flags = _vtf_flags(command, vtf_flags)
    o.mips = 0 if nomip else 1
    o.fast = 1 if fast_compression else 0
    return o


# ---------------------------------------------------------------- arrays

class _Image:
    """A bb_image over a numpy array's float32 pixels (a copy when the array
    is not already contiguous float32); keeps the array alive."""

    def __init__(self, what, array, channels=None):
        a = np.asarray(array)
        if a.ndim == 2:
            a = a[:, :, np.newaxis]
        elif a.ndim != 3:
            raise _argument_error(
                f"{what} must be an (H, W) or (H, W, C) array (got shape {a.shape})")
        if a.size:  # the library's size rule from the shape, before any copy (a
            # broadcast view of one value can stand for terabytes)
            err = _ffi.new("bb_error *")
            rows, cols, chans = (min(n, _INT_MAX) for n in a.shape)
            st = _lib.bb_image_size_check(cols, rows, chans, err)
            if st != _lib.BB_OK:
                raise _exception(st, f"{what}: {_message(err, st)}", arrays=True)
        if a.dtype.kind == "u":  # value / max code, as integer files are read
            a = a.astype(np.float32) / np.float32(np.iinfo(a.dtype).max)
        elif a.dtype.kind != "f":
            raise TypeError(f"{what} must be a float or unsigned integer array (got {a.dtype})")
        if channels is not None and a.shape[2] not in channels:
            raise _argument_error(f"{what} must have {' or '.join(map(str, channels))} "
                                  f"channels (got shape {a.shape[:2] + (a.shape[2],)})")
        # contiguous and aligned: an array on an odd offset of a buffer (numpy
        # allows it) would be read by the library through misaligned floats
        self.array = np.require(a, dtype=np.float32, requirements=("C", "A"))
        rows, cols, chans = self.array.shape
        self.image = _ffi.new("bb_image *")
        self.image.width, self.image.height, self.image.channels = cols, rows, chans
        self._buffer = _ffi.from_buffer("float[]", self.array) if self.array.size else _ffi.NULL
        self.image.pixels = self._buffer

    @property
    def alpha(self):
        """The alpha channel's index as OpenImageIO reports files: the last
        of grey + alpha and RGBA, else -1."""
        return {2: 1, 4: 3}.get(self.image.channels, -1)


def _array(img, squeeze=True):
    """A float32 copy of a bb_image: (H, W) for one channel (squeeze), else
    (H, W, C)."""
    n = img.width * img.height * img.channels
    a = np.frombuffer(_ffi.buffer(img.pixels, n * 4), dtype=np.float32).copy()
    one = squeeze and img.channels == 1
    return a.reshape((img.height, img.width) + (() if one else (img.channels,)))


def _take(img, squeeze=True):
    """_array(img), then the library's pixels freed."""
    try:
        return _array(img, squeeze)
    finally:
        _lib.bb_image_free(img)

