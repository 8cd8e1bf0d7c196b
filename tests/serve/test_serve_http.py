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
    r = run(os.path.join(FIXTURES, "rock06_128.png"), "--scale", "4", "--port", str(port))
    assert r.returncode == 1 and "cannot listen" in r.stderr


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
    # a control's value is parsed by bake's option of its name: bake's words,
    # the option named as the control (as Python's keyword)
    status, body = request(s.url, "POST", {"X-Bumpbake": "1"}, "params?rays=x")
    assert status == 400 and json.loads(body)["error"] == "rays needs an integer (got 'x')"
    status, body = request(s.url, "POST", {"X-Bumpbake": "1"}, "params?scale=8&bias=near")
    assert status == 400 and json.loads(body)["error"] == "bias needs a number (got 'near')"
    # a range in the same words as Python's bake(h, 8, bounce=2) and the CLI's
    # --bounce 2: the bounce albedo is "bounce" everywhere
    status, body = request(s.url, "POST", {"X-Bumpbake": "1"}, "params?bounce=2")
    assert status == 400 and json.loads(body)["error"] == "bake: bounce must be in 0..1 (got 2)"
    status, body = request(s.url, "POST", {"X-Bumpbake": "1"}, "params?scale=0")
    assert status == 400 and json.loads(body)["error"] == "bake: scale must be > 0 (got 0)"
    status, body = request(s.url, "POST", {"X-Bumpbake": "1"}, "params?path=/etc/passwd")
    assert status == 400 and "unknown control" in json.loads(body)["error"]
    assert sorted(os.listdir(d)) == ["h.png"]  # nothing written unless asked


FLOAT_MAX = 3.40282347e38  # a float's largest: help prints no top for it ("> 0")


def test_the_page_takes_its_ranges_from_the_library(served):
    s, _ = served
    status, body = request(s.url, path="ranges")
    assert status == 200
    served_ranges = json.loads(body)
    library = sb.library_ranges(BIN)
    assert sorted(served_ranges) == sorted(library) == sorted(
        ["scale", "rays", "slices", "bias", "bounce", "bounces", "view_elevation",
         "light_elevation"])
    for name, want in library.items():
        got = served_ranges[name]
        assert got["min"] == want["min"] and got["min_exclusive"] == want["min_exclusive"], name
        if "max" in want:
            assert got["max"] == want["max"], name
        else:
            assert got.get("max", FLOAT_MAX) >= FLOAT_MAX, name
    # the page's files say none of their own (the progress bar's max is a fraction)
    status, html = request(s.url, path="index.html")
    assert status == 200
    inputs = re.findall(r"<input[^>]*>", html.decode())
    assert inputs and not [i for i in inputs if re.search(r"\b(min|max)=", i)], inputs
    status, js = request(s.url, path="serve.js")
    assert status == 200
    code = re.sub(r"//.*", "", js.decode())  # the comments may say "90 = overhead"
    assert not re.search(r"\b90\b", code), "an elevation's top in serve.js"


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
