#!/usr/bin/python3
"""bench_serve.py BIN: `bumpbake serve`'s save-to-pixels latency.

From the rename() of a new 1024 x 1024 height (fixtures/rock06_height.png
and its inverse, made with `bumpbake program invertColor`, in turns; with
--edit N, the height and a copy with one N x N block raised, a brush
stroke's worth, in turns) over
the served file to the page in headless Chromium showing that save's ssbump
(its <body data-drawn-bake> moves on; data-drawn-at is the page's clock,
Date.now(), the same wall clock as time.time() here), at serve's default
settings and --scale 64; the median of N saves (10). Beside it: the bake's
own time inside serve (reading, baking and the page's textures, from the
state it publishes) and the cold pair of today, `bumpbake bake` then
`bumpbake render` of its ssbump, each its own process, run in turns with
the saves (medians).

  tools/bench_serve.py build/bumpbake [--saves N] [--height PATH] [--scale S]
                       [--edit SIDE] [--bounce RHO]

--bounce RHO: serve and the cold bake both bake with `--bounce RHO`
(inter-reflection; its stage shows in the page's progress).

--edit SIDE: each save changes a SIDE x SIDE region only (a soft brush of
0.1 of the height at the map's middle, added and taken away in turns,
written with the bumpbake Python package beside the build): serve bakes
it again where it changed (a context that keeps, bb_bake_context_keep).

make bench runs it as section 12. Needs chromium, chromium-driver and
python3-selenium (make deps); prints why and exits 0 without them.
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
import urllib.request

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tests", "serve"))
import serve_browser as sb  # noqa: E402


def load():
    with open("/proc/loadavg") as f:
        return " ".join(f.read().split()[:3])


def run(cmd):
    t0 = time.time()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    return time.time() - t0


def brush(binary, height, out, side):
    """height with a side x side soft brush of 0.1 added at its middle, as a
    16-bit PNG (the library's reader and writer, through the package)."""
    os.environ.setdefault("BUMPBAKE_LIBRARY", os.path.dirname(binary))
    sys.path.insert(0, os.path.join(ROOT, "python"))
    import numpy as np
    import bumpbake
    h = bumpbake.read(height)
    if h.ndim == 3:
        h = h[..., 0]
    rows, cols = h.shape
    y, x = np.mgrid[0:side, 0:side].astype(np.float64)
    r = side / 2.0
    d2 = ((x + 0.5 - r) / r) ** 2 + ((y + 0.5 - r) / r) ** 2
    bump = np.where(d2 < 1.0, 0.1 * (1.0 - d2) ** 2, 0.0)
    y0, x0 = rows // 2 - side // 2, cols // 2 - side // 2
    h = h.astype(np.float64)
    h[y0:y0 + side, x0:x0 + side] += bump
    bumpbake.write(out, np.clip(h, 0.0, 1.0).astype(np.float32), kind="height", depth=16)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("bin")
    ap.add_argument("--saves", type=int, default=10)
    ap.add_argument("--height", default=os.path.join(ROOT, "fixtures", "rock06_height.png"))
    ap.add_argument("--scale", default="64")
    ap.add_argument("--edit", type=int, default=0)
    ap.add_argument("--bounce", default=None)
    a = ap.parse_args()
    binary = os.path.abspath(a.bin)
    why = sb.browser_missing()
    if why:
        print("bench_serve: skipped: " + why)
        return 0
    work = tempfile.mkdtemp(prefix="bb-bench-serve-")
    served = os.path.join(work, "height.png")
    variant = os.path.join(work, "variant.png")
    if a.edit:
        brush(binary, a.height, variant, a.edit)
    else:
        subprocess.run([binary, "program", "invertColor(%s)" % os.path.basename(a.height),
                        "--base", os.path.dirname(os.path.abspath(a.height)), "--depth", "16",
                        "-o", variant],
                       check=True, stdout=subprocess.DEVNULL)
    with open(a.height, "rb") as f:
        original = f.read()
    with open(variant, "rb") as f:
        inverted = f.read()
    with open(served, "wb") as f:
        f.write(original)

    print("load before: %s" % load())
    bake_options = ["--scale", a.scale] + (["--bounce", a.bounce] if a.bounce else [])
    server = sb.Server(binary, served, bake_options + ["--quiet"])
    driver = sb.start_browser(1100, 800)
    latencies, bakes, cold = [], [], []
    prefix = os.path.join(work, "cold")
    try:
        driver.get(server.url)
        sb.wait_for(lambda: sb.drawn_bake(driver) >= 1, 300, "the first bake drawn")
        for i in range(a.saves):
            before = sb.drawn_bake(driver)
            data = inverted if i % 2 == 0 else original  # (--edit: edited, not inverted)
            tmp = os.path.join(work, ".~height.png")
            with open(tmp, "wb") as f:
                f.write(data)
            t0 = time.time()
            os.rename(tmp, served)
            sb.wait_for(lambda: sb.drawn_bake(driver) > before, 300, "save %d drawn" % i,
                        interval=0.005)
            drawn_at = int(driver.execute_script("return document.body.dataset.drawnAt")) / 1000
            with urllib.request.urlopen(server.url + "state", timeout=30) as r:
                bake = json.load(r)["bake"]
            latencies.append(drawn_at - t0)
            bakes.append(bake["seconds"])
            # the cold pair in turns with the saves, so both see the same load
            t_bake = run([binary, "bake", served] + bake_options + ["-o", prefix, "--quiet"])
            t_render = run([binary, "render", "--ssbump", prefix + "_ssbump.png", "-o",
                            os.path.join(work, "cold_render.png"), "--quiet"])
            cold.append((t_bake, t_render))
            print("save %2d: %.3f s to pixels; the bake inside serve %.3f s (trace %.3f s, "
                  "textures %.3f s); cold bake %.3f s + render %.3f s"
                  % (i + 1, latencies[-1], bake["seconds"], bake["seconds_trace"],
                     bake["seconds_textures"], t_bake, t_render))
    finally:
        sb.stop_browser(driver)
        server.close()
    med = statistics.median
    lat, bk = med(latencies), med(bakes)
    cold_bake = med(c[0] for c in cold)
    cold_pair = med(c[0] + c[1] for c in cold)
    print()
    what = "a %d x %d edit" % (a.edit, a.edit) if a.edit else "the whole height changed"
    print("save-to-pixels (%s), median of %d saves: %.3f s (min %.3f, max %.3f)"
          % (what, len(latencies), lat, min(latencies), max(latencies)))
    print("the bake inside serve, median:           %.3f s" % bk)
    print("save-to-pixels minus the bake, median:   %.3f s"
          % med(l - b for l, b in zip(latencies, bakes)))
    print("cold bumpbake bake, median:              %.3f s" % cold_bake)
    print("cold bumpbake bake + render, median:     %.3f s" % cold_pair)
    print("load after: %s (2 cores: %d)" % (load(), os.cpu_count()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
