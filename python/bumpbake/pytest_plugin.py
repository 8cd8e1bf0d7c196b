"""Golden maps in pytest: an assertion that a map matches its golden, and
the options to update the goldens, as pytest-mpl's for figures.

    # conftest.py
    pytest_plugins = ["bumpbake.pytest_plugin"]

    # test_maps.py
    def test_rock_normal(tmp_path, golden):
        bumpbake.bake_file("rock.png", {"normal": tmp_path / "n.png"}, scale=32)
        golden(tmp_path / "n.png", "goldens/rock_normal.png", fail=1 / 255)

`golden(new, golden_path, **limits)` (the fixture) is
assert_matches_golden with the run's options:

    pytest --bumpbake-update-goldens      a map that does not match its golden
                                          (or has none) is written over it, and
                                          only such maps; the test passes,
                                          warning what it updated
    pytest --bumpbake-generate-path DIR   every map is written to DIR under its
                                          golden's file name, nothing compared
                                          (pytest-mpl's --mpl-generate-path)

The comparison is bumpbake.check's of one file (idiff's limits as
keywords); a failure's message carries the statistics and the
provenance's differences ("scale: 32 -> 33")."""

import os
import shutil
import tempfile
import warnings

import pytest

from ._check import check
from ._files import write


class GoldenUpdated(UserWarning):
    """A golden written by --bumpbake-update-goldens."""


def _as_file(new, golden, kind, directory):
    """new as a file: a path as it is, an array written (with the library's
    writer, as the golden's format and kind quantise it) into directory."""
    if isinstance(new, (str, bytes, os.PathLike)):
        return os.fsdecode(new)
    if kind is None:
        raise TypeError("assert_matches_golden: an array needs kind= (normal, ssbump, ao, ...)")
    path = os.path.join(directory, "new" + os.path.splitext(os.fsdecode(golden))[1])
    write(path, new, kind=kind)
    return path


def assert_matches_golden(new, golden, *, update=False, generate_path=None, kind=None,
                          **limits):
    """Asserts that the map new (a file, or an array with its kind) matches
    the golden file, under idiff's limits (fail, failpercent, hardfail,
    allowfailures, warn, warnpercent, hardwarn; idiff's defaults: 1e-6):
    AssertionError with the statistics and the provenance's differences when
    it does not. A warning passes (idiff's exit 1 is not a failure here).
    update: where it does not match (or there is no golden), the golden is
    written from new and a GoldenUpdated warning says so. generate_path: new
    is written to generate_path under the golden's file name instead, and
    nothing is compared."""
    __tracebackhide__ = True
    golden = os.fsdecode(golden)
    with tempfile.TemporaryDirectory(prefix="bb-golden-") as scratch:
        path = _as_file(new, golden, kind, scratch)
        if generate_path is not None:
            os.makedirs(generate_path, exist_ok=True)
            shutil.copyfile(path, os.path.join(generate_path, os.path.basename(golden)))
            return
        if not os.path.exists(golden) and not update:
            raise AssertionError(f"{golden}: no golden (pytest --bumpbake-update-goldens "
                                 f"writes it from the map)")
        result = check(golden, path, update=update, **limits)
    case = result.cases[0]
    if case.updated:
        warnings.warn(f"{golden}: golden updated ({case.result.lower()}"
                      + (": " + "; ".join(case.provenance_diff) if case.provenance_diff else "")
                      + ")", GoldenUpdated, stacklevel=2)
        return
    if case.exit_code >= 2:
        raise AssertionError(f"map does not match its golden:\n{result.lines.rstrip()}")


# ------------------------------------------------------------ the plugin

def pytest_addoption(parser):
    group = parser.getgroup("bumpbake", "bumpbake golden maps")
    group.addoption("--bumpbake-update-goldens", action="store_true", default=False,
                    help="write the goldens of maps that do not match them (only those)")
    group.addoption("--bumpbake-generate-path", metavar="DIR", default=None,
                    help="write every map to DIR under its golden's name; compare nothing")


@pytest.fixture
def golden(request):
    """assert_matches_golden with the run's --bumpbake-* options:
    golden(new, golden_path, **limits)."""
    config = request.config
    update = config.getoption("--bumpbake-update-goldens")
    generate = config.getoption("--bumpbake-generate-path")

    def assert_golden(new, golden_path, **limits):
        __tracebackhide__ = True
        assert_matches_golden(new, golden_path, update=update, generate_path=generate,
                              **limits)
    return assert_golden
