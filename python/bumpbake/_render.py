"""Pictures and models: the maps lit as Source lights them (render), a
bake's contact sheet (sheet) and DOOM 3's RenderBumpFlat (renderbumpflat)."""

import dataclasses
import os

import numpy as np

from ._bake import BAKE_PARAMETERS, _bake_options, _height_field, _normal_y_up
from ._common import (_Image, _argument_error, _array, _check, _check_notes, _dispatch_notes,
                      _ffi, _int, _lib, _note_text, _parse, _path, _take, _text)

# The default light of bb_render_options_init: on, at this azimuth and
# elevation (degrees).
_DEFAULT_RENDER = _ffi.new("bb_render_options *")
_lib.bb_render_options_init(_DEFAULT_RENDER)
DEFAULT_LIGHT = (_DEFAULT_RENDER.light_azimuth, _DEFAULT_RENDER.light_elevation)

_AUTO = object()  # light not given: on, unless lightmaps are


def _triple(what, value):
    v = np.asarray(value, dtype=np.float64).reshape(-1)
    if v.shape != (3,):
        raise _argument_error(f"render: {what} must be 3 numbers (got {value!r})")
    return [float(x) for x in v]


def _lighting(o, mode, light, light_color, lightmap, specular, specular_strength):
    """Fills the lighting fields of a bb_render_options as render's and
    sheet's options do: lightmaps turn the static light on and, unless a
    light is given, the dynamic light off."""
    o.mode = _parse("bb_render_mode_parse", "bb_render_mode", mode, "mode")
    if lightmap is not None:
        if isinstance(lightmap, str) and lightmap == "basis":
            colours = np.eye(3)
        else:
            colours = np.asarray(lightmap, dtype=np.float64)
            if colours.shape != (3, 3):
                raise _argument_error("render: lightmap must be 'basis' or 3 colours, "
                                      f"shape (3, 3) (got {lightmap!r})")
        for c in range(3):
            for k in range(3):
                o.lightmap[c][k] = float(colours[c][k])
        o.static_light = 1
    if light is _AUTO:
        o.dynamic_light = int(lightmap is None)
    elif light is None:
        o.dynamic_light = 0
    else:
        try:
            o.light_azimuth, o.light_elevation = (float(x) for x in light)
        except (TypeError, ValueError):
            raise _argument_error(f"render: light must be (azimuth, elevation) in degrees "
                                  f"or None (got {light!r})") from None
        o.dynamic_light = 1
    o.light_color = _triple("light_color", light_color)
    o.specular_exponent = float(specular)
    o.specular_strength = float(specular_strength)


_MAPS = ("normal", "ssbump", "ao", "bent", "slope")


def render(normal=None, ssbump=None, ao=None, bent=None, slope=None, albedo=None, *,
           mode="ssbump", light=_AUTO, light_color=(1.0, 1.0, 1.0), lightmap=None,
           specular=0.0, specular_strength=1.0, albedo_mode="multiply", tile=1, crop=None,
           compare=False, normal_y="down", threads=0):
    """Lights baked maps as Source does (bb_render) and returns the picture,
    float32 (H, W, 3), linear, 1 = white, not clamped.

    Maps, each an array or an image file's path (read and checked as
    `bumpbake render --normal FILE` reads them): normal (unit N, +Y down;
    a file is decoded, normal_y="up" for OpenGL-style files), ssbump
    (Half-Life 2's basis), ao, bent (default: from the ssbump), slope
    (flipcode's bytes / 255), albedo (a colour map multiplying the diffuse
    light, 1 channel grey or RGB; albedo_mode "multiply", "mod2x" or
    "ssbump"). mode: "ssbump", "normal", "ao" (normal x ao) or "slope";
    the maps it needs must be given.
    Lights: light=(azimuth, elevation) in degrees (azimuth 0 = from the
    right, 90 = from the top; elevation 0..90), default (135, 45), or None
    for none; light_color (R, G, B); lightmap "basis" (red, green, blue
    along B0, B1, B2) or 3 colours (3, 3): Source's static light, which
    turns the default light off unless light is given. specular: a
    Blinn-Phong exponent (0 = none), specular_strength its scale.
    tile=N or (NX, NY) repeats the picture, crop=(x, y, width, height)
    cuts a window of it. compare=True: the paper's four labelled panels
    (normal-mapped, ssbump, ssbump + specular, ao; needs normal, ssbump
    and ao). Bit-identical for any thread count."""
    o = _ffi.new("bb_render_options *")
    _lib.bb_render_options_init(o)
    _lighting(o, mode, light, light_color, lightmap, specular, specular_strength)
    o.albedo_mode = _parse("bb_albedo_mode_parse", "bb_albedo_mode", albedo_mode, "albedo_mode")
    nx, ny = (tile, tile) if np.ndim(tile) == 0 else tuple(tile)
    o.tile_x, o.tile_y = _int("render", "tile", nx), _int("render", "tile", ny)
    if crop is not None:
        try:
            o.crop_x, o.crop_y, o.crop_width, o.crop_height = (
                _int("render", "crop", v) for v in crop)
        except (TypeError, ValueError):
            raise _argument_error(f"render: crop must be (x, y, width, height) "
                                  f"(got {crop!r})") from None
    o.threads = _int("render", "threads", threads)
    green_up = _normal_y_up("render", normal_y)
    given = dict(zip(_MAPS, (normal, ssbump, ao, bent, slope)))
    keep, read = [], []
    maps = _ffi.new("bb_render_maps *")
    err = _ffi.new("bb_error *")
    like = _ffi.NULL
    try:
        for index, name in enumerate(_MAPS):
            value = given[name]
            if value is None:
                continue
            if isinstance(value, (str, bytes, os.PathLike)):
                img = _ffi.new("bb_image *")
                st = _lib.bb_render_map_read(_path(value, name), index, int(green_up), like,
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
        out = _ffi.new("bb_image *")
        if compare:
            layout = _ffi.new("bb_panel_layout *")
            _lib.bb_panel_layout_init(layout)
            labels = _ffi.new("int *")
            st = _lib.bb_render_compare(maps, o, layout, out, labels, err)
        else:
            st = _lib.bb_render(maps, o, out, err)
        _check(st, err, arrays=True)
        return _take(out)
    finally:
        for img in read:
            _lib.bb_image_free(img)


def sheet(height, scale, *, panel_size=256, mode="ssbump", light=_AUTO,
          light_color=(1.0, 1.0, 1.0), lightmap=None, specular=0.0, specular_strength=1.0,
          channel="auto", **options):
    """Bakes a height array with bake()'s parameters (every map) and
    returns its labelled contact sheet (bb_sheet_make), float32 (H, W, 3)
    in [0, 1], as `bumpbake sheet` draws it: height and filtered height,
    normal, weights, ssbump, ao, bent normal and one render lit by mode and
    the lighting arguments (render()'s). panel_size: each panel's width in
    pixels. Labels need a font (fonts-dejavu-core, or BUMPBAKE_FONT); without
    one the panels are drawn unlabelled."""
    for key in options:
        if key not in BAKE_PARAMETERS:
            raise TypeError(f"sheet: unexpected keyword argument {key!r}")
    o, _ = _bake_options("sheet", scale, **options)
    s = _ffi.new("bb_sheet_options *")
    _lib.bb_sheet_options_init(s)
    s.layout.panel_width = _int("sheet", "panel_size", panel_size)
    _lighting(s.lit, mode, light, light_color, lightmap, specular, specular_strength)
    s.lit.threads = o.trace.threads
    err = _ffi.new("bb_error *")
    _check(_lib.bb_bake_options_check(o, err), err)
    field = _height_field("sheet", height, channel)
    result = _ffi.new("bb_bake_result *")
    try:
        _check(_lib.bb_bake(field, o, result, err), err, arrays=True)
        out = _ffi.new("bb_image *")
        labels = _ffi.new("int *")
        _check(_lib.bb_sheet_make(field, result, s, out, labels, err), err, arrays=True)
        return _take(out)
    finally:
        _lib.bb_bake_result_free(result)
        _lib.bb_image_free(field)


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
    model_hash: int          # bb_mesh_hash, recorded in provenance as model_hash
    notes: list              # the library's notes ("texels are ... times as wide")


def renderbumpflat(model, size=(256, 256), samples=4, axis="-y", face_normals=False,
                   rect=None, tile=False, threads=0, *, output=None, height_output=None,
                   normal_y="down", notes="warn"):
    """DOOM 3's RenderBumpFlat of a model file (anything Assimp reads) as
    `bumpbake renderbumpflat` makes it: the model projected orthographically
    along axis ("-y" DOOM 3's, "+y", "+z", "-z", "+x", "-x") onto rect
    (left, bottom, right, top in model units; None: its bounding
    rectangle), samples x samples per texel of an image of size (width,
    height); face_normals: the triangles' plane normals even where the
    model has vertex normals; tile: geometry outside rect wraps into it
    (needs rect). Returns a RenderBump (arrays +Y down). With output (and
    height_output) the files are also written all or nothing, with
    provenance, as the command line writes them (normal_y="up" flips their
    green). The library's note when the texels come out not square (with the
    size or rect that keeps them square) goes to notes ("warn": a
    NoteWarning, "ignore", or a callable) and to the result's notes."""
    o = _ffi.new("bb_renderbump_options *")
    _lib.bb_renderbump_options_init(o)
    try:
        o.width, o.height = (_int("renderbumpflat", "size", v) for v in size)
    except (TypeError, ValueError):
        raise _argument_error(f"renderbumpflat: size must be (width, height) "
                              f"(got {size!r})") from None
    o.samples = _int("renderbumpflat", "samples", samples)
    o.axis = _parse("bb_axis_parse", "bb_axis", axis, "axis")
    o.face_normals = int(bool(face_normals))
    if rect is not None:
        try:
            o.rect = [float(v) for v in rect]
        except (TypeError, ValueError, IndexError):
            raise _argument_error(f"renderbumpflat: rect must be (left, bottom, right, top) "
                                  f"(got {rect!r})") from None
        o.rect_given = 1
    if tile and rect is None:  # the bounding rectangle has nothing outside to wrap
        raise _argument_error("renderbumpflat: tile needs rect: the tile the sculpt repeats "
                              "with")
    o.tile = int(bool(tile))
    o.threads = _int("renderbumpflat", "threads", threads)
    _check_notes(notes)
    heard = []
    note = _ffi.callback("bb_note_fn",
                         lambda user, p, text: heard.append(_note_text(_text(p), _text(text))))
    o.note = note
    green_up = _normal_y_up("renderbumpflat", normal_y)
    path = _path(model, "model")
    err = _ffi.new("bb_error *")
    if output is not None:
        out_path = _path(output, "output")
        height_path = _path(height_output, "height_output") if height_output is not None \
            else None
        # The C strings, owned here for as long as the specs point at them.
        strings = [_ffi.new("char[]", v) for v in (out_path, height_path or b"", b"normal",
                                                   b"height", path)]
        specs = _ffi.new("bb_output_spec[2]", [
            {"path": strings[0], "kind": strings[2], "channels": 4},
            {"path": strings[1], "kind": strings[3], "channels": 1}])
        reads = _ffi.new("char *[1]", [strings[4]])
        _check(_lib.bb_outputs_check(specs, 2 if height_path else 1, reads, 1, err), err)
    elif height_output is not None:
        raise _argument_error("renderbumpflat: height_output needs output")
    mesh = _ffi.new("bb_mesh *")
    result = _ffi.new("bb_renderbump_result *")
    try:
        _check(_lib.bb_mesh_load(path, mesh, err), err)
        _check(_lib.bb_renderbump_flat(mesh, o, result, err), err)
        _dispatch_notes(heard, notes, stacklevel=2)
        model_hash = _lib.bb_mesh_hash(mesh)
        if output is not None:
            _check(_lib.bb_renderbump_write(result, o, int(green_up), path, model_hash,
                                            _ffi.NULL, out_path,
                                            height_path if height_path else _ffi.NULL, err), err)
        return RenderBump(
            normal=_array(result.normal, squeeze=False), height=_array(result.height),
            rect=tuple(result.rect), depth_min=result.depth_min, depth_max=result.depth_max,
            texel_size=result.texel_size, texel_aspect=result.texel_aspect,
            height_scale=result.height_scale,
            used_vertex_normals=bool(result.used_vertex_normals),
            triangles_drawn=int(result.triangles_drawn), triangles=int(mesh.triangle_count),
            vertices=int(mesh.vertex_count), model_hash=int(model_hash), notes=heard)
    finally:
        _lib.bb_renderbump_result_free(result)
        _lib.bb_mesh_free(mesh)
