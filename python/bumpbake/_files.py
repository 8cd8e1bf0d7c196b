"""Image files: read, write, what a file is (info), its hash, and two files
compared as idiff compares them (compare)."""

import dataclasses
import os
import typing

from ._bake import _KINDS
from ._command import Command
from ._common import (_Image, _NoteHooks, _argument_error, _array, _c_text, _check,
                      _check_notes, _depth, _dispatch_notes, _exception, _ffi, _lib, _path,
                      _shown, _text, _texture_options)


def read(path):
    """Reads an image file the way the command line does (OpenImageIO: PNG,
    TGA, TIFF, OpenEXR, JPEG, ...): float32, (H, W) for one channel, else
    (H, W, C); integer files are scaled to [0, 1] as value / max code. Raises
    Error with the library's message ("PATH: reason") when it cannot."""
    img = _ffi.new("bb_image *")
    info = _ffi.new("bb_image_info *")
    err = _ffi.new("bb_error *")
    st = _lib.bb_image_read(_path(path), img, info, err)
    try:
        _check(st, err)
        return _array(img)
    finally:
        _lib.bb_image_free(img)
        _lib.bb_image_info_free(info)


def file_hash(path):
    """The 64-bit FNV-1a hash of a file's bytes, as an int: what every map
    bumpbake writes records of its input as input_file_hash (16 hex
    digits), so a pipeline can tell which input a map was baked from, and
    whether it changed since, without decoding it. Raises Error with the
    library's message when the file cannot be read."""
    value = _ffi.new("uint64_t *")
    err = _ffi.new("bb_error *")
    _check(_lib.bb_file_hash(_path(path), value, err), err)
    return int(value[0])


# ------------------------------------------------------------------ info

_PROVENANCE_CLASSES = {_lib.BB_PROVENANCE_NONE: "none", _lib.BB_PROVENANCE_INTACT: "intact",
                       _lib.BB_PROVENANCE_DAMAGED: "damaged"}


def _run_files(command, *inputs, options=None, notes="ignore", stacklevel=2):
    """Runs compare or info through the library as the command line runs
    them (bb_command_run) and hands the result to the caller, who reads the
    report's data (result.compare, result.info) and frees it
    (bb_command_result_free); the result owns its strings, so the command
    may be freed first. options: keywords checked by the
    library; notes: what the run says first (bake_file()'s policy)."""
    c = Command(command)
    for p in inputs:
        c.add_input(p)
    c.set_all(options or {}, skip_default=True)
    c.check()  # the limits by their one rule, a diff's path against the inputs
    _check_notes(notes)
    hooks = _NoteHooks()
    result = _ffi.new("bb_command_result *")
    err = _ffi.new("bb_error *")
    st = _lib.bb_command_run(c.handle, hooks.hooks, result, err)
    _dispatch_notes(hooks.heard, notes, stacklevel=stacklevel + 1)
    _check(st, err)  # a file that cannot be read (the message names it)
    return result


def _provenance_dict(entries, count):
    """The key=value lines of intact provenance (bb_provenance_entry
    cdata) as {key: value}, values as written (strings), as `bumpbake info
    --json` prints them."""
    def part(p, n):
        return _ffi.unpack(p, n).decode("utf-8", "surrogateescape")
    return {part(e.key, e.key_length): part(e.value, e.value_length)
            for e in (entries[i] for i in range(count))}


@dataclasses.dataclass
class ImageInfo:
    """What an image file is, from its header (bumpbake.info)."""
    path: str
    width: int
    height: int
    channels: int
    format: str             # OpenImageIO's format name: "png", "openexr", ...
    bits_per_sample: int    # 8, 16, 32
    is_float: bool          # float or half samples
    alpha_channel: int      # index of the alpha channel, or -1
    provenance_class: str   # "intact", "damaged" (cut or re-wrapped) or "none"
    provenance: typing.Optional[dict]  # {key: value} when intact, else None
    description: typing.Optional[str]  # the stored text (provenance or another
                                       # tool's ImageDescription), or None
    vtf: typing.Optional["VtfInfo"] = None  # a .vtf's header, else None
    dds: typing.Optional["DdsInfo"] = None  # a .dds's header, else None


@dataclasses.dataclass
class VtfInfo:
    """What a Source texture's (.vtf) header says, as `bumpbake info`
    prints it."""
    version: str            # "7.2" ... "7.5"
    header_size: int        # bytes, the resource dictionary included
    width: int
    height: int
    depth: int
    frames: int
    first_frame: int
    flags: int              # TEXTUREFLAGS_* bits
    flag_names: list        # Valve's names of the bits set: ["SSBUMP"], ...
    reflectivity: tuple     # (r, g, b)
    bump_scale: float
    format: int             # Valve's IMAGE_FORMAT_* code (13 = DXT1, 15 = DXT5, ...)
    format_name: str        # "DXT1", "BGR888", ...
    mip_count: int
    low_res_format: int     # IMAGE_FORMAT_* of the low-resolution image, -1: none
    low_res_width: int
    low_res_height: int
    resource_count: int     # 7.3 and up; 0 before
    data_size: int          # bytes of image data the header declares


@dataclasses.dataclass
class DdsInfo:
    """What a DirectDraw Surface's (.dds) header says, as `bumpbake info`
    prints it."""
    width: int
    height: int
    mip_count: int
    fourcc: typing.Optional[str]  # "DXT1", "ATI2", "DX10"; None: a masked format
    dxgi_format: int        # the DX10 header's DXGI_FORMAT code, 0 without one
    format_name: str        # "DXT1", "BC5_UNORM", "R8G8B8A8", ...
    compression: str        # "BC1" to "BC5", or "none"
    pixel_flags: int        # DDS_PIXELFORMAT flags
    pixel_flag_names: list  # the library's names of the bits set: ["FOURCC"], ...
    caps2: int              # DDSCAPS2 (cube map, volume)


def _info_dict(f):
    """The fields of ImageInfo from a file of info's report (bb_info_file
    cdata): the data the library found, as a dict."""
    i = f.image
    klass = _PROVENANCE_CLASSES[f.provenance]
    names = [_text(f.flag_names[bit]) for bit in range(32) if f.flag_names[bit] != _ffi.NULL]
    vtf = dds = None
    if f.vtf != _ffi.NULL:
        v = f.vtf
        vtf = VtfInfo(
            version=f"{v.version_major}.{v.version_minor}", header_size=v.header_size,
            width=v.width, height=v.height, depth=v.depth, frames=v.frames,
            first_frame=v.first_frame, flags=v.flags, flag_names=names,
            reflectivity=tuple(v.reflectivity), bump_scale=v.bump_scale, format=v.format,
            format_name=_text(v.format_name), mip_count=v.mip_count,
            low_res_format=v.low_res_format, low_res_width=v.low_res_width,
            low_res_height=v.low_res_height, resource_count=v.resource_count,
            data_size=v.data_size)
    if f.dds != _ffi.NULL:
        d = f.dds
        dds = DdsInfo(
            width=d.width, height=d.height, mip_count=d.mip_count,
            fourcc=_text(d.fourcc) or None, dxgi_format=d.dxgi_format,
            format_name=_text(d.format_name), compression=_text(d.compression),
            pixel_flags=d.pixel_flags, pixel_flag_names=names, caps2=d.caps2)
    return dict(
        path=os.fsdecode(_ffi.string(f.path)),
        width=f.width, height=f.height, channels=f.channels, format=_text(i.format_name),
        bits_per_sample=i.bits_per_sample, is_float=bool(i.is_float),
        alpha_channel=i.alpha_channel, provenance_class=klass,
        provenance=(_provenance_dict(f.provenance_entries, f.provenance_count)
                    if klass == "intact" else None),
        description=_text(i.description), vtf=vtf, dds=dds)


def info(path):
    """What an image file is, from its header alone (no pixel is decoded),
    as `bumpbake info` reports it: an ImageInfo; for a Source texture
    (.vtf) also its header's version, format, flags and mips (.vtf, a
    VtfInfo), for a DirectDraw Surface its format and flags (.dds, a
    DdsInfo). Raises Error with the library's message when the file cannot
    be read."""
    result = _run_files("info", _path(path))
    try:
        f = result.info[0]
        if f.status != _lib.BB_OK:
            raise _exception(f.status, _ffi.string(f.error).decode("utf-8", "replace"))
        return ImageInfo(**_info_dict(f))
    finally:
        _lib.bb_command_result_free(result)


# ----------------------------------------------------------------- write

# Words for unit values besides the map kinds (which say their own range).
_UNIT_KINDS = ("height", "colour", "render")


def _signed(command, kind):
    """True when kind's values are signed unit vectors ([-1, 1]: normal and
    bent, as bb_map_kind_info says), False for unit values ([0, 1])."""
    if kind in _KINDS:
        return _KINDS[kind][2]
    if kind in _UNIT_KINDS:
        return False
    raise _argument_error(f"{command}: kind must be one of "
                          f"{', '.join(tuple(_KINDS) + _UNIT_KINDS)} (got {_shown(kind)})")


def write(path, array, *, kind="colour", depth=None, mips=False, description=None,
          texture_format=None, vtf_version=None, vtf_flags=None, nomip=False,
          fast_compression=False):
    """Writes an array to path with the library's writer, as `bumpbake bake`
    writes its maps: the format from the extension (.png .tga .tif .tiff
    .exr, and the engine textures .vtf and .dds), written to a temporary
    file and renamed into place (nothing is left at path on failure).

    kind says how values become integer codes: "normal" and "bent" arrays
    are signed unit vectors stored as 0.5 + 0.5 N (N itself in float files);
    the other map kinds ("weights", "ssbump", "ao", "filtered") and "height",
    "colour" and "render" are unit values stored as value x max code.
    Integer formats clamp and round to the nearest code.
    depth: None (8-bit for png/tga/tif, float for exr), 8, 16, "half" or
    "float". mips: a mip chain (tif and exr only), renormalised for normal
    and bent, averaged otherwise. description: text stored in the file's
    ImageDescription (bumpbake's provenance, or anything), or None.

    .vtf (Source) and .dds files are engine textures, with the command
    line's settings: texture_format (None: VTF DXT1, DXT5 with alpha; DDS
    BC5 for "normal" and "bent", BC4 for one channel, BC1 for three;
    "dxt1", "dxt5", "bgr888", "bgra8888", "rgba16f" in a VTF, "bc1", "bc3",
    "bc4", "bc5", "rgba8", "rgba16f", "rgba32f" in a DDS), vtf_version (7.2
    by default; 7.3 to 7.5 as 3, "7.3" or 7.3: these keep description),
    vtf_flags (TEXTUREFLAGS_* bits added to the kind's own: SSBUMP for
    "ssbump" and "weights", NORMAL for "normal" and "bent"), nomip (no mip
    chain; a texture has the full one by default, whatever mips says),
    fast_compression (the block codec's quick fit of colour blocks). depth must be None.
    Raises ArgumentError for a format that cannot hold the depth, mips or
    channels, a texture size or format its container cannot take (a VTF
    side not a power of two, a block format's side not a multiple of 4),
    Error when the file cannot be written."""
    signed = _signed("write", kind)
    src = _Image("write: array", array)
    d = _depth(depth)
    texture = _texture_options("write", texture_format, vtf_version, vtf_flags, nomip,
                               fast_compression)
    rng = _lib.BB_RANGE_SIGNED if signed else _lib.BB_RANGE_UNIT
    p = _path(path)
    err = _ffi.new("bb_error *")
    c_path, c_kind = _ffi.new("char[]", p), _ffi.new("char[]", _c_text(kind, "kind"))
    c_text = (_ffi.new("char[]", _c_text(description, "description")) if description is not None
              else _ffi.NULL)
    spec = _ffi.new("bb_output_spec *", {"path": c_path, "kind": c_kind,
                                         "channels": src.image.channels, "depth": d,
                                         "mips": int(bool(mips)), "width": src.image.width,
                                         "height": src.image.height, "range": rng,
                                         "texture": texture})
    _check(_lib.bb_outputs_check(spec, 1, _ffi.NULL, 0, err), err)
    f = _ffi.new("bb_output_file *", {
        "path": c_path, "kind": c_kind, "image": src.image, "range": rng,
        "depth": d, "mips": int(bool(mips)), "description": c_text, "texture": texture})
    _check(_lib.bb_outputs_write(f, 1, 1, err), err)


def write_vmt(path, bumpmap, *, materials=None, basetexture=None, ssbump=True):
    """Writes a Source material (.vmt) as `bumpbake bake --vmt` does:
    LightmappedGeneric with "$bumpmap" (and "$ssbump" "1" when ssbump), and
    "$basetexture" when given, each texture (a .vtf path; it need not exist
    yet) named relative to materials, the game's materials folder (None:
    the nearest folder named "materials" above bumpmap), without ".vtf".
    Written all or nothing. Raises ArgumentError (a path not ending in
    .vmt, or another name of a texture it names; a texture that is not a
    .vtf or lies outside materials; no materials folder), Error when it
    cannot be written."""
    strings = [_ffi.new("char[]", _path(v, what)) if v is not None else _ffi.NULL
               for v, what in ((path, "path"), (materials, "materials"),
                               (bumpmap, "bumpmap"), (basetexture, "basetexture"))]
    o = _ffi.new("bb_vmt_options *", {"materials_dir": strings[1], "bumpmap": strings[2],
                                      "basetexture": strings[3], "ssbump": int(bool(ssbump))})
    err = _ffi.new("bb_error *")
    _check(_lib.bb_vmt_write(strings[0], o, err), err)


# --------------------------------------------------------------- compare

@dataclasses.dataclass
class Comparison:
    """Two images compared (bumpbake.compare), with idiff's verdict."""
    a: str
    b: str
    result: str        # "PASS", "WARNING", "FAILURE" or "DIFFERENT SIZE"
    exit_code: int     # idiff's (and `bumpbake compare`'s): 0, 1, 2 or 3
    width: int         # of a
    height: int
    channels: int
    b_shape: tuple     # (height, width, channels) of b
    pixels: int
    mean_abs: float
    rms: float
    max_abs: float
    worst: typing.Optional[tuple]  # (x, y, channel) of max_abs, None when 0
    over_fail: int     # pixels with a channel over fail
    over_warn: int     # pixels with a channel over warn
    provenance_a: str  # "intact", "damaged" or "none"
    provenance_b: str
    provenance_diff: typing.Optional[list]  # [(key, a value, b value)] (None
                                            # for a missing key); None when
                                            # either side is not intact
    provenance_lines: typing.Optional[list]  # the same as `bumpbake compare`
                                             # prints them: "key: A -> B"
    diff_written: bool
    diff_error: typing.Optional[str]

    @property
    def passed(self):
        """True when idiff would exit 0."""
        return self.exit_code == 0

    def __bool__(self):
        return self.passed



def _diff_pairs(text, a, b):
    """(key, value in a, value in b) for each key bb__provenance_diff names
    in text ("key: A -> B" lines), values taken from the files' own
    provenance (None where a file lacks the key), since a value may hold
    " -> " itself."""
    va, vb = (info(p).provenance or {} for p in (a, b))
    return [(key, va.get(key), vb.get(key))
            for key in (line.partition(": ")[0] for line in text.splitlines())]


def _comparison_dict(result, diff):
    """The fields of Comparison from compare's report (bb_command_result
    cdata): the data the library found, as a dict."""
    r = result.compare
    s = r.stats
    same = bool(r.same_shape)
    lines = (_text(r.provenance_diff) or "") if r.provenance_differences >= 0 else None
    return dict(
        result=_text(r.result), exit_code=result.exit_code,
        width=r.width, height=r.height, channels=r.channels,
        b_shape=(r.b_height, r.b_width, r.b_channels),
        pixels=s.pixels if same else 0, mean_abs=s.mean_abs, rms=s.rms, max_abs=s.max_abs,
        worst=(s.worst_x, s.worst_y, s.worst_channel) if s.max_abs > 0 else None,
        over_fail=s.over_fail, over_warn=s.over_warn,
        provenance_a=_PROVENANCE_CLASSES[r.provenance_a],
        provenance_b=_PROVENANCE_CLASSES[r.provenance_b],
        provenance_lines=lines.splitlines() if lines is not None else None,
        diff_written=bool(r.diff_written),
        diff_error=(_text(r.diff_error.message) or None)
        if diff is not None and not r.diff_written else None)


def compare(a, b, *, fail=None, failpercent=None, hardfail=None, allowfailures=None,
            warn=None, warnpercent=None, hardwarn=None, diff=None, notes="warn"):
    """Compares two image files channel by channel as OpenImageIO's idiff
    (and `bumpbake compare`) do, and their provenance key by key, and
    returns a Comparison: `assert bumpbake.compare(out, golden,
    fail=1e-4).passed` guards a golden image.

    Tolerances are idiff's (defaults: fail and warn 1e-6, failpercent and
    warnpercent 0, hardfail and hardwarn inf, allowfailures 0; None keeps
    them), absolute, in the images' float units: a pixel
    fails when a channel differs by more than fail, warns by more than
    warn. Verdict: PASS when at most allowfailures pixels fail; else FAILURE
    when more than failpercent % fail or any difference exceeds hardfail;
    else WARNING when more than warnpercent % warn or any difference exceeds
    hardwarn; else PASS. Images of different size or channel count give
    "DIFFERENT SIZE" (exit code 3). diff: a path to write |A - B| to (raw
    in .exr, scaled so the largest difference is white elsewhere); a diff
    that cannot be written is reported (diff_error), not raised.
    Raises Error when a file cannot be read (idiff's exit 4) or the
    comparison will not fit in memory (worked out from the headers before
    a pixel is read), ArgumentError for a bad tolerance or diff path. A
    comparison over 1 GiB of memory says so first, as a note (notes: as
    bake_file()'s)."""
    pa, pb = _path(a), _path(b)
    result = _run_files("compare", pa, pb, options=dict(
        fail=fail, failpercent=failpercent, hardfail=hardfail, allowfailures=allowfailures,
        warn=warn, warnpercent=warnpercent, hardwarn=hardwarn, diff=diff),  # inf: none
        notes=notes, stacklevel=2)
    try:
        fields = _comparison_dict(result, diff)
    finally:
        _lib.bb_command_result_free(result)
    lines = fields["provenance_lines"]
    return Comparison(a=os.fsdecode(pa), b=os.fsdecode(pb), **fields,
                      provenance_diff=(_diff_pairs("\n".join(lines), pa, pb)
                                       if lines is not None else None))
