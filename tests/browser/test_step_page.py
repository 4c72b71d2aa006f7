#!/usr/bin/env python3
"""The stepper's web page in a real browser.

Starts `step --serve --port 0` on 127.0.0.1, opens the page in headless
Chromium through Selenium, clicks a pixel of the frame and checks that the
breakdown the page shows is, character for character, what the terminal
front end (`step` with `pixel X Y` on standard input) prints for the same
pixel; then a triangle from the pixel's history, the slider, and bad
requests (4xx JSON, the server still answering afterwards).
The view, at windows of 1280x800, 1600x1000 and 3840x2160 (for a 320x180 and
a 1280x720 frame): the whole frame fitted with its aspect, no sideways
scroll, the panels reachable with the image still in view; a click after a
4x and a 16x wheel zoom selects the pixel computed from the image's rect;
the value under the pointer; the keyboard; the "tri N" link brings its
panel into view; the depth stage's legend; the slider's note; the message
once the server is stopped. The Draws and Textures panels (loaded when
opened): 25 draws, draw 24's state and vertices, the env texture's level 2
at its JSON's size, zoom and channel. And the `--out DIR` page: every image has its
PNG's aspect, the depth figure its legend. Screenshots: /tmp/h3-*.png.

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
        # Each stage's scale (stepper/stages.cpp stage_scale): well formed.
        for st in stages:
            sc = st.get("scale")
            assert sc and sc["kind"] in ("ramp", "classes", "channels", "picture"), st
            colours = [c for _, c in sc["stops"]] + [c for c, _ in sc["classes"]]
            assert all(len(c) == 7 and c[0] == "#" and int(c[1:], 16) >= 0 for c in colours), st
            if sc["kind"] == "ramp":
                ts = [t for t, _ in sc["stops"]]
                assert ts[0] == 0 and ts[-1] == 1 and ts == sorted(ts) and sc["ticks"], st
            assert (sc["kind"] == "picture") == (st["name"] == "final"), st
        for x, y in ((100, 150), (0, 0), (319, 179), (160, 90)):
            code, p = get(base + "/api/pixel?x=%d&y=%d" % (x, y))
            assert code == 200 and p["text"] == step_text(step, "pixel %d %d\n" % (x, y)), (x, y)
            assert p["text"].count("\nsrgb8 ") == 1
            assert len(p["sample_list"]) == frame["samples"] and page_samples(p) == samples_in_text(p["text"]), p
        # At the slider's point: the pixel after the first N triangles, as
        # `upto N` then `pixel X Y` explains it; at all of them, the frame's end.
        with tempfile.TemporaryDirectory() as tmp:
            for n in (0, 30000, frame["triangles"]):
                code, p = get(base + "/api/pixel?x=160&y=100&upto=%d" % n)
                text = step_text(step, "upto %d %s\npixel 160 100\n" % (n, os.path.join(tmp, "u.png")))
                text = text[text.index("pixel 160 100:"):]
                assert code == 200 and p["text"] == text, n
                assert p["upto"] == (None if n == frame["triangles"] else n) and p["triangles"] == frame["triangles"], p
        assert get(base + "/api/pixel?x=160&y=100&upto=%d" % frame["triangles"])[1] == get(base + "/api/pixel?x=160&y=100")[1]
        assert "holds the clear colour" in get(base + "/api/pixel?x=160&y=100&upto=0")[1]["text"]
        # One texel, as `texel ID LEVEL X Y` prints it.
        for q, command in (("id=0&level=0&x=5&y=7", "texel 0 0 5 7"), ("id=env&level=2&x=3&y=4", "texel env 2 3 4")):
            code, v = get(base + "/api/texel?" + q)
            assert code == 200 and v["text"] == step_text(step, command + "\n"), (q, v)
        code, t = get(base + "/api/tri?n=98372")
        assert code == 200 and t["text"] == step_text(step, "tri 98372\n")
        code, t = get(base + "/api/tile?x=2&y=1")
        assert code == 200 and t["text"] == step_text(step, "tile 2 1\n")
        with urllib.request.urlopen(base + "/api/stage?name=final", timeout=60) as r:
            assert r.headers["Content-Type"] == "image/png" and r.read(8) == b"\x89PNG\r\n\x1a\n"
        # The views (stepper/views.h): the JSON of each holds the terminal's text.
        for path, command in (("/api/draws", "draws"), ("/api/draw?n=24", "draw 24"), ("/api/textures", "textures"),
                              ("/api/vertices?draw=3&first=5&count=7", "vertices 3 5 7")):
            code, v = get(base + path)
            assert code == 200, (path, v)
            if "text" in v:
                assert v["text"] == step_text(step, command + "\n"), path
        code, v = get(base + "/api/draws")
        assert len(v["draws"]) == 25 and v["draws"][24]["mesh_name"] == "floor", v["draws"][24]
        code, v = get(base + "/api/texture?id=env&level=2")
        assert code == 200 and v["id"] == "env" and v["level"] == 2, v
        with tempfile.TemporaryDirectory() as tmp:
            written = os.path.join(tmp, "env2.png")
            step_text(step, "texture env 2 %s\n" % written)
            with open(written, "rb") as f, urllib.request.urlopen(base + "/api/texture.png?id=env&level=2",
                                                                 timeout=60) as r:
                assert r.headers["Content-Type"] == "image/png" and r.read() == f.read()
        # Malformed requests, a fixed list and a bounded, seeded random loop.
        bad = [("/api/pixel?x=-1&y=0", 400), ("/api/pixel?x=320&y=0", 400), ("/api/pixel?x=1", 400),
               ("/api/pixel?x=1e2&y=0", 400), ("/api/pixel?x=0x10&y=0", 400), ("/api/tri?n=abc", 400),
               ("/api/tri?n=98432", 400), ("/api/tri?n=" + "9" * 40, 400), ("/api/tile?x=0", 400),
               ("/api/tile?x=5&y=0", 400), ("/api/upto?n=-1", 400), ("/api/upto", 400),
               ("/api/stage?name=nope", 404), ("/api/stage", 404), ("/nope", 404), ("/../../etc/passwd", 404),
               ("/api/pixel?x=" + "9" * 9000, 414), ("/api/draw?n=25", 400), ("/api/draw", 400),
               ("/api/texture?id=nope", 404), ("/api/texture", 400), ("/api/texture?id=0&level=99", 400),
               ("/api/texture.png?id=env&level=-1", 400), ("/api/vertices?draw=0&count=1001", 400),
               ("/api/vertices?draw=0&first=999999", 400), ("/api/vertices", 400),
               ("/api/pixel?x=1&y=1&upto=-1", 400), ("/api/pixel?x=1&y=1&upto=98433", 400),
               ("/api/pixel?x=1&y=1&upto=1e3", 400), ("/api/pixel?x=1&y=1&upto=1&upto=1", 400),
               ("/api/texel?id=nope&level=0&x=0&y=0", 404), ("/api/texel?id=0&level=0&x=0", 400),
               ("/api/texel?id=0&x=0&y=0", 400), ("/api/texel?id=0&level=0&x=-1&y=0", 400),
               ("/api/texel?id=env&level=7&x=0&y=999999", 400), ("/api/texel", 400)]
        rng = random.Random(10)
        alphabet = "0123456789-+.e%&=?/xyn abc\u00e9"
        for _ in range(150):
            endpoint = rng.choice(["/api/pixel", "/api/tri", "/api/tile", "/api/upto", "/api/stage", "/api/draw",
                                   "/api/texture", "/api/texture.png", "/api/vertices", "/api/texel"])
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


WINDOWS = ((1280, 800), (1600, 1000), (3840, 2160))


def rect(driver, element):
    return driver.execute_script("const r = arguments[0].getBoundingClientRect();"
                                 "return [r.left, r.top, r.right, r.bottom];", element)


def set_viewport(driver, w, h):
    """Makes the page's viewport w x h CSS px at 1 device pixel per CSS px (the
    DevTools protocol's override: a headless window is bounded by its screen)."""
    driver.execute_cdp_cmd("Emulation.setDeviceMetricsOverride",
                           {"width": w, "height": h, "deviceScaleFactor": 1, "mobile": False})
    inner = driver.execute_script("return [window.innerWidth, window.innerHeight, window.devicePixelRatio]")
    assert inner == [w, h, 1], ("viewport", inner, (w, h))


def wait_image(driver, wait, width, src=None):
    img = driver.find_element("id", "image")
    if src:
        wait.until(lambda d: src in img.get_attribute("src"))
    wait.until(lambda d: d.execute_script("return arguments[0].complete && arguments[0].naturalWidth", img) == width)
    return img


def check_fit(driver, wait, frame_w, frame_h, label):
    """The whole frame in the view with its aspect, filling it one way; no
    scrolling of the page; every panel reachable with the image still in view."""
    img = wait_image(driver, wait, frame_w)
    view = driver.find_element("id", "view")
    border = 1

    def inside(_):
        i, v = rect(driver, img), rect(driver, view)
        return i[0] >= v[0] + border - 0.01 and i[1] >= v[1] + border - 0.01 and i[2] <= v[2] - border + 0.01 \
            and i[3] <= v[3] - border + 0.01
    # The page refits when the view's size changes (a ResizeObserver, before the next frame).
    wait.until(lambda d: d.execute_script("return document.getElementById('zoom-value').textContent")
               .endswith("(fit)"))
    try:
        wait.until(inside)
    except Exception:
        pass  # the assertion below says what is wrong
    il, it, ir, ib = rect(driver, img)
    vl, vt, vr, vb = rect(driver, view)
    assert il >= vl + border - 0.01 and it >= vt + border - 0.01 and ir <= vr - border + 0.01 \
        and ib <= vb - border + 0.01, (label, "image", (il, it, ir, ib), "view", (vl, vt, vr, vb))
    aspect = (ir - il) / (ib - it)
    assert abs(aspect / (frame_w / frame_h) - 1) < 0.01, (label, aspect)
    # Fitted: as wide or as high as the view (within a pixel).
    inner_w, inner_h = vr - vl - 2 * border, vb - vt - 2 * border
    assert abs((ir - il) - inner_w) < 1 or abs((ib - it) - inner_h) < 1, (label, "not fitted")
    inner = driver.execute_script("return [window.innerWidth, window.innerHeight]")
    assert vl >= 0 and vt >= 0 and vr <= inner[0] and vb <= inner[1], (label, "view outside the window")
    sw, cw, sh, ch = driver.execute_script("const e = document.documentElement;"
                                           "return [e.scrollWidth, e.clientWidth, e.scrollHeight, e.clientHeight]")
    assert sw <= cw and sh <= ch, (label, "the page scrolls", sw, cw, sh, ch)
    for panel in ("pixel-panel", "tri-panel", "tile-panel"):
        el = driver.find_element("id", panel)
        driver.execute_script("arguments[0].open = true; arguments[0].scrollIntoView({block: 'start'})", el)
        top = rect(driver, el.find_element("tag name", "summary"))
        assert top[1] >= 0 and top[3] <= inner[1] and top[2] <= inner[0], (label, panel, top)
        assert rect(driver, view) == [vl, vt, vr, vb], (label, panel, "scrolled the image away")
        assert driver.execute_script("return [window.scrollX, window.scrollY]") == [0, 0], (label, panel)
    driver.execute_script("document.getElementById('right').scrollTop = 0")
    return (il, it, ir, ib)


def pointer(driver, x, y, click=False):
    """Moves the mouse to window position (x, y), and clicks there."""
    from selenium.webdriver.common.actions.action_builder import ActionBuilder
    ab = ActionBuilder(driver)
    ab.pointer_action.move_to_location(int(x), int(y))
    if click:
        ab.pointer_action.click()
    ab.perform()


def wheel(driver, x, y, delta_y):
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.actions.wheel_input import ScrollOrigin
    ActionChains(driver).scroll_from_origin(ScrollOrigin.from_viewport(int(x), int(y)), 0, int(delta_y)).perform()


def screen_point(img_rect, frame_w, frame_h, px, py):
    """An integer window position inside image pixel (px, py), away from
    its edges (the middle half of the pixel when it is 2 px wide or more),
    and the pixel the image's rect puts under it."""
    il, it, ir, ib = img_rect
    sx, sy = (ir - il) / frame_w, (ib - it) / frame_h
    best = None
    for X in range(int(il + px * sx) - 1, int(il + (px + 1) * sx) + 2):
        for Y in range(int(it + py * sy) - 1, int(it + (py + 1) * sy) + 2):
            fx, fy = (X - il) / sx, (Y - it) / sy
            if (int(fx), int(fy)) != (px, py):
                continue
            margin = min(fx - int(fx), 1 - (fx - int(fx)), fy - int(fy), 1 - (fy - int(fy)))
            if best is None or margin > best[0]:
                best = (margin, X, Y, int(fx), int(fy))
    margin, X, Y, ex, ey = best
    assert margin >= 0.2, ("no position well inside the pixel", best)
    return X, Y, ex, ey


def click_pixel_at_zoom(driver, wait, step, frame, zoom_notches, target):
    """Zooms by 2^(notches/2) around the target pixel with the wheel (4 notches
    at a time: one wheel event of -400 px), then
    clicks inside the target pixel and checks that the page explains the
    pixel computed from the image's rect, with step's exact text."""
    img = driver.find_element("id", "image")
    before = rect(driver, img)
    X, Y, _, _ = screen_point(before, frame["width"], frame["height"], *target)
    for _ in range(zoom_notches // 4):
        wheel(driver, X, Y, -400)
    after = rect(driver, img)
    factor = (after[2] - after[0]) / (before[2] - before[0])
    assert abs(factor - 2 ** (zoom_notches / 2)) < 1e-3 * factor, ("zoom", factor)
    # The point under the pointer stayed on the same image point.
    for a, b, c, d, p in ((before[0], before[2], after[0], after[2], X), (before[1], before[3], after[1], after[3], Y)):
        assert abs((p - a) / (b - a) - (p - c) / (d - c)) < 2e-3, ("zoom moved the point under the pointer",)
    X, Y, ex, ey = screen_point(after, frame["width"], frame["height"], *target)
    pointer(driver, X, Y)
    wait.until(lambda d: d.find_element("id", "cursor-value").text.startswith("x %d y %d " % (ex, ey)))
    pointer(driver, X, Y, click=True)
    wait.until(lambda d: d.find_element("id", "pixel-coords").text == "%d %d" % (ex, ey))
    wait.until(lambda d: d.find_element("id", "pixel-text").get_attribute("textContent").startswith(
        "pixel %d %d:" % (ex, ey)))
    shown = driver.find_element("id", "pixel-text").get_attribute("textContent")
    expected = step_text(step, "pixel %d %d\n" % (ex, ey))
    assert shown == expected, "the page's breakdown differs from step's:\n" + shown + "\n---\n" + expected
    return ex, ey, expected, factor


def open_browser(browser, driver_path, profile, size):
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service
    options = webdriver.ChromeOptions()
    options.binary_location = browser
    for flag in ("--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                 "--disable-background-networking", "--disable-component-update", "--disable-sync",
                 "--hide-scrollbars", "--force-device-scale-factor=1",
                 "--window-size=%d,%d" % size, "--user-data-dir=" + profile):
        options.add_argument(flag)
    return webdriver.Chrome(service=Service(driver_path), options=options)


def page_checks(driver, step, server, url):
    from selenium.webdriver.common.by import By
    from selenium.webdriver.common.keys import Keys
    from selenium.webdriver.support.ui import Select, WebDriverWait
    wait = WebDriverWait(driver, 60)
    set_viewport(driver, 1600, 1000)
    driver.get(url)
    wait.until(lambda d: "triangles" in d.find_element(By.ID, "summary").text)
    frame = get(url.rstrip("/") + "/api/frame")[1]
    W, H = frame["width"], frame["height"]
    img = wait_image(driver, wait, W)

    # Fitted at each window size; the page never scrolls.
    for w, h in WINDOWS:
        set_viewport(driver, w, h)
        r = check_fit(driver, wait, W, H, "%dx%d" % (w, h))
        driver.save_screenshot("/tmp/h3-%dx%d.png" % (w, h))
        print("%dx%d: the %dx%d frame fitted at %.3fx, aspect kept, no page scroll, panels reachable"
              % (w, h, W, H, (r[2] - r[0]) / W))
    set_viewport(driver, 1600, 1000)
    check_fit(driver, wait, W, H, "1600x1000 again")

    # Clicks: at fit, then after a 4x and a 16x wheel zoom around the pixel
    # (the pixel grid shows from 8 device pixels per image pixel).
    zoom = 1
    for notches, target in ((0, (100, 150)), (4, (100, 150)), (4, (101, 151))):
        x, y, expected, factor = click_pixel_at_zoom(driver, wait, step, frame, notches, target)
        assert (x, y) == target, ((x, y), target)
        zoom *= factor
        driver.save_screenshot("/tmp/h3-zoom%d.png" % round(zoom))
        print("zoom %g x fit: the click inside pixel %d %d explains that pixel (step's text exactly)" % (zoom, x, y))
    assert "srgb8 " in expected and "shading of #" in expected
    rows = driver.find_elements(By.CSS_SELECTOR, "#history tbody tr")
    assert len(rows) >= 1
    # The value under the pointer: the final image's colour is the pixel's srgb8.
    srgb8 = [l for l in expected.splitlines() if l.startswith("srgb8 ")][0].split()[1:]
    value = driver.find_element(By.ID, "cursor-value").text
    assert "displayed colour (%s)" % ", ".join(srgb8) in value, (value, srgb8)
    print("value under the pointer: %s" % value)
    # The samples table: one row per sample, holding what the text says.
    sample_rows = driver.find_elements(By.CSS_SELECTOR, "#samples tbody tr")
    assert len(sample_rows) == frame["samples"], len(sample_rows)
    shown_held = {k: r.find_elements(By.TAG_NAME, "td")[2].text for k, r in enumerate(sample_rows)}
    assert shown_held == samples_in_text(expected), (shown_held, samples_in_text(expected))
    if frame["samples"] > 1:
        covers = [l.split("covers samples ")[1].split(" of")[0] for l in expected.splitlines()
                  if l.startswith("     covers samples ")]
        assert [r.find_elements(By.TAG_NAME, "td")[3].text for r in rows] == covers

    # Keyboard: the arrows move the selected pixel, Enter explains it; F fits.
    view = driver.find_element(By.ID, "view")
    view.send_keys(Keys.ARROW_RIGHT, Keys.ARROW_RIGHT, Keys.ARROW_UP, Keys.ENTER)
    wait.until(lambda d: d.find_element(By.ID, "pixel-coords").text == "%d %d" % (x + 2, y - 1))
    wait.until(lambda d: d.find_element(By.ID, "pixel-text").get_attribute("textContent")
               == step_text(step, "pixel %d %d\n" % (x + 2, y - 1)))
    view.send_keys("1")  # one image pixel per CSS px (the device scale factor is 1)
    wait.until(lambda d: abs(rect(d, img)[2] - rect(d, img)[0] - W) < 0.01)
    view.send_keys("f")
    check_fit(driver, wait, W, H, "after F")
    print("keyboard: arrows moved the selection to %d %d, Enter explained it, 1 showed 1:1, F fitted the frame"
          % (x + 2, y - 1))

    # The "tri N" link: its setup as `tri N` prints it, its panel brought into view.
    set_viewport(driver, 1280, 800)
    link = driver.find_element(By.CSS_SELECTOR, "#history a.tri")
    tri = int(link.text.split()[1])
    link.click()
    wait.until(lambda d: d.find_element(By.ID, "tri-text").get_attribute("textContent").startswith("tri %d:" % tri))
    assert driver.find_element(By.ID, "tri-text").get_attribute("textContent") == step_text(step, "tri %d\n" % tri)
    summary = rect(driver, driver.find_element(By.CSS_SELECTOR, "#tri-panel > summary"))
    right = rect(driver, driver.find_element(By.ID, "right"))
    assert summary[1] >= right[1] - 0.5 and summary[3] <= min(right[3], 800), ("tri panel not in view", summary, right)
    driver.save_screenshot("/tmp/h3-tri-link-1280x800.png")
    print("tri %d: the page shows step's setup exactly, its panel scrolled into view" % tri)

    # The clicked pixel's tile: its bins as `tile TX TY` prints them.
    px, py = x + 2, y - 1
    tx, ty = px // frame["tile_size"], py // frame["tile_size"]
    wait.until(lambda d: d.find_element(By.ID, "tile-coords").text == "%d %d" % (tx, ty))
    assert driver.find_element(By.ID, "tile-text").get_attribute("textContent") == \
        step_text(step, "tile %d %d\n" % (tx, ty))
    print("tile %d %d: the page shows step's bins exactly" % (tx, ty))
    view_panel_checks(driver, wait, url.rstrip("/"))

    # The depth stage: its image, its sentence and its legend (near to far).
    set_viewport(driver, 1600, 1000)
    Select(driver.find_element(By.ID, "stage")).select_by_value("depth")
    wait_image(driver, wait, W, "/api/stage?name=depth")
    stages = {st["name"]: st for st in get(url.rstrip("/") + "/api/stages")[1]}
    assert driver.find_element(By.ID, "stage-about").get_attribute("textContent") == stages["depth"]["about"]
    assert "scale" in stages["depth"], "/api/stages gives no scale (stepper/http_server.cpp: stage_list_json)"
    scale = stages["depth"]["scale"]
    assert scale["kind"] == "ramp" and scale["units"] == "scene units" and scale["min"] < scale["max"], scale
    legend = driver.find_element(By.ID, "legend-depth")
    assert legend.is_displayed() and "(near)" in legend.text and "(far)" in legend.text, legend.text
    assert "linear-gradient" in driver.find_element(By.CSS_SELECTOR, "#legend-depth .bar").value_of_css_property(
        "background-image")
    pointer(driver, *screen_point(rect(driver, img), W, H, 100, 150)[:2])
    wait.until(lambda d: "scene units" in d.find_element(By.ID, "cursor-value").text)
    driver.save_screenshot("/tmp/h3-depth.png")
    print("stage: depth, its sentence, its legend (%s) and the depth under the pointer: %s"
          % (legend.text.replace("\n", " / "), driver.find_element(By.ID, "cursor-value").text))

    # Every legend tells the truth: each colour of a stage image is one of
    # its classes, or on its colour bar (within 4 steps per channel).
    checked = []
    for name, st in stages.items():
        if st["scale"]["kind"] not in ("classes", "ramp"):
            continue
        off = driver.execute_async_script("""
            const [name, scale, done] = arguments, im = new Image();
            im.onload = () => {
              const c = document.createElement('canvas');
              c.width = im.naturalWidth; c.height = im.naturalHeight;
              const g = c.getContext('2d');
              g.drawImage(im, 0, 0);
              const d = g.getImageData(0, 0, c.width, c.height).data, seen = new Set(), off = [];
              for (let i = 0; i < d.length; i += 4) seen.add((d[i] << 16) | (d[i + 1] << 8) | d[i + 2]);
              for (const v of seen) {
                const rgb = [v >> 16, (v >> 8) & 255, v & 255];
                const known = scale.classes.some(([c]) => parseInt(c.slice(1), 16) === v);
                if (!known && (scale.kind === 'classes' || readScale(scale, rgb) === 'not on the scale')) off.push(rgb);
              }
              done([seen.size, off.slice(0, 5)]);
            };
            im.onerror = () => done([0, ['cannot load']]);
            im.src = '/api/stage?name=' + name;""", name, st["scale"])
        assert off[0] >= 1 and not off[1], (name, "colours off its legend", off)
        checked.append("%s (%d colours)" % (name, off[0]))
    print("legends: every colour of " + ", ".join(checked) + " is on its legend")

    # The slider: the frame after the first 1000 triangles; a click then
    # says which frame the explanation is of.
    driver.execute_script("const u = document.getElementById('upto'); u.value = 1000;"
                          "u.dispatchEvent(new Event('input'));")
    wait_image(driver, wait, W, "/api/upto?n=1000")
    X, Y, ex, ey = screen_point(rect(driver, img), W, H, 60, 160)
    pointer(driver, X, Y, click=True)
    wait.until(lambda d: d.find_element(By.ID, "pixel-coords").text == "%d %d" % (ex, ey))
    head = "pixel %d %d:" % (ex, ey)
    wait.until(lambda d: d.find_element(By.ID, "pixel-text").get_attribute("textContent").startswith(head) and
               "Updating" not in d.find_element(By.ID, "pixel-note").text)
    note = driver.find_element(By.ID, "pixel-note").text
    assert "after the first 1000 of %d triangles" % frame["triangles"] in note, note
    # The explanation is of that point: `upto 1000` then `pixel X Y`, exactly.
    with tempfile.TemporaryDirectory() as tmp:
        expected = step_text(step, "upto 1000 %s\npixel %d %d\n" % (os.path.join(tmp, "u.png"), ex, ey))
    expected = expected[expected.index(head):]
    shown = driver.find_element(By.ID, "pixel-text").get_attribute("textContent")
    assert shown == expected, (shown[:300], expected[:300])
    # Back to the end: the slider at all triangles explains the frame's end.
    driver.execute_script("const u = document.getElementById('upto'); u.value = u.max;"
                          "u.dispatchEvent(new Event('input'));")
    wait.until(lambda d: "all %d triangles" % frame["triangles"] in d.find_element(By.ID, "pixel-note").text and
               "Updating" not in d.find_element(By.ID, "pixel-note").text)
    assert driver.find_element(By.ID, "pixel-text").get_attribute("textContent") == step_text(
        step, "pixel %d %d\n" % (ex, ey))
    print("slider: after 1000 triangles a click explains the pixel then (step's upto 1000, pixel text exactly): " +
          note + "; at the end, the frame's end again")
    driver.execute_script("const u = document.getElementById('upto'); u.value = 1000;"
                          "u.dispatchEvent(new Event('input'));")
    wait_image(driver, wait, W, "/api/upto?n=1000")
    wait.until(lambda d: "after the first 1000 " in d.find_element(By.ID, "pixel-note").text and
               "Updating" not in d.find_element(By.ID, "pixel-note").text)

    # Bad requests: JSON errors, and the server goes on.
    for path, status in (("/api/pixel?x=-1&y=0", 400), ("/api/pixel?x=320&y=0", 400), ("/api/tri?n=abc", 400),
                         ("/api/tile?x=0", 400), ("/api/stage?name=nope", 404), ("/nope", 404),
                         ("/api/pixel?x=" + "9" * 9000, 414)):
        code, body = get(url.rstrip("/") + path)
        assert code == status and "error" in body, (path, code, body)
    code, body = get(url.rstrip("/") + "/api/frame")
    assert code == 200 and body["width"] == 320
    print("bad requests: 4xx JSON errors, server still answering")

    # The server stops: the page says so, and keeps what it shows.
    stop_server(server)
    text_before = driver.find_element(By.ID, "pixel-text").get_attribute("textContent")
    X, Y, _, _ = screen_point(rect(driver, img), W, H, 200, 100)
    pointer(driver, X, Y, click=True)
    wait.until(lambda d: "the step server stopped (or cannot be reached)" in d.find_element(By.ID, "status").text)
    # Another stage cannot load: the last image stays, and so do the controls that describe it.
    stage = Select(driver.find_element(By.ID, "stage"))
    stage.select_by_value("normal")
    wait.until(lambda d: stage.first_selected_option.get_attribute("value") == "depth")
    assert "/api/upto?n=1000" in img.get_attribute("src")
    assert driver.execute_script("return [arguments[0].naturalWidth, document.getElementById('upto').value]",
                                 img) == [W, "1000"]
    assert driver.find_element(By.ID, "pixel-text").get_attribute("textContent") == text_before
    view.send_keys("+")
    assert not driver.find_element(By.ID, "zoom-value").text.endswith("(fit)")
    # A view panel says so in its own text.
    row = driver.find_elements(By.CSS_SELECTOR, "#draws tbody tr")[3]
    driver.execute_script("arguments[0].scrollIntoView({block: 'center'})", row)
    row.click()
    wait.until(lambda d: d.find_element(By.ID, "draw-text").get_attribute("textContent").startswith(
        "error: the step server stopped"))
    driver.save_screenshot("/tmp/h3-stopped.png")
    print("stopped server: \"%s\"; the image and the texts stay, zoom still works"
          % driver.find_element(By.ID, "status").text)


def view_panel_checks(driver, wait, base):
    """The Draws and Textures panels: loaded when opened, the texts those of
    the API (the `serve` test ties the API to the terminal), the texture's
    level the size its JSON gives. At 1280x800: /tmp/h6-views-1280x800.png,
    /tmp/h6-textures-1280x800.png."""
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import Select
    set_viewport(driver, 1280, 800)
    text = lambda i: driver.find_element(By.ID, i).get_attribute("textContent")  # noqa: E731
    assert not driver.find_elements(By.CSS_SELECTOR, "#draws tbody tr"), "the draws loaded before the panel opened"
    driver.find_element(By.CSS_SELECTOR, "#draws-panel > summary").click()
    wait.until(lambda d: len(d.find_elements(By.CSS_SELECTOR, "#draws tbody tr")) == 25)
    row = driver.find_elements(By.CSS_SELECTOR, "#draws tbody tr")[24]
    assert [c.text for c in row.find_elements(By.TAG_NAME, "td")] == ["24", "floor", "tiles", "128", "OPAQUE",
                                                                     "visible"], row.text
    driver.execute_script("arguments[0].scrollIntoView({block: 'center'})", row)
    row.click()
    wait.until(lambda d: text("draw-text").startswith("draw 24:"))
    assert "floor" in text("draw-text") and text("draw-text") == get(base + "/api/draw?n=24")[1]["text"]
    driver.find_element(By.CSS_SELECTOR, "#draw-links a").click()
    first = get(base + "/api/vertices?draw=24&first=0&count=16")[1]["text"]
    wait.until(lambda d: text("vertices-text") == first)
    more = get(base + "/api/vertices?draw=24&first=16&count=16")[1]["text"]
    driver.find_element(By.ID, "vertices-more").click()
    wait.until(lambda d: text("vertices-text") == more)
    assert text("vertices-title") == "draw 24: vertices 16..31 of 81", text("vertices-title")
    print("draws: 25 rows, row 24 shows draw 24 ('floor'), its vertices 0..15 then 16..31 as the API gives them")

    textures = get(base + "/api/textures")[1]["textures"]
    env = [t for t in textures if t["id"] == "env"][0]
    driver.find_element(By.CSS_SELECTOR, "#textures-panel > summary").click()
    wait.until(lambda d: len(d.find_elements(By.CSS_SELECTOR, "#textures tbody tr")) == len(textures))
    row = driver.find_element(By.CSS_SELECTOR, "#textures tbody tr[data-id='env']")
    driver.execute_script("arguments[0].scrollIntoView({block: 'center'})", row)
    row.click()
    Select(driver.find_element(By.ID, "texture-level")).select_by_value("2")
    img = driver.find_element(By.ID, "texture-image")
    wait.until(lambda d: "id=env&level=2" in (img.get_attribute("src") or "") and d.execute_script(
        "return arguments[0].complete && arguments[0].naturalWidth > 0", img))
    size = env["level_sizes"][2]
    natural = driver.execute_script("return [arguments[0].naturalWidth, arguments[0].naturalHeight]", img)
    assert natural == [size["width"], size["height"]], (natural, size)
    wait.until(lambda d: text("texture-text") == get(base + "/api/texture?id=env&level=2")[1]["text"])
    line = text("texture-line")
    assert "level 2 of 8: %dx%d" % (size["width"], size["height"]) in line, line
    assert [li.text for li in driver.find_elements(By.CSS_SELECTOR, "#texture-uses li")] == env["images"] + env["uses"]
    assert img.value_of_css_property("image-rendering") == "pixelated"
    driver.find_element(By.ID, "texture-four").click()
    assert rect(driver, img)[2] - rect(driver, img)[0] == 4 * size["width"]
    # The texel under the pointer, and a click keeps its `texel` text.
    driver.execute_script("arguments[0].scrollIntoView({block: 'center', inline: 'start'})", img)
    r = rect(driver, img)
    tx, ty = 5, 3
    pointer(driver, r[0] + 4 * tx + 2, r[1] + 4 * ty + 2)
    wait.until(lambda d: text("texel-value").startswith("texel %d %d" % (tx, ty)) and "..." not in text("texel-value"))
    hover = text("texel-value")
    pointer(driver, r[0] + 4 * tx + 2, r[1] + 4 * ty + 2, click=True)
    expected = get(base + "/api/texel?id=env&level=2&x=%d&y=%d" % (tx, ty))[1]["text"]  # step's text (api_checks)
    wait.until(lambda d: d.find_element(By.ID, "texel-text").get_attribute("textContent") == expected)
    assert expected.startswith("texel %d %d of texture env level 2" % (tx, ty)), expected
    driver.find_element(By.ID, "texture-one").click()
    assert rect(driver, img)[2] - rect(driver, img)[0] == size["width"]
    Select(driver.find_element(By.ID, "texture-channel")).select_by_value("r")
    canvas = driver.find_element(By.ID, "texture-canvas")
    assert canvas.is_displayed() and not img.is_displayed()
    assert driver.execute_script("return [arguments[0].width, arguments[0].height]", canvas) == natural
    # Each texel of the canvas is grey, the PNG's red.
    off = driver.execute_script("""
        const [img, c] = arguments, t = document.createElement('canvas');
        t.width = img.naturalWidth; t.height = img.naturalHeight;
        const g = t.getContext('2d');
        g.drawImage(img, 0, 0);
        const a = g.getImageData(0, 0, t.width, t.height).data;
        const b = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
        let off = 0;
        for (let i = 0; i < a.length; i += 4)
          if (b[i] !== a[i] || b[i + 1] !== a[i] || b[i + 2] !== a[i] || b[i + 3] !== 255) ++off;
        return off;""", img, canvas)
    assert off == 0, ("texels of the R view that are not the PNG's red as grey", off)
    Select(driver.find_element(By.ID, "texture-channel")).select_by_value("rgb")
    driver.find_element(By.ID, "texture-fit").click()
    fitted = rect(driver, img)
    assert abs((fitted[2] - fitted[0]) / (fitted[3] - fitted[1]) - size["width"] / size["height"]) < 0.01
    driver.execute_script("document.getElementById('draws-panel').scrollIntoView({block: 'start'})")
    driver.save_screenshot("/tmp/h6-views-1280x800.png")
    driver.execute_script("document.getElementById('textures-panel').scrollIntoView({block: 'start'})")
    driver.save_screenshot("/tmp/h6-textures-1280x800.png")
    print("texel: the pointer over texel %d %d of env level 2 shows '%s'; a click shows its texel text exactly"
          % (tx, ty, hover))
    print("textures: env level 2 shown at %dx%d as its JSON says, pixelated, 4x / 1:1 / fit, channel R in a canvas"
          % tuple(natural))


def large_frame_checks(driver, step):
    """A 1280x720 frame (step's default size) fitted at each window size."""
    from selenium.webdriver.support.ui import WebDriverWait
    server = subprocess.Popen([step, "--size", "1280x720", "--threads", "2", "--serve", "--port", "0"],
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        line = server.stdout.readline()
        assert "serving http://127.0.0.1:" in line, line + server.stderr.read()
        url = line.split("serving ")[1].split(" ")[0]
        wait = WebDriverWait(driver, 120)
        driver.get(url)
        wait.until(lambda d: "triangles" in d.find_element("id", "summary").text)
        for w, h in WINDOWS:
            set_viewport(driver, w, h)
            r = check_fit(driver, wait, 1280, 720, "1280x720 frame at %dx%d" % (w, h))
            driver.save_screenshot("/tmp/h3-1280x720-at-%dx%d.png" % (w, h))
            print("%dx%d: the 1280x720 frame fitted at %.3fx" % (w, h, (r[2] - r[0]) / 1280))
    finally:
        stop_server(server)


def export_checks(driver, step):
    """The `--out DIR` page: each image with its PNG's aspect, legends."""
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import WebDriverWait
    out = tempfile.mkdtemp(prefix="prast_out_")
    try:
        r = subprocess.run([step] + FLAGS + ["--out", out], capture_output=True, text=True, timeout=300)
        assert r.returncode == 0, r.stderr
        stages = [n[:-4] for n in os.listdir(out) if n.endswith(".png")]
        for w, h in ((1280, 800), (3840, 2160)):
            set_viewport(driver, w, h)
            driver.get("file://" + os.path.join(out, "index.html"))
            WebDriverWait(driver, 60).until(lambda d: d.execute_script(
                "return [...document.images].every((i) => i.complete && i.naturalWidth > 0)"))
            images = driver.find_elements(By.CSS_SELECTOR, "figure img")
            assert len(images) == len(stages) == 22, (len(images), len(stages))
            for im in images:
                nw, nh = driver.execute_script("return [arguments[0].naturalWidth, arguments[0].naturalHeight]", im)
                l, t, rr, b = rect(driver, im)
                assert (nw, nh) == (320, 180) and abs(((rr - l) / (b - t)) / (nw / nh) - 1) < 0.01, \
                    (im.get_attribute("src"), (nw, nh), (l, t, rr, b))
                assert rr <= w, ("image wider than the window", im.get_attribute("src"))
            sw, cw = driver.execute_script("return [document.documentElement.scrollWidth,"
                                           "document.documentElement.clientWidth]")
            assert sw <= cw, ("--out page scrolls sideways", sw, cw)
            depth = driver.find_element(By.CSS_SELECTOR, "figure#depth .legend")
            assert "(near)" in depth.text and "(far)" in depth.text, depth.text
            assert driver.find_elements(By.CSS_SELECTOR, "figure#overdraw .legend .classes i")
            assert not driver.find_elements(By.CSS_SELECTOR, "figure#final .legend")
            driver.execute_script("document.getElementById('depth').scrollIntoView()")
            driver.save_screenshot("/tmp/h3-out-%dx%d.png" % (w, h))
        print("--out: 22 images with their PNGs' aspect at 1280 and 3840 wide, no sideways scroll, legends")
    finally:
        shutil.rmtree(out, ignore_errors=True)


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
        import selenium  # noqa: F401
    except ImportError:
        skip("python3-selenium is not installed (apt-get install python3-selenium)")

    server, url = start_server(step)
    url += "/"
    profile = tempfile.mkdtemp(prefix="prast_browser_")
    driver = None
    try:
        driver = open_browser(browser, driver_path, profile, (1600, 1000))
        page_checks(driver, step, server, url)
        export_checks(driver, step)
        large_frame_checks(driver, step)
        print("1 passed, 0 failed")
        return 0
    finally:
        if driver is not None:
            driver.quit()
        if server.poll() is None:
            stop_server(server)
        shutil.rmtree(profile, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
