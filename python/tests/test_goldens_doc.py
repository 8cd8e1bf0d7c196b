"""docs/goldens.md's commands and CI jobs, run: its GitLab and GitHub
snippets parse as YAML, and their check commands, with the page's limits
file, run in a project laid out as the page says: pass on the goldens the
page's first command blesses, fail when a parameter changes, and leave the
JUnit file and the report folder the jobs upload."""

import os
import re
import shutil
import subprocess

import pytest

from conftest import BIN, FIXTURES, ROOT

yaml = pytest.importorskip("yaml", reason="python3-yaml is not installed")

PAGE = os.path.join(ROOT, "docs", "goldens.md")


def blocks(kind):
    text = open(PAGE).read()
    return re.findall(r"```%s\n(.*?)```" % kind, text, re.S)


@pytest.fixture
def project(tmp_path):
    """heights/ with two fixtures, limits.txt as the page writes it, and
    bumpbake on the PATH."""
    if not os.access(BIN, os.X_OK):
        pytest.skip(f"{BIN} not built")
    heights = tmp_path / "heights"
    heights.mkdir()
    for name in ("pit_65x65.png", "noise_96x80.png"):
        shutil.copy(os.path.join(FIXTURES, name), heights / name)
    limits = [b for b in blocks("text") if b.lstrip().startswith("# kind or pattern")]
    assert len(limits) == 1
    (tmp_path / "limits.txt").write_text(limits[0])
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    os.symlink(os.path.abspath(BIN), bin_dir / "bumpbake")
    env = dict(os.environ, PATH=f"{bin_dir}{os.pathsep}{os.environ['PATH']}")

    def sh(command):
        return subprocess.run(["bash", "-c", command], cwd=tmp_path, env=env,
                              capture_output=True, text=True)
    return tmp_path, sh


def ci_commands():
    """The check commands of the GitLab job's script and the GitHub job's
    steps, as the runners hand them to a shell."""
    gitlab, github = (yaml.safe_load(b) for b in blocks("yaml"))
    gitlab_script = gitlab["goldens"]["script"]
    steps = github["jobs"]["goldens"]["steps"]
    github_runs = [s["run"] for s in steps if s.get("name") == "check the goldens"]
    assert gitlab["goldens"]["artifacts"]["reports"]["junit"] == "check.xml"
    assert any(s.get("uses", "").startswith("mikepenz/action-junit-report") for s in steps)
    return [("gitlab", c) for c in gitlab_script] + [("github", c) for c in github_runs]


def test_the_jobs_pass_on_blessed_goldens_and_fail_on_a_change(project):
    path, sh = project
    bless = next(line for block in blocks("sh") for line in block.splitlines()
                 if line.startswith("bumpbake check") and "--update" in line)
    done = sh(bless)
    assert done.returncode == 0, done.stdout + done.stderr
    assert len(os.listdir(path / "goldens")) == 6
    commands = ci_commands()
    assert len(commands) == 2
    for ci, command in commands:
        assert command.startswith("bumpbake check goldens heights --bake"), (ci, command)
        for report in ("check.xml", "check-report"):
            shutil.rmtree(path / report, ignore_errors=True)
            if (path / report).exists():
                os.remove(path / report)
        run = sh(command)
        assert run.returncode == 0, (ci, run.stdout, run.stderr)
        assert (path / "check.xml").exists() and (path / "check-report" / "index.html").exists()
        changed = sh(command.replace("--scale 32", "--scale 33"))
        assert changed.returncode == 2, (ci, changed.stdout)
        assert "scale: 32 -> 33" in changed.stdout
