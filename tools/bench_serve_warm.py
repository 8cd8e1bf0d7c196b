#!/usr/bin/python3
"""bench_serve_warm.py BIN [SAVES]: what one re-bake of `bumpbake serve`
costs its process, without a browser: the minor page faults and the CPU
seconds (user + system, from /proc/PID/stat: far steadier than wall time on
a loaded machine) of the serve process from the rename() of a new height to
its bake being published, and the bake's own times from its state. rock06
(1024 x 1024) and its inverse in turns, --scale 64, defaults; medians of
SAVES (8). Run it on two binaries in turns to compare them.

  tools/bench_serve_warm.py build/bumpbake 8
"""

import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import urllib.request

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tests", "serve"))
import serve_browser as sb  # noqa: E402

SLOW = 300


def main():
    binary = sys.argv[1]
    saves = int(sys.argv[2]) if len(sys.argv) > 2 else 8
    work = tempfile.mkdtemp(prefix="bb-serve-warm-")
    source = os.path.join(ROOT, "fixtures", "rock06_height.png")
    inverse = os.path.join(work, "inverse.png")
    shutil.copy(source, os.path.join(work, "h.png"))
    subprocess.run([binary, "program", "invertColor(%s)" % os.path.basename(source), "--base",
                    os.path.dirname(source), "--depth", "16", "-o", inverse], check=True,
                   capture_output=True)
    data = [open(source, "rb").read(), open(inverse, "rb").read()]
    server = sb.Server(binary, os.path.join(work, "h.png"), ["--scale", "64", "--quiet"])

    def state():
        with urllib.request.urlopen(server.url + "state", timeout=30) as r:
            return json.load(r)

    def baked_after(last):
        s = state()
        return s if s.get("bake", {}).get("id", 0) > last and not s["baking"] else None

    def process():
        with open("/proc/%d/stat" % server.proc.pid) as f:
            fields = f.read().rsplit(")", 1)[1].split()
        return int(fields[7]), (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")

    rows = []
    try:
        sb.wait_for(lambda: baked_after(0), SLOW, "the first bake")
        for k in range(saves):
            last = state()["bake"]["id"]
            faults0, cpu0 = process()
            sb.save_by_rename(data[(k + 1) % 2], os.path.join(work, "h.png"))
            bake = sb.wait_for(lambda: baked_after(last), SLOW, "the bake", 0.02)["bake"]
            faults1, cpu1 = process()
            rows.append((faults1 - faults0, cpu1 - cpu0, bake["seconds"], bake["seconds_trace"]))
    finally:
        server.close()
        shutil.rmtree(work, ignore_errors=True)
    with open("/proc/loadavg") as f:
        load = " ".join(f.read().split()[:3])
    med = lambda i: statistics.median(r[i] for r in rows)  # noqa: E731
    print("%s: %d re-bakes, medians: minor page faults %d, serve CPU %.3f s, bake %.3f s "
          "(trace %.3f s); load %s" % (binary, saves, med(0), med(1), med(2), med(3), load))


if __name__ == "__main__":
    main()
