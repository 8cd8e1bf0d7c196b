"""Bakes of files and batches through the library's job (bake_files,
bake_file, BakeJob): the command line's bytes and up-to-date decisions,
failures, notes, cancelling, and a job sent to another process."""

import json
import os
import shlex
import pickle
import shutil
import signal

import numpy as np
import pytest

import bumpbake

MAPS = ("normal", "ao")


def dome(side=48, bits=16):
    y, x = np.mgrid[0:side, 0:side].astype(np.float64) - side / 2
    h = np.clip(1 - (x * x + y * y) / (side * side / 5), 0, 1)
    return (np.round(h * (2**bits - 1)) / (2**bits - 1)).astype(np.float32)


def make_heights(directory, fixtures):
    """A directory of four small heights: three fixtures and a 16-bit dome
    written by the library."""
    os.makedirs(directory)
    for name in ("pit_65x65.png", "noise_96x80.png", "bricks_128x64.png"):
        shutil.copy(os.path.join(fixtures, name), directory)
    bumpbake.write(os.path.join(directory, "dome16.png"), dome(), kind="height", depth=16)


def files_of(directory):
    out = {}
    for base, _, names in os.walk(directory):
        for n in names:
            path = os.path.join(base, n)
            with open(path, "rb") as f:
                out[os.path.relpath(path, directory)] = f.read()
    return out


def cli_statuses(out):
    """{input: status} of `bumpbake bake ... --json` lines."""
    lines = [json.loads(line) for line in out.stdout.splitlines()]
    return {d["input"]: d["status"] for d in lines if "input" in d}


def test_a_batch_is_the_cli_batch_byte_for_byte(tmp_path, monkeypatch, fixtures, cli):
    """bake_files and `bumpbake bake DIR ... --out-dir OUT` typed as
    the library spells the options, from one directory with the
    same relative names: the same files, byte for byte, and the same
    up-to-date decisions on a re-run and after an input changed."""
    monkeypatch.chdir(tmp_path)
    make_heights("heights", fixtures)
    job = bumpbake.BakeJob("heights", "out", maps=MAPS, scale=16)
    command = job.command_text(0)
    assert command == ("bumpbake bake heights/bricks_128x64.png --scale 16 --out-dir out "
                       "--maps normal,ao")
    options = shlex.split(command)[3:]  # what follows "bumpbake bake INPUT"

    reports = bumpbake.bake_files("heights", "out", maps=MAPS, scale=16, depfile="py.d")
    assert [r.status for r in reports] == ["baked"] * 4
    assert [os.path.basename(r.input) for r in reports] == [
        "bricks_128x64.png", "dome16.png", "noise_96x80.png", "pit_65x65.png"]
    assert reports[1].outputs == {"normal": "out/dome16_normal.png", "ao": "out/dome16_ao.png"}
    os.rename("out", "out_py")

    cli("bake", "heights", *options)
    ours, theirs = files_of("out_py"), files_of("out")
    assert sorted(ours) == sorted(theirs) and len(ours) == 8
    different = [name for name in ours if ours[name] != theirs[name]]
    assert not different, f"not byte-identical: {different}"

    # Nothing is baked again, by either.
    again = cli_statuses(cli("bake", "heights", *options, "--json"))
    assert set(again.values()) == {"up to date"}
    assert [r.status for r in bumpbake.bake_files("heights", "out", maps=MAPS, scale=16)] \
        == ["up to date"] * 4
    assert files_of("out") == theirs

    # One input changes: both re-bake it alone.
    bumpbake.write("heights/dome16.png", dome()[::-1].copy(), kind="height", depth=16)
    job = bumpbake.BakeJob("heights", "out", maps=MAPS, scale=16)
    ours = {r.input: job.check_current(i) for i, r in enumerate(job.reports)}
    assert job.report(1).reason.startswith("out/dome16_normal.png: input_file_hash: ")
    theirs = cli_statuses(cli("bake", "heights", *options, "--json", "--depfile", "cli.d"))
    assert {k: ("up to date" if v else "baked") for k, v in ours.items()} == theirs
    assert list(theirs.values()).count("baked") == 1
    # ... and once the CLI has, Python finds every output current.
    assert {r.status for r in bumpbake.bake_files("heights", "out", maps=MAPS, scale=16)} \
        == {"up to date"}
    # The depfiles name the same rules.
    with open("py.d", "rb") as a, open("cli.d", "rb") as b:
        assert a.read() == b.read()


def test_single_bake_names_its_outputs(tmp_path, fixtures):
    src = os.path.join(fixtures, "pit_65x65.png")
    out = tmp_path / "n.exr"
    report = bumpbake.bake_file(src, {"normal": out, "ssbump": tmp_path / "s.exr"},
                                prefix=tmp_path / "p", slope=tmp_path / "slope.png",
                                lit=(30, 45), scale=8, rays=16)
    assert report.status == "baked" and report.width == 65 and report.channel == "grey"
    assert set(report.outputs) == {"normal", "ssbump", "ao", "slope", "slope_lit"}
    assert report.outputs["ao"] == str(tmp_path / "p_ao.png")
    assert report.outputs["slope_lit"] == str(tmp_path / "slope_lit.png")
    assert report.slices == 4 and report.rayset.startswith("bb-horizon-v1:a4:")
    # What the file holds is bake()'s array, bit for bit (float EXR).
    maps = bumpbake.bake(bumpbake.read(src), 8, rays=16, outputs=("normal", "ssbump"))
    np.testing.assert_array_equal(bumpbake.read(out), maps["normal"])
    np.testing.assert_array_equal(bumpbake.read(tmp_path / "s.exr"), maps["ssbump"])
    # A single bake bakes again unless told not to.
    assert bumpbake.bake_file(src, {"normal": out}, scale=8).status == "baked"
    assert bumpbake.bake_file(src, {"normal": out}, scale=8, force=False).status == "up to date"
    assert bumpbake.bake_file(src, {"normal": out}, scale=9, force=False).status == "baked"


def test_the_recorded_command_is_quoted_for_a_shell(tmp_path, monkeypatch, fixtures):
    """The provenance's command, as Python records it (bb_command_text),
    quotes every word for a POSIX shell: typed in one, a name with a blank
    or a ';' is one word, and runs nothing."""
    monkeypatch.chdir(tmp_path)
    name = "my rock;x.png"
    shutil.copy(os.path.join(fixtures, "pit_65x65.png"), name)
    report = bumpbake.bake_file(name, {"ao": "a o.png"}, scale=8, rays=16)
    assert report.status == "baked"
    command = bumpbake.info("a o.png").provenance["command"]
    assert command == "bumpbake bake 'my rock;x.png' --scale 8 --rays 16 --ao 'a o.png'"
    assert shlex.split(command)[2] == name


def test_failures_stop_the_batch_unless_keep_going(tmp_path, fixtures):
    heights = tmp_path / "heights"
    make_heights(heights, fixtures)
    (heights / "a_cut.png").write_bytes(b"\x89PNG\r\n\x1a\n not really")
    with pytest.raises(bumpbake.Error, match="a_cut.png") as e:
        bumpbake.bake_files(heights, tmp_path / "out", maps="normal", scale=4)
    assert [r.status for r in e.value.reports] == ["failed"] + ["not run"] * 4
    assert e.value.reports[0].error_status == "bad image format"
    assert not (tmp_path / "out" / "a_cut_normal.png").exists()

    reports = bumpbake.bake_files(heights, tmp_path / "out", maps="normal", scale=4,
                                  keep_going=True, check=False)
    assert [r.status for r in reports] == ["failed"] + ["baked"] * 4
    assert str(e.value) == reports[0].error and not reports[0].ok and reports[1].ok


@pytest.mark.parametrize("kwargs, error, message", [
    ({"name": "../{stem}.png"}, bumpbake.ArgumentError,
     "name ../{stem}.png: '..' would leave the output directory"),
    ({"maps": ("normal", "shine")}, bumpbake.ArgumentError, "bake: maps: unknown map 'shine'"),
    ({"depth": 12}, bumpbake.ArgumentError, "depth must be one of 8, 16, half, float"),
    ({"rays": 0}, bumpbake.ArgumentError, "bake: rays must be in 1..65536 (got 0)"),
    ({"mips": True}, bumpbake.ArgumentError, "mips needs a .tif or .exr output"),
    ({"texture_format": "dxt7"}, bumpbake.ArgumentError, "texture_format must be one of"),
    ({"vtf_version": "7.9"}, bumpbake.ArgumentError, "VTF version must be 7.2, 7.3, 7.4 or 7.5"),
    ({"vtf_flags": -1}, bumpbake.ArgumentError, "VTF flags must be a 32-bit number"),
    ({"vmt": "m.vmt"}, bumpbake.ArgumentError, "vmt writes one material"),
    ({"lit": (45, 30)}, bumpbake.ArgumentError, "lit previews one slope map"),
    ({"name": "{stem}_{kind}.vtf"}, bumpbake.ArgumentError,
     "Source textures need a power of two on each side"),
])
def test_bad_jobs_are_refused_before_any_bake(tmp_path, fixtures, kwargs, error, message):
    with pytest.raises(error) as e:
        bumpbake.bake_files(os.path.join(fixtures, "pit_65x65.png"), tmp_path / "out",
                            scale=4, **kwargs)
    assert message in str(e.value)
    assert not list(tmp_path.glob("out/*"))
    with pytest.raises(TypeError, match="scale is required"):
        bumpbake.bake_files(fixtures, tmp_path / "out")


@pytest.mark.parametrize("kwargs", [{"maps": "ao"}, {"name": "{stem}.png"},
                                    {"keep_going": True}])
def test_a_batchs_options_are_refused_in_a_single_bake(tmp_path, fixtures, kwargs):
    with pytest.raises(bumpbake.ArgumentError, match="is for batches: give out_dir=DIR"):
        bumpbake.bake_file(os.path.join(fixtures, "pit_65x65.png"),
                           {"ao": tmp_path / "a.png"}, scale=4, **kwargs)
    assert not list(tmp_path.iterdir())


def test_an_output_over_an_input_is_an_io_error(tmp_path, fixtures):
    src = tmp_path / "h.png"
    shutil.copy(os.path.join(fixtures, "pit_65x65.png"), src)
    with pytest.raises(bumpbake.Error, match="h.png: would overwrite the input ") as e:
        bumpbake.bake_file(src, {"normal": tmp_path / "." / "h.png"}, scale=4)
    assert e.value.status == "i/o error" and not isinstance(e.value, bumpbake.ArgumentError)


def colour_with_height_in_alpha(path):
    rgba = np.zeros((24, 24, 4), np.float32)
    rgba[..., 0], rgba[..., 1], rgba[..., 2] = 0.8, 0.3, 0.1
    rgba[..., 3] = dome(24, 8)
    bumpbake.write(path, rgba)


def test_notes_warn_by_default_and_stay_in_the_report(tmp_path):
    src = tmp_path / "rgba.png"
    colour_with_height_in_alpha(src)
    with pytest.warns(bumpbake.NoteWarning, match="rgba.png: .*alpha") as caught:
        report = bumpbake.bake_file(src, {"normal": tmp_path / "n.png"}, scale=4)
    assert caught[0].filename == __file__, "the warning points at the caller"
    assert report.channel == "a" and len(report.notes) == 1
    assert report.notes[0] == str(caught[0].message)
    heard = []
    report = bumpbake.bake_file(src, {"normal": tmp_path / "n.png"}, scale=4, notes=heard.append)
    assert heard == report.notes and len(heard) == 1
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        report = bumpbake.bake_file(src, {"normal": tmp_path / "n.png"}, scale=4, notes="ignore")
    assert len(report.notes) == 1


def test_a_note_made_an_error_writes_nothing(tmp_path):
    """With warnings.simplefilter("error", NoteWarning), or a notes callback
    that raises, bake_file raised after its files were written. A note made
    an error now stops the bake before anything is baked or written, as an
    exception in a progress callback does, and is raised as it was."""
    import warnings
    src = tmp_path / "rgba.png"
    colour_with_height_in_alpha(src)
    outputs = {"normal": tmp_path / "n.png", "ao": tmp_path / "ao.png"}
    with warnings.catch_warnings():
        warnings.simplefilter("error", bumpbake.NoteWarning)
        with pytest.raises(bumpbake.NoteWarning, match="rgba.png: .*alpha"):
            bumpbake.bake_file(src, outputs, scale=4, depfile=tmp_path / "d.d")

    def refuse(line):
        raise RuntimeError(f"no notes here: {line}")

    with pytest.raises(RuntimeError, match="no notes here: .*rgba.png"):
        bumpbake.bake_file(src, outputs, scale=4, notes=refuse)
    job = bumpbake.BakeJob([src], tmp_path / "out", scale=4, notes=refuse)
    with pytest.raises(RuntimeError):
        job.run_all()
    assert job.report(0).status == "failed" and "cancelled" in job.report(0).error
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out", "rgba.png"]
    assert not list((tmp_path / "out").iterdir())
    # A progress callback is never shown the notes' checkpoint (0 of 0).
    seen = []
    bumpbake.bake_file(src, {"ao": tmp_path / "ao.png"}, scale=4, notes="ignore",
                       progress=lambda done, total: seen.append(total))
    assert seen and 0 not in seen


def test_progress_may_cancel_and_an_exception_in_it_cancels(tmp_path, fixtures):
    src = os.path.join(fixtures, "noise_96x80.png")
    out = tmp_path / "ao.png"
    calls = []
    report = bumpbake.bake_file(src, {"ao": out}, scale=8, check=False,
                                progress=lambda done, total: calls.append((done, total)) or True)
    assert report.status == "failed" and "cancelled" in report.error
    assert report.error_status == "cancelled"
    assert calls and not out.exists()

    def interrupt(done, total):
        raise KeyboardInterrupt  # what Ctrl-C raises in the callback

    with pytest.raises(KeyboardInterrupt):
        bumpbake.bake_file(src, {"ao": out}, scale=8, progress=interrupt)
    assert not out.exists() and not list(tmp_path.iterdir())


def test_a_job_planned_here_runs_elsewhere(tmp_path, fixtures):
    """A pickled job is planned again where it lands (a Dask worker); the
    client then finds each input up to date and writes the depfile."""
    heights = tmp_path / "heights"
    make_heights(heights, fixtures)
    job = bumpbake.BakeJob(heights, tmp_path / "out", maps="normal", scale=4,
                           depfile=tmp_path / "d.d")
    assert len(job) == 4 and all(r.status == "pending" for r in job.reports)
    worker = pickle.loads(pickle.dumps(job))
    assert worker.inputs == job.inputs
    assert [worker.run(i).status for i in range(len(worker))] == ["baked"] * 4
    assert [r.status for r in job.run_all()] == ["up to date"] * 4
    rules = (tmp_path / "d.d").read_text().splitlines()
    assert len(rules) == 4 and rules[0].endswith(os.path.join("heights", "bricks_128x64.png"))
    with pytest.raises(IndexError):
        job.run(4)


def test_ctrl_c_during_a_trace_cancels_it_cleanly(tmp_path, fixtures):
    """A real SIGINT (Python's own handler raises KeyboardInterrupt at the
    next bytecode, here inside the progress callback on the calling
    thread): the bake stops, nothing is written, and KeyboardInterrupt
    reaches the caller."""
    src = os.path.join(fixtures, "noise_96x80.png")
    seen = []

    def ctrl_c(done, total):
        seen.append(done)
        if len(seen) == 1:
            os.kill(os.getpid(), signal.SIGINT)
            for _ in range(10000):  # bytecodes, where the handler runs
                pass

    with pytest.raises(KeyboardInterrupt):
        bumpbake.bake_file(src, {"ao": tmp_path / "ao.png"}, scale=8, rays=1024, progress=ctrl_c)
    assert len(seen) == 1, "stopped at the first slice"
    assert not list(tmp_path.iterdir())
