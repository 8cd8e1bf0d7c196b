"""bumpbake.dask on a LocalCluster of 2 worker processes: a batch is the
CLI batch byte for byte and a re-run bakes nothing; a clash is refused
before anything is baked; one map split over the workers is the single
process's bake bit for bit; a worker killed in the middle of a batch
changes nothing of the result."""

import json
import os
import re
import shlex
import shutil
import signal
import threading
import time
import warnings

import numpy as np
import pytest

import bumpbake

distributed = pytest.importorskip(
    "distributed", reason="python3-distributed is not installed (make deps installs it)")
import bumpbake.dask  # noqa: E402

SCALE = 16


def heights(directory, count, side=40, width=None):
    """count small, different height files (16-bit PNG) of side rows and
    width columns (side + 8 by default): smooth bumps with noise, so every
    map shadows."""
    os.makedirs(directory, exist_ok=True)
    rng = np.random.default_rng(20240611)
    y, x = np.mgrid[0:side, 0:width or side + 8].astype(np.float64)
    for i in range(count):
        h = 0.5 + 0.3 * np.sin(x * (0.2 + 0.01 * i)) * np.cos(y * 0.17) + 0.2 * rng.random(x.shape)
        bumpbake.write(os.path.join(directory, f"h{i:02d}.png"), h.astype(np.float32),
                       kind="height", depth=16)


def files_of(directory):
    out = {}
    for base, _, names in os.walk(directory):
        for n in names:
            with open(os.path.join(base, n), "rb") as f:
                out[os.path.relpath(os.path.join(base, n), directory)] = f.read()
    return out


def test_a_batch_is_the_cli_batch_and_a_rerun_bakes_nothing(tmp_path, monkeypatch, client,
                                                            cli):
    monkeypatch.chdir(tmp_path)
    heights("heights", 40)
    maps = ("normal", "ssbump", "ao")
    reports = bumpbake.dask.bake_files("heights", "out", client=client, maps=maps, scale=SCALE,
                                       rays=64, chunk_size=3, depfile="dask.d")
    assert [r.status for r in reports] == ["baked"] * 40
    assert [os.path.basename(r.input) for r in reports] == [f"h{i:02d}.png" for i in range(40)]
    assert reports[7].outputs == {k: f"out/h07_{k}.png" for k in maps}
    # the chunks ran on both workers: a worker's horizons count, each
    assert {r.slices for r in reports} == {8} and all(r.threads == 1 for r in reports)
    os.rename("out", "out_dask")

    job = bumpbake.BakeJob("heights", "out", maps=maps, scale=SCALE, rays=64)
    options = shlex.split(job.command_text(0))[3:]
    assert options == ["--scale", "16", "--rays", "64", "--out-dir", "out"]
    cli("bake", "heights", *options)  # as typed: -q, --depfile would be recorded too
    ours, theirs = files_of("out_dask"), files_of("out")
    assert len(ours) == 120 and sorted(ours) == sorted(theirs)
    assert not [n for n in ours if ours[n] != theirs[n]], "not byte-identical to the CLI batch"
    cli("bake", "heights", *options, "--depfile", "cli.d")  # up to date: the depfile alone
    assert files_of("out") == theirs
    with open("dask.d", "rb") as a, open("cli.d", "rb") as b:
        assert a.read() == b.read()

    # A re-run, by the cluster or by the CLI, bakes nothing.
    again = bumpbake.dask.bake_files("heights", "out", client=client, maps=maps, scale=SCALE,
                                     rays=64, chunk_size=3)
    assert {r.status for r in again} == {"up to date"}
    assert files_of("out") == theirs
    # one input changed: that one alone is baked again
    heights("changed", 1)
    os.replace("changed/h00.png", "heights/h13.png")
    again = bumpbake.dask.bake_files("heights", "out", client=client, maps=maps, scale=SCALE,
                                     rays=64)
    assert [i for i, r in enumerate(again) if r.status == "baked"] == [13]
    assert not [p for p in os.listdir("out") if p.startswith(".bb-tmp-")]


def test_a_clash_across_chunks_is_refused_before_any_bake(tmp_path, monkeypatch, client):
    monkeypatch.chdir(tmp_path)
    heights("heights", 40)
    # heights/a.png and more/a.png both give out/a_ao.png: the first input
    # and the last, a chunk apart and more
    os.replace("heights/h00.png", "heights/a.png")
    os.makedirs("more")
    os.replace("heights/h39.png", "more/a.png")
    with pytest.raises(bumpbake.ArgumentError, match="would both be written to out/a_ao.png"):
        bumpbake.dask.bake_files(["heights", "more"], "out", client=client, maps="ao",
                                 scale=SCALE, chunk_size=1)
    assert not os.path.exists("out") or not os.listdir("out"), "nothing is baked"


def test_a_failure_stops_the_batch_unless_keep_going(tmp_path, monkeypatch, client):
    monkeypatch.chdir(tmp_path)
    heights("heights", 12)
    with open("heights/h05.png", "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n not really")
    with pytest.raises(bumpbake.Error, match="h05.png") as e:
        bumpbake.dask.bake_files("heights", "out", client=client, maps="normal", scale=SCALE,
                                 chunk_size=1)
    statuses = [r.status for r in e.value.reports]
    assert statuses[5] == "failed" and e.value.reports[5].error_status == "bad image format"
    assert statuses[:5] == ["baked"] * 5, "inputs before the failure run, as in the CLI"
    assert "not run" in statuses[6:], "the batch stopped"
    assert set(statuses[6:]) <= {"baked", "not run"}
    reports = bumpbake.dask.bake_files("heights", "out", client=client, maps="normal",
                                       scale=SCALE, keep_going=True, check=False)
    assert [r.status == "failed" for r in reports] == [i == 5 for i in range(12)]
    assert all(r.ok for i, r in enumerate(reports) if i != 5)


def test_a_batch_over_leaves_nothing_for_dask_to_run_again(tmp_path, monkeypatch, client):
    """A failed batch's exception keeps its frame; the chunks' futures must
    not live on in it: Dask runs a held future's task again when the worker
    holding its result is lost, and such a chunk, its batch's stop variable
    deleted, waited for it for ever (a later batch hung behind it). A chunk
    run after its batch is over does nothing."""
    from bumpbake.dask import _batch, _shared
    monkeypatch.chdir(tmp_path)
    heights("heights", 6)
    with open("heights/h02.png", "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n not really")
    with pytest.raises(bumpbake.Error) as e:
        bumpbake.dask.bake_files("heights", "out", client=client, maps="normal", scale=SCALE,
                                 chunk_size=1)
    assert e.value.__traceback__ is not None

    def chunks(dask_scheduler):
        return [k for k in dask_scheduler.tasks if str(k).startswith("bumpbake-chunk-")]

    deadline = time.monotonic() + 120  # a hang guard, not a bound on time
    while client.run_on_scheduler(chunks):
        assert time.monotonic() < deadline, client.run_on_scheduler(chunks)
        time.sleep(0.05)

    monkeypatch.setattr(_shared, "_VARIABLE_WAIT", 0.2)
    args = dict(bumpbake.BakeJob("heights", "out", maps="normal", scale=SCALE)._args,
                keep_going=True, depfile=None)
    done = []
    run = threading.Thread(target=lambda: done.append(_batch._bake_chunk(
        os.getcwd(), ["heights/h00.png"], [0], args, _batch._Stop("bumpbake-stop-gone"), True)))
    run.start()
    run.join(timeout=120)  # a hang guard
    assert done == [[(0, None)]], "a chunk of a batch that is over waits or bakes"


CASES = [  # (addressing, slices, basis): each at a size that is no power of two
    ("periodic", 8, "hl2"),
    ("clamp", 16, "dirs:6"),
    ("periodic", 16, "dirs:6"),
    ("clamp", 8, "hl2"),
    # vectors, which no option spells: set on each worker's command too
    ("clamp", 6, ((0.6, 0.0, 0.8), (0.0, 0.6, 0.8), (-0.6, 0.0, 0.8), (0.0, -0.6, 0.8))),
]


@pytest.mark.parametrize("addressing, slices, basis", CASES)
def test_one_map_split_over_the_workers_is_the_single_bake(tmp_path, monkeypatch, client,
                                                           addressing, slices, basis):
    monkeypatch.chdir(tmp_path)
    heights("in", 1, side=61)  # 69 x 61
    os.replace("in/h00.png", "in/map.png")
    outputs = {k: f"map_{k}.exr" for k in bumpbake.OUTPUTS}
    options = dict(scale=SCALE, slices=slices, basis=basis, clamp=addressing == "clamp")
    os.makedirs("single")
    os.makedirs("split")
    os.symlink("../in", "single/in")
    os.symlink("../in", "split/in")
    monkeypatch.chdir(tmp_path / "split")
    report = bumpbake.dask.bake_big("in/map.png", outputs, client=client, **options)
    assert report.status == "baked" and report.slices == slices
    c = report.cluster
    assert c["slices"] == slices and c["tasks"] == slices // 2
    assert sum(c["slices_by_worker"].values()) == slices
    assert c["bytes_received"] == slices * 69 * 61 * 4
    # each group is counted on the worker that traced it; what moved is
    # what the other worker traced (the driver's own are taken from its
    # memory)
    assert set(c["slices_by_worker"]) <= set(client.nthreads()) and c["driver"] in client.nthreads()
    assert c["bytes_moved"] == (slices - c["slices_by_worker"].get(c["driver"], 0)) * 69 * 61 * 4
    assert 0 <= c["seconds_adding"] <= c["seconds_trace"] <= c["seconds_driver"]
    monkeypatch.chdir(tmp_path / "single")
    single = bumpbake.bake_file("in/map.png", outputs, **options)
    assert single.status == "baked"
    a, b = files_of(tmp_path / "single"), files_of(tmp_path / "split")
    assert sorted(a) == sorted(b) and len(a) == len(bumpbake.OUTPUTS)  # in/ is a link
    assert not [n for n in a if a[n] != b[n]], "the split bake's bits differ"
    # the pixels are not flat: a test that can fail
    ao = bumpbake.read("map_ao.exr")
    assert ao.min() < 0.9 and ao.max() == 1.0


def test_split_bake_is_the_cli_bake(tmp_path, monkeypatch, client, cli):
    """The CLI typed as command_text spells it writes the same bytes."""
    monkeypatch.chdir(tmp_path)
    heights(".", 1, side=50)
    report = bumpbake.dask.bake_big("h00.png", {"ssbump": "s.png", "ao": "a.png"},
                                    client=client, scale=SCALE, slices=8, clamp=True)
    split = files_of(".")
    command = bumpbake.BakeJob("h00.png", outputs={"ssbump": "s.png", "ao": "a.png"},
                               scale=SCALE, slices=8, clamp=True).command_text(0)
    assert command == "bumpbake bake h00.png --scale 16 --slices 8 --clamp --ssbump s.png --ao a.png"
    cli(*shlex.split(command)[1:])
    assert files_of(".") == split and report.status == "baked"


def test_a_worker_killed_in_the_middle_of_a_batch(tmp_path, monkeypatch, client, cli):
    """SIGKILL to a worker busy with a chunk: Dask runs the chunk again on
    a worker that is left (the nanny restarts the killed one); the batch
    completes with the CLI's bytes and leaves no temporary behind."""
    monkeypatch.chdir(tmp_path)
    heights("heights", 40, side=120)
    killed = []

    def kill_a_busy_worker(done, total):
        # twice: once early, once when the restarted worker is busy again;
        # six maps an input, so a kill often lands in a write
        if len(killed) >= 2 or done < 6 + 14 * len(killed):
            return False
        pids = client.run(os.getpid)
        for address, tasks in client.processing().items():
            if tasks and address in pids:
                os.kill(pids[address], signal.SIGKILL)
                killed.append(address)
                break
        return False

    reports = bumpbake.dask.bake_files("heights", "out", client=client, maps=bumpbake.OUTPUTS,
                                       scale=SCALE, rays=16, chunk_size=2,
                                       progress=kill_a_busy_worker)
    assert killed, "no worker was busy to be killed"
    assert all(r.ok for r in reports) and len(reports) == 40
    assert not [p for p in os.listdir("out") if p.startswith(".bb-tmp-")]
    os.rename("out", "out_dask")
    cli("bake", "heights", "--scale", "16", "--rays", "16", "--out-dir", "out", "--maps",
        ",".join(bumpbake.OUTPUTS))
    assert files_of("out_dask") == files_of("out")
    client.wait_for_workers(2, timeout=60)  # the nanny brought it back


def test_the_cli_with_a_scheduler_runs_the_same_code(tmp_path, monkeypatch, client, cli):
    """`bumpbake bake ... --scheduler ADDRESS` (the C program checks and
    plans the command, then hands it to bumpbake.dask): a batch and a
    single map, each the bytes of the same command without --scheduler,
    options that do not change the output (-q, --json, --force, --depfile)
    included: the files record the command as the CLI does."""
    monkeypatch.chdir(tmp_path)
    heights("heights", 6)
    address = client.scheduler.address
    batch = ["bake", "heights", "--scale", "16", "--rays", "16", "--out-dir", "out", "--maps",
             "normal,ao"]
    out = cli(*batch[:2], "--scheduler", address, *batch[2:])
    assert out.stdout.splitlines()[-1] == "bake: 6 files: 6 baked, 0 up to date, 0 failed"
    assert "wrote ao out/h03_ao.png" in out.stdout
    os.rename("out", "out_dask")
    cli(*batch)
    assert files_of("out_dask") == files_of("out")
    again = cli(*batch, "--scheduler=" + address, "--json")
    assert again.stdout.splitlines()[-1] == (
        '{"summary":{"files":6,"baked":0,"up_to_date":6,"failed":0,"not_run":0}}')
    # a baked input's JSON line is the command line's (the library's
    # lines, bb_job_report_lines): the same members, the same parameters
    lines = [json.loads(line) for line in
             (cli(*batch, "--json", "--force", *more).stdout.splitlines()[0]
              for more in (("--scheduler", address), ()))]
    for line in lines:
        del line["seconds"], line["parameters"]["threads"]
    assert lines[0] == lines[1] and lines[0]["status"] == "baked"
    quiet = batch + ["-q", "--force", "--depfile", "out.d"]
    assert cli(*quiet, "--scheduler", address).stdout == ""
    forced, depfile = files_of("out"), open("out.d").read()
    cli(*quiet)
    assert files_of("out") == forced and open("out.d").read() == depfile

    single = ["bake", "heights/h01.png", "--scale", "16", "--slices", "8", "-o", "one/m"]
    os.makedirs("one")
    cli(*single[:2], "--scheduler", address, *single[2:])
    split = files_of("one")
    assert sorted(split) == ["m_ao.png", "m_normal.png", "m_ssbump.png"]
    cli(*single)
    assert files_of("one") == split
    # usage errors are the C program's, before Python starts
    bad = cli("bake", "heights/h01.png", "heights/h02.png", "--scale", "16", "--scheduler",
              address, "-o", "x", check=False)
    assert bad.returncode == 2 and "several HEIGHT files need --out-dir DIR" in bad.stderr
    # the library's checks and plan, before Python starts: a clash, an
    # output over an input, with the CLI's words and exit codes
    clash = cli("bake", "heights", "--scale", "16", "--out-dir", "heights", "--maps", "normal",
                "--name", "h00.png", "--scheduler", "tcp://127.0.0.1:1", check=False)
    assert clash.returncode == 1 and "would overwrite the input" in clash.stderr
    # what the library bakes, the cluster bakes: inter-reflection, a batch
    # and one split map, the bytes of one machine
    for args, d in ((["heights", "--out-dir", "bb", "--maps", "ao,ssbump"], "bb"),
                    (["heights/h01.png", "--ao", "b/a.png", "--ssbump", "b/s.png"], "b")):
        bounce = ["bake", *args, "--scale", "16", "--slices", "4", "--bounce", "0.5"]
        os.makedirs(d, exist_ok=True)
        cli(*bounce, "--scheduler", address)
        os.rename(d, d + "_dask")
        os.makedirs(d)
        cli(*bounce)
        assert files_of(d + "_dask") == files_of(d) and len(files_of(d)) in (2, 12)


def test_the_cli_with_a_scheduler_imports_nothing_from_the_working_directory(
        tmp_path, monkeypatch, client, cli):
    """`python3 -m bumpbake.dask` put the working directory first on
    sys.path: a numpy.py, distributed/ or bumpbake/ in the directory being
    baked ran (a stub exiting 0 gave exit 0 and nothing written). Python now
    runs isolated, with the package's own directory on its path alone; an
    empty PYTHONPATH entry (the current directory, to Python) changes
    nothing."""
    monkeypatch.chdir(tmp_path)
    heights(".", 1)
    stub = f"open({str(tmp_path / 'RAN')!r}, 'a').write(__name__ + '\\n')\nraise SystemExit(0)\n"
    for name in ("numpy.py", "distributed/__init__.py", "bumpbake/__init__.py",
                 "bumpbake/dask/__init__.py", "runpy.py"):
        os.makedirs(os.path.dirname(name) or ".", exist_ok=True)
        with open(name, "w") as f:
            f.write(stub)
    monkeypatch.setenv("PYTHONPATH", ":")
    monkeypatch.setenv("BUMPBAKE_PYTHONPATH", "::")
    out = cli("bake", "h00.png", "--scale", "16", "--slices", "4", "--normal", "n.png",
              "--scheduler", client.scheduler.address, check=False)
    assert not os.path.exists("RAN"), open("RAN").read()
    assert out.returncode == 0, out.stderr
    assert os.path.exists("n.png")


def test_a_big_bake_its_client_gives_up_writes_nothing(tmp_path, monkeypatch, client, cli):
    """Ctrl-C on `bake MAP -o PREFIX --scheduler ADDRESS` while the slices
    are out: a running task cannot be killed, so the driver is told (a
    distributed.Variable) and stops at its next group of slices; no output
    is written and nothing of the bake goes on running on the workers."""
    monkeypatch.chdir(tmp_path)
    heights(".", 1, side=640)  # 648 x 640, 32 tasks of two slices: a few seconds
    bake = cli.start("bake", "h00.png", "--scale", "16", "--slices", "64", "-o", "m",
                     "--scheduler", client.scheduler.address)

    def running():  # keys of bumpbake's tasks running on the workers, seceded ones too
        return [k for keys in client.run(lambda dask_worker: list(
            dask_worker.active_threads.values())).values() for k in keys
            if "bumpbake-" in str(k)]

    deadline = time.monotonic() + 180  # a hang guard, not a bound on time
    while not any("bumpbake-horizons" in str(k) for k in running()):
        assert bake.poll() is None, bake.communicate()
        assert time.monotonic() < deadline, "the slices never went out"
        time.sleep(0.02)
    bake.send_signal(signal.SIGINT)
    _, err = bake.communicate(timeout=180)
    assert bake.returncode == 130, err
    while running():
        assert time.monotonic() < deadline, f"still running: {running()}"
        time.sleep(0.05)
    assert sorted(os.listdir(".")) == ["h00.png"], "an output was written"


def test_a_handed_over_command_is_the_command(tmp_path, monkeypatch):
    """The hand-over (bb_command_handover, bb_command_from_handover) sets
    every option of bake again from the text it was set from: the command
    read back spells every option as the one handed over; a chunk's inputs
    replace the batch's; what is not a hand-over is refused."""
    from bumpbake._common import _check, _ffi, _lib, _text
    from bumpbake._command import Command
    from bumpbake.dask._command import CommandJob
    monkeypatch.chdir(tmp_path)
    heights("heights", 2)
    with open("basis.txt", "w") as f:
        f.write("1 0 0.5\n-0.5 0.8 0.5\n-0.5 -0.8 0.5\n")
    err = _ffi.new("bb_error *")
    out = _ffi.new("bb_command **")
    _check(_lib.bb_command_new(b"bake", out, err), err)
    c = _ffi.gc(out[0], _lib.bb_command_free)
    given = {"scale": "12.5", "slices": "6", "filter-radius": "2", "filter-threshold": "0.01",
             "bias": "0.3", "power": "1.5", "basis": "basis.txt", "normal-filter": "sobel",
             "normal-y": "up", "threads": "2", "clamp": None, "channel": "r", "depth": "16",
             "mips": None, "bounce": "0.25", "bounces": "3", "out-dir": "out",
             "maps": "normal,ao", "name": "{kind}/{stem}.tif", "keep-going": None,
             "force": None, "depfile": "o.d", "json": None, "quiet": None,
             "scheduler": "tcp://h:1"}
    for name, text in given.items():
        _check(_lib.bb_command_set(c, name.encode(), text.encode() if text else _ffi.NULL,
                                   err), err)
    _check(_lib.bb_command_add_input(c, b"heights", err), err)
    _check(_lib.bb_command_set_record(c, _ffi.NULL, b"bumpbake bake heights ...",
                                      b"--scale 12.5", err), err)
    _check(_lib.bb_command_check(c, err), err)
    size = _ffi.new("size_t *")
    data = _lib.bb_command_handover(c, size)
    handed = bytes(_ffi.buffer(data, size[0]))
    _lib.free(data)

    def spelled(command):
        text = _lib.bb_command_text(command, _ffi.NULL, 0)
        try:
            return _text(text)
        finally:
            _lib.free(text)

    back = Command.from_handover(handed)
    assert spelled(back.handle) == spelled(c)
    assert all(_lib.bb_command_given(back.handle, n.encode()) for n in given)
    assert back.value("json") == "1" and back.value("quiet") == "1"  # the printer's, too
    assert back.value("scheduler") == "tcp://h:1"
    chunk = Command.from_handover(handed, ["heights/h01.png"])
    assert spelled(chunk.handle).startswith("bumpbake bake heights/h01.png --scale 12.5")
    job = CommandJob(handed, ["heights/h01.png"], notes="ignore")
    assert job.inputs == ["heights/h01.png"]
    assert job.report(0).outputs == {"normal": "out/normal/h01.tif", "ao": "out/ao/h01.tif"}
    for bad in (b"", b"bake\0", handed[:-4], handed.replace(b"input\0", b"inpux\0")):
        with pytest.raises(bumpbake.ArgumentError, match="hand-over"):
            Command.from_handover(bad)


def test_engine_textures_on_a_cluster_are_the_cli_bytes(tmp_path, monkeypatch, client, cli):
    """.vtf and .dds outputs with their settings and a Source material,
    through `bake --scheduler` (a batch and a split single map) and
    through bake_files: the bytes of the same command on one machine."""
    monkeypatch.chdir(tmp_path)
    heights("heights", 4, side=32, width=64)  # Source textures: powers of two
    address = client.scheduler.address
    batch = ["bake", "heights", "--scale", "16", "--slices", "8", "--out-dir", "out", "--maps",
             "normal,ssbump", "--name", "{stem}_{kind}.vtf", "--vtf-version", "7.3",
             "--texture-format", "dxt5", "--vtf-flags", "0x4"]
    out = cli(*batch, "--scheduler", address)
    assert "wrote ssbump out/h02_ssbump.vtf" in out.stdout
    os.rename("out", "out_dask")
    cli(*batch)
    ours, theirs = files_of("out_dask"), files_of("out")
    assert sorted(ours) == sorted(theirs) and len(ours) == 8
    assert not [n for n in ours if ours[n] != theirs[n]], "not the CLI batch's bytes"
    assert b"bumpbake" in ours["h02_ssbump.vtf"], "7.3 keeps the provenance"

    # the Python API, typed as command_text spells it
    shutil.rmtree("out")
    options = dict(scale=SCALE, slices=8, maps=("normal", "ssbump"), name="{stem}_{kind}.vtf",
                   vtf_version="7.3", texture_format="dxt5", vtf_flags=4, nomip=True)
    bumpbake.dask.bake_files("heights", "out", client=client, **options)
    command = bumpbake.BakeJob("heights", "out", **options).command_text(0)
    # the format by its first name (bc3 is dxt5), as bb__texture_format_name spells it
    assert command.endswith("--texture-format bc3 --vtf-version 7.3 --vtf-flags 0x4 --nomip")
    os.rename("out", "out_api")
    cli("bake", "heights", *shlex.split(command)[3:])
    assert files_of("out_api") == files_of("out")

    # one map split over the workers: a .vtf, a .dds and the material
    os.makedirs("materials/rock")
    single = ["bake", "heights/h01.png", "--scale", "16", "--slices", "8", "--ssbump",
              "materials/rock/m_ssbump.vtf", "--normal", "materials/rock/m_normal.dds",
              "--vtf-version", "7.4", "--vmt", "materials/rock/m.vmt"]
    out = cli(*single, "--scheduler", address)
    assert "wrote material materials/rock/m.vmt" in out.stdout
    split = files_of("materials")
    assert sorted(split) == ["rock/m.vmt", "rock/m_normal.dds", "rock/m_ssbump.vtf"]
    assert b'"$bumpmap" "rock/m_ssbump"' in split["rock/m.vmt"]
    shutil.rmtree("materials")
    os.makedirs("materials/rock")
    cli(*single)
    assert files_of("materials") == split


def _idle(client):
    """Waits until no task of bumpbake's runs or waits on the cluster."""
    deadline = time.monotonic() + 600  # a hang guard, not a bound on time
    while any(client.processing().values()):
        assert time.monotonic() < deadline, client.processing()
        time.sleep(0.05)


def test_a_note_made_an_error_writes_nothing(tmp_path, monkeypatch, client):
    """A note the caller makes an error (a warnings filter, a notes callable
    that raises) means nothing of its input is written, on the cluster as
    in bake_file: the worker that read the input asks the client before
    writing, the client raises, and that input is cancelled. The batch then
    stops as when the client gives up: nothing starts after it."""
    from bumpbake import NoteWarning
    monkeypatch.chdir(tmp_path)
    heights("heights", 3)  # 16-bit: no note at scale 64
    h = bumpbake.read("heights/h01.png")
    os.remove("heights/h01.png")
    bumpbake.write("heights/h01.png", h, kind="height", depth=8)  # 8 bits at 64: terraces

    def noted_input_written(out):
        _idle(client)
        return [n for n in os.listdir(out) if n.startswith("h01")] if os.path.isdir(out) else []

    with warnings.catch_warnings():
        warnings.simplefilter("error", NoteWarning)
        with pytest.raises(NoteWarning, match="8-bit heights"):
            bumpbake.dask.bake_files("heights", "a", client=client, scale=64, slices=4,
                                     maps="ao", keep_going=True)
        assert noted_input_written("a") == []
        with pytest.raises(NoteWarning, match="8-bit heights"):
            bumpbake.dask.bake_big("heights/h01.png", {"ao": "big_ao.png"}, client=client,
                                   scale=64, slices=4)
        _idle(client)
        assert not os.path.exists("big_ao.png")

    def refuse(line):
        raise RuntimeError(f"refused: {line}")

    with pytest.raises(RuntimeError, match="refused: heights/h01.png: 8-bit"):
        bumpbake.dask.bake_files("heights", "b", client=client, scale=64, slices=4,
                                 maps="ao", notes=refuse, chunk_size=1)
    assert noted_input_written("b") == []
    with pytest.raises(RuntimeError, match="refused"):
        bumpbake.dask.bake_big("heights/h01.png", {"ao": "big_ao.png"}, client=client,
                               scale=64, slices=4, notes=refuse)
    _idle(client)
    assert not os.path.exists("big_ao.png")

    # a note that stays a note: every file, the note given once
    seen = []
    reports = bumpbake.dask.bake_files("heights", "c", client=client, scale=64, slices=4,
                                       maps="ao", notes=seen.append)
    assert [r.status for r in reports] == ["baked"] * 3
    assert len(seen) == 1 and seen[0].startswith("heights/h01.png: 8-bit")
    with pytest.warns(NoteWarning, match="8-bit heights"):
        bumpbake.dask.bake_big("heights/h01.png", {"ao": "big_ao.png"}, client=client,
                               scale=64, slices=4)
    assert os.path.exists("big_ao.png")


def test_a_forced_batch_with_a_depfile_is_baked_once(tmp_path, monkeypatch, client):
    """The depfile is the client's: it learns what the workers baked by
    finding each input up to date. With force, its job baked every input
    a second time, on the client."""
    monkeypatch.chdir(tmp_path)
    heights("heights", 3)
    on_the_client = []
    run = bumpbake.BakeJob.run

    def counted(self, i, progress=None):
        report = run(self, i, progress)
        on_the_client.append(report.status)
        return report

    monkeypatch.setattr(bumpbake.BakeJob, "run", counted)
    reports = bumpbake.dask.bake_files("heights", "out", client=client, scale=SCALE, slices=4,
                                       maps="ao", force=True, depfile="out.d")
    assert [r.status for r in reports] == ["baked"] * 3
    assert on_the_client == ["up to date"] * 3
    assert open("out.d").read().count(": heights/h0") == 3


def test_the_command_lines_forced_batch_with_a_depfile_is_baked_once(tmp_path, monkeypatch,
                                                                     client):
    """The same for `bumpbake bake --scheduler --force --depfile`: the
    client's depfile job is the handed-over command without --force (a
    flag set to "0"), so it finds each input the workers baked up to date
    rather than baking it again."""
    from bumpbake._common import _check, _ffi, _lib
    from bumpbake._command import Command
    monkeypatch.chdir(tmp_path)
    heights("heights", 3)
    err = _ffi.new("bb_error *")
    out = _ffi.new("bb_command **")
    _check(_lib.bb_command_new(b"bake", out, err), err)
    c = _ffi.gc(out[0], _lib.bb_command_free)
    for name, text in {"scale": str(SCALE), "slices": "4", "out-dir": "out", "maps": "ao",
                       "force": None, "depfile": "out.d"}.items():
        _check(_lib.bb_command_set(c, name.encode(), text.encode() if text else _ffi.NULL,
                                   err), err)
    _check(_lib.bb_command_add_input(c, b"heights", err), err)
    _check(_lib.bb_command_set_record(c, _ffi.NULL, b"bumpbake bake heights", b"", err), err)
    _check(_lib.bb_command_check(c, err), err)
    size = _ffi.new("size_t *")
    data = _lib.bb_command_handover(c, size)
    handed = bytes(_ffi.buffer(data, size[0]))
    _lib.free(data)
    on_the_client = []
    run = bumpbake.BakeJob.run

    def counted(self, i, progress=None):
        report = run(self, i, progress)
        on_the_client.append(report.status)
        return report

    monkeypatch.setattr(bumpbake.BakeJob, "run", counted)
    reports = bumpbake.dask.bake_files(None, None, client=client, check=False, notes="ignore",
                                       _command=Command.from_handover(handed), _ask_notes=False)
    assert [r.status for r in reports] == ["baked"] * 3
    assert on_the_client == ["up to date"] * 3
    assert open("out.d").read().count(": heights/h0") == 3
