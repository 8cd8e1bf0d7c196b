"""Maps on arrays against known answers (decode_normals, normal2ssbump,
ssbump2normal, combine, program, mips), and render, sheet and
renderbumpflat against the command line's output of the same operation."""

import os
import re
import shutil

import numpy as np
import pytest

import bumpbake

FLAT_SSBUMP = 1 / np.sqrt(3)


def bump(side=32, sigma2=18.0):
    y, x = np.mgrid[0:side, 0:side].astype(np.float64) - side // 2
    return np.exp(-(x * x + y * y) / sigma2).astype(np.float32)


# ------------------------------------------------------------- normals

def test_decode_normals_is_two_v_minus_one():
    v = np.array([[[127.5 / 255, 1.0, 0.0], [128 / 255, 0.5, 0.75]]], np.float32)
    n = bumpbake.decode_normals(v, normalize=False)
    np.testing.assert_allclose(n, 2 * v - 1, atol=1e-7)
    assert n[0, 1, 0] == pytest.approx(1 / 255, abs=1e-7)  # DOOM 3's zero, 128, reads +1/255
    np.testing.assert_allclose(np.linalg.norm(bumpbake.decode_normals(v), axis=2), 1, atol=1e-6)
    up = bumpbake.decode_normals(v, normal_y="up", normalize=False)
    np.testing.assert_array_equal(up[..., 1], -n[..., 1])
    f = np.array([[[0.6, -0.8, 0.0]]], np.float32)
    np.testing.assert_array_equal(bumpbake.decode_normals(f, is_float=True), f)
    rgba = np.concatenate([v, np.ones((1, 2, 1), np.float32)], axis=2)
    np.testing.assert_array_equal(bumpbake.decode_normals(rgba), bumpbake.decode_normals(v))
    bad = v.copy()
    bad[0, 1, 2] = np.nan
    with pytest.raises(bumpbake.ArgumentError, match=r"\(1, 0\)"):
        bumpbake.decode_normals(bad)


def test_normal2ssbump_is_the_bakes_weights():
    maps = bumpbake.bake(bump(), 8, outputs=("normal", "weights"))
    np.testing.assert_array_equal(bumpbake.normal2ssbump(maps["normal"]), maps["weights"])
    flat = np.broadcast_to(np.float32([0, 0, 1]), (4, 4, 3))
    np.testing.assert_allclose(bumpbake.normal2ssbump(flat), 1 / 3, atol=1e-7)
    assert bumpbake.normal2ssbump(flat, basis="dirs:6").shape == (4, 4, 6)
    with pytest.raises(bumpbake.ArgumentError, match="3 channels"):
        bumpbake.normal2ssbump(np.zeros((4, 4, 4), np.float32))


def test_ssbump2normal_gives_back_the_normal():
    flat = np.full((4, 4, 3), FLAT_SSBUMP, np.float32)
    np.testing.assert_allclose(bumpbake.ssbump2normal(flat), np.broadcast_to([0, 0, 1],
                                                                             (4, 4, 3)), atol=1e-6)
    # Gentle slopes face every basis direction: weights undo to N.
    n = bumpbake.normal(bump(), 1)
    back = bumpbake.ssbump2normal(bumpbake.normal2ssbump(n), kind="weights")
    np.testing.assert_allclose(back, n, atol=2e-6)
    with pytest.raises(bumpbake.ArgumentError, match="another basis|other than"):
        bumpbake.ssbump2normal(np.zeros((4, 4, 6), np.float32))
    with pytest.raises(bumpbake.ArgumentError, match="kind must be one of ssbump|weights"):
        bumpbake.ssbump2normal(flat, kind="normal")


# ------------------------------------------------------------- combine

def test_combine_blends_and_overlays():
    maps = bumpbake.bake(bump(), 8, rays=16, outputs=("ssbump", "weights", "normal"))
    a, b = maps["ssbump"], maps["weights"]
    np.testing.assert_array_equal(bumpbake.combine(a, b, mix=0), a)
    np.testing.assert_array_equal(bumpbake.combine(a, b, mix=1), b)
    np.testing.assert_allclose(bumpbake.combine(a, b, mix=0.25), 0.75 * a + 0.25 * b, atol=1e-6)
    mask = np.zeros((32, 32), np.float32)
    mask[:, 16:] = 1
    m = bumpbake.combine(a, b, mask=mask)
    np.testing.assert_array_equal(m[:, :16], a[:, :16])
    np.testing.assert_array_equal(m[:, 16:], b[:, 16:])
    np.testing.assert_array_equal(bumpbake.combine(a, b, mask=np.dstack([mask] * 3)), m)
    # A flat detail changes nothing, exact or as an 8-bit file holds it.
    flat = np.full((32, 32, 3), FLAT_SSBUMP, np.float32)
    np.testing.assert_array_equal(bumpbake.combine(a, flat, detail=True), a)
    flat8 = np.full((32, 32, 3), 147 / 255, np.float32)
    np.testing.assert_array_equal(bumpbake.combine(a, flat8, detail=True, detail_depth=8), a)
    assert not np.array_equal(bumpbake.combine(a, flat8, detail=True), a)
    n = bumpbake.combine(maps["normal"], -maps["normal"] * [1, 1, -1], mix=0.5, kind="normal")
    np.testing.assert_allclose(np.linalg.norm(n, axis=2), 1, atol=1e-6)
    with pytest.raises(bumpbake.ArgumentError,
                       match="exactly one of mix, mask, detail and brightness"):
        bumpbake.combine(a, b, mix=0.5, detail=True)
    with pytest.raises(bumpbake.ArgumentError, match="kind must be one of"):
        bumpbake.combine(a, b, mix=0.5, kind="height")
    # brightness: the paper's modulation, the command line's --brightness
    half = np.full((32, 32), 0.5, np.float32)
    np.testing.assert_allclose(bumpbake.combine(a, brightness=half), 0.5 * a, atol=1e-6)


# ------------------------------------------------------------- program

def test_program_evaluates_id_tech_4(tmp_path):
    bumpbake.write(tmp_path / "flat.png", np.zeros((4, 6), np.float32))
    bumpbake.write(tmp_path / "c.png", np.array([[[0.2, 0.4, 0.6]]], np.float32))
    n, is_normal = bumpbake.program("heightmap(flat.png, 4)", base=tmp_path)
    assert is_normal and n.shape == (4, 6, 3)
    np.testing.assert_allclose(n, np.broadcast_to([0, 0, 1], n.shape), atol=1e-6)
    c, is_normal = bumpbake.program("invertColor(c.png)", base=tmp_path)
    assert not is_normal
    np.testing.assert_allclose(c[0, 0], [0.8, 0.6, 0.4, 1.0], atol=1e-6)
    with pytest.raises(bumpbake.ArgumentError, match="column 19: expected .,. and the scale of heightmap"):
        bumpbake.program("heightmap(flat.png")
    with pytest.raises(bumpbake.Error, match="nothing.png") as e:
        bumpbake.program("makeIntensity(nothing.png)", base=tmp_path)
    assert not isinstance(e.value, bumpbake.ArgumentError)
    (tmp_path / "sub").mkdir()
    with pytest.raises(bumpbake.ArgumentError, match="c.png"):
        bumpbake.program("invertColor(../c.png)", base=tmp_path / "sub")
    outside, _ = bumpbake.program("invertColor(../c.png)", base=tmp_path / "sub",
                                  allow_outside_base=True)
    np.testing.assert_array_equal(outside, c)


# ---------------------------------------------------------------- mips

def test_mips_average_and_renormalise():
    n = np.array([[[1, 0, 0], [0, 1, 0]], [[0, 0, 1], [0, 0, 1]]], np.float32)
    levels = bumpbake.mips(n, "normal")
    assert [lv.shape for lv in levels] == [(2, 2, 3), (1, 1, 3)]
    np.testing.assert_array_equal(levels[0], n)
    np.testing.assert_allclose(levels[1][0, 0], np.array([1, 1, 2]) / np.sqrt(6), atol=1e-6)
    ao = bumpbake.mips(np.arange(16, dtype=np.float32).reshape(4, 4) / 16, "ao")
    assert [lv.shape for lv in ao] == [(4, 4), (2, 2), (1, 1)]
    np.testing.assert_allclose(ao[1], [[2.5 / 16, 4.5 / 16], [10.5 / 16, 12.5 / 16]])
    assert ao[2][0, 0] == pytest.approx(7.5 / 16)


# ------------------------------------------------- against the command

def test_render_sheet_and_renderbumpflat_are_the_clis(tmp_path, fixtures, cli):
    height = os.path.join(fixtures, "pit_65x65.png")
    maps = {k: tmp_path / f"{k}.exr" for k in ("normal", "ssbump", "ao")}
    bumpbake.bake_file(height, maps, scale=8, rays=64)
    model = os.path.join(fixtures, "rivet_panel.obj")
    light = ["--light", "60,30", "--specular", "16", "--tile", "2", "--crop", "10,20,100,90"]
    running = [
        cli.start("render", *sum((["--" + k, p] for k, p in maps.items()), []), *light,
                  "-o", tmp_path / "render.exr"),
        cli.start("sheet", height, "--scale", "8", "--rays", "64", "--mode", "ao",
                  "-o", tmp_path / "sheet.exr"),
        cli.start("renderbumpflat", "-size", "64", "32", model, "-o", tmp_path / "rbf.png",
                  "--height", tmp_path / "rbf_h.png"),
    ]
    outs = [p.communicate() for p in running]
    assert [p.returncode for p in running] == [0, 0, 0], outs

    picture = bumpbake.render(**{k: str(p) for k, p in maps.items()}, light=(60, 30),
                              specular=16, tile=2, crop=(10, 20, 100, 90))
    assert picture.shape == (90, 100, 3) and picture.dtype == np.float32
    np.testing.assert_array_equal(picture, bumpbake.read(tmp_path / "render.exr"))
    arrays = {k: bumpbake.read(p) for k, p in maps.items()}
    np.testing.assert_allclose(bumpbake.render(**arrays, light=(60, 30), specular=16, tile=2,
                                               crop=(10, 20, 100, 90)), picture, atol=1e-6)

    sheet = bumpbake.sheet(bumpbake.read(height), 8, rays=64, mode="ao")
    np.testing.assert_array_equal(sheet, bumpbake.read(tmp_path / "sheet.exr"))

    with pytest.warns(bumpbake.NoteWarning, match="texels are 0.6456 times as wide as high"):
        rb = bumpbake.renderbumpflat(model, size=(64, 32), output=tmp_path / "py.png",
                                     height_output=tmp_path / "py_h.png")
    assert len(rb.notes) == 1 and "size 64 50" in rb.notes[0]
    for ours, theirs in (("py.png", "rbf.png"), ("py_h.png", "rbf_h.png")):
        c = bumpbake.compare(tmp_path / ours, tmp_path / theirs, fail=0)
        assert c.passed and c.max_abs == 0 and c.provenance_diff == [], ours
    printed = re.search(r"height scale (\S+) texels", outs[2][0]).group(1)
    assert f"{rb.height_scale:.6g}" == printed
    assert rb.normal.shape == (32, 64, 4) and rb.height.shape == (32, 64)
    assert rb.triangles > 0 and rb.texel_aspect != 1


def test_renderbumpflat_files_are_the_clis_bytes(tmp_path, fixtures, cli, monkeypatch):
    """One run in the library for both: the same words give the same bytes,
    the command line recorded in each; the arrays are the files' pixels;
    the model's notes name it."""
    for side in ("cli", "py"):
        (tmp_path / side).mkdir()
        shutil.copy(os.path.join(fixtures, "rivet_panel.obj"), tmp_path / side / "m.obj")
    words = ["renderbumpflat", "m.obj", "--size", "48", "40", "--output", "n.tif",
             "--height", "h.png", "--normal-y", "up"]
    out = cli(*words, cwd=tmp_path / "cli")
    assert "wrote normal n.tif" in out.stdout and "wrote height h.png" in out.stdout
    assert "m.obj: note: texels are" in out.stderr
    monkeypatch.chdir(tmp_path / "py")
    with pytest.warns(bumpbake.NoteWarning, match=r"^m\.obj: texels are"):
        rb = bumpbake.renderbumpflat("m.obj", size=(48, 40), output="n.tif", height="h.png",
                                     normal_y="up")
    for name in ("n.tif", "h.png"):
        assert (tmp_path / "py" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes()
    assert f"height scale {rb.height_scale:.6g} texels" in out.stdout
    assert f"{rb.triangles} triangles" in out.stdout
    np.testing.assert_allclose(bumpbake.read("h.png"), rb.height, atol=0.5 / 65535)
    # Without output or height nothing is written; the arrays are the same.
    before = sorted(os.listdir("."))
    again = bumpbake.renderbumpflat("m.obj", size=(48, 40), notes="ignore")
    assert sorted(os.listdir(".")) == before
    np.testing.assert_array_equal(again.normal, rb.normal)


def test_flat_maps_under_an_overhead_light_render_white():
    flat = {"normal": np.broadcast_to(np.float32([0, 0, 1]), (8, 8, 3)),
            "ssbump": np.full((8, 8, 3), FLAT_SSBUMP, np.float32),
            "ao": np.ones((8, 8), np.float32)}
    for mode in ("ssbump", "normal", "ao"):
        np.testing.assert_allclose(bumpbake.render(**flat, mode=mode, light=(0, 90)), 1,
                                   atol=1e-6, err_msg=mode)
    # Lightmaps alone: "basis" gives each direction its colour; the dynamic
    # light goes off unless asked.
    lit = bumpbake.render(**flat, mode="normal", lightmap="basis")
    np.testing.assert_allclose(lit, 1 / 3, atol=1e-6)
    both = bumpbake.render(**flat, mode="normal", lightmap="basis", light=(0, 90))
    np.testing.assert_allclose(both, 1 + 1 / 3, atol=1e-6)
    assert bumpbake.render(**flat, compare=True).shape[2] == 3
    # An albedo multiplies the diffuse light; mod2x's neutral is 0.5.
    grey = np.full((8, 8), 0.5, np.float32)
    lit = bumpbake.render(**flat, light=(0, 90), albedo=grey)
    np.testing.assert_allclose(lit, 0.5, atol=1e-6)
    lit = bumpbake.render(**flat, light=(0, 90), albedo=grey, albedo_mode="mod2x")
    np.testing.assert_allclose(lit, 1, atol=1e-6)
    rgb = np.broadcast_to(np.float32([1, 0.5, 0.25]), (8, 8, 3))
    np.testing.assert_allclose(bumpbake.render(**flat, light=(0, 90), albedo=rgb)[3, 4],
                               [1, 0.5, 0.25], atol=1e-6)
    with pytest.raises(bumpbake.ArgumentError, match="elevation must be in 0..90"):
        bumpbake.render(**flat, light=(0, 95))
    with pytest.raises(bumpbake.ArgumentError, match="slope needs slope=FILE"):
        bumpbake.render(**flat, mode="slope")


def test_renderbumpflat_refusals(fixtures, tmp_path):
    model = os.path.join(fixtures, "rivet_panel.obj")
    with pytest.raises(bumpbake.ArgumentError, match="tile needs rect"):
        bumpbake.renderbumpflat(model, tile=True)
    with pytest.raises(bumpbake.ArgumentError, match=r"samples must be in 1..16 \(got 17\)"):
        bumpbake.renderbumpflat(model, samples=17)
    with pytest.raises(bumpbake.ArgumentError, match="axis must be one of"):
        bumpbake.renderbumpflat(model, axis="w")
    with pytest.raises(bumpbake.Error, match="nothing.obj"):
        bumpbake.renderbumpflat(tmp_path / "nothing.obj")
    square = bumpbake.renderbumpflat(model, size=(64, 50), notes="ignore")
    assert square.notes == [] and abs(square.texel_aspect - 1) < 0.01
