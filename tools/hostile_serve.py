#!/usr/bin/env python3
"""hostile_serve.py BIN: `bumpbake serve` probed as a server, the part of
`make hostile` (tools/hostile_repro.sh runs it) for the issue's seven
items and the usual attacks on a process that listens: a port already
taken, framing, slow clients, 1,000 connections at once, event streams
opened and dropped, stalled downloads, concurrent writes, malformed HTTP,
a folder moved under the watch, the controls' values, names a shell would
take apart. One line per case, as hostile_repro.sh prints them: its id,
what ran, and CLEAN or NOT CLEAN with the reasons; the last line is "N
cases tried, M clean"; the exit code is 0 when every case is clean.

Clean means: serve never dies (nor prints a sanitizer's report, nor a
control character), the page (/, state and a map) loads during each
attack within PAGE_SECONDS, serve's peak RSS stays under the documented
bound (docs/commands/serve.md, "Bounds": BOUND_BASE_MB + BOUND_BYTES_PER_TEXEL
a texel of the height; not judged under AddressSanitizer, whose quarantine
keeps freed memory), and what the case checks besides holds.

Traffic goes to 127.0.0.1 only; every loop is bounded in count and in
time. Needs python3 and the fixtures; about three minutes on 2 cores.
"""
import concurrent.futures
import http.client
import json
import os
import re
import shlex
import shutil
import socket
import subprocess
import sys
import tempfile
import time
import urllib.parse

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FIXTURES = os.path.join(ROOT, "fixtures")
PAGE_SECONDS = 20      # the page's three requests, however loaded the machine
# docs/commands/serve.md, "Bounds": serve's resident memory stays under
# BOUND_BASE_MB plus BOUND_BYTES_PER_TEXEL a texel of the height.
BOUND_BASE_MB = 250
BOUND_BYTES_PER_TEXEL = 300

results = []
BIN = None  # the bumpbake under test


# ------------------------------------------------------------------ serve

class Serve:
    """bumpbake serve HEIGHT ARGS... on 127.0.0.1, any free port; stderr to
    a file, read at the end."""

    def __init__(self, binary, height, args, cwd):
        self.err_path = os.path.join(cwd, ".serve-%d.err" % time.monotonic_ns())
        self.err = open(self.err_path, "w")
        self.proc = subprocess.Popen([binary, "serve", height, "--port", "0", *args],
                                     stdout=subprocess.PIPE, stderr=self.err, text=True, cwd=cwd)
        line = self.proc.stdout.readline()
        m = re.search(r"(http://\S+)", line)
        if not m:
            self.proc.kill()
            raise RuntimeError("serve printed no URL: %r" % line)
        self.url = m.group(1)
        u = urllib.parse.urlsplit(self.url)
        self.host, self.port, self.prefix = u.hostname, u.port, u.path

    def alive(self):
        return self.proc.poll() is None

    def memory_mb(self, key="VmHWM"):
        try:
            with open("/proc/%d/status" % self.proc.pid) as f:
                for line in f:
                    if line.startswith(key + ":"):
                        return int(line.split()[1]) / 1024
        except OSError:
            pass
        return 0.0

    def sanitized(self):
        try:
            with open("/proc/%d/maps" % self.proc.pid) as f:
                return "libasan" in f.read()
        except OSError:
            return False

    def close(self):
        """Ends serve; its stderr."""
        if self.alive():
            self.proc.terminate()
            try:
                self.proc.wait(10)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        self.err.close()
        with open(self.err_path, errors="replace") as f:
            text = f.read()
        os.remove(self.err_path)
        return text


def request(server, path="", method="GET", headers=None, timeout=PAGE_SECONDS):
    c = http.client.HTTPConnection(server.host, server.port, timeout=timeout)
    try:
        c.request(method, server.prefix + path, headers=headers or {})
        r = c.getresponse()
        return r.status, {k.lower(): v for k, v in r.getheaders()}, r.read()
    finally:
        c.close()


def state(server):
    return json.loads(request(server, "state")[2])


def page_loads(server):
    """'' when /, state and the map load within PAGE_SECONDS, else why."""
    t0 = time.monotonic()
    try:
        for path in ("", "state", "map/ssbump_ao"):
            status = request(server, path)[0]
            if status != 200:
                return "%s gave %d" % (path or "/", status)
    except OSError as e:
        return "the page did not load: %s" % e
    took = time.monotonic() - t0
    return "" if took <= PAGE_SECONDS else "the page took %.1f s" % took


def wait_bake(server, after=0, seconds=180):
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        try:
            s = state(server)
            if s.get("bake", {}).get("id", 0) > after and not s["baking"] and not s["pending"]:
                return s
        except OSError:
            pass
        time.sleep(0.05)
    raise RuntimeError("no bake after %d in %d s" % (after, seconds))


def height_texels(path):
    with open(path, "rb") as f:
        head = f.read(24)
    return int.from_bytes(head[16:20], "big") * int.from_bytes(head[20:24], "big")


# ------------------------------------------------------------------ cases

def case(case_id, what, run, binary, work, height="rock06_128.png", args=(), fresh=True):
    """Runs one case: run(server, reasons) against a fresh serve of a copy
    of height, then the checks every case shares."""
    d = os.path.join(work, case_id)
    os.makedirs(d)
    shutil.copy(os.path.join(FIXTURES, height), os.path.join(d, "h.png"))
    reasons, t0 = [], time.monotonic()
    server = None
    try:
        server = Serve(binary, "h.png", ["--scale", "16", "--rays", "16", *args], d)
        wait_bake(server)
        run(server, reasons, d)
        if not server.alive():
            reasons.append("serve died (exit %s)" % server.proc.returncode)
        else:
            why = page_loads(server)
            if why:
                reasons.append("after it: " + why)
        peak = server.memory_mb()
        bound = BOUND_BASE_MB + BOUND_BYTES_PER_TEXEL * height_texels(
            os.path.join(FIXTURES, height)) / 2 ** 20
        if peak > bound and not server.sanitized():
            reasons.append("peak RSS %.0f MB (bound %.0f MB)" % (peak, bound))
    except Exception as e:  # a case that cannot run is not clean
        reasons.append("%s: %s" % (type(e).__name__, e))
        peak = server.memory_mb() if server else 0
    err = server.close() if server else ""
    if re.search(r"Sanitizer|runtime error:", err):
        reasons.append("a sanitizer's report: %s" % err[err.find("ERROR"):][:160].strip())
    if re.search(r"[\x00-\x08\x0b-\x1f\x7f]", err):
        reasons.append("a control character on stderr")
    summary = "peak %.0f MB, %.1f s" % (peak, time.monotonic() - t0)
    results.append((case_id, what, reasons, summary))
    line = "%-5s %-62s %-10s %s" % (case_id, what, "CLEAN" if not reasons else "NOT CLEAN",
                                      summary if not reasons else "; ".join(reasons))
    print(line, flush=True)


def during(server, reasons, attack_done):
    """The page loads while an attack holds (checked 3 times)."""
    for _ in range(3):
        if attack_done():
            break
        why = page_loads(server)
        if why:
            reasons.append("during it: " + why)
            return
        time.sleep(0.5)


def busy_port(binary, work):
    """39.1: serve started twice on one port: the second ends with one line."""
    d = os.path.join(work, "39.1")
    os.makedirs(d)
    shutil.copy(os.path.join(FIXTURES, "rock06_128.png"), os.path.join(d, "h.png"))
    reasons, t0 = [], time.monotonic()
    first = Serve(binary, "h.png", ["--scale", "8", "--quiet"], d)
    try:
        for _ in range(20):
            r = subprocess.run([binary, "serve", "h.png", "--scale", "8", "--port",
                                str(first.port)], cwd=d, capture_output=True, timeout=60,
                               errors="replace")
            lines = r.stderr.splitlines()
            if r.returncode != 1 or len(lines) != 1 or "cannot listen" not in r.stderr:
                reasons.append("exit %d, stderr %r" % (r.returncode, r.stderr[:200]))
                break
            if re.search(r"[\x00-\x08\x0b-\x1f\x7f]", r.stderr):
                reasons.append("a control character: %r" % r.stderr[:200])
                break
    finally:
        first.close()
    results.append(("39.1", "serve twice on one port (x20)", reasons, ""))
    print("%-5s %-62s %-10s %s" % ("39.1", "serve twice on one port (x20)",
                                   "CLEAN" if not reasons else "NOT CLEAN",
                                   "%.1f s" % (time.monotonic() - t0) if not reasons
                                   else "; ".join(reasons)), flush=True)


def framing(server, reasons, d):
    """39.2: every response: X-Frame-Options DENY, frame-ancestors 'none',
    scripts from serve only."""
    for method, path, headers in (("GET", "", {}), ("GET", "serve.js", {}), ("GET", "state", {}),
                                  ("GET", "map/ssbump_ao", {}), ("GET", "nothing", {}),
                                  ("POST", "write", {}), ("DELETE", "", {}),
                                  ("POST", "params?rays=x", {"X-Bumpbake": "1"})):
        status, got, _ = request(server, path, method, headers)
        csp = [x.strip() for x in got.get("content-security-policy", "").split(";")]
        if got.get("x-frame-options") != "DENY" or "frame-ancestors 'none'" not in csp \
                or "script-src 'self'" not in csp:
            reasons.append("%s /%s (%d): %s" % (method, path, status, got))
            return


def slowloris(server, reasons, d):
    """39.3: 70 clients sending a header line every 2 s."""
    socks = []
    for _ in range(70):
        k = socket.create_connection((server.host, server.port), timeout=5)
        k.sendall(b"GET / HTTP/1.1\r\n")
        socks.append(k)
    end = time.monotonic() + 30
    open_ = list(socks)
    while open_ and time.monotonic() < end:
        for k in list(open_):
            try:
                k.sendall(b"X-Slow: 1\r\n")
            except OSError:
                open_.remove(k)
        during(server, reasons, lambda: not open_)
        time.sleep(2)
    if open_:
        reasons.append("%d slow clients still connected after 30 s" % len(open_))
    for k in socks:
        k.close()


def thousand(server, reasons, d):
    """39.4: 1,000 connections at once: half idle, half asking for the state."""
    socks = []
    try:
        for i in range(1000):
            k = socket.create_connection((server.host, server.port), timeout=10)
            if i % 2:
                k.sendall(("GET %sstate HTTP/1.1\r\nHost: %s:%d\r\n\r\n"
                           % (server.prefix, server.host, server.port)).encode())
            socks.append(k)
        during(server, reasons, lambda: False)
        answered = 0
        for k in socks[1::2]:
            k.settimeout(PAGE_SECONDS)
            try:
                if k.recv(64).startswith(b"HTTP/1.1 200"):
                    answered += 1
            except OSError:
                pass
        if answered < 500:
            reasons.append("%d of 500 requests answered" % answered)
    finally:
        for k in socks:
            k.close()


def streams(server, reasons, d):
    """39.5: 300 event streams opened and dropped (a reset each), twice."""
    import struct

    for _ in range(2):
        socks = []
        for _ in range(300):
            k = socket.create_connection((server.host, server.port), timeout=10)
            k.sendall(("GET %sevents HTTP/1.1\r\nHost: %s:%d\r\n\r\n"
                       % (server.prefix, server.host, server.port)).encode())
            socks.append(k)
        during(server, reasons, lambda: False)
        for k in socks:
            k.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
            k.close()
        # the slots come back within seconds
        end, ok = time.monotonic() + 15, False
        while time.monotonic() < end and not ok:
            c = http.client.HTTPConnection(server.host, server.port, timeout=10)
            c.request("GET", server.prefix + "events")
            ok = c.getresponse().status == 200
            c.close()
            time.sleep(0.2)
        if not ok:
            reasons.append("no event stream 15 s after 300 left")
            return


def per_client(server, reasons, d):
    """39.6: with --address, one address's share is bounded."""
    socks = []
    try:
        for _ in range(100):
            socks.append(socket.create_connection((server.host, server.port), timeout=10))
        closed = 0
        for k in socks:
            k.settimeout(0.2)
            try:
                if k.recv(1) == b"":
                    closed += 1
            except socket.timeout:
                pass
            except OSError:
                closed += 1
        if closed < 30:
            reasons.append("only %d of 100 connections from one address refused" % closed)
    finally:
        for k in socks:
            k.close()


def stalled(server, reasons, d):
    """39.7: 8 bakes of a 1024 x 1024 height, a stalled download of each."""
    socks = []
    try:
        last = state(server)["bake"]["id"]
        for i in range(8):
            k = socket.create_connection((server.host, server.port), timeout=10)
            k.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
            k.sendall(("GET %smap/ssbump_ao HTTP/1.1\r\nHost: %s:%d\r\n\r\n"
                       % (server.prefix, server.host, server.port)).encode())
            k.recv(512)
            socks.append(k)
            request(server, "params?scale=%d" % (20 + i), "POST", {"X-Bumpbake": "1"})
            last = wait_bake(server, last)["bake"]["id"]
        during(server, reasons, lambda: False)
    finally:
        for k in socks:
            k.close()


def writes(server, reasons, d):
    """39.8: 12 concurrent writes while a control is pending: one write at
    a time."""
    request(server, "params?scale=21", "POST", {"X-Bumpbake": "1"})

    def write(_):
        return request(server, "write", "POST", {"X-Bumpbake": "1"}, timeout=600)[0]

    with concurrent.futures.ThreadPoolExecutor(12) as pool:
        futures = [pool.submit(write, i) for i in range(12)]
        during(server, reasons, lambda: all(f.done() for f in futures))
        statuses = [f.result() for f in futures]
    if statuses != [200] * 12:
        reasons.append("replies %s" % statuses)


MALFORMED = [
    b"\x00\x01\x02garbage\r\n\r\n",
    b"GET / HTTP/1.1\r\n" + b"X: " + b"a" * 100000 + b"\r\n\r\n",
    b"GET /" + b"a" * 70000 + b" HTTP/1.1\r\nHost: h\r\n\r\n",
    b"GET / HTTP/1.1\r\n" + b"".join(b"X-%d: 1\r\n" % i for i in range(3000)) + b"\r\n",
    b"GET\r\n\r\n",
    b"GET / HTTP/9.9\r\nHost: h\r\n\r\n",
    b"BREW / HTTP/1.1\r\nHost: h\r\n\r\n",
    b"GET /%00../../etc/passwd HTTP/1.1\r\nHost: h\r\n\r\n",
    b"GET /..%2f..%2fetc%2fpasswd HTTP/1.1\r\nHost: h\r\n\r\n",
    b"POST /write HTTP/1.1\r\nHost: h\r\nX-Bumpbake: 1\r\nContent-Length: 10\r\n"
    b"Transfer-Encoding: chunked\r\n\r\nzz\r\n",
    b"POST /params HTTP/1.1\r\nHost: h\r\nX-Bumpbake: 1\r\nContent-Length: 99999999\r\n\r\nx",
    b"POST /params HTTP/1.1\r\nHost: h\r\nX-Bumpbake: 1\r\nTransfer-Encoding: chunked\r\n\r\n"
    b"fffffffffffffffff\r\n",
    b"GET / HTTP/1.1\r\nHost: h\r\n\r\nGET / HTTP/1.1\r\nHost: h\r\n\r\n" * 50,
    b"GET / HTTP/1.1\r\nHost:\r\n\r\n",
    b"GET / HTTP/1.1\r\n Host: folded\r\n\r\n",
    b"\r\n" * 10000,
]


def malformed(server, reasons, d):
    """39.9: malformed HTTP, each on its own connection, then the page."""
    for i, data in enumerate(MALFORMED):
        k = socket.create_connection((server.host, server.port), timeout=10)
        try:
            k.sendall(data.replace(b"Host: h", ("Host: %s:%d" % (server.host, server.port))
                                   .encode()))
            k.settimeout(2)
            try:
                while k.recv(65536):
                    pass
            except OSError:
                pass
        except OSError:
            pass
        finally:
            k.close()
        if not server.alive():
            reasons.append("died on malformed request %d" % i)
            return
    during(server, reasons, lambda: False)


def controls(server, reasons, d):
    """39.10: the controls as the command line checks them, and values
    of every kind (each refused or taken, never an error of serve's)."""
    r = subprocess.run([BIN, "bake", "h.png", "--scale", "16", "-o", "/nonexistent/x",
                        "--bounces", "3"], cwd=d, capture_output=True, text=True, timeout=60)
    cli = r.stderr.strip().split(": ", 1)[1]
    status, _, body = request(server, "params?bounces=3", "POST", {"X-Bumpbake": "1"})
    if status != 400 or json.loads(body)["error"] != cli:
        reasons.append("bounces without bounce: %d %s (the CLI: %s)" % (status, body[:120], cli))
    status, _, body = request(server, "params?scale=1%00x", "POST", {"X-Bumpbake": "1"})
    if status != 400:
        reasons.append("scale=1%%00x: %d %s" % (status, body[:120]))
    values = ["", "-1", "1e999", "nan", "inf", "0x10", "1,2", "%ff%fe", "9" * 400, "1%0a2",
              "%00", "1e-400", "+5", "%203", "3%20"]  # as sent: percent-encoded
    names = ["scale", "rays", "slices", "bias", "bounce", "bounces", "brightness",
             "light-color", "path", "scale%00", ""]
    for n in names:
        for v in values:
            status = request(server, "params?%s=%s" % (n, v), "POST", {"X-Bumpbake": "1"})[0]
            if status not in (200, 400):
                reasons.append("%s=%s: %d" % (n, v, status))
                return


def watch(server, reasons, d):
    """39.11: the folder moved away and made again, the height deleted, a
    change the watch cannot see before a write."""
    first = state(server)["bake"]["id"]
    sub, sub2 = os.path.join(d, "sub"), os.path.join(d, "sub2")
    os.rename(sub, sub2)
    end = time.monotonic() + 60
    while time.monotonic() < end and not state(server)["error"]:
        time.sleep(0.05)
    if "sub/h.png" not in state(server)["error"]:
        reasons.append("the height's loss not reported: %r" % state(server)["error"])
    os.mkdir(sub)
    with open(os.path.join(FIXTURES, "bricks_128x64.png"), "rb") as f:
        data = f.read()
    with open(os.path.join(sub, ".~h.png"), "wb") as f:
        f.write(data)
    os.rename(os.path.join(sub, ".~h.png"), os.path.join(sub, "h.png"))
    try:
        s = wait_bake(server, first, 60)
        if s["bake"]["height"] != 64:
            reasons.append("the save in the folder made again: bake of height %d"
                           % s["bake"]["height"])
    except RuntimeError as e:
        reasons.append("the save in the folder made again was not baked: %s" % e)
    other = os.path.join(d, "other")
    os.mkdir(other)
    os.link(os.path.join(sub, "h.png"), os.path.join(other, "same.png"))
    with open(os.path.join(FIXTURES, "rock06_128.png"), "rb") as f:
        rock = f.read()
    with open(os.path.join(other, "same.png"), "r+b") as f:
        f.truncate(0)
        f.write(rock)
    status, _, body = request(server, "write", "POST", {"X-Bumpbake": "1"}, timeout=600)
    reply = json.loads(body)
    if status != 200 or reply.get("from") != "bake":
        reasons.append("a write after an unseen change: %d %s" % (status, body[:160]))


def quoting(binary, work):
    """39.12: names a shell takes apart: the line shown is one word each,
    and runs nothing when typed in sh."""
    for i, name in enumerate(["x;touch PWNED;y.png", "my rock.png", "$(touch PWNED).png",
                              "it's `touch PWNED`.png", "a\nb.png"]):
        def run(server, reasons, d, name=name):
            line = state(server)["command"]
            if shlex.split(line)[2] != name:
                reasons.append("the line names %r" % shlex.split(line)[2])
            r = subprocess.run(["sh", "-c", 'bumpbake() { "$BB" "$@"; }; ' + line], cwd=d,
                               env=dict(os.environ, BB=binary), capture_output=True,
                               timeout=120)
            if r.returncode != 0:
                reasons.append("sh: exit %d" % r.returncode)
            if os.path.exists(os.path.join(d, "PWNED")):
                reasons.append("PWNED")

        d = os.path.join(work, "39.12." + str(i))
        os.makedirs(d)
        shutil.copy(os.path.join(FIXTURES, "rock06_128.png"), os.path.join(d, name))
        reasons = []
        server = Serve(binary, name, ["--scale", "8", "--rays", "16", "--quiet"], d)
        try:
            wait_bake(server)
            run(server, reasons, d)
        except Exception as e:
            reasons.append("%s: %s" % (type(e).__name__, e))
        err = server.close()
        if re.search(r"Sanitizer|runtime error:", err):
            reasons.append("a sanitizer's report")
        what = "serve %s: the line shown, typed in sh" % ascii(name)[1:-1]
        results.append(("39.12", what, reasons, ""))
        print("%-5s %-62s %-10s %s" % ("39.12", what, "CLEAN" if not reasons else "NOT CLEAN",
                                       "" if not reasons else "; ".join(reasons)), flush=True)


def main():
    if len(sys.argv) != 2 or not os.access(sys.argv[1], os.X_OK):
        print("usage: hostile_serve.py BIN (a bumpbake executable)", file=sys.stderr)
        return 2
    global BIN
    binary = BIN = os.path.realpath(sys.argv[1])
    work = tempfile.mkdtemp(prefix="bb-hostile-serve.")
    try:
        busy_port(binary, work)
        case("39.2", "framing: X-Frame-Options, CSP on every response", framing, binary, work)
        case("39.3", "70 slow clients (a header line each 2 s), 30 s", slowloris, binary, work)
        case("39.4", "1,000 connections at once (500 idle, 500 asking)", thousand, binary,
             work)
        case("39.5", "300 event streams opened and reset, twice", streams, binary, work)
        case("39.6", "--address: 100 connections from one address", per_client, binary, work,
             args=("--address", "127.0.0.1"))
        case("39.7", "1024^2: 8 bakes, a stalled download of each", stalled, binary, work,
             height="rock06_height.png")
        case("39.8", "1024^2: 12 concurrent writes, a control pending", writes, binary, work,
             height="rock06_height.png")
        case("39.9", "malformed HTTP (%d kinds)" % len(MALFORMED), malformed, binary, work)
        case("39.10", "the controls: CLI's rules, NUL, 165 odd values", controls, binary, work)

        d = os.path.join(work, "39.11")
        os.makedirs(os.path.join(d, "sub"))
        shutil.copy(os.path.join(FIXTURES, "rock06_128.png"), os.path.join(d, "sub", "h.png"))
        reasons, t0 = [], time.monotonic()
        server = Serve(binary, "sub/h.png", ["--scale", "16", "--rays", "16", "--quiet"], d)
        try:
            wait_bake(server)
            watch(server, reasons, d)
            if not server.alive():
                reasons.append("serve died")
        except Exception as e:
            reasons.append("%s: %s" % (type(e).__name__, e))
        err = server.close()
        if re.search(r"Sanitizer|runtime error:", err):
            reasons.append("a sanitizer's report")
        what = "the watch: folder moved and made again, an unseen change"
        results.append(("39.11", what, reasons, ""))
        print("%-5s %-62s %-10s %s" % ("39.11", what, "CLEAN" if not reasons else "NOT CLEAN",
                                       "%.1f s" % (time.monotonic() - t0) if not reasons
                                       else "; ".join(reasons)), flush=True)
        quoting(binary, work)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    clean = sum(1 for r in results if not r[2])
    print("%d cases tried, %d clean" % (len(results), clean))
    return 0 if clean == len(results) else 1


if __name__ == "__main__":
    sys.exit(main())
