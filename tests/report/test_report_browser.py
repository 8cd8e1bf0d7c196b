"""`bumpbake check --html`'s report in a real browser (Debian's Chromium,
headless, driven by python3-selenium, as tests/serve drives serve's page):
the page loads every picture from its folder and nothing from anywhere
else, shows a thumbnail per map and, for each map that did not pass, its
golden, new map and difference; the flip shows golden then new, the slider
moves its split. Skipped, with the reason, without Chromium. Screenshots
go to build/report-test/ (BB_REPORT_SHOTS) to be looked at."""

import os
import shutil
import subprocess
import sys
import time

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "tests", "serve"))
import serve_browser as sb  # noqa: E402 (the browser the serve test starts)

BIN = os.environ.get("BB_BIN", os.path.join(ROOT, "build", "bumpbake"))
FIXTURES = os.path.join(ROOT, "fixtures")
SHOTS = os.environ.get("BB_REPORT_SHOTS", os.path.join(ROOT, "build", "report-test"))

missing = sb.browser_missing()
pytestmark = pytest.mark.skipif(missing is not None, reason="browser test skipped: %s" % missing)


def run(*args, ok=(0,)):
    p = subprocess.run([BIN, *args], capture_output=True, text=True)
    assert p.returncode in ok, (args, p.returncode, p.stdout, p.stderr)
    return p


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    """A suite of three heights: goldens at scale 16, checked at 16.5 with
    the normal maps within 0.02 (they pass), so ssbump and ao fail."""
    d = tmp_path_factory.mktemp("report")
    heights = d / "heights"
    heights.mkdir()
    for name in ("rock06_128.png", "pit_65x65.png", "noise_96x80.png"):
        shutil.copy(os.path.join(FIXTURES, name), heights / name)
    run("bake", str(heights), "--out-dir", str(d / "goldens"), "--scale", "16", "--rays", "64",
        "--maps", "normal,ssbump,ao", "-q")
    p = run("check", str(d / "goldens"), str(heights), "--bake", "--scale", "16.5", "--rays",
            "64", "--maps", "normal,ssbump,ao", "--limits", "normal: -fail 0.02", "--html",
            str(d / "report"), ok=(2,))
    assert "check: 9 maps: 3 passed, 0 warnings, 6 failed" in p.stdout, p.stdout
    return d / "report"


@pytest.fixture(scope="module")
def page(report):
    driver = sb.start_browser(1200, 900)
    driver.get((report / "index.html").as_uri())
    sb.wait_for(lambda: driver.execute_script(
        "return Array.from(document.images).every(i => i.complete)"), 60, "pictures loaded")
    yield driver
    sb.stop_browser(driver)


def shot(driver, name, element=None):
    os.makedirs(SHOTS, exist_ok=True)
    path = os.path.join(SHOTS, name)
    if element is None:
        driver.save_screenshot(path)
    else:
        element.screenshot(path)
    return path


def test_every_picture_loads_from_its_folder_and_nothing_else(page, report):
    images = page.execute_script(
        "return Array.from(document.images).map(i => [i.src, i.naturalWidth])")
    assert images and all(w > 0 for _, w in images), images
    folder = report.as_uri() + "/img/"
    thumbs = page.execute_script(
        "return Array.from(document.querySelectorAll('.thumb i')).map("
        "t => getComputedStyle(t).backgroundImage)")
    assert all(src.startswith(folder) for src, _ in images), images
    assert len(thumbs) == 9 and all(folder in t for t in thumbs), thumbs
    # nothing else is named: no address, no script or style file
    html = (report / "index.html").read_text()
    assert "http:" not in html and "https:" not in html and "//" not in html
    assert page.execute_script(
        "return document.querySelectorAll('script[src], link, iframe, object').length") == 0
    policy = page.execute_script(
        "return document.querySelector('meta[http-equiv=Content-Security-Policy]').content")
    assert "default-src 'none'" in policy
    shot(page, "report.png")


def test_a_thumbnail_per_map_and_a_section_per_failure(page):
    assert page.execute_script("return document.querySelectorAll('.thumb').length") == 9
    assert page.execute_script("return document.querySelectorAll('.thumb.pass').length") == 3
    sections = page.execute_script(
        "return Array.from(document.querySelectorAll('section.case h2')).map(h => h.textContent)")
    assert len(sections) == 6 and all(s.startswith("FAILURE") for s in sections), sections
    text = page.execute_script("return document.querySelector('section.case').textContent")
    assert "scale: 16 -> 16.5" in text and "max abs error" in text, text
    # a failing thumbnail links to its section
    href = page.execute_script("return document.querySelector('a.thumb').getAttribute('href')")
    assert page.execute_script("return document.querySelector(arguments[0]) !== null", href)
    page.execute_script("document.getElementById('only').click()")
    assert page.execute_script(
        "return Array.from(document.querySelectorAll('.thumb.pass'))"
        ".every(t => getComputedStyle(t).display === 'none')")
    page.execute_script("document.getElementById('only').click()")


def _pixels(path):
    import bumpbake
    return bumpbake.read(path)


def test_golden_new_and_difference_show_what_changed(page):
    section = page.find_element("css selector", "section.case")
    page.execute_script("arguments[0].scrollIntoView()", section)
    time.sleep(0.3)
    shot(page, "failure.png")
    frames = section.find_elements("css selector", ".view .frame")
    golden, new, difference = (shot(page, f"part{i}.png", frames[i]) for i in range(3))
    g, n, d = _pixels(golden), _pixels(new), _pixels(difference)
    assert abs(g - n).max() > 0.01, "golden and new should differ"
    assert d.max() > 0.5 and d.mean() > 0.01, "the heat map should show the change"


def test_the_flip_and_the_slider(page):
    section = page.find_element("css selector", "section.case")
    flip = section.find_element("css selector", ".frame.flip")
    # centred: scrolled to the top, the sticky header would cover the frames'
    # first rows and the screenshots would compare the header's text
    page.execute_script("arguments[0].scrollIntoView({block: 'center'})", flip)
    before = _pixels(shot(page, "flip-golden.png", flip))
    caption = lambda: page.execute_script(  # noqa: E731
        "return arguments[0].parentNode.querySelector('figcaption').textContent", flip)
    assert caption() == "flip: golden"
    flip.click()
    assert caption() == "flip: new"
    after = _pixels(shot(page, "flip-new.png", flip))
    assert abs(before - after).max() > 0.01
    golden = _pixels(shot(page, "part0.png", section.find_elements("css selector",
                                                                    ".view .frame")[0]))
    assert abs(before - golden).max() < 0.02, "the flip starts on the golden"
    slider = section.find_element("css selector", ".frame.slider")
    page.execute_script(
        "var r = arguments[0].parentNode.querySelector('input[type=range]');"
        "r.value = 20; r.dispatchEvent(new Event('input'));", slider)
    clip = page.execute_script(
        "return arguments[0].querySelector('.over').style.clipPath", slider)
    assert clip.replace("px", "") in ("inset(0 0 0 20%)",), clip
    shot(page, "slider.png", slider)
