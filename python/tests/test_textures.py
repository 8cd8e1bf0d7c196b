"""Engine textures from Python: write() and the bakes of files give .vtf
and .dds files whose headers say what was asked (read back by info() and
bb__vtf_read_info), whose pixels read() gives back within the block codec's
error (DDS through OpenImageIO, VTF and float DDS through bumpbake's own
reader), the command line's bytes and up-to-date decisions, and the
library's refusals."""

import dataclasses
import json
import os
import shlex
import shutil

import numpy as np
import pytest

import bumpbake
from conftest import FIXTURES

SSBUMP, NORMAL = bumpbake._lib.BB_VTF_FLAG_SSBUMP, bumpbake._lib.BB_VTF_FLAG_NORMAL
NOMIP, NOLOD = bumpbake._lib.BB_VTF_FLAG_NOMIP, bumpbake._lib.BB_VTF_FLAG_NOLOD
DXT1, BGR888 = 13, 3  # Valve's IMAGE_FORMAT_* codes


@pytest.fixture(scope="module")
def rock():
    """rock06 at 128 x 128, scale 32: the float maps."""
    h = bumpbake.read(os.path.join(FIXTURES, "rock06_128.png"))
    return bumpbake.bake(h, 32, rays=16, outputs=("normal", "ssbump", "ao"))


def level_sizes(side, block):
    """Bytes of each level of a square texture, largest first: 4 x 4 blocks
    of `block` bytes."""
    out = []
    while True:
        out.append(max(1, (side + 3) // 4) ** 2 * block)
        if side == 1:
            return out
        side //= 2


# ------------------------------------------------------------------- VTF

def test_a_vtf_header_says_what_was_written(tmp_path, rock):
    path = tmp_path / "rock-ssbump.vtf"
    bumpbake.write(path, rock["ssbump"], kind="ssbump")
    i = bumpbake.info(path)
    assert (i.format, i.width, i.height) == ("vtf", 128, 128)
    v = i.vtf
    # Valve's ssbump: DXT1, the full chain, exactly the SSBUMP flag, bump scale 1.
    assert (v.version, v.header_size, v.format, v.format_name) == ("7.2", 80, DXT1, "DXT1")
    assert v.flags == SSBUMP and v.flag_names == ["SSBUMP"]
    assert v.mip_count == 8 and (v.frames, v.depth, v.bump_scale) == (1, 1, 1.0)
    assert (v.low_res_format, v.low_res_width, v.low_res_height) == (DXT1, 16, 16)
    assert v.data_size == sum(level_sizes(128, 8))
    # Header, the 16 x 16 DXT1 low-resolution image, the levels: nothing else.
    assert os.path.getsize(path) == 80 + 16 * 8 + v.data_size
    # Reflectivity: the mean of (code / 255)^2.2 per channel of the top level.
    codes = np.clip(np.floor(rock["ssbump"] * 255 + 0.5), 0, 255) / 255
    np.testing.assert_allclose(v.reflectivity, (codes ** 2.2).mean(axis=(0, 1)), atol=2e-3)
    # 7.2 has no room for provenance.
    assert i.provenance_class == "none"


def test_vtf_settings_reach_the_file(tmp_path, rock):
    path = tmp_path / "n.vtf"
    bumpbake.write(path, rock["normal"], kind="normal", vtf_version="7.3", nomip=True,
                   vtf_flags="0x4", description="made=here")
    v = bumpbake.info(path).vtf
    assert v.version == "7.3" and v.resource_count >= 2 and v.header_size > 80
    assert v.flags == NORMAL | NOMIP | NOLOD | 0x4
    assert v.flag_names == ["CLAMPS", "NORMAL", "NOMIP", "NOLOD"]
    assert v.mip_count == 1 and v.data_size == level_sizes(128, 8)[0]
    # 7.3 keeps the description, with the texture's settings added.
    lines = bumpbake.info(path).description.splitlines()
    assert lines[0] == "made=here" and "texture=vtf" in lines and "vtf_version=7.3" in lines
    assert "texture_mips=0" in lines and "vtf_flags=0x00000004" in lines

    bumpbake.write(path, rock["ssbump"], kind="ssbump", texture_format="bgr888",
                   vtf_version=5, fast_compression=True, description="made=here")
    v = bumpbake.info(path).vtf
    assert (v.version, v.format, v.format_name) == ("7.5", BGR888, "BGR888")
    assert v.data_size == sum(s * s * 3 for s in (128, 64, 32, 16, 8, 4, 2, 1))
    assert "texture_fit=range" in bumpbake.info(path).description.splitlines()

    # Plain maps get no flag; colour with alpha gets DXT5 and EIGHTBITALPHA.
    bumpbake.write(path, rock["ao"], kind="ao")
    assert bumpbake.info(path).vtf.flags == 0
    rgba = np.dstack([rock["ssbump"], rock["ao"]])
    bumpbake.write(path, rgba)
    v = bumpbake.info(path).vtf
    assert (v.format_name, v.flags) == ("DXT5", bumpbake._lib.BB_VTF_FLAG_EIGHTBITALPHA)


# ------------------------------------------------------------------- DDS

def angles(decoded, normals):
    """Degrees between decoded (renormalised) and true normals."""
    n = bumpbake.decode_normals(decoded[..., :3])
    return np.degrees(np.arccos(np.clip((n * normals).sum(axis=-1), -1, 1)))


def codes_error(decoded, reference):
    """(PSNR in dB, worst error) in 8-bit codes."""
    e = (decoded - reference) * 255
    return 10 * np.log10(255 ** 2 / np.mean(e * e)), np.abs(e).max()


def test_dds_read_back_through_openimageio(tmp_path, rock):
    """read() decodes the DDS write() made within the block codec's error
    (bounds a little above what libsquish's cluster fit, the codec once,
    gave on this 128 x 128 rock at scale 32, far steeper than rock06 at
    1024: bumpbake's own fits it better)."""
    n = rock["normal"]
    path = tmp_path / "n.dds"
    bumpbake.write(path, n, kind="normal")  # BC5: x and y, z rebuilt by the reader
    assert os.path.getsize(path) == 128 + sum(level_sizes(128, 16))
    bc5 = bumpbake.read(path)
    a = angles(bc5, n)
    assert a.mean() < 1.7 and a.max() < 27
    assert codes_error(bc5[..., 2], 0.5 + 0.5 * n[..., 2])[0] > 40  # z was rebuilt
    bumpbake.write(path, n, kind="normal", texture_format="bc1")
    bc1 = angles(bumpbake.read(path), n)
    assert 4 < bc1.mean() < 5.5 and bc1.mean() > 2 * a.mean()  # BC5 is the better
    bumpbake.write(path, n, kind="normal", texture_format="rgba8", nomip=True)
    assert os.path.getsize(path) == 128 + 128 * 128 * 4
    exact = angles(bumpbake.read(path), n)
    assert exact.max() < 0.4  # 8-bit rounding alone

    path = tmp_path / "s.dds"
    bumpbake.write(path, rock["ssbump"], kind="ssbump")  # BC1
    psnr, worst = codes_error(bumpbake.read(path)[..., :3], rock["ssbump"])
    assert psnr > 25 and worst < 110

    path = tmp_path / "ao.dds"
    bumpbake.write(path, rock["ao"], kind="ao")  # BC4
    ao = bumpbake.read(path)
    assert ao.shape == (128, 128)
    psnr, worst = codes_error(ao, rock["ao"])
    assert psnr > 43 and worst < 12
    bumpbake.write(path, rock["ao"], kind="ao", texture_format="rgba8")
    codes = np.floor(rock["ao"] * 255 + 0.5)
    assert np.abs(bumpbake.read(path)[..., 0] * 255 - codes).max() < 1e-3


@pytest.mark.parametrize("kind, fmt", [("normal", None), ("ao", None),
                                       ("normal", "rgba8"), ("ssbump", "rgba16f")])
def test_dds_info_is_what_the_command_line_says(tmp_path, rock, cli, kind, fmt):
    path = tmp_path / "m.dds"
    bumpbake.write(path, rock[kind], kind=kind, texture_format=fmt)
    d = bumpbake.info(path).dds
    said = json.loads(cli("info", "--json", path).stdout)["dds"]
    said["format_name"] = said.pop("format")  # as VtfInfo names it
    assert dataclasses.asdict(d) == {**said, "width": 128, "height": 128}
    assert d.pixel_flag_names and all(n.isupper() for n in d.pixel_flag_names)
    assert bumpbake.info(path).vtf is None


def test_vtf_and_float_dds_read_back(tmp_path, rock):
    """read() takes what write() made: VTF of every format (bumpbake's own
    reader, blocks decoded by the exact rules), and the float DDS
    OpenImageIO refuses; bounds as for DDS above."""
    s = rock["ssbump"]
    codes = np.floor(np.clip(s, 0, 1) * 255 + 0.5)
    path = tmp_path / "s.vtf"
    for fmt, version in (("bgr888", "7.2"), ("bgra8888", "7.5")):
        bumpbake.write(path, s, kind="ssbump", texture_format=fmt, vtf_version=version)
        back = bumpbake.read(path)
        assert back.shape == (128, 128, 3)  # no alpha flag: no alpha channel
        assert np.abs(back * 255 - codes).max() < 1e-3
    bumpbake.write(path, s, kind="ssbump")  # DXT1: the DDS's BC1 blocks
    psnr, worst = codes_error(bumpbake.read(path), s)
    assert bumpbake.info(path).channels == 3
    assert psnr > 25 and worst < 110  # 25.70 dB, 105.4 (libsquish's blocks: 25.68, 105.4)
    bumpbake.write(path, s, kind="ssbump", texture_format="rgba16f")
    assert np.abs(bumpbake.read(path) - s).max() < 2 ** -11
    path = tmp_path / "s.dds"
    bumpbake.write(path, s, kind="ssbump", texture_format="rgba32f")
    back = bumpbake.read(path)
    assert back.shape == (128, 128, 4) and (back[..., 3] == 1).all()
    assert (back[..., :3] == s.astype(np.float32)).all()


# -------------------------------------------------- the command line's bytes

def files_of(directory):
    out = {}
    for base, _, names in os.walk(directory):
        for name in names:
            path = os.path.join(base, name)
            with open(path, "rb") as f:
                out[os.path.relpath(path, directory)] = f.read()
    return out


def test_one_bake_is_the_clis_byte_for_byte(tmp_path, monkeypatch, fixtures, cli):
    """height -> name-ssbump.vtf (7.3, with provenance), name.vmt and
    name_normal.dds, from Python and from the command typed as
    command_text spells it."""
    monkeypatch.chdir(tmp_path)
    shutil.copy(os.path.join(fixtures, "rock06_128.png"), "rock.png")
    outputs = {"ssbump": "game/materials/rock/rock-ssbump.vtf",
               "normal": "game/materials/rock/rock_normal.dds"}
    settings = dict(scale=32, rays=64, vtf_version="7.3", vmt="game/materials/rock/rock.vmt")
    os.makedirs("game/materials/rock")
    job = bumpbake.BakeJob("rock.png", outputs=outputs, **settings)
    command = job.command_text(0)
    assert command == ("bumpbake bake rock.png --scale 32 --rays 64 "
                       "--normal game/materials/rock/rock_normal.dds "
                       "--ssbump game/materials/rock/rock-ssbump.vtf --vtf-version 7.3 "
                       "--vmt game/materials/rock/rock.vmt")
    report = bumpbake.bake_file("rock.png", outputs, **settings)
    assert report.outputs["material"] == "game/materials/rock/rock.vmt"
    # the blocks' compression: a part of the write, its own figure
    assert 0 < report.seconds["compress"] <= report.seconds["write"]
    png = bumpbake.bake_file("rock.png", {"ssbump": "s.png"}, scale=32, rays=64)
    assert png.seconds["compress"] == 0
    ours = files_of("game")
    shutil.rmtree("game")
    os.makedirs("game/materials/rock")
    cli(*shlex.split(command)[1:])
    theirs = files_of("game")
    assert sorted(ours) == sorted(theirs) == [
        "materials/rock/rock-ssbump.vtf", "materials/rock/rock.vmt",
        "materials/rock/rock_normal.dds"]
    assert [name for name in ours if ours[name] != theirs[name]] == []
    assert b'"$bumpmap" "rock/rock-ssbump"' in ours["materials/rock/rock.vmt"]
    assert bumpbake.info("game/materials/rock/rock-ssbump.vtf").provenance["command"] == command


def test_batches_of_textures_are_the_clis_and_only_vtf_73_is_up_to_date(
        tmp_path, monkeypatch, fixtures, cli):
    monkeypatch.chdir(tmp_path)
    os.makedirs("heights")
    for name in ("rock06_128.png", "bricks_128x64.png"):
        shutil.copy(os.path.join(fixtures, name), "heights")
    runs = {"vtf73": dict(name="{stem}_{kind}.vtf", vtf_version=3, fast_compression=True),
            "vtf72": dict(name="{stem}_{kind}.vtf", texture_format="dxt5"),
            "dds": dict(name="{stem}_{kind}.dds", nomip=True)}
    for out, settings in runs.items():
        options = dict(maps=("normal", "ssbump", "ao"), scale=8, rays=16, **settings)
        command = bumpbake.BakeJob("heights", out, **options).command_text(0)
        assert command.endswith({"vtf73": "--vtf-version 7.3 --fast-compression",
                                 "vtf72": "--texture-format bc3",
                                 "dds": "--nomip"}[out]), command
        reports = bumpbake.bake_files("heights", out, **options)
        assert [r.status for r in reports] == ["baked"] * 2
        os.rename(out, out + "_py")
        cli(*shlex.split(command)[1:2], "heights", *shlex.split(command)[3:])
        ours, theirs = files_of(out + "_py"), files_of(out)
        assert len(ours) == 6 and sorted(ours) == sorted(theirs), out
        assert [name for name in ours if ours[name] != theirs[name]] == [], out
        # Run again: a VTF 7.3 holds its provenance, the others hold none.
        again = {r.status for r in bumpbake.bake_files("heights", out, **options)}
        assert again == ({"up to date"} if out == "vtf73" else {"baked"}), out
    v = bumpbake.info("vtf72/bricks_128x64_normal.vtf").vtf
    assert (v.width, v.height, v.format_name, v.flags) == (128, 64, "DXT5", NORMAL)


# ---------------------------------------------------------------- refusals

def test_what_a_texture_cannot_hold_is_refused_before_any_work(tmp_path, fixtures, rock):
    def refused(match, call, *args, **kwargs):
        with pytest.raises(bumpbake.ArgumentError, match=match):
            call(*args, **kwargs)

    odd = np.zeros((65, 65), np.float32)
    refused(r"65 x 65: Source textures need a power of two on each side \(resize to 64 x 64\)",
            bumpbake.write, tmp_path / "o.vtf", odd)
    refused(r"66 x 66: block compression \(bc4\) needs sides that are multiples of 4",
            bumpbake.write, tmp_path / "o.dds", np.zeros((66, 66), np.float32))
    refused("VTF has no format bc5", bumpbake.write, tmp_path / "o.vtf", rock["normal"],
            kind="normal", texture_format="bc5")
    refused("format bc4 holds 1 channel, and the normal map has 3", bumpbake.write,
            tmp_path / "o.dds", rock["normal"], kind="normal", texture_format="bc4")
    refused("texture format", bumpbake.write, tmp_path / "o.dds", odd, texture_format="bc7")
    refused(r"vtf_version: VTF version must be 7.2, 7.3, 7.4 or 7.5 \(got '7.9'\)", bumpbake.write,
            tmp_path / "o.vtf", rock["ao"], vtf_version="7.9")
    refused("VTF version must be 7.2, 7.3, 7.4 or 7.5", bumpbake.write, tmp_path / "o.vtf",
            rock["ao"], vtf_version="seven")
    refused("ENVMAP flag", bumpbake.write, tmp_path / "o.vtf", rock["ao"], vtf_flags=0x4000)
    refused("32-bit number", bumpbake.write, tmp_path / "o.vtf", rock["ao"],
            vtf_flags=1 << 32)
    refused("texture format sets it", bumpbake.write, tmp_path / "o.vtf", rock["ao"], depth=16)
    assert os.listdir(tmp_path) == []

    pit = os.path.join(fixtures, "pit_65x65.png")
    refused("s.vtf: 65 x 65: Source textures need a power of two", bumpbake.bake_file, pit,
            {"ssbump": tmp_path / "s.vtf"}, scale=8)
    refused("n.dds: 65 x 65: block compression", bumpbake.bake_file, pit,
            {"normal": tmp_path / "n.dds"}, scale=8)
    refused("needs a .vtf bump map", bumpbake.bake_file, pit,
            {"ssbump": tmp_path / "s.png"}, scale=8, vmt=tmp_path / "s.vmt")
    refused("one material", bumpbake.bake_files, [pit, pit], tmp_path / "out", scale=8,
            name="{stem}_{kind}.vtf", vmt=tmp_path / "s.vmt")
    refused("give vmt=FILE", bumpbake.bake_file, pit, {"ssbump": tmp_path / "s.png"}, scale=8,
            materials=tmp_path)
    assert os.listdir(tmp_path) == []


def test_write_vmt(tmp_path):
    path = tmp_path / "game/materials/stone/wall.vmt"
    path.parent.mkdir(parents=True)
    bumpbake.write_vmt(path, path.parent / "wall-ssbump.vtf",
                       basetexture=path.parent / "wall.vtf")
    text = path.read_text()
    assert '"$basetexture" "stone/wall"' in text and '"$bumpmap" "stone/wall-ssbump"' in text
    assert '"$ssbump" "1"' in text
    bumpbake.write_vmt(path, path.parent / "wall_normal.vtf", materials=path.parent,
                       ssbump=False)
    assert '"$bumpmap" "wall_normal"' in path.read_text() and "$ssbump" not in path.read_text()
    with pytest.raises(bumpbake.ArgumentError, match="vtf"):
        bumpbake.write_vmt(path, path.parent / "wall.png")


def test_write_vmt_refuses_what_bake_vmt_refuses(tmp_path):
    """write_vmt("s.vtf", "s.vtf") turned the texture into a 103-byte
    material, and write_vmt("x.png", ...) overwrote the PNG: as `bake
    --vmt`, a material's name ends in .vmt and is no texture it names."""
    stone = tmp_path / "materials/stone"
    stone.mkdir(parents=True)
    texture, png = stone / "s.vtf", stone / "x.png"
    texture.write_bytes(b"VTF\0 a texture")
    png.write_bytes(b"a png")
    for path in (texture, png, stone / "s.vtf.txt"):
        with pytest.raises(bumpbake.ArgumentError, match="ends in .vmt"):
            bumpbake.write_vmt(path, texture)
    os.link(texture, stone / "s.vmt")
    with pytest.raises(bumpbake.ArgumentError, match="would overwrite the texture"):
        bumpbake.write_vmt(stone / "s.vmt", texture)
    assert texture.read_bytes() == b"VTF\0 a texture" and png.read_bytes() == b"a png"
    assert sorted(os.listdir(stone)) == ["s.vmt", "s.vtf", "x.png"]


def test_a_name_with_a_newline_is_refused_in_one_line(tmp_path):
    """A newline (or an escape sequence) in a path came back inside the
    message, splitting it: the library writes it as \\x0a, as the command
    line prints it."""
    materials = tmp_path / "materials"
    materials.mkdir()
    for path, bump in ((materials / "a\nb.txt", materials / "s.vtf"),
                       (materials / "x.vmt", materials / "s\nx.vtf"),
                       (materials / "x\x1b[2J.txt", materials / "s.vtf")):
        with pytest.raises(bumpbake.ArgumentError) as e:
            bumpbake.write_vmt(path, bump)
        message = str(e.value)
        assert "\n" not in message and "\x1b" not in message and message.isprintable(), message
        assert "\\x0a" in message or "\\x1b" in message, message
    assert os.listdir(materials) == []
