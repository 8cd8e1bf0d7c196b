"""What the browser test and tools/bench_serve.py share: `bumpbake serve`
started on a free port, and Debian's Chromium, headless, driven by
python3-selenium (WebGL on SwiftShader, no GPU, no network)."""

import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

CHROMIUM = shutil.which("chromium")
CHROMEDRIVER = shutil.which("chromedriver")
# Seconds a page's script may take: a hang guard, never a bound on speed.
SCRIPT_SECONDS = 120


def browser_missing():
    """Why the browser tests cannot run here, or None."""
    try:
        import selenium  # noqa: F401
    except ImportError:
        return "python3-selenium is not installed (make deps)"
    if not CHROMIUM or not CHROMEDRIVER:
        return "chromium or chromium-driver is not installed (make deps)"
    return None


class Server:
    """bumpbake serve HEIGHT ARGS... on 127.0.0.1, any free port."""

    def __init__(self, binary, height, args, cwd=None):
        self.proc = subprocess.Popen(
            [binary, "serve", height, "--port", "0", *args],
            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=cwd)
        line = self.proc.stdout.readline()
        m = re.search(r"(http://\S+)", line)
        if not m:
            self.proc.kill()
            raise RuntimeError("serve printed no URL: %r %r" % (line, self.proc.stderr.read()))
        self.url = m.group(1)

    def close(self):
        self.proc.terminate()
        try:
            self.proc.wait(10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()


def start_browser(width=1100, height=760):
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    profile = tempfile.mkdtemp(prefix="bb-chromium-")
    options = webdriver.ChromeOptions()
    options.binary_location = CHROMIUM
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})  # the console, for tests
    for flag in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-quic",
                 "--no-first-run", "--disable-background-networking",
                 "--disable-component-update", "--disable-sync",
                 "--use-gl=angle", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
                 "--disable-dev-shm-usage", "--user-data-dir=" + profile,
                 "--window-size=%d,%d" % (width, height)):
        options.add_argument(flag)
    driver = webdriver.Chrome(service=Service(CHROMEDRIVER), options=options)
    # A script may run as long as the tests wait for anything (their SLOW):
    # WebDriver's 30 s failed a relief drawn on SwiftShader at load 16.
    driver.set_script_timeout(SCRIPT_SECONDS)
    driver._bb_profile = profile
    return driver


def stop_browser(driver):
    profile = getattr(driver, "_bb_profile", None)
    driver.quit()
    if profile:
        shutil.rmtree(profile, ignore_errors=True)


def drawn_bake(driver):
    return int(driver.execute_script("return document.body.dataset.drawnBake || '0'"))


def wait_for(predicate, timeout, what, interval=0.01):
    """Polls until predicate() is true; generous timeouts, never a race."""
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        value = predicate()
        if value:
            return value
        time.sleep(interval)
    raise AssertionError("timed out after %g s waiting for %s" % (timeout, what))


def save_by_rename(source_bytes, path):
    """As Krita, GIMP or Photoshop save: a new file renamed over the old."""
    tmp = os.path.join(os.path.dirname(path), ".~" + os.path.basename(path))
    with open(tmp, "wb") as f:
        f.write(source_bytes)
    os.rename(tmp, path)


def _bounds(text):
    """{"min", "max", "min_exclusive"} of a range as help prints it (the
    library's bb_option_range_text: "1..65536", "> 0", ">= 0", "EL 0..90")."""
    text = re.sub(r"^[A-Z]+ ", "", text.strip())
    m = re.fullmatch(r"(-?[\d.e+-]+)\.\.(-?[\d.e+-]+)", text)
    if m:
        return {"min": float(m.group(1)), "max": float(m.group(2)), "min_exclusive": False}
    m = re.fullmatch(r"(>=?) (-?[\d.e+-]+)", text)
    if m:
        return {"min": float(m.group(2)), "min_exclusive": m.group(1) == ">"}
    raise ValueError("a range help does not print: %r" % text)


def library_ranges(binary):
    """The ranges of the picture's inputs as `bumpbake render --help` prints
    them (its --view and --light elevations): the library's words, read
    apart from the server's "controls"."""
    found = {}
    names = {"view": "view_elevation", "light": "light_elevation"}
    text = subprocess.run([binary, "render", "--help"], capture_output=True, text=True,
                          check=True).stdout
    for line in text.splitlines():
        m = re.match(r"\s+(?:-\w, )?--([\w-]+) .*; range (.*)$", line)
        if m and m.group(1) in names:
            found[names[m.group(1)]] = _bounds(m.group(2))
    return found


def library_rows(command):
    """The library's rows of command's options, read through the Python
    package (bumpbake._command.option_table: bb_command_option,
    bb_option_default_text, bb_option_range_text), apart from the server:
    {name: {"type", "value_name", "default", "range", "help"} and, for a
    range of numbers, its bounds ("min", "max", "min_exclusive")}."""
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    if os.path.join(root, "python") not in sys.path:
        sys.path.insert(0, os.path.join(root, "python"))
    from bumpbake import _command

    rows = {}
    for key, type_, value, default, range_text, help_ in _command.option_table(command):
        row = {"type": type_, "value_name": value, "default": default, "range": range_text,
               "help": help_}
        if type_ in ("integer", "number", "numbers") and range_text:
            row.update(_bounds(range_text))
        rows[key.replace("_", "-")] = row
    return rows
