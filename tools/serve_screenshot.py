#!/usr/bin/python3
"""serve_screenshot.py BIN OUT.png: docs/serve.png, the page of
`bumpbake serve fixtures/rock06_height.png --scale 64` in headless Chromium
with the light dragged low from the left (tools/docs.sh runs it)."""

import os
import shutil
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tests", "serve"))
import serve_browser as sb  # noqa: E402


def main():
    binary, out = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    why = sb.browser_missing()
    if why:
        print("serve_screenshot: skipped: " + why)
        return 0
    from selenium.webdriver.common.action_chains import ActionChains

    work = tempfile.mkdtemp(prefix="bb-serve-shot-")
    shutil.copy(os.path.join(ROOT, "fixtures", "rock06_height.png"), work)
    os.chdir(work)  # the page names the height as typed
    server = sb.Server(binary, "rock06_height.png", ["--scale", "64", "--quiet"])
    driver = sb.start_browser(1130, 720)
    try:
        driver.get(server.url)
        sb.wait_for(lambda: sb.drawn_bake(driver) >= 1, 300, "the bake drawn")
        canvas = driver.find_element("id", "canvas")
        ActionChains(driver).move_to_element_with_offset(canvas, 0, 0).click_and_hold() \
            .move_by_offset(-270, -60).release().perform()
        time.sleep(1)
        driver.save_screenshot(out)
    finally:
        sb.stop_browser(driver)
        server.close()
        shutil.rmtree(work, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
