"""Maps on arrays: decoding normal maps, Valve's conversions, combining,
DOOM 3 image programs and mip chains, each one call of the library."""

from ._bake import _IN_MEMORY, _basis, _normal_y_up
from ._command import Command
from ._common import _Image, _array, _c_text, _check, _depth, _ffi, _lib, _shown, _take
from ._files import _signed


def decode_normals(values, is_float=False, normal_y="down", normalize=True):
    """The unit normals N a normal-map file holds, from the values
    bumpbake.read returns for it (bb_normal_map_decode): integer files hold
    0.5 + 0.5 N, so N = 2 v - 1 (code 127.5 of 255 is 0; 128 reads as
    +1/255); float files (is_float=True) hold N itself. normal_y="up": the
    map's green is +Y up (OpenGL) and is negated to the library's +Y down.
    normalize: each texel scaled to unit length ((0, 0, 0) becomes
    (0, 0, 1)). values: (H, W, C), C >= 3 (channels past 3 are ignored).
    Returns float32 (H, W, 3)."""
    src = _Image("decode_normals: values", values)
    up = _normal_y_up("decode_normals", normal_y)
    out = _ffi.new("bb_image *")
    err = _ffi.new("bb_error *")
    _check(_lib.bb_normal_map_decode(src.image, int(bool(is_float)), up, int(bool(normalize)),
                                     out, err), err, arrays=True)
    return _take(out)


def _map(c, a, b=None, mask=None, depth=None, basis=None):
    """bb_command_map of a checked command: the float32 map of images in
    memory (_Image's; b, mask, basis may be None; depth a bb_depth)."""
    out = _ffi.new("bb_image *")
    err = _ffi.new("bb_error *")
    null = _ffi.NULL
    _check(_lib.bb_command_map(c.handle, a.image, b.image if b is not None else null,
                               mask if mask is not None else null,
                               depth if depth is not None else _lib.BB_DEPTH_DEFAULT,
                               basis if basis is not None else null, out, err),
           err, arrays=True)
    return _take(out)


def normal2ssbump(normals, basis="hl2", *, normal_y=None):
    """Valve's normal2ssbump: the basis weights w_c = sat(N.B_c)^2 /
    sum_k sat(N.B_k)^2 of unit normals (H, W, 3), +Y down (decode a file
    with decode_normals), one channel per direction of basis (bake()'s
    basis argument). A normal facing away from every direction gets 1 /
    count in each. normal_y="up": the normals' green is +Y up (OpenGL), as
    the command line's --normal-y reads a file. Returns float32 (H, W,
    count)."""
    c = Command("normal2ssbump")
    c.set("normal_y", normal_y)
    c.in_memory()
    c.check()
    src = _Image("normal2ssbump: normals", normals, channels=(3,))
    b, _ = _basis(basis)
    return _map(c, src, basis=b)


def ssbump2normal(ssbump, kind=None, *, normal_y=None):
    """The normal of a Half-Life 2 basis map: N = normalize(sum_c f(s_c)
    B_c) over channels 0..2 (a fourth, Valve's alpha, is ignored), f(s) = s
    for kind "ssbump" (bake's ssbump, height2ssbump) and sqrt(s) for
    "weights" (normal2ssbump's, whose square it undoes). A texel of no
    weight gives (0, 0, 1). More than 4 channels (another basis) is refused.
    Returns float32 (H, W, 3), +Y down (normal_y="up": +Y up, as the
    command line's --normal-y writes the map)."""
    c = Command("ssbump2normal")
    c.set("kind", kind)
    c.set("normal_y", normal_y)
    c.in_memory()
    c.check()
    return _map(c, _Image("ssbump2normal: ssbump", ssbump))


def _mask_field(mask):
    """A blend mask as the command line reads one: a 2-D array as it is, else
    its grey (or the mean of R, G, B) by the height channel rule. Returns
    (the _Image kept, or None; the bb_image * of the field made, or None)."""
    src = _Image("combine: mask", mask)
    if src.image.channels == 1:
        return src, None
    field = _ffi.new("bb_image *")
    err = _ffi.new("bb_error *")
    _check(_lib.bb_height_from_image(src.image, src.alpha, _lib.BB_CHANNEL_AUTO, field, err),
           err, arrays=True)
    return None, field


def combine(a, b=None, mix=None, mask=None, detail=False, kind=None, detail_depth=None, *,
            brightness=None, normal_y=None):
    """Combines two maps of the same size, as `bumpbake combine` does;
    exactly one of mix, mask, detail and brightness (the library's rule).

    mix=T or mask (an (H, W) array, or an image whose grey / mean of R, G,
    B is taken; clamped to 0..1): (1 - T) a + T b, linear for "ssbump",
    "weights" and "ao" (every channel), renormalised for "normal" (decoded
    normals, as decode_normals makes them; the command line decodes with
    normalize=False, so a texel the blend copies keeps its code).
    detail=True overlays b on a: a * b / flat for ssbump, weights and ao,
    DOOM 3's addnormals for normals; flat is the kind's flat, unoccluded
    texel, exact (detail_depth None) or as a file of detail_depth (8, 16,
    "half", "float") stores it (147/255 in an 8-bit ssbump, as the command
    line reads such a file), so a flat detail read from such a file leaves a
    unchanged bit for bit. brightness (an (H, W) grey array; b not given): a
    times it, the paper's brightness modulation (combine --brightness).
    kind: "ssbump" (default), "weights", "ao" or "normal"; normal_y="up":
    normals in and out have +Y up (OpenGL), as the command line's
    --normal-y. Each runs through the command in memory (bb_command_map).
    Returns float32 with a's channels (3 for normals)."""
    c = Command("combine")
    c.set_all(dict(mix=mix, detail=detail, kind=kind, normal_y=normal_y))
    for key, value in (("mask", mask), ("brightness", brightness)):
        if value is not None:
            c.set(key, _IN_MEMORY)
    c.in_memory()
    c.check()
    if brightness is None and b is None:
        raise TypeError("combine: b is required (the second map) unless brightness is given")
    ia = _Image("combine: a", a)
    if brightness is not None:
        return _map(c, ia, _Image("combine: brightness", brightness))
    ib = _Image("combine: b", b)
    if detail:
        return _map(c, ia, ib, depth=_depth(detail_depth) if detail_depth is not None else None)
    keep, field = (None, None)
    if mask is not None:
        keep, field = _mask_field(mask)
    try:
        return _map(c, ia, ib, mask=keep.image if keep is not None else field)
    finally:
        if field is not None:
            _lib.bb_image_free(field)


def program(text, base=None, allow_outside_base=False, **options):
    """Evaluates a DOOM 3 image program ("addnormals(a_local.tga,
    heightmap(a_h.tga, 4))") as `bumpbake program` does: image names are
    files, relative to base (a directory; None: the current one), and must
    stay inside it (no absolute path, "..", or symbolic link out) unless
    allow_outside_base. Returns (array,
    is_normal_map): the decoded normals N, float32 (H, W, 3), +Y down, when
    the program makes a normal map (heightmap, addnormals, smoothnormals or
    _flat in it), else RGBA colour, float32 (H, W, 4) in [0, 1]. A syntax
    error is ArgumentError giving the column; a file that cannot be read,
    Error naming it. Keywords are the command's options (base,
    allow_outside_base), set and checked by the library; those about the
    file written (output, depth, ...) are run("program", text, ...)'s."""
    if not isinstance(text, str):
        raise TypeError(f"program: text must be a str (got {_shown(text)})")
    c = Command("program")
    c.add_input(_c_text(text, "program"))
    c.set_all(dict(options, base=base, allow_outside_base=allow_outside_base))
    c.in_memory()
    c.check()
    err = _ffi.new("bb_error *")
    out = _ffi.new("bb_image *")
    is_normal = _ffi.new("int *")
    _check(_lib.bb_command_program(c.handle, out, is_normal, err), err)
    return _take(out, squeeze=False), bool(is_normal[0])


def mips(array, kind="colour"):
    """The mip chain of an array down to 1 x 1, as written with mips=True
    (bb_mip_chain): level 0 a copy, each next level the box filter of the
    one before to half its size (OpenImageIO's resize; odd sides cover 3
    texels), renormalised for kind "normal" and "bent" (a zero average
    becomes (0, 0, 1)), averaged for every other kind (write()'s kinds).
    Returns a list of float32 arrays, largest first."""
    signed = _signed("mips", kind)
    src = _Image("mips: array", array)
    levels = _ffi.new("bb_image **")
    count = _ffi.new("int *")
    err = _ffi.new("bb_error *")
    flt = _lib.BB_MIP_RENORMALIZE if signed else _lib.BB_MIP_AVERAGE
    _check(_lib.bb_mip_chain(src.image, flt, levels, count, err), err, arrays=True)
    try:
        return [_array(levels[0][i]) for i in range(count[0])]
    finally:
        _lib.bb_mip_chain_free(levels[0], count[0])
