"""What a failed read says through the package: the library's one line, as
the exception, and nothing on stderr (libpng used to print its own line
there, past the library, whenever a PNG was cut or damaged)."""

import os

import pytest

import bumpbake

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
FIXTURES = os.path.join(ROOT, "fixtures")


def test_a_cut_png_says_nothing_on_stderr(tmp_path, capfd):
    with open(os.path.join(FIXTURES, "rock06_128.png"), "rb") as f:
        whole = f.read()
    cut = tmp_path / "cut.png"
    cut.write_bytes(whole[: len(whole) // 2])
    with pytest.raises(bumpbake.Error, match="cut.png: corrupt or truncated image"):
        bumpbake.read(str(cut))
    assert capfd.readouterr().err == ""
