#!/usr/bin/python3
"""bench_loop.py BEFORE AFTER: a bake's whole loop, two builds in turns.

BEFORE and AFTER are build directories (each with bumpbake and
tools/bench_trace), say an older commit's build and this one. Every row
runs the two builds alternately, PAIRS times (the first of each pair
alternates too, so neither build always runs on a warmer cache), and prints
the medians and after / before:

- the stages of `bumpbake bake` on rock06 (1024 x 1024, scale 128, 256
  rays, 2 threads, `--json`): the trace, and the write of 8-bit PNGs
  (`-o PREFIX`), float EXRs (ao and ssbump), an ssbump VTF (DXT1 and its
  mips), a DDS (BC1 and its mips) and the VTF with --fast-compression; for
  each, the write's share of the stages (the goal: under 0.10);
- the VTF and DDS writes at 2048 x 2048 (rock06 resized with oiiotool);
- the trace kernel: `tools/bench_trace MAP 128 256 1 --subset 0`, horizons
  per second per thread at 16 slices;
- a bounce's cost over a bake's: `bake --bounce 0.5` against the same bake
  without, ao and ssbump to float EXR, CPU seconds (user + system) of the
  whole process, on rock06 resized to 512 (scale 64) and the rivet panel's
  height at 512 (renderbumpflat, its own scale);
- the whole bake at 256 rays and at 10 slices (the slice count at which
  the bake's error on rock06 is the peer's at 256 rays, docs/accuracy.md),
  ao and ssbump to PNG, wall seconds of the process.

As in tools/bench.sh, a row whose first pair takes over 20 s (10 s a run)
is run once.

  tools/bench_loop.py BEFORE_BUILD AFTER_BUILD [--pairs N] [--rock PATH] [--rows R,R]

make bench runs it as section 13 when BENCH_BEFORE names the older build.
Rows are named trace, png, exr, vtf, dds, vtf_fast, vtf2048, dds2048,
kernel, bounce_rock, bounce_rivet, whole, whole10 (--rows picks some).
Everything it writes goes into build/bench/loop/.
"""

import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUT = os.path.join(ROOT, "build", "bench", "loop")


def load():
    with open("/proc/loadavg") as f:
        return float(f.read().split()[0])


def run(argv):
    """Runs argv; (stdout, wall seconds, CPU seconds of the child)."""
    before = os.times()
    t0 = time.monotonic()
    p = subprocess.run(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    wall = time.monotonic() - t0
    after = os.times()
    if p.returncode != 0:
        sys.exit(f"bench_loop: {' '.join(argv)} exited {p.returncode}: {p.stderr.strip()[-300:]}")
    cpu = (after.children_user - before.children_user) + (after.children_system -
                                                          before.children_system)
    return p.stdout, wall, cpu


def stages(stdout):
    """The "seconds" object of a bake's --json line."""
    return json.loads(stdout.strip().splitlines()[-1])["seconds"]


class Bake:
    """A bake of MAP with OUTPUTS; measures write, trace and write / stages."""

    def __init__(self, label, map_path, scale, outputs, extra=()):
        self.label, self.map, self.scale = label, map_path, scale
        self.outputs, self.extra = outputs, list(extra)

    def measure(self, build, tag):
        argv = [os.path.join(build, "bumpbake"), "bake", self.map, "--scale", str(self.scale),
                "--rays", "256", "--threads", "2", "--json", "-q", *self.extra]
        for opt, name in self.outputs:
            argv += [opt, os.path.join(OUT, f"{tag}_{name}")]
        s = stages(run(argv)[0])
        total = sum(s.values())
        return {"write": s["write"], "trace": s["trace"], "share": s["write"] / total}


class Kernel:
    label = "trace kernel, M horizons/s/thread, 16 slices, 1 thread"

    def __init__(self, map_path):
        self.map = map_path

    def measure(self, build, tag):
        out = run([os.path.join(build, "tools", "bench_trace"), self.map, "128", "256", "1",
                   "--subset", "0"])[0]
        # (its trace_over_brute is "inf" without a subset: not JSON, so read the one number)
        return {"mhps": float(re.search(r'"horizons_per_s":([0-9.eE+-]+)', out).group(1)) / 1e6}


class Bounce:
    """A bake with --bounce 0.5 against the same without: CPU seconds, ratio."""

    def __init__(self, label, map_path, scale):
        self.label, self.map, self.scale = label, map_path, scale

    def measure(self, build, tag):
        base = [os.path.join(build, "bumpbake"), "bake", self.map, "--scale", str(self.scale),
                "--threads", "2", "-q", "--ao", os.path.join(OUT, f"{tag}_b_ao.exr"),
                "--ssbump", os.path.join(OUT, f"{tag}_b_ss.exr")]
        plain = run(base)[2]
        bounce = run(base + ["--bounce", "0.5"])[2]
        return {"bake_cpu": plain, "bounce_cpu": bounce, "ratio": bounce / plain}


class Whole:
    """A whole bake (ao and ssbump, PNG): wall seconds of the process."""

    def __init__(self, label, map_path, extra):
        self.label, self.map, self.extra = label, map_path, extra

    def measure(self, build, tag):
        argv = [os.path.join(build, "bumpbake"), "bake", self.map, "--scale", "128",
                "--threads", "2", "-q", *self.extra, "--ao", os.path.join(OUT, f"{tag}_w_ao.png"),
                "--ssbump", os.path.join(OUT, f"{tag}_w_ss.png")]
        return {"wall": run(argv)[1]}


def prepare(rock, bumpbake):
    """The resized maps: rock06 at 512 and 2048, the rivet panel's height at 512."""
    os.makedirs(OUT, exist_ok=True)
    paths = {}
    for n in (512, 2048):
        p = os.path.join(OUT, f"rock{n}.png")
        if not os.path.exists(p):
            subprocess.run(["oiiotool", rock, "--resize", f"{n}x{n}", "-d", "uint16", "-o", p],
                           check=True)
        paths[n] = p
    rivet = os.path.join(OUT, "rivet512.png")
    text = subprocess.run([bumpbake, "renderbumpflat", "-size",
                           "512", "512", os.path.join(ROOT, "fixtures", "rivet_panel.obj"),
                           "--rect", "0", "0", "1", "1", "--tile", "-o",
                           os.path.join(OUT, "rivet512.tga"), "--height", rivet],
                          check=True, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                          text=True).stdout
    scale = re.search(r"height scale ([0-9.]+)", text).group(1)
    return paths, rivet, scale


def rows(rock, bumpbake):
    paths, rivet, rivet_scale = prepare(rock, bumpbake)
    png = [("-o", "png")]
    return {
        "png": Bake("write, -o PREFIX (normal, ssbump, ao; 8-bit PNG)", rock, 128, png),
        "exr": Bake("write, --ao a.exr --ssbump s.exr (float)", rock, 128,
                    [("--ao", "a.exr"), ("--ssbump", "s.exr")]),
        "vtf": Bake("write, --ssbump s.vtf (DXT1 + mips)", rock, 128, [("--ssbump", "s.vtf")]),
        "dds": Bake("write, --ssbump s.dds (BC1 + mips)", rock, 128, [("--ssbump", "s.dds")]),
        "vtf_fast": Bake("write, --ssbump s.vtf --fast-compression", rock, 128,
                         [("--ssbump", "s.vtf")], ["--fast-compression"]),
        "vtf2048": Bake("write, 2048 x 2048, --ssbump s.vtf", paths[2048], 256,
                        [("--ssbump", "s2048.vtf")]),
        "dds2048": Bake("write, 2048 x 2048, --ssbump s.dds", paths[2048], 256,
                        [("--ssbump", "s2048.dds")]),
        "kernel": Kernel(rock),
        "bounce_rock": Bounce("--bounce 0.5, rock06 512 (scale 64)", paths[512], 64),
        "bounce_rivet": Bounce(f"--bounce 0.5, rivet panel 512 (scale {rivet_scale})", rivet,
                               rivet_scale),
        "whole": Whole("whole bake, 256 rays (16 slices), ao + ssbump PNG", rock, ["--rays", "256"]),
        "whole10": Whole("whole bake, 10 slices (the peer's accuracy at 256 rays)", rock,
                         ["--slices", "10"]),
    }


def fmt(v):
    return f"{v:.3f}" if v < 100 else f"{v:.1f}"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("before")
    ap.add_argument("after")
    ap.add_argument("--pairs", type=int, default=3)
    ap.add_argument("--rock", default=os.path.join(ROOT, "fixtures", "rock06_height.png"))
    ap.add_argument("--rows", default="")
    a = ap.parse_args()
    builds = {"before": os.path.abspath(a.before), "after": os.path.abspath(a.after)}
    table = rows(os.path.abspath(a.rock), os.path.join(builds["after"], "bumpbake"))
    picked = a.rows.split(",") if a.rows else list(table)
    print(f"before: {builds['before']}\nafter:  {builds['after']}\n"
          f"up to {a.pairs} pairs per row, the two builds in turns; medians")
    loads = [load()]
    for key in picked:
        row = table[key]
        got = {"before": [], "after": []}
        t0 = time.monotonic()
        for i in range(a.pairs):
            order = ("before", "after") if i % 2 == 0 else ("after", "before")
            for which in order:
                got[which].append(row.measure(builds[which], which))
            if i == 0 and time.monotonic() - t0 > 20:
                break  # the bench's rule: a measurement over 10 s is run once
        loads.append(load())
        med = {w: {k: statistics.median(r[k] for r in got[w]) for k in got[w][0]} for w in got}
        n = len(got["after"])
        print(f"\n{row.label} ({'1 pair' if n == 1 else f'medians of {n} pairs'})")
        for k in med["after"]:
            b, f = med["before"][k], med["after"][k]
            ratio = f / b if b else float("nan")
            print(f"  {k:<11} before {fmt(b):>8}   after {fmt(f):>8}   after/before {ratio:.2f}")
        sys.stdout.flush()
    print(f"\nload average (1 min) at each row's end: {', '.join(f'{x:.1f}' for x in loads)}")


if __name__ == "__main__":
    main()
