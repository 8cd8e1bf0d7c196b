"""Python's keyword arguments are the library's descriptions of the
commands (bb_command_*, bb_option_*): every option of every command has a
Python keyword, values are set and checked by the library, and what Python
writes is the command line's bytes."""

import os
import shlex
import shutil
import signal
import subprocess

import numpy as np
import pytest

import bumpbake
from bumpbake import _command
from test_jobs import files_of
from bumpbake._common import _ffi, _lib, _text

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BIN = os.environ.get("BB_BIN", os.path.join(ROOT, "build", "bumpbake"))
FIXTURES = os.path.join(ROOT, "fixtures")

# The Python functions that do what each command does. run() runs every
# command that writes files, with all of its options; the others work on
# arrays (and take the options that are not about files) or are the
# command's own function.
FUNCTIONS = {
    "bake": ("bake_file", "bake_files", "bake", "run"),
    "normal": ("normal", "run"),
    "height2ssbump": ("run",),
    "compare": ("compare",),
    "check": ("check",),
    "info": ("info",),
    "renderbumpflat": ("renderbumpflat",),
    "render": ("render", "run"),
    "sheet": ("sheet", "run"),
    "normal2ssbump": ("normal2ssbump", "run"),
    "ssbump2normal": ("ssbump2normal", "run"),
    "combine": ("combine", "run"),
    "program": ("program", "run"),
}

# Options with no Python keyword, and why. Every option the library marks
# BB_OPTION_CLIENT (--help, -q, --json: how the command line prints; bake
# --scheduler: a cluster from Python is bumpbake.dask.bake_files(client=...))
# is one too: Python returns reports and raises errors instead.
NOT_IN_PYTHON = {
    ("check", "bake"): "check(golden, heights=...) bakes; the command line says --bake",
    ("serve", None): "the command line's HTTP preview server (bake() and render() make "
                     "what it shows)",
}


def commands():
    names = []
    while _lib.bb_command_info_get(len(names)) != _ffi.NULL:
        names.append(_text(_lib.bb_command_info_get(len(names)).name))
    return names


def call_with(name, command, key, value):
    """Calls Python function name with keyword key = value, the rest as
    small valid arguments; returns the exception raised (or None)."""
    h = np.zeros((8, 8), np.float32)
    n = np.zeros((8, 8, 3), np.float32)
    n[..., 2] = 1
    f = getattr(bumpbake, name)
    calls = {
        "bake_file": lambda kw: f("missing.png", **kw),
        "bake_files": lambda kw: f("missing.png", "out", **kw),
        "bake": lambda kw: f(h, 1, **kw),
        "normal": lambda kw: f(h, 1, **kw),
        "run": lambda kw: f(command, **kw),
        "compare": lambda kw: f("a.png", "b.png", **kw),
        "check": lambda kw: f("g", "n", **kw),
        "info": lambda kw: f("a.png", **kw),
        "renderbumpflat": lambda kw: f("m.obj", **kw),
        "render": lambda kw: f(normal=n, **kw),
        "sheet": lambda kw: f(h, 1, **kw),
        "normal2ssbump": lambda kw: f(n, **kw),
        "ssbump2normal": lambda kw: f(n, **kw),
        "combine": lambda kw: f(n, n, **kw),
        "program": lambda kw: f("_flat", **kw),
    }
    try:
        calls[name]({key: value})
    except Exception as e:  # noqa: BLE001: what was raised is the answer
        return e
    return None


def knows(name, command, key):
    """Whether Python function name takes keyword key: a value of no
    option's type is refused as a bad value, not as an unknown keyword."""
    e = call_with(name, command, key, object())
    return not (isinstance(e, TypeError) and "unexpected keyword argument" in str(e))


def test_every_option_of_every_command_has_a_python_keyword(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert set(FUNCTIONS) | {"serve"} == set(commands())
    missing = []
    for command in commands():
        for o in _command.options(command):
            key = _command.keyword(o)
            if o.flags & _lib.BB_OPTION_CLIENT or (command, None) in NOT_IN_PYTHON or \
                    (command, key) in NOT_IN_PYTHON:
                continue
            if not any(knows(name, command, key) for name in FUNCTIONS[command]):
                missing.append(f"{command} --{_text(o.name)}")
            # an option not about files is every function's (program's
            # too, not run()'s alone)
            if not o.flags & _lib.BB_OPTION_FILES:
                missing += [f"{name}() of {command} --{_text(o.name)}"
                            for name in FUNCTIONS[command] if not knows(name, command, key)]
    assert not missing, f"CLI options with no Python keyword: {missing}"


def test_program_takes_its_keywords_through_the_library(tmp_path, monkeypatch):
    """program()'s keywords are the command's options, set and checked by
    the library (Command): the options about the file written are run()'s,
    refused in the library's words; a mistyped one gets the nearest."""
    monkeypatch.chdir(tmp_path)
    with pytest.raises(bumpbake.ArgumentError, match="^program: depth is about files"):
        bumpbake.program("_flat", depth=16)
    e = call_with("program", "program", "bace", ".")
    assert isinstance(e, TypeError) and "(did you mean 'base'?)" in str(e)
    flat, is_normal = bumpbake.program("_flat", base=tmp_path)
    assert is_normal and flat.shape[-1] == 3


def test_the_walk_fails_on_an_unknown_keyword():
    """The probe above can fail: a keyword no option has is refused as
    unknown, with the library's nearest option."""
    assert not knows("bake", "bake", "raise_the_roof")
    e = call_with("bake_file", "bake", "bounse", 0.3)
    assert isinstance(e, TypeError)
    assert str(e) == "bake() got an unexpected keyword argument 'bounse' (did you mean " \
                     "'bounce'?)"
    # the command line's own options are not Python's
    e = call_with("bake", "bake", "json", True)
    assert isinstance(e, TypeError) and "unexpected keyword argument 'json'" in str(e)


def test_values_are_refused_with_the_librarys_words():
    h = np.zeros((8, 8), np.float32)
    with pytest.raises(bumpbake.ArgumentError, match=r"^bake: bounce must be in 0\.\.1 "
                                                     r"\(got 2\)$"):
        bumpbake.bake(h, 1, bounce=2.0)
    with pytest.raises(bumpbake.ArgumentError, match="bounces must be in 0..64"):
        bumpbake.bake(h, 1, bounce=0.5, bounces=65)
    with pytest.raises(bumpbake.ArgumentError, match="bounces does nothing without"):
        bumpbake.bake(h, 1, outputs=("ao",), bounces=3)
    with pytest.raises(bumpbake.ArgumentError, match="is about files"):
        bumpbake.bake(h, 1, depth=16)
    with pytest.raises(TypeError, match="rays must be an integer"):
        bumpbake.bake(h, 1, rays="64")
    with pytest.raises(TypeError, match="clamp must be True or False"):
        bumpbake.bake(h, 1, clamp="no")
    # 5e-324 is a number: spelled exactly (repr), not as a word
    assert bumpbake.bake(h, 1, outputs=("ao",), rays=4, bounce=5e-324)["ao"].shape == (8, 8)


def cli(*args, cwd=None):
    return subprocess.run([BIN, *map(str, args)], capture_output=True, text=True, cwd=cwd)


needs_cli = pytest.mark.skipif(not os.access(BIN, os.X_OK), reason=f"{BIN} not built")


@needs_cli
def test_a_bounce_bake_is_the_clis_byte_for_byte(tmp_path, monkeypatch):
    """bake_file with bounce, bounces, bounce_albedo and brightness, and the
    command its provenance records typed: the same files, byte for byte;
    bake() of the same height gives the same pixels."""
    monkeypatch.chdir(tmp_path)
    shutil.copy(os.path.join(FIXTURES, "rock06_128.png"), "rock.png")
    albedo = np.full((128, 128), 0.5, np.float32)
    albedo[:, 64:] = 0.9
    bumpbake.write("albedo.png", albedo)
    bright = np.full((128, 128), 0.8, np.float32)
    bumpbake.write("bright.png", bright)
    settings = dict(scale=16, rays=16, bounce=0.3, bounces=2, bounce_albedo="albedo.png",
                    brightness="bright.png")
    outputs = {"ao": "py/ao.exr", "ssbump": "py/ssbump.exr"}
    os.makedirs("py")
    job = bumpbake.BakeJob("rock.png", outputs=outputs, **settings)
    command = job.command_text(0)
    assert command == ("bumpbake bake rock.png --scale 16 --rays 16 --bounce 0.3 --bounces 2 "
                       "--bounce-albedo albedo.png --brightness bright.png "
                       "--ssbump py/ssbump.exr --ao py/ao.exr")
    report = bumpbake.bake_file("rock.png", outputs, **settings)
    assert report.status == "baked"
    ours = files_of("py")
    shutil.rmtree("py")
    os.makedirs("py")
    done = cli(*shlex.split(command)[1:])
    assert done.returncode == 0, done.stderr
    theirs = files_of("py")
    assert sorted(ours) == ["ao.exr", "ssbump.exr"] == sorted(theirs)
    assert [k for k in ours if ours[k] != theirs[k]] == []

    arrays = bumpbake.bake(bumpbake.read("rock.png"), 16, outputs=("ao", "ssbump"), rays=16,
                           bounce=0.3, bounces=2, bounce_albedo=bumpbake.read("albedo.png"),
                           brightness="bright.png")
    np.testing.assert_array_equal(arrays["ao"], bumpbake.read("py/ao.exr"))
    np.testing.assert_array_equal(arrays["ssbump"], bumpbake.read("py/ssbump.exr"))


@needs_cli
def test_a_map_written_to_several_files_is_one_bake_and_the_clis(tmp_path, monkeypatch):
    """A list of paths for a map's keyword writes the map to each file,
    each in its format, from one bake: run() and bake_file() write the
    command line's bytes, and each file is what a bake of it alone writes."""
    monkeypatch.chdir(tmp_path)
    shutil.copy(os.path.join(FIXTURES, "rock06_128.png"), "rock.png")
    settings = dict(scale=8, rays=4)
    for d in ("py", "cli", "alone", "file"):
        os.makedirs(d)
    monkeypatch.chdir(tmp_path / "py")
    wrote = bumpbake.run("bake", "../rock.png", normal="n.png",
                         ssbump=["s.png", "s.tga", "s.vtf"], **settings)
    assert wrote == [("normal", "n.png"), ("ssbump", "s.png"), ("ssbump", "s.tga"),
                     ("ssbump", "s.vtf")]
    done = cli("bake", "../rock.png", "--scale", "8", "--rays", "4", "--normal", "n.png",
               "--ssbump", "s.png", "--ssbump", "s.tga", "--ssbump", "s.vtf",
               cwd=tmp_path / "cli")
    assert done.returncode == 0, done.stderr
    monkeypatch.chdir(tmp_path / "alone")
    for name in ("s.png", "s.tga", "s.vtf"):
        bumpbake.run("bake", "../rock.png", normal="n.png", ssbump=name, **settings)
    monkeypatch.chdir(tmp_path / "file")
    outputs = {"normal": "n.png", "ssbump": ["s.png", "s.vtf"]}
    report = bumpbake.bake_file("../rock.png", outputs, **settings)
    assert report.outputs == {"normal": "n.png", "ssbump": ["s.png", "s.vtf"]}
    monkeypatch.chdir(tmp_path)
    ours, theirs, alone = files_of("py"), files_of("cli"), files_of("alone")
    assert sorted(ours) == ["n.png", "s.png", "s.tga", "s.vtf"] == sorted(theirs)
    assert [k for k in ours if ours[k] != theirs[k]] == []
    assert [k for k in ("s.png", "s.tga", "s.vtf") if ours[k] != alone[k]] == []
    made = files_of("file")
    assert sorted(made) == ["n.png", "s.png", "s.vtf"]
    assert made["s.png"] == alone["s.png"] and made["s.vtf"] == alone["s.vtf"]
    assert b"--ssbump s.png --ssbump s.tga --ssbump s.vtf" in ours["n.png"]
    with pytest.raises(bumpbake.ArgumentError, match="basetexture is given twice"):
        bumpbake.run("bake", "rock.png", ssbump="x.png", basetexture=["a.vtf", "b.vtf"],
                     **settings)
    with pytest.raises(TypeError, match="ssbump must be a path or a list of paths"):
        bumpbake.run("bake", "rock.png", ssbump=["x.png", ["y.png"]], **settings)


@needs_cli
def test_a_relief_render_is_the_clis(tmp_path, monkeypatch):
    """render --relief from Python: run() writes the command line's bytes;
    render(height=...) gives its pixels."""
    for side in ("py", "cli"):
        os.makedirs(tmp_path / side)
        shutil.copy(os.path.join(FIXTURES, "rock06_128.png"), tmp_path / side / "rock.png")
    monkeypatch.chdir(tmp_path / "py")
    options = dict(scale=8, rays=16, relief=True, view=(30, 40))
    written = bumpbake.run("render", "rock.png", output="r.exr", **options)
    assert written == [("render", "r.exr")]
    # typed as the library spells the command Python ran (its provenance)
    done = cli("render", "rock.png", "--scale", 8, "--rays", 16, "--view", "30,40", "--relief",
               "--output", "r.exr", cwd=tmp_path / "cli")
    assert done.returncode == 0, done.stderr
    with open("r.exr", "rb") as a, open(tmp_path / "cli" / "r.exr", "rb") as b:
        assert a.read() == b.read()
    picture = bumpbake.render(height=bumpbake.read("rock.png"), **options)
    np.testing.assert_array_equal(picture, bumpbake.read("r.exr"))
    flat = bumpbake.render(height=bumpbake.read("rock.png"), scale=8, rays=16, view=(30, 40))
    assert not np.array_equal(flat, picture)  # the relief did something
    with pytest.raises(bumpbake.ArgumentError, match="relief needs view"):
        bumpbake.render(height=bumpbake.read("rock.png"), scale=8, relief=True)


def test_huge_broadcast_arrays_are_refused_from_their_shape():
    """A view of one value standing for gigabytes is refused by the
    library's size rule before anything is copied."""
    for view in (np.broadcast_to(np.float32(0.5), (40000, 30000)),
                 np.broadcast_to(np.uint8(7), (70000, 70000)),
                 np.broadcast_to(np.float32(0.5), (100000, 100000))):
        with pytest.raises(bumpbake.ArgumentError, match="over the maximum"):
            bumpbake.bake(view, 4)
        with pytest.raises(bumpbake.ArgumentError, match="over the maximum"):
            bumpbake.normal(view, 4)


def test_an_array_bake_is_cancelled_by_its_progress_and_by_ctrl_c():
    h = np.random.default_rng(3).random((256, 256), np.float32)
    calls = []

    def stop(done, total):
        calls.append(done)
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        bumpbake.bake(h, 8, rays=4096, outputs=("ao",), progress=stop)
    assert len(calls) == 1  # cancelled at the first call

    # A real SIGINT during the trace: Python's handler raises in the
    # progress callback, which cancels the bake.
    def interrupt(signum, frame):
        raise KeyboardInterrupt

    old = signal.signal(signal.SIGALRM, interrupt)
    try:
        signal.setitimer(signal.ITIMER_REAL, 0.2)
        with pytest.raises(KeyboardInterrupt):
            bumpbake.bake(np.tile(h, (4, 4)), 8, rays=65536, outputs=("ao",), threads=1)
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


def test_ctrl_c_stops_a_bounce_bake_inside_a_slice():
    """Ctrl-C during a bake with bounce: a bounce pass's slice at 1024 x
    1024 takes seconds (2048 x 2048 took 18 s to stop), so its line sweeps
    ask the progress every 50 ms, as a stage without progress does, and
    the lines being walked stop at their next line; the steps between the
    passes (the columns of steep relief: this noise has millions) poll it
    too. Measured in CPU time from the moment the interrupt is armed (0.3 s
    before it comes), which load does not stretch: about 0.4 s here, where
    a bundle of lines left to finish and the columns' serial loop took 4."""
    h = np.random.default_rng(5).random((1024, 1024), np.float32)
    armed = []

    def interrupt(signum, frame):
        raise KeyboardInterrupt

    def progress(done, total):
        # the trace and the bounce's direct pass are done: the passes of
        # long slices have started
        if done * 7 >= total and not armed:
            armed.append(os.times())
            signal.setitimer(signal.ITIMER_REAL, 0.3)

    old = signal.signal(signal.SIGALRM, interrupt)
    try:
        with pytest.raises(KeyboardInterrupt):
            bumpbake.bake(h, 16, rays=16, bounce=0.5, outputs=("ao",), progress=progress,
                          threads=2)
        stopped = os.times()
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)
    assert armed
    cpu = (stopped.user - armed[0].user) + (stopped.system - armed[0].system)
    assert cpu < 3.0, f"{cpu:.1f} s of CPU from arming Ctrl-C to the stop"


@needs_cli
def test_nan_normals_are_refused_by_python_and_the_cli(tmp_path):
    n = np.zeros((8, 8, 3), np.float32)
    n[..., 2] = 1
    n[2, 3, 0] = np.nan
    with pytest.raises(bumpbake.ArgumentError, match=r"texel \(3, 2\) channel 0 is NaN"):
        bumpbake.normal2ssbump(n)
    with pytest.raises(bumpbake.ArgumentError, match=r"texel \(3, 2\) channel 0 is NaN"):
        bumpbake.render(normal=n, mode="normal")
    with pytest.raises(bumpbake.ArgumentError, match="is NaN"):
        bumpbake.render(normal=n, ssbump=np.ones((8, 8, 3), np.float32) * np.nan)
    bumpbake.write(tmp_path / "n.exr", n, kind="normal")
    for args in (("normal2ssbump", "n.exr", "-o", "s.png"),
                 ("render", "--normal", "n.exr", "--mode", "normal", "-o", "r.png")):
        done = cli(*args, cwd=tmp_path)
        assert done.returncode == 1 and "channel 0 is NaN" in done.stderr, done.stderr
    assert not (tmp_path / "s.png").exists() and not (tmp_path / "r.png").exists()


def test_wrong_types_are_type_errors_not_internal_ones(tmp_path):
    with pytest.raises(TypeError, match=r"outputs must be a dict \{kind: path\}"):
        bumpbake.bake_file(tmp_path / "h.png", ["a.png"], scale=4)
    with pytest.raises(TypeError, match="description must be a str"):
        bumpbake.write(tmp_path / "t.png", np.zeros((4, 4), np.float32), description=b"x")
    with pytest.raises(TypeError, match="inputs must be a path or a list"):
        bumpbake.bake_files(42, tmp_path, scale=4)


def test_whole_numbers_are_spelled_as_typed():
    """30 is recorded as 30, not as the shortest %g that reads back (3e+01)."""
    job = bumpbake.BakeJob(os.path.join(FIXTURES, "rock06_128.png"),
                           outputs={"normal": "n.png"}, scale=30, rays=100, bias=1e6)
    assert shlex.split(job.command_text(0))[3:] == ["--scale", "30", "--rays", "100", "--bias",
                                               "1000000", "--normal", "n.png"]


def test_the_option_table_is_the_librarys():
    rows = {row[0]: row for row in _command.option_table("bake")}
    assert rows["rays"][3] == "256" and rows["rays"][4] == "1..65536"
    assert rows["bounces"][4] == "0..64"
    assert "bounce" in bumpbake.BAKE_PARAMETERS and "brightness" in bumpbake.BAKE_PARAMETERS


def test_defaults_are_exactly_the_bake_a_command_checks():
    """DEFAULTS, read by name from a bake command, are the very values a
    bake with nothing set bakes with: given as keywords, the same maps bit
    for bit; each one changed, other maps (the test can fail); the floats
    the numbers the checked command holds (filter_threshold a C float's)."""
    y, x = np.mgrid[0:23, 0:29]
    h = (0.5 + 0.3 * np.sin(0.7 * x) * np.cos(0.45 * y)).astype(np.float32)
    plain = bumpbake.bake(h, 9, outputs=bumpbake.OUTPUTS)
    given = bumpbake.bake(h, 9, outputs=bumpbake.OUTPUTS, **bumpbake.DEFAULTS)
    assert all(np.array_equal(plain[k], given[k]) for k in bumpbake.OUTPUTS)
    changed = dict(rays=64, filter_radius=3, filter_threshold=0.05, bias=0.1, power=2.0,
                   basis="hl2+z", normal_filter="valve", normal_y="up", clamp=True)
    for key, value in changed.items():
        other = bumpbake.bake(h, 9, outputs=bumpbake.OUTPUTS,
                              **dict(bumpbake.DEFAULTS, **{key: value}))
        assert any(plain[k].shape != other[k].shape or not np.array_equal(plain[k], other[k])
                   for k in bumpbake.OUTPUTS), key
    c = _command.Command("bake", "bake")
    c.set("scale", 1.0)
    c.in_memory(0)
    c.check()
    assert bumpbake.DEFAULTS["filter_threshold"] == float(np.float32(
        c.numbers("filter-threshold")[0]))
    assert bumpbake.DEFAULTS["bias"] == c.numbers("bias")[0]
    assert [type(v) for v in bumpbake.DEFAULTS.values()] == [int, int, float, float, float,
                                                             str, str, str, bool, int]


def test_the_python_reference_names_every_command_and_bake_keyword():
    """docs/python.md's table of which function takes which command's
    options names every command (serve aside, as it says), and its bake()
    entry every keyword of `bumpbake bake` for arrays."""
    with open(os.path.join(ROOT, "docs", "python.md"), encoding="utf-8") as f:
        doc = f.read()
    table = doc[doc.index("| command | Python |"):doc.index("Not in Python, by design")]
    rows = [line.split("|")[1] for line in table.splitlines()[2:] if line.startswith("|")]
    listed = {name.strip() for row in rows for name in row.split(",")}
    assert listed == set(FUNCTIONS), listed ^ set(FUNCTIONS)
    for names in FUNCTIONS.values():
        for name in names:
            assert f"`{name}`" in table and hasattr(bumpbake, name), name
    entry = " ".join(doc[doc.index("- `bake(height, scale"):doc.index("- `normal(height")].split())
    for key in bumpbake.BAKE_PARAMETERS + ("channel",):
        assert key in entry, key


def test_normal_y_up_arrays_are_read_and_written_as_the_cli_reads_files():
    n = bumpbake.bake(np.random.default_rng(5).random((16, 16), np.float32), 8,
                      outputs=("normal",))["normal"]
    up = n * np.float32([1, -1, 1])
    np.testing.assert_array_equal(bumpbake.normal2ssbump(up, normal_y="up"),
                                  bumpbake.normal2ssbump(n))
    assert up[0, 0, 1] == -n[0, 0, 1]  # the caller's array is left alone
    s = bumpbake.normal2ssbump(n)
    np.testing.assert_array_equal(bumpbake.ssbump2normal(s, kind="weights", normal_y="up"),
                                  bumpbake.ssbump2normal(s, kind="weights") * [1, -1, 1])
    np.testing.assert_array_equal(
        bumpbake.combine(up, up[::-1], mix=0.5, kind="normal", normal_y="up"),
        bumpbake.combine(n, n[::-1] * 1, mix=0.5, kind="normal") * [1, -1, 1])
    with pytest.raises(bumpbake.ArgumentError, match="normal_y must be one of down, up"):
        bumpbake.normal2ssbump(n, normal_y="sideways")


def test_run_refuses_what_is_not_a_command_or_a_path(tmp_path, monkeypatch):
    """run() took any command value (AttributeError from None, 5 or bytes),
    ran "bake\\0" as bake, turned an array into its text (a multi-line "no
    such file") and baked locally with scheduler= the docs refuse."""
    monkeypatch.chdir(tmp_path)
    h = np.zeros((8, 8), np.float32)
    bumpbake.write("h.png", h)
    for command in (None, 5, b"bake"):
        with pytest.raises(TypeError, match=r"^run: command must be a str \(got "):
            bumpbake.run(command, "h.png", scale=8, normal="n.png")
    with pytest.raises(ValueError, match="embedded null byte"):
        bumpbake.run("bake\0", "h.png", scale=8, normal="n.png")
    with pytest.raises(TypeError) as e:
        bumpbake.run("bake", np.zeros((64, 64), np.float32), scale=8, normal="n.png")
    assert "\n" not in str(e.value) and "input 1 must be a path" in str(e.value), str(e.value)
    assert "numpy array of shape (64, 64)" in str(e.value)
    with pytest.raises(TypeError) as e:
        bumpbake.run("bake", "h.png", normal=np.zeros((64, 64), np.float32), scale=8)
    assert "\n" not in str(e.value) and "normal must be a path" in str(e.value), str(e.value)
    with pytest.raises(TypeError, match=r"^run\('bake'\) got an unexpected keyword argument "
                                        r"'scheduler' \(--scheduler is the command line's own"):
        bumpbake.run("bake", "h.png", scale=8, output="q", scheduler="tcp://127.0.0.1:1")
    with pytest.raises(TypeError, match="unexpected keyword argument 'scheduler'"):
        bumpbake.bake_file("h.png", {"normal": "n.png"}, scale=8, scheduler="tcp://h:1")
    assert sorted(os.listdir(".")) == ["h.png"]
    # height2ssbump's BUMPSCALE is a number, given as one
    assert bumpbake.run("height2ssbump", "h.png", 4, rays=4, notes="ignore") == [
        ("ssbump+height", "h-ssbump.tga")]


def test_a_large_file_no_reader_knows_is_refused_at_once(tmp_path):
    """A 2 GiB file of zeros (sparse) named .png: refused in one line
    naming the format its extension promised, without reading it through
    (it took OpenImageIO's walk through every reader minutes)."""
    z = tmp_path / "z.png"
    with open(z, "wb") as f:
        f.truncate(2 << 30)
    before = os.times()
    for call in (lambda: bumpbake.read(z), lambda: bumpbake.info(z),
                 lambda: bumpbake.bake_file(z, {"normal": tmp_path / "n.png"}, scale=8),
                 lambda: bumpbake.run("bake", z, scale=8, normal=tmp_path / "n.png")):
        with pytest.raises(bumpbake.Error, match="z.png: not a readable image: its extension "
                                                 "says PNG") as e:
            call()
        assert "\n" not in str(e.value)
    after = os.times()
    assert (after.user - before.user) + (after.system - before.system) < 2.0
    assert sorted(os.listdir(tmp_path)) == ["z.png"]
