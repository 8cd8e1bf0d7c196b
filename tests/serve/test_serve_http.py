"""`bumpbake serve` without a browser: its command line, what its server
refuses, and its watch of the height (a save by rename, a save in several
writes, a broken save), through the state it publishes. Runs everywhere
make test runs (no Chromium needed)."""

import http.client
import json
import os
import re
import shlex
import shutil
import subprocess
import time
import urllib.parse

import pytest

import serve_browser as sb

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BIN = os.environ.get("BB_BIN", os.path.join(ROOT, "build", "bumpbake"))
FIXTURES = os.path.join(ROOT, "fixtures")
SLOW = 120


def request(url, method="GET", headers=None, path=""):
    u = urllib.parse.urlsplit(url)
    c = http.client.HTTPConnection(u.hostname, u.port, timeout=30)
    c.request(method, u.path + path, headers=headers or {})
    r = c.getresponse()
    body = r.read()
    c.close()
    return r.status, body


def state(server):
    status, body = request(server.url, path="state")
    assert status == 200
    return json.loads(body)


def wait_bake(server, after, what):
    return sb.wait_for(lambda: (lambda s: s if s.get("bake", {}).get("id", 0) > after
                                and not s["baking"] else None)(state(server)),
                       SLOW, what, interval=0.02)


@pytest.fixture
def served(tmp_path):
    shutil.copy(os.path.join(FIXTURES, "rock06_128.png"), tmp_path / "h.png")
    s = sb.Server(BIN, str(tmp_path / "h.png"), ["--scale", "16", "--rays", "16", "--quiet"])
    wait_bake(s, 0, "the first bake")
    yield s, tmp_path
    s.close()


def run(*args):
    return subprocess.run([BIN, "serve", *args], capture_output=True, text=True, timeout=60)


def test_command_line_errors():
    r = run(os.path.join(FIXTURES, "rock06_128.png"))
    assert r.returncode == 2 and "--scale is required" in r.stderr
    r = run("/nonexistent/h.png", "--scale", "4")
    assert r.returncode == 1 and "/nonexistent/h.png" in r.stderr
    r = run(os.path.join(FIXTURES, "rock06_128.png"), "--scale", "4", "--bias", "-1")
    assert r.returncode == 2 and "bias" in r.stderr
    r = run(os.path.join(FIXTURES, "rock06_128.png"), "--scale", "4", "--address", "nowhere")
    assert r.returncode == 2 and "not an IPv4 or IPv6 address" in r.stderr
    r = run(os.path.join(FIXTURES, "rock06_128.png"), "--scale", "4", "--port", "70000")
    assert r.returncode == 2


def test_the_port_taken_is_an_error(served):
    s, _ = served
    port = urllib.parse.urlsplit(s.url).port
    # The threads a failed start had begun are stopped before what they
    # read is freed: the one line, every time (a bake thread reading the
    # freed command printed a second, garbled line in about 1 run in 3).
    for _ in range(12):
        r = run(os.path.join(FIXTURES, "rock06_128.png"), "--scale", "4", "--port", str(port))
        assert r.returncode == 1 and "cannot listen" in r.stderr
        assert len(r.stderr.splitlines()) == 1, r.stderr


def test_the_server_refuses(served):
    s, d = served
    assert request(s.url)[0] == 200
    assert request(s.url, path="../h.png")[0] == 404       # no request names a file
    assert request(s.url, path="map/h.png")[0] == 404
    assert request(s.url, path="map/ssbump_ao")[0] == 200
    assert request(s.url, headers={"Host": "attacker.example:80"})[0] == 403  # rebinding
    assert request(s.url, "POST", path="write")[0] == 403  # no X-Bumpbake header
    assert request(s.url, "DELETE")[0] == 405
    status, body = request(s.url, "POST", {"X-Bumpbake": "1"}, "params?rays=0")
    assert status == 400 and "rays" in json.loads(body)["error"]
    # a control's value is parsed by bake's option of its name: bake's words
    status, body = request(s.url, "POST", {"X-Bumpbake": "1"}, "params?rays=x")
    assert status == 400 and json.loads(body)["error"] == "--rays needs an integer (got 'x')"
    status, body = request(s.url, "POST", {"X-Bumpbake": "1"}, "params?scale=8&bias=near")
    assert status == 400 and json.loads(body)["error"] == "--bias needs a number (got 'near')"
    status, body = request(s.url, "POST", {"X-Bumpbake": "1"}, "params?path=/etc/passwd")
    assert status == 400 and "unknown control" in json.loads(body)["error"]
    assert sorted(os.listdir(d)) == ["h.png"]  # nothing written unless asked


def response_headers(url, method="GET", headers=None, path=""):
    u = urllib.parse.urlsplit(url)
    c = http.client.HTTPConnection(u.hostname, u.port, timeout=30)
    c.request(method, u.path + path, headers=headers or {})
    r = c.getresponse()
    got = {k.lower(): v for k, v in r.getheaders()}
    c.close()  # an event stream is left unread
    return r.status, got


def test_no_page_may_frame_it_and_it_loads_nothing_from_elsewhere(served):
    s, _ = served
    cases = [("GET", {}, ""), ("GET", {}, "index.html"), ("GET", {}, "serve.js"),
             ("GET", {}, "serve.css"), ("GET", {}, "state"), ("GET", {}, "controls"),
             ("GET", {}, "map/ssbump_ao"), ("GET", {}, "events"), ("GET", {}, "nothing"),
             ("HEAD", {}, ""), ("GET", {"Host": "attacker.example:80"}, ""),
             ("DELETE", {}, ""), ("POST", {}, "write"),
             ("POST", {"X-Bumpbake": "1"}, "params?rays=x")]
    for method, headers, path in cases:
        status, got = response_headers(s.url, method, headers, path)
        what = "%s /%s -> %d" % (method, path, status)
        assert got.get("x-frame-options") == "DENY", what
        csp = [d.strip() for d in got.get("content-security-policy", "").split(";")]
        assert "frame-ancestors 'none'" in csp, (what, csp)
        assert "default-src 'none'" in csp and "script-src 'self'" in csp, (what, csp)
        assert not [d for d in csp if "unsafe" in d or "*" in d or "http" in d], (what, csp)
        assert got.get("x-content-type-options") == "nosniff", what
    # the page has no inline script or style the policy would stop
    html = request(s.url, path="index.html")[1].decode()
    assert not re.search(r"<script(?![^>]*\bsrc=)", html) and "<style" not in html
    assert not re.search(r"\sstyle=|\son[a-z]+=", html)


FLOAT_MAX = 3.40282347e38  # a float's largest: help prints no top for it ("> 0")
# The options the page offers, in its order (serve_params.c names them once).
CONTROLS = ["scale", "rays", "slices", "bias", "bounce", "bounces", "brightness", "light-color"]


def test_the_page_takes_its_controls_from_the_library(served):
    s, _ = served
    status, body = request(s.url, path="controls")
    assert status == 200
    served_controls = json.loads(body)
    rows = sb.library_rows("serve")
    assert [c["name"] for c in served_controls["controls"]] == CONTROLS
    for c in served_controls["controls"]:
        want = rows[c["name"]]
        for field in ("type", "value_name", "default", "range", "help"):
            assert c[field] == want[field], (c["name"], field, c[field], want[field])
        assert c["key"] == c["name"].replace("-", "_")
        assert c["place"] == ("light" if c["name"] == "light-color" else "bake")
        if "min" not in want:
            assert "min" not in c and "max" not in c, c
            continue
        assert c["min"] == want["min"] and c["min_exclusive"] == want["min_exclusive"], c
        if "max" in want:
            assert c["max"] == want["max"], c
        else:
            assert c.get("max", FLOAT_MAX) >= FLOAT_MAX, c
    # what a control goes back to: the value a command holds without it
    unset = {c["name"]: c["unset"] for c in served_controls["controls"]}
    assert unset == {"scale": "0", "rays": "256", "slices": "0", "bias": "0.55", "bounce": "0",
                     "bounces": "0", "brightness": "", "light-color": "1,1,1"}, unset
    # the picture's ranges: render's --view and --light elevations
    library = sb.library_ranges(BIN)
    assert sorted(served_controls["view"]) == sorted(library) == ["light_elevation",
                                                                   "view_elevation"]
    for name, want in library.items():
        assert served_controls["view"][name] == want, name
    # the page's files say none of their own: no range (the progress bar's
    # max is a fraction) and no control, in the page or its script
    status, html = request(s.url, path="index.html")
    assert status == 200
    inputs = re.findall(r"<input[^>]*>", html.decode())
    assert inputs and not [i for i in inputs if re.search(r"\b(min|max)=", i)], inputs
    names = "|".join(re.escape(n) for n in CONTROLS)
    assert not re.search(r"\b(%s)\b" % names, html.decode()), "a control in index.html"
    status, js = request(s.url, path="serve.js")
    assert status == 200
    code = re.sub(r"//.*", "", js.decode())  # the comments may say "90 = overhead"
    assert not re.search(r"\b90\b", code), "an elevation's top in serve.js"
    assert not re.search(r"[\"'](%s)[\"'=]" % names, code), "a control named in serve.js"


def test_with_address_every_path_needs_the_token(tmp_path):
    shutil.copy(os.path.join(FIXTURES, "rock06_128.png"), tmp_path / "h.png")
    s = sb.Server(BIN, str(tmp_path / "h.png"),
                  ["--scale", "8", "--rays", "16", "--address", "127.0.0.1", "--quiet"])
    try:
        u = urllib.parse.urlsplit(s.url)
        token = u.path.strip("/")
        assert len(token) == 32, s.url
        assert request(s.url)[0] == 200
        assert request("http://%s/" % u.netloc)[0] == 404
        assert request("http://%s/state" % u.netloc)[0] == 404
        assert request("http://%s/%s/state" % (u.netloc, "0" * 32))[0] == 404
    finally:
        s.close()


def save_in_place_in_pieces(path, data, pause):
    with open(path, "r+b") as f:  # as a program that writes over the file, in goes
        f.truncate(0)
        f.write(data[: len(data) // 2])
        f.flush()
        os.fsync(f.fileno())
        time.sleep(pause)
        f.write(data[len(data) // 2:])
        f.flush()


def test_saves_rebake(served):
    s, d = served
    first = state(s)["bake"]
    with open(os.path.join(FIXTURES, "bricks_128x64.png"), "rb") as f:
        bricks = f.read()
    with open(os.path.join(FIXTURES, "rock06_128.png"), "rb") as f:
        rock = f.read()
    # by rename
    sb.save_by_rename(bricks, str(d / "h.png"))
    st = wait_bake(s, first["id"], "the renamed save's bake")
    assert (st["bake"]["width"], st["bake"]["height"]) == (128, 64) and st["error"] == ""
    # written in place in two goes, the file closed at the end: whatever was
    # seen in between, the whole file is baked last and no error stays
    save_in_place_in_pieces(str(d / "h.png"), rock, 0.05)
    sb.wait_for(lambda: (lambda x: x["bake"]["height"] == 128 and not x["baking"]
                         and x["error"] == "")(state(s)), SLOW, "the whole save baked")
    # a broken save: the error shown, the last good maps kept
    last = state(s)["bake"]["id"]
    sb.save_by_rename(rock[:500], str(d / "h.png"))
    st = sb.wait_for(lambda: (lambda x: x if x["error"] else None)(state(s)), SLOW, "the error")
    assert "h.png" in st["error"] and st["bake"]["id"] == last
    assert request(s.url, path="map/ssbump_ao")[0] == 200
    # and the process is still there for the next save
    sb.save_by_rename(rock, str(d / "h.png"))
    st = wait_bake(s, last, "the next good save")
    assert st["error"] == ""
    assert s.proc.poll() is None


def test_a_newer_control_cancels_the_bake_in_flight(tmp_path):
    shutil.copy(os.path.join(FIXTURES, "rock06_height.png"), tmp_path / "h.png")
    s = sb.Server(BIN, str(tmp_path / "h.png"), ["--scale", "64", "--rays", "4096"])
    try:
        sb.wait_for(lambda: state(s)["baking"], SLOW, "the first bake started")
        # a second request while the slow first one runs
        status, _ = request(s.url, "POST", {"X-Bumpbake": "1"}, "params?rays=1")
        assert status == 200
        st = wait_bake(s, 0, "a bake at rays 1")
        assert st["bake"]["id"] == 1, "the first, slow bake was cancelled, not shown"
        assert st["params"]["rays"] == 1 and st["bake"]["slices"] == 1
    finally:
        s.close()
    # serve said nothing of the cancelled bake but the bake that was shown
    err = s.proc.stderr.read()
    assert err.count("serve: bake") == 1, err


def test_the_brightness_map_switches_on_and_off(tmp_path):
    shutil.copy(os.path.join(FIXTURES, "rock06_128.png"), tmp_path / "h.png")
    shutil.copy(os.path.join(FIXTURES, "rock06_128.png"), tmp_path / "b.png")
    s = sb.Server(BIN, str(tmp_path / "h.png"),
                  ["--scale", "8", "--rays", "16", "--brightness", str(tmp_path / "b.png"),
                   "--quiet"])
    try:
        st = wait_bake(s, 0, "the first bake")
        assert st["params"]["brightness"] and "--brightness" in st["command"]
        assert "--brightness" in st["bake"]["command"]
        status, _ = request(s.url, "POST", {"X-Bumpbake": "1"}, "params?brightness=off")
        assert status == 200
        st = wait_bake(s, st["bake"]["id"], "the bake without it")
        assert not st["params"]["brightness"] and "--brightness" not in st["bake"]["command"]
        # a save of the brightness map bakes again too (it is watched)
        status, _ = request(s.url, "POST", {"X-Bumpbake": "1"}, "params?brightness=on")
        st = wait_bake(s, st["bake"]["id"], "the bake with it")
        with open(os.path.join(FIXTURES, "rock06_128.png"), "rb") as f:
            sb.save_by_rename(f.read(), str(tmp_path / "b.png"))
        wait_bake(s, st["bake"]["id"], "the bake after the brightness map's save")
    finally:
        s.close()
    s = sb.Server(BIN, str(tmp_path / "h.png"), ["--scale", "8", "--rays", "16", "--quiet"])
    try:
        status, body = request(s.url, "POST", {"X-Bumpbake": "1"}, "params?brightness=on")
        assert status == 400 and "no --brightness FILE" in json.loads(body)["error"]
    finally:
        s.close()


def test_write_writes_the_maps_shown_as_bake_would(served):
    s, d = served
    # the maps shown are the line's bake: written from memory, no second bake
    status, body = request(s.url, "POST", {"X-Bumpbake": "1"}, "write")
    assert status == 200, body
    reply = json.loads(body)
    assert reply["from"] == "memory", reply
    paths = [o["path"] for o in reply["outputs"]]
    assert sorted(os.path.basename(p) for p in paths) == ["h_ao.png", "h_normal.png",
                                                          "h_ssbump.png"]
    written = {p: open(p, "rb").read() for p in paths}
    for p in paths:
        os.remove(p)
    words = shlex.split(state(s)["command"])
    assert words[:2] == ["bumpbake", "bake"]
    subprocess.run([BIN, *words[1:]], check=True, timeout=SLOW,
                   stdout=subprocess.DEVNULL)
    for p in paths:
        assert open(p, "rb").read() == written[p], p + " differs from bumpbake bake's"
        os.remove(p)
    # after a broken save the maps shown are not the file's: "write" does
    # what bake would (bake again, and fail on the file), writing nothing
    good = open(d / "h.png", "rb").read()
    before = state(s)["bake"]["id"]
    sb.save_by_rename(good[: len(good) // 3], str(d / "h.png"))
    sb.wait_for(lambda: state(s)["error"], SLOW, "the broken save's error")
    status, body = request(s.url, "POST", {"X-Bumpbake": "1"}, "write")
    assert status == 422 and "h.png" in json.loads(body)["error"], body
    assert not any(os.path.exists(p) for p in paths)
    # a good save again: from memory again
    sb.save_by_rename(good, str(d / "h.png"))
    wait_bake(s, before, "the bake of the good save")
    status, body = request(s.url, "POST", {"X-Bumpbake": "1"}, "write")
    assert status == 200 and json.loads(body)["from"] == "memory", body


@pytest.mark.parametrize("args,params", [
    # --slices override --rays, but the files record the rays asked: the
    # line names them, or typing it would make other bytes
    (["--slices", "8", "--rays", "32", "--ao", "a.png"], ["rays=64"]),
    # the page lights the ssbump with the brightness; the write names only
    # an ao, which it does nothing for: the line leaves it out (bake would
    # refuse it), and serve starts
    (["--rays", "16", "--ao", "a.png", "--brightness", "b.png"], []),
    (["--rays", "16", "--ssbump", "s.vtf", "--texture-format", "bc3",
      "--bounce-albedo", "b.png", "--bounce", "1"], ["scale=12"]),
    # a bounce set on the page does nothing for a normal map alone
    (["--rays", "16", "--normal", "n.png"], ["bounce=0.5"]),
], ids=["rays-under-slices", "brightness-without-ssbump", "vtf-bounce-albedo",
        "bounce-without-traced-map"])
def test_the_line_recorded_is_a_bake_of_the_same_bytes(tmp_path, args, params):
    shutil.copy(os.path.join(FIXTURES, "rock06_128.png"), tmp_path / "h.png")
    shutil.copy(os.path.join(FIXTURES, "rock06_128.png"), tmp_path / "b.png")
    s = sb.Server(BIN, "h.png", ["--scale", "8", "--quiet", *args], cwd=str(tmp_path))
    try:
        last = wait_bake(s, 0, "the first bake")["bake"]["id"]
        for p in params:
            status, body = request(s.url, "POST", {"X-Bumpbake": "1"}, "params?" + p)
            assert status == 200, body
            last = wait_bake(s, last, "the bake of " + p)["bake"]["id"]
        status, body = request(s.url, "POST", {"X-Bumpbake": "1"}, "write")
        assert status == 200, body
        line = state(s)["command"]
    finally:
        s.close()
    paths = [os.path.join(tmp_path, o["path"]) for o in json.loads(body)["outputs"]]
    written = {p: open(p, "rb").read() for p in paths}
    for p in paths:
        os.remove(p)
    words = shlex.split(line)
    assert words[:2] == ["bumpbake", "bake"]
    r = subprocess.run([BIN, *words[1:], "--quiet"], cwd=str(tmp_path), capture_output=True,
                       text=True, timeout=SLOW)
    assert r.returncode == 0, line + ": " + r.stderr
    for p in paths:
        assert open(p, "rb").read() == written[p], p + " differs from " + line


# ------------------------------------------------------ slow and many clients

def slow_sockets(url, count, first=b"GET / HTTP/1.1\r\n"):
    """count connections that have sent first and nothing more yet."""
    import socket

    u = urllib.parse.urlsplit(url)
    socks = []
    for _ in range(count):
        k = socket.create_connection((u.hostname, u.port), timeout=10)
        if first:
            k.sendall(first)
        socks.append(k)
    return socks


def closed_by_server(k, timeout):
    """1 when the server closed k (end of file or a reset) within timeout."""
    import socket

    k.settimeout(timeout)
    try:
        return k.recv(4096) == b""
    except (ConnectionResetError, BrokenPipeError):
        return True
    except socket.timeout:
        return False


def test_the_page_loads_while_70_slow_clients_hold_connections(served):
    import time

    s, _ = served
    socks = slow_sockets(s.url, 70)
    try:
        for k in socks:  # a header line each, as a slowloris sends them
            k.sendall(b"X-Slow: 1\r\n")
        t0 = time.monotonic()
        assert request(s.url)[0] == 200
        assert request(s.url, path="state")[0] == 200
        assert request(s.url, path="map/ssbump_ao")[0] == 200
        assert time.monotonic() - t0 < 20
        # headers that take longer than the bound are cut, a line every 2 s
        # or not: well within 25 s every slow connection is closed
        end = time.monotonic() + 25
        open_ = list(socks)
        while open_ and time.monotonic() < end:
            for k in list(open_):
                try:
                    k.sendall(b"X-Slow: 2\r\n")
                except OSError:
                    open_.remove(k)
                    continue
                if closed_by_server(k, 0.01):
                    open_.remove(k)
            time.sleep(2)
        assert not open_, "%d slow connections still open after 25 s" % len(open_)
    finally:
        for k in socks:
            k.close()


def open_event_streams(url, count, refused_ok=False):
    """count /events streams, each read up to its first event; with
    refused_ok, None when one is refused (503: too many)."""
    import socket

    u = urllib.parse.urlsplit(url)
    streams = []
    for _ in range(count):
        k = socket.create_connection((u.hostname, u.port), timeout=10)
        streams.append(k)
        k.sendall(("GET %sevents HTTP/1.1\r\nHost: %s\r\n\r\n" % (u.path, u.netloc)).encode())
        got = b""
        while b"\r\n\r\n" not in got or (got.startswith(b"HTTP/1.1 200")
                                          and b"data: " not in got):
            chunk = k.recv(65536)
            assert chunk, "an event stream closed before its first event: %r" % got[:200]
            got += chunk
        if refused_ok and got.startswith(b"HTTP/1.1 503"):
            for x in streams:
                x.close()
            return None
        assert got.startswith(b"HTTP/1.1 200"), got[:100]
    return streams


STREAM_LIMIT = 256  # serve_http.c: event streams at once


def test_event_streams_leave_room_and_free_their_slot_when_the_client_goes(served):
    import time

    s, _ = served
    streams = open_event_streams(s.url, STREAM_LIMIT)
    try:
        assert request(s.url)[0] == 200  # the page, beside them
        assert response_headers(s.url, path="events")[0] == 503  # too many streams
    finally:
        for k in streams:
            k.close()
    # their slots come back within seconds of the clients leaving
    t0 = time.monotonic()
    streams = sb.wait_for(lambda: open_event_streams(s.url, STREAM_LIMIT, refused_ok=True), 30,
                          "every stream's slot free again", interval=0.2)
    print("%d streams again after %.2f s" % (STREAM_LIMIT, time.monotonic() - t0))
    try:
        assert request(s.url, path="state")[0] == 200
    finally:
        for k in streams:
            k.close()


def test_with_address_one_client_has_a_bounded_share(tmp_path):
    shutil.copy(os.path.join(FIXTURES, "rock06_128.png"), tmp_path / "h.png")
    s = sb.Server(BIN, str(tmp_path / "h.png"),
                  ["--scale", "8", "--rays", "16", "--address", "127.0.0.1", "--quiet"])
    socks = []
    try:
        assert request(s.url)[0] == 200
        socks = slow_sockets(s.url, 80, first=b"")
        # the server closes what is over one client's share at once
        refused = [k for k in socks if closed_by_server(k, 0.5)]
        assert 8 <= len(refused) < 80, len(refused)
        for k in socks:
            k.close()
        socks = []
        assert sb.wait_for(lambda: request(s.url)[0] == 200, 30, "the page again")
    finally:
        for k in socks:
            k.close()
        s.close()


# ------------------------------------------------------------- memory bound

def sanitized(pid):
    """1 when the process runs under AddressSanitizer (make DEBUG=1), whose
    quarantine keeps freed memory: its RSS says nothing of serve's."""
    with open("/proc/%d/maps" % pid) as f:
        return "libasan" in f.read()


def memory_mb(pid, key):
    """VmRSS or VmHWM (the peak) of a process, in MB."""
    with open("/proc/%d/status" % pid) as f:
        for line in f:
            if line.startswith(key + ":"):
                return int(line.split()[1]) / 1024
    raise AssertionError("no %s for %d" % (key, pid))


@pytest.fixture
def served_1024(tmp_path):
    shutil.copy(os.path.join(FIXTURES, "rock06_height.png"), tmp_path / "h.png")
    s = sb.Server(BIN, str(tmp_path / "h.png"), ["--scale", "64", "--rays", "16"])
    wait_bake(s, 0, "the first bake")
    yield s, tmp_path
    s.close()


def test_concurrent_writes_are_one_write_at_a_time(served_1024):
    import concurrent.futures

    s, d = served_1024
    base = memory_mb(s.proc.pid, "VmRSS")
    # a control changed: the maps shown are not the line's, so a write bakes
    status, _ = request(s.url, "POST", {"X-Bumpbake": "1"}, "params?scale=63")
    assert status == 200
    with concurrent.futures.ThreadPoolExecutor(12) as pool:
        replies = list(pool.map(lambda _: request(s.url, "POST", {"X-Bumpbake": "1"}, "write"),
                                range(12)))
    assert [r[0] for r in replies] == [200] * 12, replies
    peak = memory_mb(s.proc.pid, "VmHWM")
    asan = sanitized(s.proc.pid)
    words = shlex.split(state(s)["command"])
    assert "63" in words
    s.close()
    err = s.proc.stderr.read()
    writes = err.count("serve: wrote the maps")
    print("12 writes at once: %d runs, RSS %.0f MB before, peak %.0f MB" % (writes, base, peak))
    # the requests that wait while one write runs are answered by the next
    assert 1 <= writes <= 3, err
    # one bake of a 1024 x 1024 height at a time besides the one shown
    assert peak < base + 400 or asan, (base, peak)


def test_stalled_downloads_do_not_hold_the_maps(served_1024):
    import socket

    s, d = served_1024
    u = urllib.parse.urlsplit(s.url)
    base = memory_mb(s.proc.pid, "VmRSS")
    stalled = []
    try:
        last = state(s)["bake"]["id"]
        for i in range(8):
            k = socket.create_connection((u.hostname, u.port), timeout=10)
            k.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
            k.sendall(("GET %smap/ssbump_ao HTTP/1.1\r\nHost: %s\r\n\r\n"
                       % (u.path, u.netloc)).encode())
            assert k.recv(1024).startswith(b"HTTP/1.1 200")
            stalled.append(k)  # read no further
            status, _ = request(s.url, "POST", {"X-Bumpbake": "1"}, "params?scale=%d" % (70 + i))
            assert status == 200
            last = wait_bake(s, last, "bake %d" % i)["bake"]["id"]
        rss = memory_mb(s.proc.pid, "VmRSS")
        print("8 stalled downloads of 8 bakes: RSS %.0f MB, from %.0f MB" % (rss, base))
        assert rss < base + 150 or sanitized(s.proc.pid), (base, rss)
        assert request(s.url)[0] == 200
    finally:
        for k in stalled:
            k.close()


# ---------------------------------------------------------------- the watch

def test_a_folder_moved_away_and_made_again_keeps_the_watch(tmp_path):
    os.mkdir(tmp_path / "sub")
    shutil.copy(os.path.join(FIXTURES, "rock06_128.png"), tmp_path / "sub" / "h.png")
    s = sb.Server(BIN, "sub/h.png", ["--scale", "8", "--rays", "16", "--quiet"],
                  cwd=str(tmp_path))
    try:
        first = wait_bake(s, 0, "the first bake")["bake"]["id"]
        os.rename(tmp_path / "sub", tmp_path / "sub2")
        # the height is gone from its path: the page says so
        st = sb.wait_for(lambda: (lambda x: x if x["error"] else None)(state(s)), 60,
                         "the height's loss reported")
        assert "sub/h.png" in st["error"], st["error"]
        os.mkdir(tmp_path / "sub")
        with open(os.path.join(FIXTURES, "bricks_128x64.png"), "rb") as f:
            sb.save_by_rename(f.read(), str(tmp_path / "sub" / "h.png"))
        st = sb.wait_for(lambda: (lambda x: x if x.get("bake", {}).get("height") == 64
                                  and not x["baking"] else None)(state(s)), 60,
                         "the save in the new folder baked")
        assert st["error"] == "" and st["bake"]["id"] > first
        # and the folder moved away is not watched any more
        last = st["bake"]["id"]
        with open(os.path.join(FIXTURES, "rock06_128.png"), "rb") as f:
            sb.save_by_rename(f.read(), str(tmp_path / "sub2" / "h.png"))
        time.sleep(1.5)
        assert state(s)["bake"]["id"] == last
    finally:
        s.close()


def test_a_deleted_height_is_reported(served):
    s, d = served
    assert state(s)["error"] == ""
    os.remove(d / "h.png")
    st = sb.wait_for(lambda: (lambda x: x if x["error"] else None)(state(s)), 60,
                     "the deletion reported")
    assert "h.png" in st["error"] and st["bake"]["id"] >= 1
    # the maps shown stay; "write" does what bake would: fail on the file
    status, body = request(s.url, "POST", {"X-Bumpbake": "1"}, "write")
    assert status == 422 and "h.png" in json.loads(body)["error"], body
    assert sorted(os.listdir(d)) == []


def test_write_from_memory_only_while_the_height_is_the_one_baked(served, tmp_path_factory):
    s, d = served
    # a change the watch cannot see: written through a second name of the
    # file in another folder (inotify reports it to that folder only)
    other = tmp_path_factory.mktemp("other")
    os.link(d / "h.png", other / "same.png")
    with open(os.path.join(FIXTURES, "bricks_128x64.png"), "rb") as f:
        bricks = f.read()
    with open(other / "same.png", "r+b") as f:
        f.truncate(0)
        f.write(bricks)
    time.sleep(1)
    assert state(s)["bake"]["height"] == 128, "the watch saw it: no test"
    status, body = request(s.url, "POST", {"X-Bumpbake": "1"}, "write")
    assert status == 200, body
    reply = json.loads(body)
    assert reply["from"] == "bake" and reply["height"] == 64, reply
    assert "h.png" in reply.get("reason", ""), reply


# ------------------------------------------- the controls, as the CLI checks

def cli_refusal(*args):
    """What `bumpbake bake` says of these options, without its prefix."""
    r = subprocess.run([BIN, "bake", os.path.join(FIXTURES, "rock06_128.png"), "-o",
                        "/nonexistent/x", *args], capture_output=True, text=True, timeout=60)
    assert r.returncode == 2, r.stderr
    return r.stderr.strip().split(": ", 1)[1]


def params(server, query):
    status, body = request(server.url, "POST", {"X-Bumpbake": "1"}, "params?" + query)
    return status, json.loads(body)


def test_the_controls_are_checked_as_the_command_line_is(served):
    s, _ = served
    # bounces without bounce: the CLI refuses it, so does the page, in its words
    status, body = params(s, "bounces=3")
    assert status == 400 and body["error"] == cli_refusal("--scale", "16", "--bounces", "3")
    assert "--bounces" not in state(s)["command"]
    # a NUL in a value is no end of it: refused as the text it is
    status, body = params(s, "scale=1%00x")
    assert status == 400 and body["error"] == "--scale needs a number (got '1\\0x')", body
    status, body = params(s, "sca%00le=1")
    assert status == 400 and "unknown control" in body["error"], body
    assert state(s)["params"]["scale"] == 16
    # with bounce, bounces is taken; bounce back to 0 alone is refused,
    # both back to their defaults leave both out of the line
    status, body = params(s, "bounce=0.5&bounces=3")
    assert status == 200, body
    assert "--bounce 0.5 --bounces 3" in state(s)["command"]
    status, body = params(s, "bounce=0")
    assert status == 400 and body["error"] == cli_refusal("--scale", "16", "--bounces", "3")
    status, body = params(s, "bounce=0&bounces=0")
    assert status == 200, body
    assert "--bounce" not in state(s)["command"]
    # slices 0 is "from rays": --slices left out, not refused as out of 1..256
    status, body = params(s, "slices=8")
    assert status == 200 and "--slices 8" in state(s)["command"]
    status, body = params(s, "slices=0&rays=64")
    assert status == 200, body
    assert "--slices" not in state(s)["command"] and "--rays 64" in state(s)["command"]


# ------------------------------------------------ the line, typed in a shell

@pytest.mark.parametrize("name", ["x;touch PWNED;y.png", "my rock.png", "it's $HOME.png"])
def test_the_line_shown_is_quoted_for_a_shell(tmp_path, name):
    shutil.copy(os.path.join(FIXTURES, "rock06_128.png"), tmp_path / name)
    s = sb.Server(BIN, name, ["--scale", "8", "--rays", "16", "--quiet"], cwd=str(tmp_path))
    try:
        st = wait_bake(s, 0, "the first bake")
        line = st["command"]
        assert st["bake"]["command"] == line
        words = shlex.split(line)
        assert words[:3] == ["bumpbake", "bake", name], line
        status, body = request(s.url, "POST", {"X-Bumpbake": "1"}, "write")
        assert status == 200, body
        paths = [o["path"] for o in json.loads(body)["outputs"]]
        written = {p: open(os.path.join(tmp_path, p), "rb").read() for p in paths}
        for p in paths:
            os.remove(os.path.join(tmp_path, p))
        # the line as it is, typed in sh, with this build's bumpbake
        r = subprocess.run(["sh", "-c", 'bumpbake() { "$BB" "$@"; }; ' + line],
                           cwd=str(tmp_path), env=dict(os.environ, BB=BIN),
                           capture_output=True, text=True, timeout=SLOW)
        assert r.returncode == 0, r.stderr
        assert not os.path.exists(tmp_path / "PWNED")
        for p in paths:
            assert open(os.path.join(tmp_path, p), "rb").read() == written[p], p
    finally:
        s.close()


# ------------------------------------------------------------- the progress

def test_the_state_names_the_stage_running_bounce_included(tmp_path):
    shutil.copy(os.path.join(FIXTURES, "rock06_128.png"), tmp_path / "h.png")
    # 32 slices: a trace of tenths of a second, the bounces' seconds
    s = sb.Server(BIN, str(tmp_path / "h.png"),
                  ["--scale", "16", "--rays", "1024", "--bounce", "0.5", "--quiet"])
    seen = []
    try:
        end = time.monotonic() + SLOW
        while time.monotonic() < end:
            st = state(s)
            if st["baking"] and (not seen or seen[-1] != st["stage"]):
                seen.append(st["stage"])
            if st.get("bake"):
                break
            time.sleep(0.01)
        assert st.get("bake"), "no bake in %d s" % SLOW
        assert st["stage"] is None and not st["baking"]
    finally:
        s.close()
    print("stages seen:", seen)
    # in the order they run; a short one may pass between two looks
    order = ["load and smooth", "trace", "bounce", "derive"]
    assert seen and all(x in order for x in seen), seen
    assert [order.index(x) for x in seen] == sorted(order.index(x) for x in seen), seen
    assert "trace" in seen and "bounce" in seen, seen


TEXTURE_NAMES = ["ssbump_ao", "normal_height", "bent", "weights"]


def get_map(server, name, since=None):
    """(status, headers, body) of map/NAME, ?since=ID when given."""
    u = urllib.parse.urlsplit(server.url)
    c = http.client.HTTPConnection(u.hostname, u.port, timeout=30)
    c.request("GET", u.path + "map/" + name + ("?since=%d" % since if since else ""))
    r = c.getresponse()
    got = {k.lower(): v for k, v in r.getheaders()}
    body = r.read()
    c.close()
    return r.status, got, body


def save_pgm(path, h):
    """h (uint16, rows x columns) saved by rename as a 16-bit PGM: a file
    format needing no encoder to write, which bumpbake reads."""
    rows, cols = h.shape
    sb.save_by_rename(b"P5\n%d %d\n65535\n" % (cols, rows) + h.astype(">u2").tobytes(), path)


def test_an_edit_is_sent_as_the_rectangle_it_changed(tmp_path):
    import numpy as np

    y, x = np.mgrid[0:128, 0:128] * (2 * np.pi / 128)
    h = 0.5 + 0.2 * np.sin(3 * x) * np.cos(2 * y) + 0.05 * np.random.RandomState(7).rand(128, 128)
    h = np.round(h * 65535).astype(np.uint16)
    path = str(tmp_path / "h.pgm")
    save_pgm(path, h)
    s = sb.Server(BIN, path, ["--scale", "16", "--rays", "16", "--quiet"])
    try:
        before = wait_bake(s, 0, "the first bake")["bake"]
        assert before["base"] == 0 and before["changed"] == [0, 0, 128, 128]
        # a block raised in the middle, then one across the periodic edge
        edits = [((60, 66), (40, 46)), ((90, 96), (-2, 4))]
        for (r0, r1), (c0, c1) in edits:
            shown = {n: get_map(s, n)[2] for n in TEXTURE_NAMES}
            rows = np.arange(r0, r1) % 128
            cols = np.arange(c0, c1) % 128
            h[np.ix_(rows, cols)] += 600  # a brush of 0.01: 0.15 texels at scale 16
            save_pgm(path, h)
            bake = wait_bake(s, before["id"], "the edit's bake")["bake"]
            x0, y0, w, hh = bake["changed"]
            assert bake["base"] == before["id"], (bake["base"], bake["changed"], bake["id"])
            assert 0 < w * hh < 128 * 128 / 4, bake["changed"]
            assert all(x0 <= c < x0 + w for c in cols) and all(y0 <= r < y0 + hh for r in rows)
            for name in TEXTURE_NAMES:
                status, headers, part = get_map(s, name, since=before["id"])
                assert status == 200 and headers["x-bake-id"] == str(bake["id"])
                assert headers["x-region"] == "%d,%d,%d,%d" % (x0, y0, w, hh)
                assert len(part) == 4 * w * hh
                whole = get_map(s, name)[2]
                patched = np.frombuffer(shown[name], np.uint8).reshape(128, 128, 4).copy()
                patched[y0:y0 + hh, x0:x0 + w] = np.frombuffer(part, np.uint8).reshape(hh, w, 4)
                # the bake before with the rectangle written in is the new bake, bit for bit
                assert patched.tobytes() == whole, name
                if name == "ssbump_ao":
                    assert whole != shown[name]  # the edit changed the picture
            # a since that is not the bake's base: the whole texture
            status, headers, body = get_map(s, "ssbump_ao", since=before["id"] + 100)
            assert status == 200 and "x-region" not in headers and len(body) == 4 * 128 * 128
            before = bake
        # a control changes every texel: a whole bake, no base
        status, _ = request(s.url, "POST", {"X-Bumpbake": "1"}, "params?scale=12")
        assert status == 200
        bake = wait_bake(s, before["id"], "the control's bake")["bake"]
        assert bake["base"] == 0 and bake["changed"] == [0, 0, 128, 128]
        status, headers, body = get_map(s, "bent", since=before["id"])
        assert "x-region" not in headers and len(body) == 4 * 128 * 128
    finally:
        s.close()
