"""The Python package against known answers, the command line and its errors.

Run by `make test` (python3 -m pytest in python/); BUMPBAKE_LIBRARY names
the build's library and BB_BIN the command line, else the source tree's
build/ is used.
"""

import math
import os
import re
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import bumpbake

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
FIXTURES = os.path.join(ROOT, "fixtures")
BIN = os.environ.get("BB_BIN") or os.path.join(ROOT, "build", "bumpbake")
SSBUMP_FLAT = 1.0 / math.sqrt(3.0)


def bump(side=32, sigma2=18.0):
    """A round bump of height 1 in the middle of a side x side field."""
    y, x = np.mgrid[0:side, 0:side].astype(np.float64) - side // 2
    return np.exp(-(x * x + y * y) / sigma2).astype(np.float32)


# ------------------------------------------------------------------ values

def test_flat_field_gives_the_flat_values():
    maps = bumpbake.bake(np.zeros((16, 20), np.float32), scale=8, outputs=bumpbake.OUTPUTS)
    assert set(maps) == set(bumpbake.OUTPUTS)
    assert maps["normal"].shape == (16, 20, 3) and maps["normal"].dtype == np.float32
    assert maps["ao"].shape == (16, 20) and maps["filtered"].shape == (16, 20)
    np.testing.assert_array_equal(maps["normal"], np.broadcast_to([0, 0, 1], (16, 20, 3)))
    np.testing.assert_allclose(maps["ssbump"], SSBUMP_FLAT, atol=1e-6)
    np.testing.assert_array_equal(maps["ao"], 1.0)
    np.testing.assert_allclose(maps["weights"], 1.0 / 3.0, atol=1e-6)
    np.testing.assert_allclose(maps["bent"], np.broadcast_to([0, 0, 1], (16, 20, 3)), atol=1e-6)


def test_normals_of_a_bump_lean_away_from_its_top():
    h = bump()
    n = bumpbake.normal(h, scale=8)
    c = 16
    assert n.shape == (32, 32, 3)
    assert n[c, c + 3, 0] > 0.3 and n[c, c - 3, 0] < -0.3  # right flank leans +x
    assert n[c + 3, c, 1] > 0.3 and n[c - 3, c, 1] < -0.3  # y is down: lower flank leans +y
    np.testing.assert_allclose(np.linalg.norm(n, axis=2), 1.0, atol=1e-5)
    # The default estimator is centred on the vertex: the top comes out
    # level. Valve's is centred half a texel off it (docs/conventions.md).
    np.testing.assert_array_equal(n[c, c], [0, 0, 1])
    valve = bumpbake.normal(h, scale=8, normal_filter="valve")
    assert valve[c, c, 0] > 0.1 and valve[c, c, 1] > 0.1
    up = bumpbake.normal(h, scale=8, normal_y="up")
    np.testing.assert_array_equal(up[..., 1], -n[..., 1])
    np.testing.assert_array_equal(up[..., 0], n[..., 0])


def test_ssbump_and_ao_of_a_bump():
    maps = bumpbake.bake(bump(), scale=8, rays=64, outputs=("ssbump", "ao"))
    s, ao = maps["ssbump"], maps["ao"]
    c = 16
    # The right flank faces +x: red (B0, light from the right) is brightest.
    assert s[c, c + 3, 0] > s[c, c + 3, 1] and s[c, c + 3, 0] > s[c, c + 3, 2]
    # At the foot the bump blocks rays; its top sees the whole sky.
    assert ao[c, c + 5] < 0.95
    assert ao[c, c] > ao[c, c + 5]


def test_integer_heights_are_value_over_max_code():
    h8 = (bump() * 255).round().astype(np.uint8)
    a = bumpbake.normal(h8, scale=8)
    b = bumpbake.normal(h8.astype(np.float32) / np.float32(255), scale=8)
    np.testing.assert_array_equal(a, b)
    assert abs(a[16, 19, 0]) > 0.3


def test_a_misaligned_array_is_handed_over_aligned():
    """numpy lets an array start at any byte of a buffer; the library reads
    floats, so what it is given is an aligned copy, and the bake the same."""
    rng = np.random.default_rng(7)
    h = rng.random((24, 20), dtype=np.float32)
    raw = bytearray(h.nbytes + 1)
    odd = np.frombuffer(raw, dtype=np.float32, count=h.size, offset=1).reshape(h.shape)
    odd[...] = h
    assert not odd.flags.aligned
    from bumpbake._common import _Image
    assert _Image("height", odd).array.flags.aligned
    a = bumpbake.bake(odd, 4.0, outputs=("normal", "ao"), rays=16)
    b = bumpbake.bake(h, 4.0, outputs=("normal", "ao"), rays=16)
    for k in a:
        assert np.array_equal(a[k], b[k])


def test_rgba_heights_follow_the_channel_rule():
    h = bump()
    rgba = np.zeros((32, 32, 4), np.float32)
    rgba[..., 3] = h  # Valve's convention: height in alpha, constant RGB
    np.testing.assert_array_equal(bumpbake.normal(rgba, 8, channel="a"), bumpbake.normal(h, 8))
    # auto sees a constant colour and a varying alpha, and takes alpha ...
    np.testing.assert_array_equal(bumpbake.normal(rgba, 8), bumpbake.normal(h, 8))
    # ... while the mean of R, G, B, asked for, is flat
    np.testing.assert_array_equal(bumpbake.normal(rgba, 8, channel="mean")[..., 2], 1.0)
    rgba[5, 7, 1] = 0.25  # a colour with a graded alpha: still Valve's convention
    np.testing.assert_array_equal(bumpbake.normal(rgba, 8), bumpbake.normal(h, 8))
    rgba[5, 7, :3] = 0.25  # a grey that varies is a height: auto takes it
    assert bumpbake.normal(rgba, 8)[..., 2].min() < 1.0
    assert not np.array_equal(bumpbake.normal(rgba, 8), bumpbake.normal(h, 8))


def test_same_bits_for_any_thread_count():
    h = np.random.default_rng(7).random((40, 48), dtype=np.float32)
    one = bumpbake.bake(h, 16, rays=32, threads=1, outputs=("ssbump", "ao"))
    two = bumpbake.bake(h, 16, rays=32, threads=2, outputs=("ssbump", "ao"))
    for k in one:
        np.testing.assert_array_equal(one[k], two[k])


def test_slices_override_rays():
    h = np.random.default_rng(3).random((24, 20), dtype=np.float32)
    a = bumpbake.bake(h, 8, rays=49, outputs="ao")["ao"]  # round(sqrt(49)) = 7 slices
    b = bumpbake.bake(h, 8, rays=1000, slices=7, outputs="ao")["ao"]
    np.testing.assert_array_equal(a, b)
    with pytest.raises(bumpbake.ArgumentError, match="slices must be in 1..256"):
        bumpbake.bake(h, 8, slices=0, outputs="ao")
    with pytest.raises(bumpbake.ArgumentError, match="slices must be in 1..256"):
        bumpbake.bake(h, 8, slices=257, outputs="ao")


def test_basis_hl2_z_adds_a_fourth_ssbump_channel():
    s = bumpbake.bake(np.zeros((8, 8)), 4, rays=16, basis="hl2+z", outputs="ssbump")["ssbump"]
    assert s.shape == (8, 8, 4)
    np.testing.assert_allclose(s[..., 3], 1.0, atol=1e-6)  # N.B3 = 1 on a flat field


def test_dirs_basis_has_a_channel_per_direction():
    h = np.random.default_rng(5).random((16, 12), dtype=np.float32)
    maps = bumpbake.bake(h, 6, slices=8, basis="dirs:6", outputs=("ssbump", "weights"))
    assert maps["ssbump"].shape == (16, 12, 6)
    assert maps["weights"].shape == (16, 12, 6)
    np.testing.assert_allclose(maps["weights"].sum(axis=2), 1.0, atol=1e-6)
    flat = bumpbake.bake(np.zeros((8, 8)), 4, slices=8, basis="dirs:6", outputs="ssbump")
    np.testing.assert_allclose(flat["ssbump"], 1 / np.sqrt(3), atol=1e-7)
    # dirs:3 is Half-Life 2's basis, bit for bit.
    a = bumpbake.bake(h, 6, slices=8, basis="dirs:3", outputs="ssbump")["ssbump"]
    b = bumpbake.bake(h, 6, slices=8, outputs="ssbump")["ssbump"]
    np.testing.assert_array_equal(a, b)


def test_basis_from_an_array_a_file_and_a_name_agree(tmp_path):
    v = bumpbake.basis("dirs:5")
    assert v.shape == (5, 3)
    np.testing.assert_allclose(np.linalg.norm(v, axis=1), 1.0, atol=1e-15)
    path = tmp_path / "five.txt"
    path.write_text("# five directions\n" + "".join(
        f"{x!r} {y!r} {z!r}\n" for x, y, z in (2 * v).tolist()))
    np.testing.assert_array_equal(bumpbake.basis(path), bumpbake.basis(v))
    np.testing.assert_allclose(bumpbake.basis(path), v, atol=1e-15)
    h = np.random.default_rng(6).random((10, 10), dtype=np.float32)
    from_file = bumpbake.bake(h, 5, slices=6, basis=str(path), outputs="ssbump")["ssbump"]
    from_array = bumpbake.bake(h, 5, slices=6, basis=2 * v, outputs="ssbump")["ssbump"]
    np.testing.assert_array_equal(from_file, from_array)
    bad = tmp_path / "bad.txt"
    bad.write_text("0 0 1\n1 0 1\n0 1\n")
    with pytest.raises(bumpbake.Error, match=r"bad.txt:3: 2 numbers; a direction is 3"):
        bumpbake.basis(bad)


@pytest.mark.skipif(not os.access(BIN, os.X_OK), reason=f"{BIN} not built")
def test_same_bits_as_the_command_line(tmp_path):
    """Defaults, reading and every output as `bumpbake bake` makes them."""
    src = os.path.join(FIXTURES, "rock06_128.png")
    kinds = bumpbake.OUTPUTS
    args = [BIN, "bake", src, "--scale", "24", "--quiet"]
    for k in kinds:
        args += [f"--{k}", str(tmp_path / f"{k}.exr")]
    subprocess.run(args, check=True)
    ours = bumpbake.bake(bumpbake.read(src), scale=24, outputs=kinds)
    for k in kinds:
        theirs = bumpbake.read(tmp_path / f"{k}.exr")
        np.testing.assert_array_equal(ours[k], theirs, err_msg=k)


# ------------------------------------------------------------------ errors

@pytest.mark.parametrize("kwargs, message", [
    ({"rays": 0}, "bake: rays must be in 1..65536 (got 0)"),
    ({"rays": 70000}, "bake: rays must be in 1..65536 (got 70000)"),
    ({"scale": 0}, "bake: scale must be > 0 (got 0)"),
    ({"scale": float("nan")}, "bake: scale needs a number (got 'nan')"),
    ({"bias": -1}, "bake: bias must be in 0..1e6 (got -1)"),
    ({"bias": 2e6}, "bake: bias must be in 0..1e6 (got 2e6)"),
    ({"power": 0.5}, "bake: power must be in 1..1e6 (got 0.5)"),
    ({"power": 2e6}, "bake: power must be in 1..1e6"),
    ({"filter_threshold": 0}, "bake: filter_threshold must be > 0 (got 0)"),
    ({"filter_radius": -1}, "bake: filter_radius must be in 0..4096 (got -1)"),
    ({"filter_radius": 4097}, "bake: filter_radius must be in 0..4096 (got 4097)"),
    ({"threads": -1}, "bake: threads must be in 0..4096 (got -1)"),
    ({"threads": 4097}, "bake: threads must be in 0..4096 (got 4097)"),
    ({"rays": 2**40}, "bake: rays must be in 1..65536 (got 1099511627776)"),
    ({"basis": "hl3"}, "bake: basis must be hl2, hl2+z, dirs:N (N in 3..16) or a file of directions "
                        "(got 'hl3': No such file or directory)"),
    ({"basis": "dirs:2"}, "bake: basis dirs:N needs a whole N in 3..16 (got 'dirs:2')"),
    ({"basis": [[0, 0, 1], [1, 0, 0], [0, 0, 0]]}, "basis: vector 2: the zero vector"),
    ({"basis": np.zeros((3, 2))}, "basis vectors must be an (N, 3) array"),
    ({"normal_filter": "box"}, "bake: normal_filter must be one of valve, central, sobel, vertex (got 'box')"),
    ({"normal_y": "left"}, "bake: normal_y must be one of down, up (got 'left')"),
    ({"channel": "z"}, "bake: channel must be one of auto, r, g, b, a, luma, mean, valve (got 'z')"),
    ({"channel": "a"}, "channel 'a' asked of an image with no alpha (1 channels)"),
    ({"outputs": ("normal", "shadow")}, "bake: unknown output 'shadow'"),
    ({"outputs": ()}, "bake: nothing to make: outputs is empty"),
])
def test_bad_parameters_raise_with_the_message(kwargs, message):
    args = {"scale": 8, **kwargs}
    with pytest.raises(bumpbake.ArgumentError) as e:
        bumpbake.bake(np.zeros((8, 8), np.float32), **args)
    assert str(e.value).startswith(message)
    assert e.value.status == "bad argument"
    assert isinstance(e.value, ValueError)


def test_bad_heights_raise_with_the_message():
    h = np.zeros((6, 7), np.float32)
    h[2, 3] = np.nan
    with pytest.raises(bumpbake.ArgumentError, match=r"height at texel \(3, 2\) is NaN") as e:
        bumpbake.bake(h, 8)
    assert e.value.status == "bad value"
    with pytest.raises(bumpbake.ArgumentError, match="empty image"):
        bumpbake.normal(np.zeros((0, 5), np.float32), 8)
    with pytest.raises(bumpbake.ArgumentError, match=r"\(H, W\) or \(H, W, C\)"):
        bumpbake.normal(np.zeros(5, np.float32), 8)
    with pytest.raises(TypeError, match="float or unsigned integer"):
        bumpbake.normal(np.zeros((4, 4), np.int32), 8)
    with pytest.raises(TypeError, match="rays must be an integer"):
        bumpbake.bake(np.zeros((4, 4)), 8, rays=2.5)


def test_read_errors_carry_the_library_message(tmp_path):
    missing = tmp_path / "missing.png"
    with pytest.raises(bumpbake.Error, match="missing.png") as e:
        bumpbake.read(missing)
    assert e.value.status == "i/o error"
    junk = tmp_path / "junk.png"
    junk.write_bytes(b"not a png at all")
    with pytest.raises(bumpbake.Error) as e:
        bumpbake.read(junk)
    assert e.value.status == "bad image format" and "junk.png" in str(e.value)


# -------------------------------------------------------------- threading

def test_the_gil_is_released_while_baking():
    """A Python thread keeps running while another thread is inside bb_command_bake:
    cffi drops the GIL for the call. Were it held, the main loop below would
    get no CPU for the whole bake. Measured in each thread's CPU time, which
    a busy machine shares out alike, not in wall-clock gaps, which it
    stretches."""
    h = np.random.default_rng(1).random((160, 160), dtype=np.float32)
    done = threading.Event()
    baked, worker_cpu = {}, []

    def work():
        t0 = time.thread_time()
        baked.update(bumpbake.bake(h, 24, rays=1024, threads=1, outputs="ao"))
        worker_cpu.append(time.thread_time() - t0)
        done.set()

    worker = threading.Thread(target=work)
    start = time.thread_time()
    loops = 0
    worker.start()
    while not done.is_set():
        loops += 1
    main_cpu = time.thread_time() - start
    worker.join()
    assert baked["ao"].shape == (160, 160)
    assert worker_cpu[0] > 0.1, "the bake was too short to tell"
    # (the GIL held: the loop gets next to nothing; released: about as much
    # as the bake on two cores, and its share of them under any load)
    assert main_cpu > 0.2 * worker_cpu[0], (main_cpu, worker_cpu, loops)


# ---------------------------------------------------------------- loading

def test_docstrings_show_the_library_defaults():
    """The docstrings are written from the library's descriptions."""
    doc = " ".join(bumpbake.bake.__doc__.split())
    assert "rays: ray budget" in doc and "(default 256; 1..65536)" in doc
    assert "normal_filter: normal estimator" in bumpbake.normal.__doc__
    assert "(default vertex)" in bumpbake.normal.__doc__
    for key in bumpbake.BAKE_PARAMETERS:
        assert f"    {key}: " in bumpbake.bake.__doc__, key
    assert bumpbake.DEFAULTS["rays"] == 256 and bumpbake.DEFAULTS["bias"] == pytest.approx(0.55)


@pytest.mark.skipif(not os.access(BIN, os.X_OK), reason=f"{BIN} not built")
def test_defaults_are_those_of_the_command_line():
    """Every default --help prints for bake is DEFAULTS' (the library's)."""
    text = subprocess.run([BIN, "bake", "--help"], capture_output=True, text=True,
                          check=True).stdout
    for name, value in bumpbake.DEFAULTS.items():
        if name == "clamp":
            continue  # a flag: --help says "default periodic"
        option = "--" + name.replace("_", "-")
        line = next(l for l in text.splitlines() if l.strip().startswith(option + " "))
        shown = re.search(r"default ([^;]+)", line).group(1)
        if isinstance(value, str):
            assert shown == value, option
        else:
            assert float(shown) == pytest.approx(value, rel=1e-4), option


def test_the_library_is_found_in_the_source_tree_build():
    built = os.path.join(ROOT, "build", bumpbake._library.SONAME)
    assert bumpbake._library.candidates({})[0] == built
    if not os.path.exists(built):
        pytest.skip("no release build in build/")
    env = {k: v for k, v in os.environ.items() if k != "BUMPBAKE_LIBRARY"}
    env["PYTHONPATH"] = os.path.join(ROOT, "python")
    out = subprocess.run([sys.executable, "-c", "import bumpbake; print(bumpbake.library_path)"],
                         env=env, cwd="/", capture_output=True, text=True, check=True)
    assert out.stdout.strip() == built


def test_a_missing_library_fails_import_with_a_hint(tmp_path):
    env = dict(os.environ, BUMPBAKE_LIBRARY=str(tmp_path / "nowhere.so"),
               PYTHONPATH=os.path.join(ROOT, "python"))
    out = subprocess.run([sys.executable, "-c", "import bumpbake"], env=env, cwd="/",
                         capture_output=True, text=True)
    assert out.returncode != 0
    assert "ImportError: bumpbake: cannot load" in out.stderr
    assert "nowhere.so (no such file)" in out.stderr


@pytest.mark.skipif(not os.access(BIN, os.X_OK), reason=f"{BIN} not built")
def test_file_hash_is_what_the_command_line_records(tmp_path):
    src = os.path.join(FIXTURES, "rock06_128.png")
    out = tmp_path / "n.png"
    subprocess.run([BIN, "bake", src, "--scale", "8", "--normal", str(out), "-q"], check=True)
    info = subprocess.run([BIN, "info", str(out)], check=True, capture_output=True,
                          text=True).stdout
    recorded = re.search(r"input_file_hash=([0-9a-f]{16})", info).group(1)
    assert f"{bumpbake.file_hash(src):016x}" == recorded
    (tmp_path / "a").write_bytes(b"a")
    assert bumpbake.file_hash(tmp_path / "a") == 0xaf63dc4c8601ec8c  # FNV-1a 64 of "a"
    with pytest.raises(bumpbake.Error, match="cannot read"):
        bumpbake.file_hash(tmp_path / "missing.png")


def test_an_installed_package_loads_the_recorded_library_or_says_what_to_do(tmp_path):
    """`make install` records the library's path in bumpbake/_install.py;
    with that file gone, the error names only the paths tried and the
    remedy (tools/check_install.sh checks a real install)."""
    site = tmp_path / "dist-packages"
    (site / "bumpbake").mkdir(parents=True)
    for name in os.listdir(os.path.dirname(bumpbake.__file__)):
        if name.endswith(".py"):
            with open(os.path.join(os.path.dirname(bumpbake.__file__), name), "rb") as f:
                (site / "bumpbake" / name).write_bytes(f.read())
    gone = tmp_path / "lib" / bumpbake._library.SONAME
    (site / "bumpbake" / "_install.py").write_text(f"LIBRARY = {str(gone)!r}\n")
    env = {"PATH": os.environ.get("PATH", "/usr/bin:/bin"), "PYTHONPATH": str(site)}
    out = subprocess.run([sys.executable, "-c", "import bumpbake"], env=env, cwd="/",
                         capture_output=True, text=True)
    assert out.returncode != 0
    message = out.stderr.strip().splitlines()[-1]
    assert message.startswith(f"ImportError: bumpbake: cannot load {bumpbake._library.SONAME}: "
                              "the library this package was installed with is gone: run "
                              "`make install` again")
    tried = message.split("Tried: ")[1]
    assert tried.startswith(f"{gone} (no such file); {bumpbake._library.SONAME} by the dynamic "
                            "loader's search")
    assert "build" not in tried and "pkg-config" not in tried


# ------------------------------------------------------- edit-local bakes

@pytest.mark.parametrize("clamp", [False, True])
def test_bake_context_equals_whole_bakes_after_edits(clamp):
    rng = np.random.default_rng(7)
    y, x = np.mgrid[0:61, 0:83].astype(np.float64)
    h = (0.5 + 0.2 * np.sin(0.3 * x) * np.cos(0.2 * y) + 0.05 * rng.random((61, 83)))
    h = h.astype(np.float32)
    brightness = (0.5 + rng.random((61, 83, 3))).astype(np.float32)
    options = dict(outputs=bumpbake.OUTPUTS, clamp=clamp, brightness=brightness)
    with bumpbake.BakeContext() as context:
        first = context.bake(h, 16, **options)
        assert context.changed == (0, 0, 83, 61)
        for key, value in bumpbake.bake(h, 16, **options).items():
            np.testing.assert_array_equal(first[key], value)
        for edit in range(4):
            if edit == 3:  # a tall peak at an edge
                h[0:4, 80:83] += 1.5
            else:
                r, c = rng.integers(0, 61), rng.integers(0, 83)
                h[r:r + 5, c:c + 3] += np.float32(rng.normal() * 0.1)
            if edit == 1:
                brightness[10, 10] = 2.0
            got = context.bake(h, 16, threads=1 + edit % 2, **options)
            x0, y0, width, height = context.changed
            assert 0 < width * height < 83 * 61 or edit == 3
            want = bumpbake.bake(h, 16, **options)
            for key in bumpbake.OUTPUTS:  # the whole bake's bits
                np.testing.assert_array_equal(got[key], want[key], err_msg=f"{key}, edit {edit}")
        again = context.bake(h, 16, **options)
        assert context.changed[2] == 0  # the same height: nothing changed
        np.testing.assert_array_equal(again["ssbump"], want["ssbump"])


def test_bake_context_refuses_as_bake_does():
    with bumpbake.BakeContext() as context:
        with pytest.raises(bumpbake.ArgumentError, match="scale"):
            context.bake(np.zeros((8, 8), np.float32), 0)
    with pytest.raises(ValueError, match="closed"):
        context.bake(np.zeros((8, 8), np.float32), 4)
