"""bumpbake.check: the same cases, verdicts and exit codes as `bumpbake
check`; its JUnit file read by a JUnit parser (python3-junitparser) as a CI
server reads it; the pytest plugin's assertion, update and generate path;
the cases handed between checks as a cluster's workers hand them; and on a
Dask cluster, the same cases as one process finds."""

import json
import os
import shutil
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import bumpbake
from bumpbake import _check

from conftest import FIXTURES

SCALE = 16
BAKE = dict(scale=SCALE, rays=64, maps=("normal", "ssbump", "ao"))


def bake_args(scale=SCALE):
    return ["--scale", str(scale), "--rays", "64", "--maps", "normal,ssbump,ao"]


@pytest.fixture
def suite(tmp_path, cli):
    """heights/ (two fixtures) and goldens/ they bake into."""
    heights = tmp_path / "heights"
    heights.mkdir()
    for name in ("pit_65x65.png", "noise_96x80.png"):
        shutil.copy(os.path.join(FIXTURES, name), heights / name)
    cli("bake", heights, "--out-dir", tmp_path / "goldens", *bake_args(), "-q")
    return tmp_path


def cli_cases(cli, *args):
    out = cli("check", *args, "--json", check=False)
    lines = [json.loads(line) for line in out.stdout.splitlines()]
    return out.returncode, {c["name"]: c["result"] for c in lines if "name" in c}


def test_a_bake_against_its_goldens_as_the_command_line_finds_it(suite, cli):
    r = bumpbake.check(suite / "goldens", heights=[suite / "heights"], **BAKE)
    assert r.passed and r.exit_code == 0 and len(r.cases) == 6
    assert all(c.result == "PASS" and c.max_abs == 0 for c in r.cases)
    # another scale: every map fails, naming the scale
    r = bumpbake.check(suite / "goldens", heights=[suite / "heights"], **dict(BAKE, scale=17))
    assert not r and r.exit_code == 2
    assert all(c.result == "FAILURE" and "scale: 16 -> 17" in c.provenance_diff
               for c in r.cases)
    code, cases = cli_cases(cli, suite / "goldens", suite / "heights", "--bake",
                            *bake_args(17))
    assert code == r.exit_code and cases == {c.name: c.result for c in r.cases}


def test_limits_by_kind_and_pattern(suite):
    options = dict(BAKE, scale=18)
    every = bumpbake.check(suite / "goldens", heights=[suite / "heights"], **options)
    assert len(every.failed) == 6, every.lines
    r = bumpbake.check(suite / "goldens", heights=[suite / "heights"], **options,
                       limits={"ssbump": {"fail": 1}, "ao": {"fail": 1},
                               "pit_*_ao.png": {"fail": 0}})
    failed = sorted(c.name for c in r.failed)
    assert failed == ["noise_96x80_normal.png", "pit_65x65_ao.png", "pit_65x65_normal.png"]
    assert next(c for c in r.cases if c.name == "noise_96x80_ao.png").limits["fail"] == 1
    with pytest.raises(bumpbake.ArgumentError, match="not one of idiff's limits"):
        bumpbake.check(suite / "goldens", heights=[suite / "heights"], **BAKE,
                       limits={"ao": {"scale": 1}})
    with pytest.raises(bumpbake.ArgumentError, match="is not one of idiff's limits"):
        bumpbake.check(suite / "goldens", heights=[suite / "heights"], **BAKE,
                       limits="ao: -scale 1")


def test_update_writes_only_the_goldens_that_did_not_pass(suite):
    goldens = suite / "goldens"
    before = {p.name: p.read_bytes() for p in goldens.iterdir()}
    r = bumpbake.check(goldens, heights=[suite / "heights"], **dict(BAKE, rays=81), update=True)
    assert r.passed, r.lines
    updated = sorted(c.name for c in r.cases if c.updated)
    assert updated == ["noise_96x80_ao.png", "noise_96x80_ssbump.png", "pit_65x65_ao.png",
                       "pit_65x65_ssbump.png"], r.lines
    after = {p.name: p.read_bytes() for p in goldens.iterdir()}
    assert {n for n in after if after[n] != before[n]} == set(updated)
    assert bumpbake.check(goldens, heights=[suite / "heights"], **dict(BAKE, rays=81)).passed


def test_junit_is_read_by_a_junit_parser(suite, tmp_path):
    junitparser = pytest.importorskip(
        "junitparser", reason="python3-junitparser is not installed (make deps installs it)")
    new = tmp_path / "new"
    shutil.copytree(suite / "goldens", new)
    bumpbake.bake_file(suite / "heights" / "pit_65x65.png", {"ao": new / "pit_65x65_ao.png"},
                       scale=SCALE + 1, rays=64, maps=None)
    (new / "noise_96x80_normal.png").write_bytes(b"\x89PNG\r\n\x1a\nbroken")
    os.remove(new / "noise_96x80_ssbump.png")
    shutil.copy(new / "pit_65x65_normal.png", new / "extra_normal.png")
    xml = tmp_path / "check.xml"
    r = bumpbake.check(suite / "goldens", new, junit=xml)
    assert r.exit_code == 4
    report = junitparser.JUnitXml.fromfile(str(xml))
    cases = {c.name: c for suite_ in report for c in suite_}
    assert len(cases) == 7 == len(r.cases)
    assert report.tests == 7 and report.failures == 3 and report.errors == 1

    def outcome(case):
        return [type(x).__name__ for x in case.result]
    assert outcome(cases["pit_65x65_normal.png"]) == []
    ao = cases["pit_65x65_ao.png"]
    assert outcome(ao) == ["Failure"]
    assert ao.result[0].type == "FAILURE"
    assert "max abs error" in ao.result[0].message and "scale: 16 -> 17" in ao.result[0].text
    assert ao.classname == "bumpbake.check.ao"
    assert outcome(cases["noise_96x80_normal.png"]) == ["Error"]
    assert cases["noise_96x80_ssbump.png"].result[0].type == "MISSING"
    assert cases["extra_normal.png"].result[0].type == "EXTRA"


def test_a_name_that_is_not_utf8_stays_valid_xml(tmp_path):
    junitparser = pytest.importorskip("junitparser")
    golden, new = tmp_path / "g", tmp_path / "n"
    golden.mkdir()
    new.mkdir()
    a = np.full((4, 4), 0.5, np.float32)
    for d, value in ((golden, 0.5), (new, 0.7)):
        path = os.path.join(os.fsencode(d), b"odd\xff<&>\x1b.png")
        bumpbake.write(path, a * value / 0.5, kind="ao")
    r = bumpbake.check(golden, new, junit=tmp_path / "r.xml")
    assert r.exit_code == 2
    case = next(iter(next(iter(junitparser.JUnitXml.fromfile(str(tmp_path / "r.xml"))))))
    assert case.name == "odd\\xff<&>\\x1b.png"


def test_cases_travel_between_checks(suite):
    cmd = _check.command(suite / "goldens", heights=[suite / "heights"], **dict(BAKE, scale=17))
    one = _check.Check(cmd)
    one.run(inputs=[0], rest=False)
    two = _check.Check(cmd)
    two.run(inputs=[1], rest=False)
    whole = _check.Check(cmd)
    whole.import_cases(one.export())
    whole.import_cases(two.export())
    whole.run(inputs=[], rest=True)
    alone = bumpbake.check(suite / "goldens", heights=[suite / "heights"], **dict(BAKE, scale=17))
    assert whole.result().cases == alone.cases or [
        (a.name, a.result, a.max_abs) for a in whole.result().cases] == [
        (a.name, a.result, a.max_abs) for a in alone.cases]
    with pytest.raises(bumpbake.ArgumentError, match="not the cases of a check"):
        whole.import_cases(b"junk")


# ---------------------------------------------------------- pytest plugin

PLUGIN_TEST = textwrap.dedent('''
    import bumpbake

    def test_pit_ao(tmp_path, golden):
        out = tmp_path / "ao.png"
        bumpbake.bake_file(HEIGHT, {"ao": out}, scale=SCALE, rays=64)
        golden(out, GOLDEN, fail=1 / 255)
''')


def run_pytest(directory, *args):
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        [os.path.dirname(os.path.dirname(bumpbake.__file__))] +
        os.environ.get("PYTHONPATH", "").split(os.pathsep)))
    return subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
                           "-W", "error::bumpbake.NoteWarning", *args], cwd=directory,
                          capture_output=True, text=True, env=env)


def test_the_pytest_plugin_asserts_updates_and_generates(suite, tmp_path):
    project = tmp_path / "project"
    project.mkdir()
    golden = suite / "goldens" / "pit_65x65_ao.png"
    source = PLUGIN_TEST.replace("HEIGHT", repr(str(suite / "heights" / "pit_65x65.png")))
    source = source.replace("GOLDEN", repr(str(golden)))
    (project / "conftest.py").write_text('pytest_plugins = ["bumpbake.pytest_plugin"]\n')
    (project / "test_ao.py").write_text(source.replace("SCALE", str(SCALE)))
    passed = run_pytest(project)
    assert passed.returncode == 0, passed.stdout + passed.stderr
    (project / "test_ao.py").write_text(source.replace("SCALE", str(SCALE + 1)))
    before = golden.read_bytes()
    failed = run_pytest(project)
    assert failed.returncode == 1
    assert "map does not match its golden" in failed.stdout
    assert "scale: 16 -> 17" in failed.stdout, failed.stdout
    assert golden.read_bytes() == before
    generated = tmp_path / "generated"
    done = run_pytest(project, "--bumpbake-generate-path", str(generated))
    assert done.returncode == 0 and (generated / golden.name).exists(), done.stdout + done.stderr
    assert golden.read_bytes() == before
    updated = run_pytest(project, "--bumpbake-update-goldens")
    assert updated.returncode == 0 and "GoldenUpdated" in updated.stdout, updated.stdout
    assert golden.read_bytes() != before
    assert run_pytest(project).returncode == 0


def test_the_assertion_takes_an_array_with_its_kind(tmp_path):
    from bumpbake.pytest_plugin import assert_matches_golden
    ao = np.linspace(0, 1, 64, dtype=np.float32).reshape(8, 8)
    golden = tmp_path / "ao.png"
    with pytest.raises(AssertionError, match="no golden"):
        assert_matches_golden(ao, golden, kind="ao")
    with pytest.warns(UserWarning, match="golden updated"):
        assert_matches_golden(ao, golden, kind="ao", update=True)
    assert_matches_golden(ao, golden, kind="ao")
    with pytest.raises(AssertionError, match="FAILURE"):
        assert_matches_golden(ao * 0.9, golden, kind="ao")
    assert_matches_golden(ao * 0.9, golden, kind="ao", fail=0.11)
    with pytest.raises(TypeError, match="kind="):
        assert_matches_golden(ao, golden)


# --------------------------------------------------------------- cluster

def test_a_suite_on_a_dask_cluster_is_one_process_check(suite, tmp_path, client):
    import bumpbake.dask
    options = dict(BAKE, scale=17)
    r = bumpbake.dask.check_files(suite / "goldens", [suite / "heights"], client=client,
                                  html=tmp_path / "report", junit=tmp_path / "c.xml",
                                  chunk_size=1, **options)
    alone = bumpbake.check(suite / "goldens", heights=[suite / "heights"], **options)
    assert [(c.name, c.result, c.max_abs, c.provenance_diff) for c in r.cases] == [
        (c.name, c.result, c.max_abs, c.provenance_diff) for c in alone.cases]
    assert r.exit_code == alone.exit_code == 2
    html = (tmp_path / "report" / "index.html").read_text()
    pictures = os.listdir(tmp_path / "report" / "img")
    assert all(p in html for p in pictures) and len(pictures) == 6 + 2  # strips, atlases
