"""Pictures and models: the maps lit as Source lights them (render), a
bake's contact sheet (sheet) and DOOM 3's RenderBumpFlat (renderbumpflat)."""

import dataclasses
import numbers
import os

import numpy as np

from ._bake import _IN_MEMORY, _height_field
from ._command import Command
from ._common import (_Image, _NoteHooks, _argument_error, _array, _c_text, _check,
                      _check_notes, _dispatch_notes, _exception, _ffi, _lib, _message, _path,
                      _progress_hook, _progress_hooks, _shown, _take, _text)

# The default light of render: on, at this azimuth and elevation (degrees),
# as a new render command holds it.
def _default_light():
    azimuth, elevation = Command("render").numbers("light")
    return (azimuth, elevation)


DEFAULT_LIGHT = _default_light()

_AUTO = object()  # light not given: on, unless lightmaps are


# The maps render() reads, as bb_map_kind values by their names.
_MAPS = ("normal", "ssbump", "ao", "bent", "slope")
_MAP_KINDS = {name: getattr(_lib, "BB_MAP_" + name.upper()) for name in _MAPS}


def _set_lighting(c, light, lightmap):
    """render's and sheet's light and lightmap, as the command line spells
    them; light=None (no dynamic light) has no spelling: set after the
    check (_lights_off)."""
    if light is not _AUTO and light is not None:
        c.set("light", light)
    if lightmap is not None and not isinstance(lightmap, str):
        values = np.asarray(lightmap, dtype=np.float64)
        if values.shape != (3, 3):
            raise _argument_error(f"{c.function}: lightmap must be 'basis' or 3 colours, "
                                  f"shape (3, 3) (got {_shown(lightmap)})")
        lightmap = ",".join(repr(float(v)) for v in values.reshape(-1))
    c.set("lightmap", lightmap)


def _picture(c, height, maps, progress):
    """bb_command_picture of a checked command: the float32 picture."""
    field = None
    if height is not None:
        field = _height_field(c.function, height, c.word("channel"))  # its bb_channel
    raised = []
    hooks, _keep = _progress_hooks(progress, raised)
    out = _ffi.new("bb_image *")
    labels = _ffi.new("int *")
    err = _ffi.new("bb_error *")
    try:
        st = _lib.bb_command_picture(c.handle, field if field is not None else _ffi.NULL,
                                     maps, hooks, out, labels, err)
    finally:
        if field is not None:
            _lib.bb_image_free(field)
    if st != _lib.BB_OK and raised:
        raise raised[0]
    if st != _lib.BB_OK:
        raise _exception(st, c.prefixed(_message(err, st)), arrays=True)
    return _take(out)


def render(normal=None, ssbump=None, ao=None, bent=None, slope=None, albedo=None, *,
           height=None, light=_AUTO, lightmap=None, tile=None, progress=None, **options):
    """Lights baked maps as Source does (bumpbake render) and returns the
    picture, float32 (H, W, 3), linear, 1 = white, not clamped.

    Maps, each an array or an image file's path (read and checked as
    `bumpbake render --normal FILE` reads them): normal (unit N, +Y down;
    a file is decoded, normal_y="up" for OpenGL-style files), ssbump
    (Half-Life 2's basis), ao, bent (default: from the ssbump), slope
    (flipcode's bytes / 255), albedo (a colour map multiplying the diffuse
    light, 1 channel grey or RGB). Or height: a height array, baked first
    as the command line bakes a HEIGHT (scale and the bake's options), which
    relief=True (with view=(azimuth, elevation)) raises as a relief.
    light=(azimuth, elevation) in degrees, or None for no dynamic light;
    lightmap "basis" or 3 colours (3, 3) (Source's static light: turns the
    default light off unless light is given). tile=N or (NX, NY) repeats
    the picture. progress: as bake()'s (Ctrl-C cancels). Bit-identical for
    any thread count.
"""
    c = Command("render")
    given = dict(zip(_MAPS, (normal, ssbump, ao, bent, slope)))
    for name, value in list(given.items()) + [("albedo", albedo)]:
        if value is not None:
            c.set(name, value if isinstance(value, (str, bytes, os.PathLike)) else _IN_MEMORY)
    if height is not None:
        c.add_input(_IN_MEMORY)
    _set_lighting(c, light, lightmap)
    nx, ny = (tile, tile) if tile is None or np.ndim(tile) == 0 else tuple(tile)
    if ny is not None and ny != nx:
        c.set("tile", ny)  # checked by the library as NX is, then set by hand
        c.in_memory()
        c.check()
    c.set("tile", nx)
    c.set_all(options)
    c.in_memory()
    c.check()
    # what the command line cannot spell, after the library's check
    _lib.bb_command_set_picture(c.handle, int(light is not None),
                                int(ny) if ny is not None else 0)
    green_up = c.options.maps_normal_y_up
    keep, read = [], []
    maps = _ffi.new("bb_render_maps *")
    err = _ffi.new("bb_error *")
    like = _ffi.NULL
    try:
        for name in _MAPS:
            value = given[name]
            if value is None:
                continue
            if isinstance(value, (str, bytes, os.PathLike)):
                img = _ffi.new("bb_image *")
                st = _lib.bb_render_map_read(_path(value, name), _MAP_KINDS[name], green_up, like,
                                             img, _ffi.NULL, err)
                _check(st, err)
                read.append(img)
            else:
                src = _Image(f"render: {name}", value)
                keep.append(src)
                img = src.image
            setattr(maps, name, img)
            if like == _ffi.NULL:
                like = img
        if albedo is not None:
            if isinstance(albedo, (str, bytes, os.PathLike)):
                img = _ffi.new("bb_image *")
                _check(_lib.bb_image_read(_path(albedo, "albedo"), img, _ffi.NULL, err), err)
                read.append(img)
            else:
                src = _Image("render: albedo", albedo)
                keep.append(src)
                img = src.image
            maps.albedo = img
        return _picture(c, height, maps, progress)
    finally:
        for img in read:
            _lib.bb_image_free(img)


def sheet(height, scale, *, light=_AUTO, lightmap=None, progress=None, **options):
    """Bakes a height array with bake()'s parameters (every map) and
    returns its labelled contact sheet, float32 (H, W, 3) in [0, 1], as
    `bumpbake sheet` draws it: height and filtered height, normal, weights,
    ssbump, ao, bent normal and one render lit by mode and the lighting
    arguments (render()'s). panel_size: each panel's width in pixels.
    Labels need a font (fonts-dejavu-core, or BUMPBAKE_FONT); without one
    the panels are drawn unlabelled."""
    c = Command("sheet")
    c.set("scale", scale)
    _set_lighting(c, light, lightmap)
    c.set_all(options)
    c.in_memory()
    c.check()
    if light is None:  # no spelling on the command line
        _lib.bb_command_set_picture(c.handle, 0, 0)
    return _picture(c, height, _ffi.NULL, progress)


def run(command, *inputs, progress=None, notes="warn", **options):
    """Runs a `bumpbake` command that writes files (bake, normal,
    height2ssbump, render, sheet, normal2ssbump, ssbump2normal, combine,
    program, renderbumpflat) as the command line runs it, with its options as keywords
    (the long options with '_' for '-'; a flag takes True, several numbers
    a sequence), and returns [(kind, path)] of the files written: the
    command line's bytes. progress: as bake()'s; notes as bake_file()'s."""
    _check_notes(notes)
    if not isinstance(command, str):
        raise TypeError(f"run: command must be a str (got {_shown(command)})")
    c = Command(_c_text(command, "run: command").decode(), f"run({command!r})")
    for i, value in enumerate(inputs):
        # a path, or a number (height2ssbump's BUMPSCALE) spelled as typed
        if isinstance(value, numbers.Real) and not isinstance(value, (bool, np.bool_)):
            value = str(value)
        elif not isinstance(value, (str, bytes, os.PathLike)):
            raise TypeError(f"run({command!r}): input {i + 1} must be a path (str, bytes or "
                            f"os.PathLike) or a number (got {_shown(value)})")
        c.add_input(value)
    c.set_all(options)
    c.check()
    hooks = _NoteHooks()
    heard = hooks.heard
    raised = []
    cb = _progress_hook(progress, raised)
    hooks.hooks.progress = cb
    result = _ffi.new("bb_command_result *")
    err = _ffi.new("bb_error *")
    st = _lib.bb_command_run(c.handle, hooks.hooks, result, err)
    if st != _lib.BB_OK:
        if raised:
            raise raised[0]
        raise _exception(st, c.prefixed(_message(err, st)))
    try:
        _dispatch_notes(heard, notes, stacklevel=2)
        return [(_text(result.files[i].kind), _text(result.files[i].path))
                for i in range(result.file_count)]
    finally:
        _lib.bb_command_result_free(result)


# ---------------------------------------------------------- render bump

@dataclasses.dataclass
class RenderBump:
    """What renderbumpflat made."""
    normal: np.ndarray       # float32 (H, W, 4): unit N (x right, y down, z out),
                             # alpha = covered fraction of the texel's samples
    height: np.ndarray       # float32 (H, W): h in [0, 1], 0 where uncovered
    rect: tuple              # (left, bottom, right, top), model units
    depth_min: float         # model units along the axis that h = 0 and 1 are
    depth_max: float
    texel_size: float        # model units per texel (geometric mean of the sides)
    texel_aspect: float      # texel width / height (1: square texels)
    height_scale: float      # bake()'s scale for this height (0: flat)
    used_vertex_normals: bool
    triangles_drawn: int     # triangle copies rasterised (tile copies included)
    triangles: int           # of the model
    vertices: int
    model_hash: int          # bb__mesh_hash, recorded in provenance as model_hash
    notes: list              # the library's notes ("texels are ... times as wide")


def renderbumpflat(model, size=None, samples=None, axis=None, face_normals=False, rect=None,
                   tile=False, threads=None, *, output=None, height=None, height_output=None,
                   normal_y=None, notes="warn"):
    """DOOM 3's RenderBumpFlat of a model file (anything Assimp reads) as
    `bumpbake renderbumpflat` makes it: the model projected orthographically
    along axis ("-y" DOOM 3's, "+y", "+z", "-z", "+x", "-x") onto rect
    (left, bottom, right, top in model units; None: its bounding
    rectangle), samples x samples per texel of an image of size (width,
    height); face_normals: the triangles' plane normals even where the
    model has vertex normals; tile: geometry outside rect wraps into it
    (needs rect). Returns a RenderBump (arrays +Y down). With output or height
    (height_output: its old name) the files are also written all or
    nothing, with provenance, as the command line writes them (the normal
    map to output, default MODEL_local.tga; normal_y="up" flips their
    green; the files record the command as bb_command_text spells it). The
    library runs it all (bb_command_renderbump), as for the command line.
    Its notes, each naming the model (the texels come out not square, with
    the size or rect that keeps them square; a file the model names is
    missing), go to notes ("warn": a NoteWarning, "ignore", or a callable)
    and to the result's notes."""
    if height_output is not None:  # the old name of the command line's --height
        if height is not None:
            raise TypeError("renderbumpflat: give height or height_output, not both")
        height = height_output
    _check_notes(notes)
    c = Command("renderbumpflat")
    c.add_input(_path(model, "model"))
    c.set_all(dict(size=size, samples=samples, axis=axis, face_normals=face_normals,
                   rect=rect, tile=tile, threads=threads, normal_y=normal_y, output=output,
                   height=height))
    if output is None and height is None:
        c.in_memory()  # nothing to write
    c.check()  # ranges, tile needs rect, the outputs apart and not over the model
    hooks = _NoteHooks()
    heard = hooks.heard
    err = _ffi.new("bb_error *")
    result = _ffi.new("bb_renderbump_result *")
    written = _ffi.new("bb_command_result *")
    _check(_lib.bb_command_renderbump(c.handle, hooks.hooks, result, written, err), err)
    try:
        _dispatch_notes(heard, notes, stacklevel=2)
        return RenderBump(
            normal=_array(result.normal, squeeze=False), height=_array(result.height),
            rect=tuple(result.rect), depth_min=result.depth_min, depth_max=result.depth_max,
            texel_size=result.texel_size, texel_aspect=result.texel_aspect,
            height_scale=result.height_scale,
            used_vertex_normals=bool(result.used_vertex_normals),
            triangles_drawn=int(result.triangles_drawn), triangles=int(result.triangles),
            vertices=int(result.vertices), model_hash=int(result.model_hash), notes=heard)
    finally:
        _lib.bb_command_result_free(written)
        _lib.bb_renderbump_result_free(result)
