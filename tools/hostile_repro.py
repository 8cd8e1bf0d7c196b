#!/usr/bin/env python3
"""hostile_repro.py: the file makers and checks of tools/hostile_repro.sh.

Writes the hostile files (models that name files outside their
directory or nest too deep, headers that declare huge allocations, PNGs
with hostile provenance, a float TIFF of NaN), snapshots a directory and
compares snapshots, checks printed text for control characters and JSON
for UTF-8, and plants links at a writer's temporaries (the attacker of
case 8). Standard library only (Debian's python3).

  hostile_repro.py make KIND PATH [ARGS...]
  hostile_repro.py snap DIR FILE           save DIR's names, kinds and hashes
  hostile_repro.py diff DIR FILE ALLOW     what changed since FILE, but ALLOW
  hostile_repro.py ctl FILE...             which FILEs hold control bytes
  hostile_repro.py json FILE [KEY LEN]     every line is JSON in valid UTF-8
  hostile_repro.py attack DIR TARGET SECS LOG STOP
"""
import hashlib
import json
import os
import re
import stat
import struct
import sys
import time
import zlib


# ------------------------------------------------------------------ makers


def write(path, data):
    with open(path, "wb") as f:
        f.write(data if isinstance(data, bytes) else data.encode())


def gltf_uri(path, uri):
    write(path, json.dumps({
        "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
        "buffers": [{"uri": uri, "byteLength": 36}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3,
                       "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 1]}]}))


def obj_mtllib(path, mtl):
    write(path, "mtllib %s\nv 0 0 0\nv 1 0 0\nv 1 0 1\nf 1 2 3\n" % mtl)


def deep_gltf(path, n):
    # A chain of n nodes, each the child of the one before.
    n = int(n)
    write(path, json.dumps({"asset": {"version": "2.0"}, "scene": 0,
                            "scenes": [{"nodes": [0]}],
                            "nodes": [{"children": [i + 1]} for i in range(n)] + [{}]}))


def deep_dae(path, n):
    n = int(n)
    write(path, '<?xml version="1.0"?>\n<COLLADA xmlns="http://www.collada.org/2005/11/'
          'COLLADASchema" version="1.4.1"><asset><up_axis>Y_UP</up_axis></asset>'
          '<library_visual_scenes><visual_scene id="s">' + '<node>' * n + '</node>' * n +
          '</visual_scene></library_visual_scenes><scene><instance_visual_scene url="#s"/>'
          '</scene></COLLADA>\n')


def deep_json(path, n):
    n = int(n)
    write(path, '{"asset":{"version":"2.0"},"extras":' + '[' * n + ']' * n + '}')


def faces_obj(path, n):
    write(path, "v 0 0 0\nv 1 0 0\nv 1 0 1\n" + "f 1 2 3\n" * int(n))


def flat_obj(path):
    # Two triangles in the plane y = 0, facing -y (DOOM 3's default axis).
    write(path, "v 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\nvn 0 -1 0\n"
          "f 1//1 2//1 3//1\nf 1//1 3//1 4//1\n")


def progressive_jpeg(path, w, h):
    # SOF2 of one component, a one-code Huffman table and a DC scan of zeros:
    # libjpeg buffers a progressive image whole, 2 bytes a texel.
    w, h = int(w), int(h)
    b = b"\xff\xd8" + b"\xff\xdb\x00\x43\x00" + b"\x01" * 64
    b += b"\xff\xc2\x00\x0b\x08" + struct.pack(">HH", h, w) + b"\x01\x01\x11\x00"
    b += b"\xff\xc4\x00\x14\x00\x01" + b"\x00" * 15 + b"\x00"
    b += b"\xff\xda\x00\x08\x01\x01\x00\x00\x00\x00" + b"\x00" * 8 + b"\xff\xd9"
    write(path, b)


def tiled_tiff(path, w, h, tw, th):
    entries = [(256, 4, int(w)), (257, 4, int(h)), (258, 3, 8), (259, 3, 1), (262, 3, 1),
               (277, 3, 1), (284, 3, 1), (322, 4, int(tw)), (323, 4, int(th)), (324, 4, 0),
               (325, 4, 16)]
    data = 8 + 2 + 12 * len(entries) + 4
    b = b"II*\x00" + struct.pack("<I", 8) + struct.pack("<H", len(entries))
    for tag, typ, value in entries:
        value = data if tag == 324 else value
        b += struct.pack("<HHI", tag, typ, 1)
        b += struct.pack("<HH", value, 0) if typ == 3 else struct.pack("<I", value)
    write(path, b + b"\x00" * 4 + b"\x00" * 16)


def exr_attribute(path, declared):
    # The first attribute, a string "comment", declares `declared` bytes.
    b = bytes([0x76, 0x2F, 0x31, 0x01, 2, 0, 0, 0]) + b"comment\x00string\x00"
    b += struct.pack("<I", int(declared))
    write(path, b + b"x" * (91 - len(b)))


def gif_screen(path, w, h):
    w, h = int(w), int(h)
    b = b"GIF89a" + struct.pack("<HH", w, h) + b"\x80\x00\x00" + b"\x00\x00\x00\xff\xff\xff"
    b += b"\x2c" + struct.pack("<HHHH", 0, 0, w, h) + b"\x00"
    b += b"\x02\x02\x44\x01\x00" + b"\x3b"
    write(path, b)


def vtf_header(path, w, h, fmt, mips):
    """A VTF 7.2 header alone (80 bytes, no low-resolution image) declaring
    w x h texels of Valve's format code fmt in `mips` levels."""
    b = b"VTF\x00" + struct.pack("<III", 7, 2, 80) + struct.pack("<HHIHH", int(w), int(h), 0, 1, 0)
    b += b"\x00" * 4 + struct.pack("<fff", 0.5, 0.5, 0.5) + b"\x00" * 4 + struct.pack("<f", 1.0)
    b += struct.pack("<IBIBBH", int(fmt), int(mips), 0xFFFFFFFF, 0, 0, 1)
    write(path, b + b"\x00" * (80 - len(b)))


def dds_mips(path, mips):
    """A 16 x 16 DXT1 DDS (legacy header) declaring `mips` mip levels, with
    the top level's blocks."""
    b = b"DDS " + struct.pack("<7I", 124, 0x000A1007, 16, 16, 128, 0, int(mips)) + b"\x00" * 44
    b += struct.pack("<II4s5I", 32, 4, b"DXT1", 0, 0, 0, 0, 0) + struct.pack("<5I", 0x401008, 0, 0, 0, 0)
    write(path, b + b"\x00" * 128)


def png_chunk(kind, data):
    return struct.pack(">I", len(data)) + kind + data + struct.pack(
        ">I", zlib.crc32(kind + data) & 0xffffffff)


def png_desc(path, desc_hex, size="4"):
    """A grey 8-bit PNG whose tEXt Description (bumpbake's provenance) holds
    the bytes desc_hex spells."""
    n = int(size)
    rows = b"".join(b"\x00" + bytes((x * 37 + y * 11) & 0xff for x in range(n)) for y in range(n))
    b = b"\x89PNG\r\n\x1a\n" + png_chunk(b"IHDR", struct.pack(">IIBBBBB", n, n, 8, 0, 0, 0, 0))
    b += png_chunk(b"tEXt", b"Description\x00" + bytes.fromhex(desc_hex))
    b += png_chunk(b"IDAT", zlib.compress(rows)) + png_chunk(b"IEND", b"")
    write(path, b)


def nan_tiff(path):
    """A 4 x 4 one-channel float TIFF, every other texel NaN."""
    n = 4
    pixels = b"".join(struct.pack("<f", float("nan") if (i % 2) else i / 16.0)
                      for i in range(n * n))
    entries = [(256, 4, n), (257, 4, n), (258, 3, 32), (259, 3, 1), (262, 3, 1), (273, 4, 0),
               (277, 3, 1), (278, 4, n), (279, 4, len(pixels)), (284, 3, 1), (339, 3, 3)]
    data = 8 + 2 + 12 * len(entries) + 4
    b = b"II*\x00" + struct.pack("<I", 8) + struct.pack("<H", len(entries))
    for tag, typ, value in entries:
        value = data if tag == 273 else value
        b += struct.pack("<HHI", tag, typ, 1)
        b += struct.pack("<HH", value, 0) if typ == 3 else struct.pack("<I", value)
    write(path, b + b"\x00" * 4 + pixels)


def flat_png(path, width, height, channels="1", value="128"):
    """A flat 8-bit PNG of width x height (1 grey or 3 RGB channels), every
    sample value: a 4096 x 4096 one is 22 KB, an 8192 x 8192 RGB one 200 KB."""
    w, h, c = int(width), int(height), int(channels)
    row = b"\x00" + bytes([int(value)]) * (w * c)
    z = zlib.compressobj(6)
    data = b"".join(z.compress(row) for _ in range(h)) + z.flush()
    colour = {1: 0, 3: 2}[c]
    write(path, b"\x89PNG\r\n\x1a\n" +
          png_chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, colour, 0, 0, 0)) +
          png_chunk(b"IDAT", data) + png_chunk(b"IEND", b""))


MAKERS = {
    "gltf_uri": gltf_uri, "obj_mtllib": obj_mtllib, "deep_gltf": deep_gltf,
    "deep_dae": deep_dae, "deep_json": deep_json, "faces_obj": faces_obj,
    "flat_obj": flat_obj, "progressive_jpeg": progressive_jpeg, "tiled_tiff": tiled_tiff,
    "exr_attribute": exr_attribute, "gif_screen": gif_screen, "png_desc": png_desc,
    "nan_tiff": nan_tiff, "vtf_header": vtf_header, "dds_mips": dds_mips,
    "flat_png": flat_png,
}


# ---------------------------------------------------------------- snapshots


def snapshot(top):
    """{relative path (bytes): (kind, hash or link target)}; regular files
    are hashed, nothing else is opened (a FIFO would block)."""
    out = {}
    top = os.fsencode(top)
    for root, dirs, files in os.walk(top):
        for name in dirs + files:
            p = os.path.join(root, name)
            rel = os.path.relpath(p, top)
            try:
                st = os.lstat(p)
            except OSError:
                continue
            if stat.S_ISREG(st.st_mode):
                h = hashlib.sha256()
                try:
                    with open(p, "rb") as f:
                        for block in iter(lambda: f.read(1 << 20), b""):
                            h.update(block)
                    out[rel] = ("f", h.hexdigest())
                except OSError as e:
                    out[rel] = ("f", "unreadable %s" % e.errno)
            elif stat.S_ISLNK(st.st_mode):
                out[rel] = ("l", os.fsdecode(os.readlink(p)))
            elif stat.S_ISDIR(st.st_mode):
                out[rel] = ("d", "")
            else:
                out[rel] = ("o", "%o" % stat.S_IFMT(st.st_mode))
    return out


def shown(name):
    return ascii(os.fsdecode(name))[1:-1]


def snap_save(top, path):
    with open(path, "w") as f:
        json.dump({k.decode("utf-8", "surrogateescape"): v for k, v in snapshot(top).items()}, f)


def snap_diff(top, path, allow):
    with open(path) as f:
        before = {k.encode("utf-8", "surrogateescape"): tuple(v) for k, v in json.load(f).items()}
    after = snapshot(top)
    allow_re = re.compile(allow.encode()) if allow else None
    problems = []
    temps = [k for k in after if b".bb-tmp" in os.path.basename(k)]
    if temps:
        problems.append("temporary left: " + shown(temps[0]))
    for k in sorted(set(before) | set(after)):
        if k in temps or (allow_re and allow_re.search(k)):
            continue
        if k not in after:
            problems.append("removed: " + shown(k))
        elif k not in before:
            problems.append("new: " + shown(k))
        elif before[k] != after[k]:
            problems.append("changed: " + shown(k))
    if problems:
        more = " (+%d more)" % (len(problems) - 3) if len(problems) > 3 else ""
        print("; ".join(problems[:3]) + more)


# ------------------------------------------------------------------ checks


# C0 but tab and newline, DEL, C1, and the bidirectional controls (U+061C,
# U+200E, U+200F, U+202A..U+202E, U+2066..U+2069)
CONTROL = re.compile(rb"[\x00-\x08\x0b-\x1f\x7f]|\xc2[\x80-\x9f]|\xd8\x9c|"
                     rb"\xe2\x80[\x8e\x8f\xaa-\xae]|\xe2\x81[\xa6-\xa9]")


def control(paths):
    bad = []
    for p in paths:
        with open(p, "rb") as f:
            if CONTROL.search(f.read()):
                bad.append(os.path.basename(p).split(".")[-1])
    if bad:
        print("control characters in " + " and ".join(bad))


def json_check(path, key=None, length=None):
    """Every line of path must be valid UTF-8 and JSON; with key and length,
    some object's provenance must hold key with a value of length characters."""
    with open(path, "rb") as f:
        data = f.read()
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as e:
        print("not UTF-8 at byte %d" % e.start)
        return
    lines = [l for l in text.split("\n") if l.strip()]
    if not lines:
        print("no JSON printed")
        return
    found = None
    for l in lines:
        try:
            obj = json.loads(l)
        except ValueError as e:
            print("not JSON: %s" % e)
            return
        if key and isinstance(obj, dict):
            prov = obj.get("provenance") or {}
            if isinstance(prov, dict):
                for k, v in prov.items():
                    if k.startswith(key[:20]):
                        found = (len(k), len(v) if isinstance(v, str) else -1)
    if key:
        if found is None:
            print("the long key is missing")
        elif found != (len(key), int(length)):
            print("key of %d characters cut to %d, value of %s cut to %d" %
                  (len(key), found[0], length, found[1]))


# ------------------------------------------------------------------ attacker


def attack(top, target, seconds, log, stop):
    """Until the file stop exists (or `seconds` pass): every temporary file of a writer in top is
    swapped for a link to target, and every private directory is moved
    aside and replaced by one of ours holding links to target at the names
    a writer would use (and, where we may, links planted inside it)."""
    end = time.time() + float(seconds)
    seen = set()
    counts = {"files_swapped": 0, "dirs_swapped": 0, "planted_inside": 0, "inside_refused": 0}
    leaves = ["staged.tif", "staged.TIF", "staged.tiff", "out.tif"]
    while time.time() < end and not os.path.exists(stop):
        try:
            entries = list(os.scandir(top))
        except OSError:
            continue
        for e in entries:
            if not e.name.startswith(".bb-tmp-") or e.name in seen or e.name.endswith(".moved"):
                continue
            p = e.path
            try:
                if e.is_symlink():
                    continue
                if e.is_dir(follow_symlinks=False):
                    for leaf in leaves:
                        try:
                            os.symlink(target, os.path.join(p, leaf))
                            counts["planted_inside"] += 1
                        except OSError:
                            counts["inside_refused"] += 1
                    os.rename(p, p + ".moved")
                    os.mkdir(p)
                    for leaf in leaves:
                        os.symlink(target, os.path.join(p, leaf))
                    counts["dirs_swapped"] += 1
                else:
                    os.unlink(p)
                    os.symlink(target, p)
                    counts["files_swapped"] += 1
                seen.add(e.name)
            except OSError:
                pass
    with open(log, "w") as f:
        f.write(" ".join("%s=%d" % kv for kv in counts.items()) + "\n")


def main(argv):
    cmd = argv[1]
    if cmd == "make":
        MAKERS[argv[2]](*argv[3:])
    elif cmd == "snap":
        snap_save(argv[2], argv[3])
    elif cmd == "diff":
        snap_diff(argv[2], argv[3], argv[4] if len(argv) > 4 else "")
    elif cmd == "ctl":
        control(argv[2:])
    elif cmd == "json":
        json_check(argv[2], *argv[3:5])
    elif cmd == "attack":
        attack(*argv[2:7])
    else:
        sys.exit("hostile_repro.py: unknown command " + cmd)


if __name__ == "__main__":
    main(sys.argv)
