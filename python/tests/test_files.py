"""Files through the library: compare against `bumpbake compare` verdict for
verdict, info against what a bake recorded, write against its codes."""

import json
import math
import os

import numpy as np
import pytest

import bumpbake

RAMP = (np.arange(64, dtype=np.float32) / 64).reshape(8, 8)


def pairs(tmp_path):
    """(name, a, b, tolerances) for a pass, a warning, a failure and a
    different size."""
    a = tmp_path / "a.exr"
    bumpbake.write(a, RAMP)
    same = tmp_path / "same.exr"
    bumpbake.write(same, RAMP)
    off = RAMP.copy()
    off.flat[[3, 17, 40]] += 0.25  # 3 of 64 pixels, 4.7 %
    b = tmp_path / "off.exr"
    bumpbake.write(b, off)
    wide = tmp_path / "wide.exr"
    bumpbake.write(wide, np.zeros((8, 9), np.float32))
    return [
        ("pass", a, same, {}),
        ("warning", a, b, {"failpercent": 5}),
        ("failure", a, b, {"fail": 0.1, "hardfail": 0.2, "failpercent": 50}),
        ("size", a, wide, {}),
    ]


def test_verdicts_and_exit_codes_are_the_clis(tmp_path, cli):
    cases = pairs(tmp_path)
    # The CLI runs side by side, spelled as idiff's options.
    running = [cli.start("compare", a, b, *sum(([f"-{k}", str(v)] for k, v in t.items()), []))
               for _, a, b, t in cases]
    codes = [p.wait() for p in running]
    for p in running:
        p.communicate()
    got = [bumpbake.compare(a, b, **t) for _, a, b, t in cases]
    assert [c.result for c in got] == ["PASS", "WARNING", "FAILURE", "DIFFERENT SIZE"]
    assert [c.exit_code for c in got] == codes == [0, 1, 2, 3]
    assert [c.passed for c in got] == [True, False, False, False]
    warn = got[1]
    assert warn.over_fail == 3 and warn.pixels == 64 and warn.max_abs == pytest.approx(0.25)
    assert warn.worst == (3, 0, 0) and warn.mean_abs == pytest.approx(0.75 / 64)
    assert got[3].b_shape == (8, 9, 1) and got[3].pixels == 0


def test_allowed_failures_and_hard_limits(tmp_path):
    _, a, b, _ = pairs(tmp_path)[1]
    assert bumpbake.compare(a, b, allowfailures=3).result == "PASS"
    assert bumpbake.compare(a, b, allowfailures=2).result == "FAILURE"
    assert bumpbake.compare(a, b, fail=0.3).result == "PASS"
    assert bumpbake.compare(a, b, failpercent=10, hardfail=0.1).result == "FAILURE"
    assert bumpbake.compare(a, b, failpercent=10, warnpercent=10, hardwarn=0.1).result == "WARNING"
    with pytest.raises(bumpbake.ArgumentError, match=r"failpercent must be in 0..100 \(got 150\)"):
        bumpbake.compare(a, b, failpercent=150)
    with pytest.raises(bumpbake.ArgumentError, match="fail needs a number"):
        bumpbake.compare(a, b, fail=math.nan)
    assert bumpbake.compare(a, b, fail=0.3, hardfail=math.inf).result == "PASS"
    with pytest.raises(bumpbake.Error, match="missing.exr") as e:
        bumpbake.compare(a, tmp_path / "missing.exr")
    assert not isinstance(e.value, bumpbake.ArgumentError)


def test_diff_image_and_its_refusals(tmp_path):
    _, a, b, _ = pairs(tmp_path)[1]
    c = bumpbake.compare(a, b, diff=tmp_path / "d.exr")
    assert c.diff_written and c.diff_error is None
    np.testing.assert_allclose(bumpbake.read(tmp_path / "d.exr"),
                               np.abs(bumpbake.read(b) - bumpbake.read(a)))
    with pytest.raises(bumpbake.Error, match="overwrite"):
        bumpbake.compare(a, b, diff=a)


def test_provenance_differences_are_the_clis(tmp_path, fixtures, cli):
    src = os.path.join(fixtures, "pit_65x65.png")
    x, y = tmp_path / "x.exr", tmp_path / "y.exr"
    bumpbake.bake_file(src, {"normal": x}, scale=8)
    bumpbake.bake_file(src, {"normal": y}, scale=16, filter_radius=4)
    c = bumpbake.compare(x, y, fail=2)
    theirs = json.loads(cli("compare", x, y, "-fail", "2", "--json").stdout)
    assert c.result == theirs["result"] == "PASS"
    assert c.provenance_lines == theirs["provenance_diff"]
    assert c.provenance_diff == [("scale", "8", "16"), ("filter_radius", "10", "4")]
    assert c.provenance_a == c.provenance_b == "intact"
    assert bumpbake.compare(x, x).provenance_diff == []


def test_info_reads_what_a_bake_recorded(tmp_path, fixtures):
    src = os.path.join(fixtures, "pit_65x65.png")
    out = tmp_path / "n.png"
    bumpbake.bake_file(src, {"normal": out}, scale=12, depth=16)
    i = bumpbake.info(out)
    assert (i.width, i.height, i.channels, i.format) == (65, 65, 3, "png")
    assert (i.bits_per_sample, i.is_float, i.alpha_channel) == (16, False, -1)
    assert i.provenance_class == "intact"
    assert i.provenance["scale"] == "12" and i.provenance["output"] == "normal"
    assert i.provenance["input_file_hash"] == f"{bumpbake.file_hash(src):016x}"
    assert i.description.startswith("bumpbake_version=")
    plain = tmp_path / "plain.tif"
    bumpbake.write(plain, RAMP, description="made by hand")
    i = bumpbake.info(plain)
    assert (i.provenance_class, i.provenance, i.description) == ("none", None, "made by hand")
    with pytest.raises(bumpbake.Error, match="nothing.png"):
        bumpbake.info(tmp_path / "nothing.png")


def test_write_stores_codes_as_bake_does(tmp_path):
    n = np.array([[[0.0, 0.0, 1.0], [0.6, -0.8, 0.0]]], np.float32)
    bumpbake.write(tmp_path / "n.png", n, kind="normal", depth=16)
    codes = np.round(bumpbake.read(tmp_path / "n.png") * 65535)
    np.testing.assert_array_equal(codes, np.round((0.5 + 0.5 * n) * 65535))
    np.testing.assert_allclose(bumpbake.decode_normals(bumpbake.read(tmp_path / "n.png"),
                                                       normalize=False), n, atol=1 / 65535)
    bumpbake.write(tmp_path / "u.png", np.array([[0.0, 0.5, 1.0, 2.0]], np.float32))
    np.testing.assert_array_equal(np.round(bumpbake.read(tmp_path / "u.png") * 255),
                                  [[0, 128, 255, 255]])  # rounded, clamped
    bumpbake.write(tmp_path / "f.exr", n, kind="normal")
    np.testing.assert_array_equal(bumpbake.read(tmp_path / "f.exr"), n)  # float: as it is
    bumpbake.write(tmp_path / "m.tif", np.ones((8, 4, 3), np.float32), mips=True)
    with pytest.raises(bumpbake.ArgumentError, match="--mips needs a .tif or .exr"):
        bumpbake.write(tmp_path / "m.png", n, mips=True)
    with pytest.raises(bumpbake.ArgumentError, match="kind must be one of"):
        bumpbake.write(tmp_path / "k.png", n, kind="normals")
    with pytest.raises(bumpbake.ArgumentError, match="depth must be one of"):
        bumpbake.write(tmp_path / "k.png", n, depth=32)


def test_an_embedded_nul_in_a_path_is_a_value_error(tmp_path, monkeypatch):
    """write("t.png\\0.exr", a) wrote t.png and read("h.png\\0junk") read
    h.png: C ends a string at its NUL. Every path the package hands to C
    (and every text: a program, a description) refuses one, as os does,
    and nothing is written."""
    monkeypatch.chdir(tmp_path)
    bumpbake.write("h.png", RAMP, kind="height", depth=16)
    os.makedirs("materials")
    calls = {
        "read": lambda: bumpbake.read("h.png\0junk"),
        "read bytes": lambda: bumpbake.read(b"h.png\0junk"),
        "info": lambda: bumpbake.info("h.png\0junk"),
        "file_hash": lambda: bumpbake.file_hash("h.png\0junk"),
        "write": lambda: bumpbake.write("t.png\0.exr", RAMP),
        "write description": lambda: bumpbake.write("d.png", RAMP, description="a\0b"),
        "write_vmt": lambda: bumpbake.write_vmt("materials/m.vmt\0.txt", "materials/s.vtf"),
        "write_vmt bumpmap": lambda: bumpbake.write_vmt("materials/m.vmt",
                                                        "materials/s.vtf\0x.vtf"),
        "compare": lambda: bumpbake.compare("h.png", "h.png\0junk"),
        "compare diff": lambda: bumpbake.compare("h.png", "h.png", diff="d.png\0.exr"),
        "bake_file input": lambda: bumpbake.bake_file("h.png\0junk", {"normal": "n.png"},
                                                      scale=8),
        "bake_file output": lambda: bumpbake.bake_file("h.png", {"normal": "n.png\0.exr"},
                                                       scale=8),
        "bake_file depfile": lambda: bumpbake.bake_file("h.png", {"normal": "n.png"},
                                                        depfile="d\0.d", scale=8),
        "bake_files out_dir": lambda: bumpbake.bake_files(["h.png"], "out\0dir", scale=8),
        "basis file": lambda: bumpbake.bake(RAMP, 8, basis="lights.txt\0junk"),
        "program": lambda: bumpbake.program("invertColor(h.png\0junk)"),
        "program base": lambda: bumpbake.program("invertColor(h.png)", base=".\0junk"),
        "render": lambda: bumpbake.render(normal="h.png\0junk", mode="normal"),
        "renderbumpflat": lambda: bumpbake.renderbumpflat("m.obj\0junk"),
    }
    for name, call in calls.items():
        with pytest.raises(ValueError, match="embedded null byte"):
            call()
            pytest.fail(f"{name}: no ValueError")
    assert sorted(os.listdir(".")) == ["h.png", "materials"]
    assert os.listdir("materials") == []
