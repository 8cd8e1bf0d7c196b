"""`bumpbake serve` in a real browser (Debian's Chromium, headless, driven
by python3-selenium): the page loads and draws the ssbump, the light and a
save by rename change the picture, a control re-bakes, a broken save shows
its error and keeps the last maps, and "write" writes what `bumpbake bake`
writes, byte for byte. Skipped, with the reason, without Chromium.
Screenshots go to build/serve-test/ (BB_SERVE_SHOTS) to be looked at."""

import json
import os
import re
import shlex
import shutil
import subprocess
import urllib.request

import pytest

import serve_browser as sb

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BIN = os.environ.get("BB_BIN", os.path.join(ROOT, "build", "bumpbake"))
FIXTURES = os.path.join(ROOT, "fixtures")
SHOTS = os.environ.get("BB_SERVE_SHOTS", os.path.join(ROOT, "build", "serve-test"))
# Generous: a loaded machine (load 10 happens) must not fail the test.
SLOW = 120

missing = sb.browser_missing()
pytestmark = pytest.mark.skipif(missing is not None, reason="browser test skipped: %s" % missing)


@pytest.fixture(scope="module")
def work(tmp_path_factory):
    d = tmp_path_factory.mktemp("serve")
    shutil.copy(os.path.join(FIXTURES, "rock06_128.png"), d / "height.png")
    return d


@pytest.fixture(scope="module")
def server(work):
    s = sb.Server(BIN, str(work / "height.png"), ["--scale", "32", "--quiet"])
    yield s
    s.close()


@pytest.fixture(scope="module")
def page(server):
    driver = sb.start_browser()
    driver.get(server.url)
    yield driver
    sb.stop_browser(driver)


@pytest.fixture(scope="module")
def browser():
    """One browser for the tests that start a server of their own: each
    loads its server's page afresh (a page keeps nothing across a load, and
    serve's replies are never cached), so starting Chromium again for each
    would prove nothing more."""
    driver = sb.start_browser()
    yield driver
    sb.stop_browser(driver)


def stats(driver):
    return driver.execute_script("return bbCanvasStats()")


def state(server):
    with urllib.request.urlopen(server.url + "state", timeout=30) as r:
        return json.load(r)


def shot(driver, name):
    os.makedirs(SHOTS, exist_ok=True)
    driver.save_screenshot(os.path.join(SHOTS, name + ".png"))


def test_page_draws_the_ssbump(page):
    sb.wait_for(lambda: sb.drawn_bake(page) >= 1, SLOW, "the first bake drawn")
    s = stats(page)
    # rock06 lit from 135,45: neither black nor white, not one flat colour
    assert 20 < s["mean"] < 235, s
    assert page.find_element("id", "error").text == ""
    assert "bumpbake bake" in page.find_element("id", "command").text
    assert not is_stale(page)
    # nothing the page asked for was missing (a favicon included)
    # (Chromium's words for a 404; not any "404", which a WebGL context's
    # address in a driver message can hold: 0x2404001cd400)
    missing = [e["message"] for e in page.get_log("browser")
               if "status of 404" in e["message"] or "Failed to load" in e["message"]]
    assert not missing, missing
    shot(page, "1-ssbump")


def is_stale(driver):
    return driver.execute_script("return document.getElementById('view').classList"
                                 ".contains('stale')")


def stale_text(driver):
    return driver.execute_script("return document.getElementById('stale').textContent")


def visible(driver, element_id):
    return driver.execute_script(
        "const e = document.getElementById(arguments[0]);"
        "return !!(e.offsetWidth || e.offsetHeight || e.getClientRects().length)", element_id)


def test_the_view_controls_show_only_where_they_apply(page):
    sb.wait_for(lambda: sb.drawn_bake(page) >= 1, SLOW, "the first bake drawn")
    expect = {"0": (True, False), "1": (True, False), "2": (True, False), "3": (False, False),
              "4": (False, False), "5": (False, False), "6": (False, False),
              "7": (False, False), "8": (True, True)}
    for mode, (light_shown, view_shown) in expect.items():
        page.execute_script("const m = document.getElementById('mode'); m.value = arguments[0];"
                            "m.dispatchEvent(new Event('input'))", mode)
        assert visible(page, "light-controls") == light_shown, mode
        assert visible(page, "light-readout") == light_shown, mode
        assert visible(page, "view-controls") == view_shown, mode
        if mode == "8":
            shot(page, "1c-relief-controls")
    page.execute_script("const m = document.getElementById('mode'); m.value = '0';"
                        "m.dispatchEvent(new Event('input'))")


def test_the_view_elevation_box_takes_and_shows_what_is_drawn(page):
    sb.wait_for(lambda: sb.drawn_bake(page) >= 1, SLOW, "the first bake drawn")
    view = sb.library_ranges(BIN)["view_elevation"]
    el = page.find_element("id", "view-el")
    # the default is a value the box accepts (its min and step allow it)
    assert el.get_attribute("value") == "30"
    assert page.execute_script("return arguments[0].checkValidity()", el)

    def picture_at(text):
        return page.execute_script(
            "const el = document.getElementById('view-el'), m = document.getElementById('mode');"
            "m.value = '8'; el.value = arguments[0]; el.dispatchEvent(new Event('change'));"
            "draw(); return [el.value, bbCanvasStats().hash];", text)

    low, high = int(view["min"]), int(view["max"])
    at_low, at_high, at_30 = picture_at(str(low)), picture_at(str(high)), picture_at("30")
    assert picture_at("0") == [str(low), at_low[1]]        # 0 draws at the bottom, not at 30
    assert picture_at("95") == [str(high), at_high[1]]     # the box shows what is drawn
    assert at_low[1] != at_30[1] != at_high[1]
    picture_at("30")
    page.execute_script("document.getElementById('mode').value = '0'; draw();")


def test_the_light_readout_is_legible_on_white(page):
    sb.wait_for(lambda: sb.drawn_bake(page) >= 1, SLOW, "the first bake drawn")
    colours = page.execute_script(
        "const s = getComputedStyle(document.getElementById('light-readout'));"
        "return [s.color, s.backgroundColor];")

    def rgba(css):
        v = [float(x) for x in css[css.index("(") + 1:-1].split(",")]
        return v + [1.0] * (4 - len(v))

    def luminance(c):
        lin = [(x / 255 / 12.92 if x / 255 <= 0.04045 else ((x / 255 + 0.055) / 1.055) ** 2.4)
               for x in c[:3]]
        return 0.2126 * lin[0] + 0.7152 * lin[1] + 0.0722 * lin[2]

    fg, bg = rgba(colours[0]), rgba(colours[1])
    # the background over a white map
    under = [bg[k] * bg[3] + 255 * (1 - bg[3]) for k in range(3)]
    ratio = (luminance(fg) + 0.05) / (luminance(under) + 0.05)
    assert ratio >= 4.5, (colours, ratio)  # WCAG's contrast for text


def test_the_command_line_wraps_between_words(page):
    sb.wait_for(lambda: sb.drawn_bake(page) >= 1, SLOW, "the first bake drawn")
    # each word of the shown command sits on one line, unless it is as wide
    # as the line itself; and the command does wrap
    got = page.execute_script("""
        const el = document.getElementById('command'), width = el.clientWidth;
        const lines = new Set(), split = [];
        for (const span of el.querySelectorAll('.word')) {
          const rects = [...span.getClientRects()];
          const r = document.createRange();
          r.selectNodeContents(span);
          const tops = new Set([...r.getClientRects()].map((x) => Math.round(x.top)));
          tops.forEach((t) => lines.add(t));
          if (tops.size > 1 && span.getBoundingClientRect().width < width - 1)
            split.push(span.textContent);
        }
        return [el.textContent, lines.size, split];""")
    text, line_count, split = got
    assert text == state_command(page), text
    assert line_count > 1, "the command fits one line: no wrapping to check (%r)" % text
    assert not split, split


def state_command(page):
    return page.execute_script("return state.command")


FLOAT_MAX = 3.40282347e38  # a float's largest: help prints no top for it ("> 0")


# The options serve offers on the page, in its order (serve_params.c).
CONTROLS = ["scale", "rays", "slices", "bias", "bounce", "bounces", "brightness", "light-color"]
# What each control's input is, by its row's type.
INPUT_OF_TYPE = {"integer": ("INPUT", "number"), "number": ("INPUT", "number"),
                 "numbers": ("INPUT", "text"), "path": ("INPUT", "checkbox")}


def test_the_controls_are_the_librarys_rows(page, server):
    """The page's controls, as it drew them, against the library's rows of
    serve's options read apart, through the Python package: the same
    options in the same order, each input of its row's type with its
    range, its default and its help, showing the command's value. The page
    makes its controls from the server's rows, so a row changed in the
    library changes both; a page with a control or a range of its own
    fails here."""
    sb.wait_for(lambda: sb.drawn_bake(page) >= 1, SLOW, "the first bake drawn")
    rows = sb.library_rows("serve")
    # the bake's controls, then the light's (in the "Show" box, above)
    got = page.execute_script(
        "return ['bake', 'light'].flatMap((place) => [...document.querySelectorAll("
        "'#controls-' + place + ' :is(input, select)')]).map((i) => ({id: i.id,"
        " tag: i.tagName, type: i.type, min: i.min, max: i.max, value: i.value,"
        " checked: i.checked, title: i.title}))")
    assert [g["id"] for g in got] == ["p-" + name for name in CONTROLS]
    params = state(server)["params"]
    for g, name in zip(got, CONTROLS):
        row = rows[name]
        assert (g["tag"], g["type"]) == INPUT_OF_TYPE[row["type"]], (name, g)
        # its help and its default, as --help words them
        assert g["title"].startswith("--%s %s: %s" % (name, row["value_name"], row["help"])), g
        assert ("default " + row["default"] in g["title"]) == bool(row["default"]), g
        assert ("range " + row["range"] in g["title"]) == bool(row["range"]), g
        if g["type"] == "number":
            # an excluded bottom ("scale > 0") is no HTML min, which would
            # admit it; nor is a bottom above the value the option holds
            # unset, which the control goes back to (slices 0, "from rays",
            # below --slices's 1..256)
            if row["min_exclusive"] or name == "slices":
                assert g["min"] == "", (name, g)
            else:
                assert float(g["min"]) == row["min"], (name, g, row)
            if "max" in row:
                assert float(g["max"]) == row["max"], (name, g, row)
            else:
                assert g["max"] == "" or float(g["max"]) >= FLOAT_MAX, (name, g)
            assert float(g["value"]) == params[name], (name, g, params)
        elif g["type"] == "checkbox":
            assert g["checked"] == params[name.replace("-", "_")], (name, g)
        else:
            want = ",".join("%g" % x for x in params[name.replace("-", "_")])
            assert g["value"] == want, (name, g)
    shot(page, "1d-controls")
    library = sb.library_ranges(BIN)
    got = page.execute_script(
        "return Object.fromEntries([...document.querySelectorAll('input[type=number]')]"
        ".map((i) => [i.id, [i.min, i.max]]))")
    low, high = got["view-el"]
    assert float(low) == library["view_elevation"]["min"], got["view-el"]
    assert float(high) == library["view_elevation"]["max"], got["view-el"]
    assert got["view-az"] == ["", ""]  # any azimuth
    # the light dragged past the rim stops at the library's lowest elevation,
    # at the centre it is overhead
    light = library["light_elevation"]
    edges = page.execute_script(
        "const r = canvas.getBoundingClientRect(), y = r.top + r.height / 2;"
        "dragLight({clientX: r.right + 100, clientY: y}); const low = light.elevation;"
        "dragLight({clientX: r.left + r.width / 2, clientY: y}); const high = light.elevation;"
        "dragLight({clientX: r.right + 100, clientY: y}); draw(); return [low, high];")
    assert edges == [light["min"], light["max"]], edges
    assert page.find_element("id", "light-text").text == "0,%d" % light["min"]
    shot(page, "1b-light-at-the-rim")  # grazing: the relief's long shadows
    page.execute_script("light.azimuth = 135; light.elevation = 45; showLight(); draw();")
    # a view below the library's lowest elevation is drawn at it (relief)
    view = library["view_elevation"]
    pictures = page.execute_script(
        "const el = document.getElementById('view-el'), mode = document.getElementById('mode');"
        "mode.value = '8'; const out = [];"
        "for (const v of [arguments[0], arguments[0] - 20, arguments[0] + 10]) {"
        "  el.value = String(v); draw(); out.push(bbCanvasStats().hash); }"
        "el.value = '30'; mode.value = '0'; draw(); return out;", view["min"])
    assert pictures[0] == pictures[1] != pictures[2], pictures


def test_dragging_the_light_relights(page):
    from selenium.webdriver.common.action_chains import ActionChains

    before = stats(page)
    canvas = page.find_element("id", "canvas")
    # from the right, low: drag to near the right edge of the picture
    ActionChains(page).move_to_element_with_offset(canvas, 0, 0).click_and_hold() \
        .move_by_offset(280, 10).release().perform()
    sb.wait_for(lambda: stats(page)["hash"] != before["hash"], 30, "the picture to change")
    assert page.find_element("id", "light-text").text != "135,45"
    shot(page, "2-light-moved")


def test_a_save_by_rename_rebakes(page, server, work):
    old = sb.drawn_bake(page)
    before = stats(page)
    with open(os.path.join(FIXTURES, "bricks_128x64.png"), "rb") as f:
        sb.save_by_rename(f.read(), str(work / "height.png"))
    sb.wait_for(lambda: sb.drawn_bake(page) > old, SLOW, "the new height's bake drawn")
    assert stats(page)["hash"] != before["hash"]
    assert state(server)["bake"]["height"] == 64
    shot(page, "3-resaved")


def test_a_control_rebakes_and_a_refusal_shows_the_library_words(page, server):
    old = sb.drawn_bake(page)
    scale = page.find_element("id", "p-scale")
    page.execute_script(
        "arguments[0].value = '8'; arguments[0].dispatchEvent(new Event('change'))", scale)
    sb.wait_for(lambda: sb.drawn_bake(page) > old, SLOW, "the re-bake at scale 8")
    assert state(server)["params"]["scale"] == 8
    assert "--scale 8 " in page.find_element("id", "command").text
    bias = page.find_element("id", "p-bias")
    page.execute_script(
        "arguments[0].value = '-1'; arguments[0].dispatchEvent(new Event('change'))", bias)
    sb.wait_for(lambda: page.find_element("id", "controls-error").text, 30, "the refusal")
    assert "bias must be in 0..1e6 (got -1)" in page.find_element("id", "controls-error").text
    assert state(server)["params"]["bias"] == 0.55
    shot(page, "4-control")


def test_a_broken_save_keeps_the_last_maps(page, server, work):
    old = sb.drawn_bake(page)
    before = stats(page)
    with open(os.path.join(FIXTURES, "rock06_128.png"), "rb") as f:
        half = f.read()[:700]  # a save caught half written
    sb.save_by_rename(half, str(work / "height.png"))
    sb.wait_for(lambda: page.find_element("id", "error").text, SLOW, "the error shown")
    assert "height.png" in page.find_element("id", "error").text
    assert sb.drawn_bake(page) == old
    assert stats(page)["hash"] == before["hash"]  # the pixels drawn; the page dims them
    assert state(server)["bake"]["id"] == old
    # the picture marked stale, saying why
    sb.wait_for(lambda: is_stale(page), 30, "the picture marked stale")
    assert "height.png" in stale_text(page) and ("bake %d" % old) in stale_text(page)
    shot(page, "5-broken-save")
    # the next good save clears it
    with open(os.path.join(FIXTURES, "rock06_128.png"), "rb") as f:
        sb.save_by_rename(f.read(), str(work / "height.png"))
    sb.wait_for(lambda: sb.drawn_bake(page) > old, SLOW, "the good save's bake drawn")
    assert page.find_element("id", "error").text == ""
    sb.wait_for(lambda: not is_stale(page), 30, "the picture no longer stale")


def test_a_deleted_height_is_reported_on_the_page(page, server, work):
    old = sb.drawn_bake(page)
    with open(work / "height.png", "rb") as f:
        kept = f.read()
    os.remove(work / "height.png")
    try:
        sb.wait_for(lambda: is_stale(page) and "height.png" in stale_text(page), SLOW,
                    "the deletion shown")
        assert "height.png" in page.find_element("id", "error").text
        assert sb.drawn_bake(page) == old
        shot(page, "5b-deleted-height")
    finally:
        sb.save_by_rename(kept, str(work / "height.png"))
    sb.wait_for(lambda: sb.drawn_bake(page) > old and not is_stale(page), SLOW,
                "the height back, baked")


def test_zoom_pan_and_one_to_one(page):
    sb.wait_for(lambda: sb.drawn_bake(page) >= 1, SLOW, "the first bake drawn")
    page.execute_script("fit(); draw();")
    fitted = stats(page)["hash"]
    page.find_element("id", "zoom-1").click()
    sb.wait_for(lambda: page.find_element("id", "zoom-text").text == "100%", 10, "1:1")
    page.execute_script("draw()")
    one = stats(page)
    assert one["hash"] != fitted
    shot(page, "10-one-to-one")
    # a wheel turn zooms in about the pointer: a texel covers more pixels
    page.execute_script(
        "const r = canvas.getBoundingClientRect();"
        "canvas.dispatchEvent(new WheelEvent('wheel', {deltaY: -100, clientX: r.left + 100,"
        " clientY: r.top + 100, bubbles: true, cancelable: true})); draw();")
    assert page.find_element("id", "zoom-text").text == "125%"
    zoomed = stats(page)["hash"]
    assert zoomed != one["hash"]
    # shift-drag pans: the picture moves, the light does not
    light_before = page.find_element("id", "light-text").text
    page.execute_script(
        "const r = canvas.getBoundingClientRect(), x = r.left + 300, y = r.top + 300;"
        "const ev = (type, dx) => new PointerEvent(type, {clientX: x + dx, clientY: y,"
        " shiftKey: true, buttons: 1, button: 0, pointerId: 1, bubbles: true});"
        "canvas.dispatchEvent(ev('pointerdown', 0)); canvas.dispatchEvent(ev('pointermove', 60));"
        "canvas.dispatchEvent(ev('pointerup', 60)); draw();")
    assert stats(page)["hash"] != zoomed
    assert page.find_element("id", "light-text").text == light_before
    shot(page, "11-zoomed-panned")
    page.find_element("id", "zoom-fit").click()
    page.execute_script("draw()")
    assert stats(page)["hash"] == fitted
    assert page.find_element("id", "zoom-text").text.startswith("fit")


def test_a_and_b_are_the_last_two_bakes(page, server):
    sb.wait_for(lambda: sb.drawn_bake(page) >= 1, SLOW, "the first bake drawn")
    before = sb.drawn_bake(page)
    a_hash = stats(page)["hash"]
    scale = page.find_element("id", "p-scale")
    old_scale = state(server)["params"]["scale"]
    new_scale = 13 if old_scale != 13 else 14
    page.execute_script("arguments[0].value = arguments[1];"
                        "arguments[0].dispatchEvent(new Event('change'))", scale, str(new_scale))
    sb.wait_for(lambda: sb.drawn_bake(page) > before and
                page.execute_script("return current && current.whole && !!previous"),
                SLOW, "the new bake drawn whole")
    after = sb.drawn_bake(page)
    new_hash = stats(page)["hash"]
    assert new_hash != a_hash
    # the toggle draws on the next animation frame, not within the click
    page.find_element("id", "ab").click()
    sb.wait_for(lambda: sb.drawn_bake(page) == before, SLOW, "B drawn")
    assert stats(page)["hash"] == a_hash
    assert ("bake %d" % before) in page.find_element("id", "ab-text").text
    shot(page, "12-b-the-bake-before")
    page.find_element("id", "ab").click()
    sb.wait_for(lambda: sb.drawn_bake(page) == after, SLOW, "A drawn again")
    assert stats(page)["hash"] == new_hash
    # the scale back as the tests after this one expect it
    page.execute_script("arguments[0].value = arguments[1];"
                        "arguments[0].dispatchEvent(new Event('change'))", scale, str(old_scale))
    sb.wait_for(lambda: sb.drawn_bake(page) > after, SLOW, "the scale back")


def test_write_is_the_bake_commands_bytes(page, server, work):
    page.find_element("id", "write").click()
    sb.wait_for(lambda: page.find_element("id", "write-result").text
                or page.find_element("id", "write-error").text, SLOW, "the write")
    assert page.find_element("id", "write-error").text == ""
    # the maps shown were written, not baked again
    assert "(the maps shown, not baked again)" in page.find_element("id", "write-result").text
    command = page.find_element("id", "command").text
    words = shlex.split(command)
    outputs = [words[i + 1] for i, w in enumerate(words) if w in ("--normal", "--ssbump", "--ao")]
    assert len(outputs) == 3 and all(os.path.exists(p) for p in outputs)
    written = {p: open(p, "rb").read() for p in outputs}
    for p in outputs:
        os.remove(p)
    assert words[:2] == ["bumpbake", "bake"]
    subprocess.run([BIN, *words[1:]], check=True, timeout=SLOW, stdout=subprocess.DEVNULL)
    for p in outputs:
        assert open(p, "rb").read() == written[p], p + " differs from bumpbake bake's"
    shot(page, "6-written")


# The page's picture of the written ssbump, drawn one pixel per texel, and
# `bumpbake render --ssbump` of the same file: the same formulas (the page
# runs shaders/ssbump_relief.glsl's ssbump_dynamic on the GPU).
COMPARE_JS = """
const [png, w, h, az, el, mode] = arguments;
const done = arguments[arguments.length - 1];
canvas.width = w; canvas.height = h;
light.azimuth = az; light.elevation = el;
document.getElementById('mode').value = String(mode);
document.getElementById('tile').checked = false;
draw();
const mine = new Uint8Array(4 * w * h);
gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, mine);
const img = new Image();
img.onload = () => {
  const c = document.createElement('canvas');
  c.width = w; c.height = h;
  const g = c.getContext('2d');
  g.drawImage(img, 0, 0);
  const ref = g.getImageData(0, 0, w, h).data;
  let worst = 0, sum = 0, over8 = 0;
  for (let y = 0; y < h; y++)
    for (let x = 0; x < w; x++)
      for (let k = 0; k < 3; k++) {
        const a = mine[4 * ((h - 1 - y) * w + x) + k], b = ref[4 * (y * w + x) + k];
        worst = Math.max(worst, Math.abs(a - b));
        sum += Math.abs(a - b);
        over8 += Math.abs(a - b) > 8;
      }
  done({worst: worst, mean: sum / (3 * w * h), over8: over8 / (3 * w * h)});
};
img.src = 'data:image/png;base64,' + png;
"""


@pytest.mark.parametrize("mode,light", [(0, "0,20"), (1, "135,45"), (2, "250,30"), (8, "135,45")])
def test_the_page_lights_as_render_does(page, server, work, mode, light):
    import base64

    ssbump = str(work / "height_ssbump.png")
    normal = str(work / "height_normal.png")
    assert os.path.exists(ssbump), "test_write_is_the_bake_commands_bytes writes it first"
    out = str(work / "render.png")
    ao = str(work / "height_ao.png")
    maps = {0: ["--ssbump", ssbump], 1: ["--normal", normal, "--mode", "normal"],
            2: ["--normal", normal, "--ao", ao, "--mode", "ao"],
            # relief: render bakes the height itself (floats), the page has 8-bit maps
            8: [str(work / "height.png"), "--scale", str(state(server)["params"]["scale"]),
                "--view", "270,30", "--relief"]}[mode]
    subprocess.run([BIN, "render", *maps, "--light", light, "-o", out], check=True,
                   timeout=SLOW, stdout=subprocess.DEVNULL)
    with open(out, "rb") as f:
        png = base64.b64encode(f.read()).decode()
    os.remove(out)
    st = state(server)["bake"]
    az, el = (float(v) for v in light.split(","))
    diff = page.execute_async_script(COMPARE_JS, png, st["width"], st["height"], az, el, mode)
    print("page against render, mode %d light %s: %s" % (mode, light, diff))
    if mode == 8:
        # the page's maps are 8-bit, render's baked floats: the relief's
        # hits move a little with the height's steps (1 level seen)
        assert diff["worst"] <= 4 and diff["mean"] < 0.5, diff
        return
    # 8-bit maps on both sides; the GPU's float and the CPU's double may
    # round a value either side of a step: one level at most
    assert diff["worst"] <= 1, diff
    assert diff["mean"] < 0.05, diff


def test_nothing_is_written_unless_asked(work):
    # only the height and what test_write asked for
    names = sorted(os.listdir(work))
    assert all(n == "height.png" or n.startswith("height_") for n in names), names
    assert not any(n.startswith(".~") for n in names), names


# ------------------------------------------------------------ other bases

# The page's picture in a mode, one pixel per texel, as rows top first
# (RGB bytes, base64).
PIXELS_JS = """
const [w, h, az, el, mode] = arguments;
canvas.width = w; canvas.height = h;
light.azimuth = az; light.elevation = el;
document.getElementById('mode').value = String(mode);
document.getElementById('tile').checked = false;
draw();
const px = new Uint8Array(4 * w * h);
gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, px);
const rgb = new Uint8Array(3 * w * h);
for (let y = 0; y < h; y++)
  for (let x = 0; x < w; x++)
    for (let k = 0; k < 3; k++) rgb[3 * (y * w + x) + k] = px[4 * ((h - 1 - y) * w + x) + k];
let s = '';
for (let i = 0; i < rgb.length; i += 8192) s += String.fromCharCode(...rgb.subarray(i, i + 8192));
return btoa(s);
"""


def light_vector(az, el):
    import math
    a, e = math.radians(az), math.radians(el)
    return [math.cos(e) * math.cos(a), -math.cos(e) * math.sin(a), math.sin(e)]


def test_a_custom_basis_lights_the_ssbump_in_its_own_directions(tmp_path, browser):
    import base64
    import math

    import numpy as np

    # Half-Life 2's directions turned 40 degrees about z: lit as HL2's, the
    # picture would be another one
    turn = math.radians(40)
    hl2 = [(math.sqrt(2 / 3), 0, 1 / math.sqrt(3)),
           (-1 / math.sqrt(6), 1 / math.sqrt(2), 1 / math.sqrt(3)),
           (-1 / math.sqrt(6), -1 / math.sqrt(2), 1 / math.sqrt(3))]
    mine = [(x * math.cos(turn) - y * math.sin(turn), x * math.sin(turn) + y * math.cos(turn), z)
            for x, y, z in hl2]
    basis = tmp_path / "turned.basis"
    basis.write_text("".join("%.12f %.12f %.12f\n" % v for v in mine))
    shutil.copy(os.path.join(FIXTURES, "rock06_128.png"), tmp_path / "height.png")
    server = sb.Server(BIN, str(tmp_path / "height.png"),
                       ["--scale", "32", "--basis", str(basis), "--quiet"])
    driver = browser
    try:
        driver.get(server.url)
        sb.wait_for(lambda: sb.drawn_bake(driver) >= 1, SLOW, "the first bake drawn")
        bake = state(server)["bake"]
        assert bake["basis"].startswith("vectors:") and bake["basis_count"] == 3, bake["basis"]
        assert np.allclose(bake["basis_vectors"], mine, atol=1e-7), bake["basis_vectors"]
        note = driver.find_element("id", "basis-note").text
        assert bake["basis"] in note and "(0.625, 0.525, 0.577)" in note, note
        w, h = bake["width"], bake["height"]
        with urllib.request.urlopen(server.url + "map/ssbump_ao", timeout=30) as r:
            s = np.frombuffer(r.read(), np.uint8).reshape(h, w, 4)[:, :, :3] / 255.0
        for az, el in ((0, 20), (200, 35)):
            page = np.frombuffer(base64.b64decode(driver.execute_script(PIXELS_JS, w, h, az, el, 0)),
                                 np.uint8).reshape(h, w, 3).astype(int)
            l = np.array(light_vector(az, el))

            def lit(directions):
                lb = np.array(directions) @ l
                return np.round(np.clip(s @ lb, 0, 1) * 255).astype(int)

            worst = np.abs(page[:, :, 0] - lit(mine)).max()
            as_hl2 = np.abs(page[:, :, 0] - lit(hl2)).max()
            print("custom basis, light %d,%d: worst %d against its basis, %d against HL2's"
                  % (az, el, worst, as_hl2))
            assert worst <= 1, worst
            assert as_hl2 > 8, "the page lit the turned basis as Half-Life 2's"
        driver.set_window_size(1100, 760)
        driver.execute_script("fitCanvas(); document.getElementById('mode').value = '0';"
                              "light.azimuth = 135; light.elevation = 45; showLight(); draw();")
        shot(driver, "7-custom-basis")
    finally:
        server.close()


def test_a_basis_of_4_turns_the_lit_ssbump_off_saying_why(tmp_path, browser):
    shutil.copy(os.path.join(FIXTURES, "rock06_128.png"), tmp_path / "height.png")
    server = sb.Server(BIN, str(tmp_path / "height.png"),
                       ["--scale", "32", "--basis", "hl2+z", "--quiet"])
    driver = browser
    try:
        driver.get(server.url)
        sb.wait_for(lambda: sb.drawn_bake(driver) >= 1, SLOW, "the first bake drawn")
        note = driver.find_element("id", "basis-note").text
        assert "hl2+z has 4 directions" in note, note
        assert driver.execute_script(
            "return [0, 8].map((m) => document.querySelector("
            "'#mode option[value=\"' + m + '\"]').disabled)") == [True, True]
        assert driver.execute_script("return document.getElementById('mode').value") == "1"
        assert stats(driver)["mean"] > 20  # the normal map, lit
        shot(driver, "8-basis-of-4")
    finally:
        server.close()


# ------------------------------------------------------ a bake in flight

def test_a_bake_in_flight_dims_the_picture_and_names_its_stage(tmp_path, browser):
    shutil.copy(os.path.join(FIXTURES, "rock06_128.png"), tmp_path / "height.png")
    # 4096 rays: the bounce (which is the trace too) takes about a second
    # here, long enough to be seen in each of its stages
    server = sb.Server(BIN, str(tmp_path / "height.png"),
                       ["--scale", "16", "--rays", "4096", "--bounce", "0.5", "--quiet"])
    driver = browser
    try:
        driver.get(server.url)
        sb.wait_for(lambda: sb.drawn_bake(driver) >= 1 and not is_stale(driver), 3 * SLOW,
                    "the first bake drawn")
        driver.execute_script(
            "const s = document.getElementById('p-scale'); s.value = '48';"
            "s.dispatchEvent(new Event('change'))")

        # one snapshot of the page: the status and the dimmed picture's
        # note are read together (read apart, the bake could end between)
        def running():
            view = driver.execute_script(
                "return [document.getElementById('view').classList.contains('stale'),"
                " document.getElementById('stale').textContent,"
                " document.getElementById('status').textContent]")
            return view if view[0] and "baking: " in view[1] else None
        stale, note, status = sb.wait_for(running, SLOW, "the bake shown as running")
        assert "the picture is bake 1's" in note
        assert status.startswith("baking: "), status
        shot(driver, "9-stale-while-baking")
        sb.wait_for(lambda: "baking: bounce" in stale_text(driver), 3 * SLOW,
                    "the bounce shown as the stage")
        shot(driver, "9b-stale-bounce-stage")
        sb.wait_for(lambda: sb.drawn_bake(driver) >= 2 and not is_stale(driver), 3 * SLOW,
                    "the new bake drawn")
        # the bake's stages name the bounce, where its time went
        assert re.search(r"bounce \d+\.\d{3}, derive", driver.find_element("id", "times").text)
    finally:
        server.close()


# ------------------------------------------ a colour map and a light colour

def test_an_albedo_and_a_light_colour_light_the_page_as_render_does(tmp_path, browser):
    import base64

    shutil.copy(os.path.join(FIXTURES, "rock06_128.png"), tmp_path / "height.png")
    albedo = str(tmp_path / "colour.png")  # a colourful map of the same size: a normal map
    subprocess.run([BIN, "bake", str(tmp_path / "height.png"), "--scale", "16", "--normal",
                    albedo, "-q"], check=True, timeout=SLOW)
    server = sb.Server(BIN, str(tmp_path / "height.png"),
                       ["--scale", "32", "--albedo", albedo, "--light-color", "1,0.8,0.6",
                        "--quiet"])
    driver = browser
    try:
        driver.get(server.url)
        sb.wait_for(lambda: sb.drawn_bake(driver) >= 1, SLOW, "the first bake drawn")
        sb.wait_for(lambda: driver.execute_script("return current && current.whole"), SLOW,
                    "every map loaded")
        st = state(server)
        assert st["params"]["light_color"] == [1, 0.800000011920929, 0.6000000238418579] or \
            [round(x, 6) for x in st["params"]["light_color"]] == [1, 0.8, 0.6]
        assert st["bake"]["albedo"] is True
        assert driver.find_element("id", "p-light-color").get_attribute("value") == "1,0.8,0.6"
        shot(driver, "13-albedo-light-colour")
        status = urllib.request.urlopen(urllib.request.Request(
            server.url + "write", method="POST", headers={"X-Bumpbake": "1"}), timeout=SLOW).status
        assert status == 200
        ssbump = str(tmp_path / "height_ssbump.png")
        out = str(tmp_path / "render.png")
        for mode, light in ((0, "135,45"), (1, "250,30")):
            maps = (["--ssbump", ssbump] if mode == 0 else
                    ["--normal", str(tmp_path / "height_normal.png"), "--mode", "normal"])
            subprocess.run([BIN, "render", *maps, "--albedo", albedo, "--light-color",
                            "1,0.8,0.6", "--light", light, "-o", out], check=True,
                           timeout=SLOW, stdout=subprocess.DEVNULL)
            with open(out, "rb") as f:
                png = base64.b64encode(f.read()).decode()
            az, el = (float(v) for v in light.split(","))
            diff = driver.execute_async_script(COMPARE_JS, png, st["bake"]["width"],
                                               st["bake"]["height"], az, el, mode)
            print("page against render --albedo --light-color, mode %d: %s" % (mode, diff))
            assert diff["worst"] <= 1 and diff["mean"] < 0.05, diff
        # the light colour is render's row: checked by the library, no re-bake
        bake = st["bake"]["id"]
        refused = driver.execute_script(
            "const c = document.getElementById('p-light-color'); c.value = '1,x,1';"
            "c.dispatchEvent(new Event('change'));")
        sb.wait_for(lambda: driver.find_element("id", "controls-error").text, 30, "the refusal")
        assert "--light-color" in driver.find_element("id", "controls-error").text
        driver.execute_script(
            "const c = document.getElementById('p-light-color'); c.value = '0.2,0.4,1';"
            "c.dispatchEvent(new Event('change'));")
        sb.wait_for(lambda: state(server)["params"]["light_color"][2] == 1 and
                    state(server)["params"]["light_color"][0] < 0.3, 30, "the new colour")
        assert state(server)["bake"]["id"] == bake and refused is None
    finally:
        server.close()


MODES_JS = """
const out = [];
for (let mode = 0; mode <= 8; mode++) {
  document.getElementById('mode').value = String(mode);
  draw();
  out.push(bbCanvasStats().hash);
}
return out;
"""


def test_an_edit_draws_what_a_fresh_page_draws(tmp_path, browser):
    import numpy as np

    def save_pgm(path, h):
        sb.save_by_rename(b"P5\n128 128\n65535\n" + h.astype(">u2").tobytes(), path)

    y, x = np.mgrid[0:128, 0:128] * (2 * np.pi / 128)
    h = 0.5 + 0.2 * np.sin(3 * x) * np.cos(2 * y) + 0.05 * np.random.RandomState(3).rand(128, 128)
    h = np.round(h * 65535).astype(np.uint16)
    height, albedo = str(tmp_path / "h.pgm"), str(tmp_path / "albedo.pgm")
    save_pgm(height, h)
    save_pgm(albedo, np.round(65535 * (0.3 + 0.6 * (x / (2 * np.pi)))).astype(np.uint16))
    server = sb.Server(BIN, height, ["--scale", "16", "--albedo", albedo, "--quiet"])
    driver = browser
    try:
        driver.get(server.url)
        sb.wait_for(lambda: sb.drawn_bake(driver) == 1 and
                    driver.execute_script("return current.whole"), SLOW, "the first bake whole")
        first = driver.execute_script(MODES_JS)
        h[60:66, 40:46] += 600
        save_pgm(height, h)
        sb.wait_for(lambda: sb.drawn_bake(driver) == 2, SLOW, "the edit drawn")
        assert state(server)["bake"]["base"] == 1
        # it came as the rectangle the edit changed: asked since bake 1
        fetched = driver.execute_script(
            "return performance.getEntriesByType('resource').map((e) => e.name)")
        assert any(n.endswith("map/ssbump_ao?since=1") for n in fetched), fetched
        edited = driver.execute_script(MODES_JS)
        assert edited[0] != first[0]  # the picture changed
        driver.execute_script("document.getElementById('mode').value = '0';"
                              "camera.zoom = 10; camera.cx = 43; camera.cy = 63; draw();")
        shot(driver, "13-an-edit-drawn-from-its-rectangle")
        driver.execute_script("fit(); draw();")
        # B is bake 1 as it was drawn
        driver.execute_script("toggleAB(); draw();")
        sb.wait_for(lambda: sb.drawn_bake(driver) == 1, SLOW, "B drawn")
        assert driver.execute_script(MODES_JS) == first
        # a fresh page loads bake 2 whole: the same pixels in every mode
        driver.get(server.url)
        sb.wait_for(lambda: sb.drawn_bake(driver) == 2 and
                    driver.execute_script("return current.whole"), SLOW, "bake 2 loaded whole")
        assert driver.execute_script(MODES_JS) == edited
    finally:
        server.close()
