#!/usr/bin/env python3
"""The stepper's web page in a real browser.

Starts `step --serve --port 0` on 127.0.0.1, opens the page in headless
Chromium through Selenium, clicks a pixel of the frame and checks that the
breakdown the page shows is, character for character, what the terminal
front end (`step` with `pixel X Y` on standard input) prints for the same
pixel; then a triangle from the pixel's history, the slider, and bad
requests (4xx JSON, the server still answering afterwards).

usage: test_step_page.py STEP_EXE [--api]
With --api, no browser: the JSON API only (every endpoint, the pixel text
against the terminal front end's, and a bounded loop of malformed requests
that must all get 4xx JSON errors while the server keeps answering), then
the hostile-input checks of hostile_http.py (Host header, methods, bodies,
traversal, numbers, malformed requests, limits, slow and concurrent
clients, a seeded fuzz loop, 127.0.0.1 only).
Without it, exit 77 (CTest: skipped) when chromium, chromedriver or
python3-selenium is missing, unless PRAST_BROWSER_REQUIRED=1 (CI) makes
that a failure.
"""
import json
import os
import random
import shutil
import subprocess
import sys
import tempfile
import urllib.error
import urllib.parse
import urllib.request

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
import hostile_http  # noqa: E402

SKIP = 77
FLAGS = ["--size", "320x180", "--threads", "2"]


def skip(why):
    if os.environ.get("PRAST_BROWSER_REQUIRED") == "1":
        print("FAILED: " + why + " (PRAST_BROWSER_REQUIRED=1)")
        sys.exit(1)
    print("skipped: " + why)
    sys.exit(SKIP)


def find_browser():
    for name in ("chromium", "chromium-browser"):
        path = shutil.which(name)
        if path:
            return path
    return None


def step_text(step, commands):
    """What the terminal front end prints for `commands`."""
    r = subprocess.run([step] + FLAGS, input=commands, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    return r.stdout


def get(url):
    """(status, parsed JSON body or None for an image) of a GET, 4xx included."""
    try:
        with urllib.request.urlopen(url, timeout=60) as r:
            body = r.read()
            return r.status, json.loads(body.decode()) if "json" in r.headers["Content-Type"] else None
    except urllib.error.HTTPError as e:
        return e.code, json.loads(e.read().decode())


def samples_in_text(text):
    """{sample: what it holds} from the `samples after the frame` lines of a
    pixel's text ("  s0 #2 (tri 43470) depth ..." -> {0: "#2 (tri 43470)"});
    with one sample, from the "shading of #k (tri N)" line or the background."""
    held = {}
    for line in text.splitlines():
        if line.startswith("  s") and " depth " in line and line[3].isdigit():
            k = int(line[3:].split()[0])
            held[k] = line.split(" ", 4)[3] if line.split()[1] == "cleared" else " ".join(line.split()[1:4])
    if not held:
        for line in text.splitlines():
            if line.startswith("shading of #"):
                held[0] = " ".join(line.split()[2:5]).rstrip(",")
                break
        else:
            held[0] = "cleared"
    return held


def page_samples(p):
    """The same from a pixel's JSON, as the page words it."""
    return {k: "cleared" if s["owner"] < 0 else "#%d (tri %d)" % (s["owner"] + 1, p["history"][s["owner"]]["tri"])
            for k, s in enumerate(p["sample_list"])}


def start_server(step):
    server = subprocess.Popen([step] + FLAGS + ["--serve", "--port", "0"], stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True)
    line = server.stdout.readline()
    assert "serving http://127.0.0.1:" in line, "no URL from step --serve: " + line + server.stderr.read()
    url = line.split("serving ")[1].split(" ")[0]
    assert url.startswith("http://127.0.0.1:")
    return server, url.rstrip("/")


def stop_server(server):
    """Stops the server; fails on anything a sanitizer build reported."""
    server.terminate()
    try:
        _, err = server.communicate(timeout=30)
    except subprocess.TimeoutExpired:
        server.kill()
        _, err = server.communicate()
    assert "runtime error" not in err and "Sanitizer" not in err, err


def api_checks(step):
    server, base = start_server(step)
    try:
        code, frame = get(base + "/api/frame")
        assert code == 200 and frame["width"] == 320 and frame["height"] == 180, frame
        code, stages = get(base + "/api/stages")
        assert code == 200 and "final" in [s["name"] for s in stages]
        for x, y in ((100, 150), (0, 0), (319, 179), (160, 90)):
            code, p = get(base + "/api/pixel?x=%d&y=%d" % (x, y))
            assert code == 200 and p["text"] == step_text(step, "pixel %d %d\n" % (x, y)), (x, y)
            assert p["text"].count("\nsrgb8 ") == 1
            assert len(p["sample_list"]) == frame["samples"] and page_samples(p) == samples_in_text(p["text"]), p
        code, t = get(base + "/api/tri?n=98372")
        assert code == 200 and t["text"] == step_text(step, "tri 98372\n")
        code, t = get(base + "/api/tile?x=2&y=1")
        assert code == 200 and t["text"] == step_text(step, "tile 2 1\n")
        with urllib.request.urlopen(base + "/api/stage?name=final", timeout=60) as r:
            assert r.headers["Content-Type"] == "image/png" and r.read(8) == b"\x89PNG\r\n\x1a\n"
        # Malformed requests, a fixed list and a bounded, seeded random loop.
        bad = [("/api/pixel?x=-1&y=0", 400), ("/api/pixel?x=320&y=0", 400), ("/api/pixel?x=1", 400),
               ("/api/pixel?x=1e2&y=0", 400), ("/api/pixel?x=0x10&y=0", 400), ("/api/tri?n=abc", 400),
               ("/api/tri?n=98432", 400), ("/api/tri?n=" + "9" * 40, 400), ("/api/tile?x=0", 400),
               ("/api/tile?x=5&y=0", 400), ("/api/upto?n=-1", 400), ("/api/upto", 400),
               ("/api/stage?name=nope", 404), ("/api/stage", 404), ("/nope", 404), ("/../../etc/passwd", 404),
               ("/api/pixel?x=" + "9" * 9000, 414)]
        rng = random.Random(10)
        alphabet = "0123456789-+.e%&=?/xyn abc\u00e9"
        for _ in range(150):
            endpoint = rng.choice(["/api/pixel", "/api/tri", "/api/tile", "/api/upto", "/api/stage"])
            query = "".join(rng.choice(alphabet) for _ in range(rng.randint(0, 30)))
            bad.append((endpoint + "?" + urllib.parse.quote(query, safe="&=%"), None))
        for path, status in bad:
            code, body = get(base + path)
            if status is None:
                assert code in (200, 400, 404, 414) and (code == 200 or "error" in body), (path, code, body)
            else:
                assert code == status and "error" in body, (path, code, body)
        code, frame = get(base + "/api/frame")
        assert code == 200 and server.poll() is None
        print("api: every endpoint answers as the terminal front end does; %d malformed requests got 4xx JSON"
              % len(bad))
        hostile_http.run(int(base.rsplit(":", 1)[1]), frame)
        assert server.poll() is None
    finally:
        stop_server(server)


def main():
    if len(sys.argv) not in (2, 3) or (len(sys.argv) == 3 and sys.argv[2] != "--api"):
        print(__doc__)
        return 2
    step = sys.argv[1]
    if len(sys.argv) == 3:
        api_checks(step)
        print("1 passed, 0 failed")
        return 0
    browser = find_browser()
    driver_path = shutil.which("chromedriver")
    if not browser or not driver_path:
        skip("chromium and chromium-driver are not installed (apt-get install chromium chromium-driver)")
    try:
        from selenium import webdriver
        from selenium.webdriver.chrome.service import Service
        from selenium.webdriver.common.action_chains import ActionChains
        from selenium.webdriver.common.by import By
        from selenium.webdriver.support.ui import Select, WebDriverWait
    except ImportError:
        skip("python3-selenium is not installed (apt-get install python3-selenium)")

    server, url = start_server(step)
    url += "/"
    profile = tempfile.mkdtemp(prefix="prast_browser_")
    driver = None
    try:
        options = webdriver.ChromeOptions()
        options.binary_location = browser
        for flag in ("--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                     "--disable-background-networking", "--disable-component-update", "--disable-sync",
                     "--window-size=1600,1000", "--user-data-dir=" + profile):
            options.add_argument(flag)
        driver = webdriver.Chrome(service=Service(driver_path), options=options)
        driver.get(url)
        wait = WebDriverWait(driver, 60)
        wait.until(lambda d: "triangles" in d.find_element(By.ID, "summary").text)
        img = driver.find_element(By.ID, "image")
        wait.until(lambda d: d.execute_script("return arguments[0].complete && arguments[0].naturalWidth", img) == 320)

        # Click a pixel of the floor (offsets from the element's centre).
        width, height = img.size["width"], img.size["height"]
        px, py = 100, 150
        ActionChains(driver).move_to_element_with_offset(
            img, int((px + 0.5) * width / 320 - width / 2), int((py + 0.5) * height / 180 - height / 2)).click().perform()
        wait.until(lambda d: d.find_element(By.ID, "pixel-text").get_attribute("textContent").startswith("pixel "))
        coords = driver.find_element(By.ID, "pixel-coords").text.split()
        x, y = int(coords[0]), int(coords[1])
        assert abs(x - px) <= 1 and abs(y - py) <= 1, (x, y)
        shown = driver.find_element(By.ID, "pixel-text").get_attribute("textContent")
        expected = step_text(step, "pixel %d %d\n" % (x, y))
        assert shown == expected, "the page's breakdown differs from step's:\n" + shown + "\n---\n" + expected
        assert "srgb8 " in shown and "shading of #" in shown
        rows = driver.find_elements(By.CSS_SELECTOR, "#history tbody tr")
        assert len(rows) >= 1
        # The samples table: one row per sample, holding what the text says.
        frame = get(url.rstrip("/") + "/api/frame")[1]
        sample_rows = driver.find_elements(By.CSS_SELECTOR, "#samples tbody tr")
        assert len(sample_rows) == frame["samples"], len(sample_rows)
        shown_held = {k: r.find_elements(By.TAG_NAME, "td")[2].text for k, r in enumerate(sample_rows)}
        assert shown_held == samples_in_text(expected), (shown_held, samples_in_text(expected))
        # The history's sample columns: those of the text's "covers samples" lines.
        if frame["samples"] > 1:
            covers = [l.split("covers samples ")[1].split(" of")[0] for l in expected.splitlines()
                      if l.startswith("     covers samples ")]
            assert [r.find_elements(By.TAG_NAME, "td")[3].text for r in rows] == covers
        print("pixel %d %d: the page shows step's breakdown exactly (%d lines, %d history rows, %d samples)"
              % (x, y, shown.count("\n"), len(rows), len(sample_rows)))

        # The triangle of the first fragment: its setup as `tri N` prints it.
        link = driver.find_element(By.CSS_SELECTOR, "#history a.tri")
        tri = int(link.text.split()[1])
        link.click()
        wait.until(lambda d: d.find_element(By.ID, "tri-text").get_attribute("textContent").startswith("tri %d:" % tri))
        assert driver.find_element(By.ID, "tri-text").get_attribute("textContent") == step_text(step, "tri %d\n" % tri)
        print("tri %d: the page shows step's setup exactly" % tri)

        # The clicked pixel's tile: its bins as `tile TX TY` prints them.
        tx, ty = x // frame["tile_size"], y // frame["tile_size"]
        wait.until(lambda d: d.find_element(By.ID, "tile-coords").text == "%d %d" % (tx, ty))
        wait.until(lambda d: d.find_element(By.ID, "tile-text").get_attribute("textContent").startswith("tile "))
        assert driver.find_element(By.ID, "tile-text").get_attribute("textContent") == \
            step_text(step, "tile %d %d\n" % (tx, ty))
        print("tile %d %d: the page shows step's bins exactly" % (tx, ty))

        # Switching stages: the depth stage's image and its sentence.
        Select(driver.find_element(By.ID, "stage")).select_by_value("depth")
        wait.until(lambda d: "/api/stage?name=depth" in img.get_attribute("src"))
        wait.until(lambda d: d.execute_script("return arguments[0].complete && arguments[0].naturalWidth", img) == 320)
        about = {st["name"]: st["about"] for st in get(url.rstrip("/") + "/api/stages")[1]}
        assert driver.find_element(By.ID, "stage-about").get_attribute("textContent") == about["depth"]
        print("stage: switched to depth, its image and sentence shown")

        # The slider: the frame after the first 1000 triangles.
        driver.execute_script("const u = document.getElementById('upto'); u.value = 1000;"
                              "u.dispatchEvent(new Event('input'));")
        wait.until(lambda d: "/api/upto?n=1000" in img.get_attribute("src"))
        wait.until(lambda d: d.execute_script("return arguments[0].complete && arguments[0].naturalWidth", img) == 320)
        print("slider: the frame after 1000 triangles loaded")

        # Bad requests: JSON errors, and the server goes on.
        for path, status in (("/api/pixel?x=-1&y=0", 400), ("/api/pixel?x=320&y=0", 400), ("/api/tri?n=abc", 400),
                             ("/api/tile?x=0", 400), ("/api/stage?name=nope", 404), ("/nope", 404),
                             ("/api/pixel?x=" + "9" * 9000, 414)):
            code, body = get(url.rstrip("/") + path)
            assert code == status and "error" in body, (path, code, body)
        code, body = get(url.rstrip("/") + "/api/frame")
        assert code == 200 and body["width"] == 320
        print("bad requests: 4xx JSON errors, server still answering")
        print("1 passed, 0 failed")
        return 0
    finally:
        if driver is not None:
            driver.quit()
        stop_server(server)
        shutil.rmtree(profile, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
