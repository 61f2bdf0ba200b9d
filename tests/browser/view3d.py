#!/usr/bin/env python3
"""The live page's 3D view and growth playback in a real browser (issue 38).

Headless Chromium (Debian's `chromium`) draws WebGL through SwiftShader
(`--enable-unsafe-swiftshader --use-angle=swiftshader`); the page's
viewer reads its own picture back (`View3D.sample()`: the pixels that are
not the background, and a checksum). For a 3D plant (a model folder whose
view file asks for cylinders), a surface grammar's mesh and a shape
grammar's building:

1. the canvas is not blank, and the status names the triangles;
2. a drag turns the view (the pixels change), Reset brings the first view
   back (the same pixels), the wheel zooms;
3. the wireframe toggle changes the picture;
4. a broken edit keeps the last good view and shows the error at its line;
5. playback: Play advances the step and the picture, Pause stops it,
   scrubbing back to a step shows that step's picture again at once (no
   request), Step moves one frame;
6. a 2D curve keeps its vector drawing, zoomed about the cursor by the
   wheel and reset by a double click.

Screenshots go to OUTDIR (default target/browser). Run by .ci/run after
`cargo build`:

    python3 tests/browser/view3d.py [SUBGRAM_BINARY] [OUTDIR]
"""

import os
import shutil
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from serve import Browser, Page  # noqa: E402 (the shared DevTools driver)

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

PLANT = """// A small 3D plant: cylinders and spheres.
#include <lpfgall.h>
#define STEPS 4
derivation length: STEPS;
module A(int);
Axiom: SetWidth(0.15) SetColor(2) F(2) A(0);
A(k) : {
  if (k < 8)
    produce F(1) SB() Down(35) RollR(90) F(1) Sphere(0.3) A(k + 1) EB() RollR(137.5) SB() Down(-35) F(1) A(k + 1) EB() A(k + 1);
}
"""

VIEW = """projection: parallel
render mode: shaded
line style: cylinder
"""

SNOWFLAKE = """angle: 60;
derivation length: 3;
Axiom: F--F--F;
F -> F+F--F+F
"""


def start(binary, path, log):
    server = subprocess.Popen([binary, "serve", path, "--port", "0"],
                              stdout=subprocess.PIPE, stderr=log, text=True)
    line = server.stdout.readline()
    url = next((w for w in line.split() if w.startswith("http://127.0.0.1:")), None)
    assert url, f"the server printed no address: {line!r}"
    return server, url


def version(page):
    return page.js("window.subgram ? window.subgram.version : 0") or 0


def sample(page):
    return page.js("window.subgram.view3d.sample()")


def drag(page, x0, y0, x1, y1, button="left"):
    page.call("Input.dispatchMouseEvent", {"type": "mousePressed", "x": x0, "y": y0,
                                           "button": button, "buttons": 1, "clickCount": 1})
    for k in range(1, 9):
        x = x0 + (x1 - x0) * k / 8
        y = y0 + (y1 - y0) * k / 8
        page.call("Input.dispatchMouseEvent", {"type": "mouseMoved", "x": x, "y": y,
                                               "button": button, "buttons": 1})
    page.call("Input.dispatchMouseEvent", {"type": "mouseReleased", "x": x1, "y": y1,
                                           "button": button, "buttons": 0, "clickCount": 1})


def canvas_centre(page):
    r = page.js("(() => { const r = document.querySelector('#picture canvas').getBoundingClientRect();"
                " return [r.left + r.width / 2, r.top + r.height / 2]; })()")
    return r[0], r[1]


def check_3d(page, what, outdir, name):
    """The first view drawn: not blank, turned by a drag, back by Reset."""
    page.wait("window.subgram && window.subgram.version >= 1 && window.subgram.mode === '3d'",
              f"the first 3D view of the {what}", timeout=120)
    status = page.js("document.getElementById('status').textContent")
    assert "triangles" in status, status
    first = sample(page)
    area = first["width"] * first["height"]
    assert first["ink"] > 0.02 * area, f"the {what}'s canvas is blank: {first}"
    page.screenshot(os.path.join(outdir, f"{name}-1-first.png"))
    x, y = canvas_centre(page)
    drag(page, x, y, x + 120, y + 40)
    page.wait("window.subgram.view3d.frames > 0", "a frame")
    turned = sample(page)
    assert turned["sum"] != first["sum"], f"a drag did not turn the {what}"
    page.screenshot(os.path.join(outdir, f"{name}-2-turned.png"))
    page.js("document.getElementById('reset').click() || true")
    back = sample(page)
    assert back["sum"] == first["sum"], f"Reset did not bring the {what}'s first view back"
    # The wheel zooms in: more of the canvas is inked.
    page.call("Input.dispatchMouseEvent", {"type": "mouseWheel", "x": x, "y": y,
                                           "deltaX": 0, "deltaY": -400})
    time.sleep(0.2)
    zoomed = sample(page)
    assert zoomed["sum"] != first["sum"], f"the wheel did not zoom the {what}"
    page.js("document.getElementById('reset').click() || true")
    # The wireframe toggle changes the picture, and back.
    page.js("document.getElementById('wire').click() || true")
    wired = sample(page)
    assert wired["sum"] != first["sum"], f"the wireframe toggle changed nothing on the {what}"
    page.js("document.getElementById('wire').click() || true")
    assert sample(page)["sum"] == first["sum"]
    return first


def frame_to(page, index):
    page.js(f"""(() => {{ const s = document.getElementById('frame'); s.value = {index};
               s.dispatchEvent(new Event('input')); return true; }})()""")


def play_checks(page, outdir):
    """Play advances the step and the picture; Pause stops; scrubbing back
    shows a step's picture again without a request; Step moves one frame."""
    page.js("document.getElementById('play').click() || true")
    page.wait("window.subgram.frameShown !== null", "the first frame", timeout=120)
    status = page.js("document.getElementById('play-status').textContent")
    assert status.startswith("5 frames"), status
    seen = {}
    deadline = time.time() + 20
    while len(seen) < 5 and time.time() < deadline:
        step = page.js("window.subgram.frameShown")
        seen.setdefault(step, sample(page)["sum"])
        time.sleep(0.05)
    assert sorted(seen) == [0, 1, 2, 3, 4], f"play showed steps {sorted(seen)}"
    assert len(set(seen.values())) == 5, "the frames' pictures are not all different"
    page.js("document.getElementById('play').click() || true")  # pause
    paused = page.js("window.subgram.frameShown")
    time.sleep(0.8)
    assert page.js("window.subgram.frameShown") == paused, "Pause did not stop the playback"
    requests = page.js("performance.getEntriesByType('resource').length")
    frame_to(page, 1)
    one = sample(page)["sum"]
    assert one == seen[1], "frame 1 is not the picture that play showed for step 1"
    frame_to(page, 4)
    frame_to(page, 1)
    assert sample(page)["sum"] == one, "scrubbing back did not show step 1 again"
    assert page.js("performance.getEntriesByType('resource').length") == requests, \
        "scrubbing made a request"
    page.js("document.getElementById('fwd').click() || true")
    assert page.js("window.subgram.frameShown") == 2, "Step did not move one frame on"
    page.screenshot(os.path.join(outdir, "plant-4-playback.png"))
    # An edit ends the playback; the still picture of the edit comes back.
    n = version(page)
    page.caret(3, len("#define STEPS 4") + 1)
    page.backspace()
    page.type("3")
    page.wait(f"window.subgram.version > {n} && window.subgram.frameShown === null",
              "the still picture after an edit")


def main():
    binary = os.path.abspath(sys.argv[1] if len(sys.argv) > 1
                             else os.path.join(ROOT, "target", "debug", "subgram"))
    outdir = os.path.abspath(sys.argv[2] if len(sys.argv) > 2
                             else os.path.join(ROOT, "target", "browser"))
    os.makedirs(outdir, exist_ok=True)
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    if not chromium:
        sys.exit("tests/browser/view3d.py: no chromium on PATH (Debian: apt-get install chromium)")
    work = tempfile.mkdtemp(prefix="subgram-view3d-")
    log = open(os.path.join(outdir, "chromium-view3d.log"), "w")
    servers = []
    browser = None
    checks = 0
    try:
        plant = os.path.join(work, "plant")
        os.mkdir(plant)
        with open(os.path.join(plant, "lsystem.l"), "w") as f:
            f.write(PLANT)
        with open(os.path.join(plant, "view.v"), "w") as f:
            f.write(VIEW)
        meshes = os.path.join(work, "meshes")
        surfaces = os.path.join(work, "surfaces")
        shapes = os.path.join(work, "shapes")
        shutil.copytree(os.path.join(ROOT, "lsystems", "meshes"), meshes)
        shutil.copytree(os.path.join(ROOT, "lsystems", "surfaces"), surfaces)
        shutil.copytree(os.path.join(ROOT, "lsystems", "shapes"), shapes)
        curve = os.path.join(work, "snowflake.lsys")
        with open(curve, "w") as f:
            f.write(SNOWFLAKE)
        browser = Browser(chromium, os.path.join(work, "profile"), log,
                          ["--enable-unsafe-swiftshader", "--use-angle=swiftshader",
                           "--ignore-gpu-blocklist"])

        # 1-3. A plant, a mesh, a building: drawn, turned, reset, zoomed.
        server, url = start(binary, plant, log)
        servers.append(server)
        page = Page(browser, url)
        check_3d(page, "plant", outdir, "plant")
        checks += 1

        # 4. A broken edit keeps the last good view, the error at its line.
        before = sample(page)
        n = version(page)
        page.caret(8, 1)
        page.type("@")
        page.wait("document.querySelector('#gutter [data-line=\"8\"]').className === 'bad'",
                  "the error's line marked")
        assert version(page) == n, "a broken edit drew something"
        assert page.js("window.subgram.mode") == "3d"
        kept = sample(page)
        assert kept["sum"] == before["sum"], "the last good view was not kept"
        assert page.js("document.getElementById('picture').classList.contains('stale')")
        page.screenshot(os.path.join(outdir, "plant-3-broken.png"))
        page.backspace()
        page.wait(f"window.subgram.version > {n}", "the view back")
        checks += 1

        # 5. Playback: every step derived once, then played and scrubbed.
        play_checks(page, outdir)
        checks += 1

        for what, path in [("mesh", os.path.join(surfaces, "loop.lsys")),
                           ("building", os.path.join(shapes, "building.lsys"))]:
            server, url = start(binary, path, log)
            servers.append(server)
            check_3d(Page(browser, url), what, outdir, what)
            checks += 1

        # 6. A 2D curve: the SVG, zoomed by the wheel, reset by a double click.
        server, url = start(binary, curve, log)
        servers.append(server)
        page = Page(browser, url)
        page.wait("window.subgram && window.subgram.version >= 1", "the curve")
        assert page.js("window.subgram.mode") == "2d"
        src = page.js("document.querySelector('#picture img').src")
        assert src.startswith("data:image/svg+xml"), src[:60]
        width = page.js("document.querySelector('#picture img').getBoundingClientRect().width")
        r = page.js("(() => { const r = document.getElementById('picture').getBoundingClientRect();"
                    " return [r.left + r.width / 2, r.top + r.height / 2]; })()")
        page.call("Input.dispatchMouseEvent", {"type": "mouseWheel", "x": r[0], "y": r[1],
                                               "deltaX": 0, "deltaY": -300})
        page.wait(f"document.querySelector('#picture img').getBoundingClientRect().width > {width} * 1.3",
                  "the curve zoomed in")
        page.call("Input.dispatchMouseEvent", {"type": "mousePressed", "x": r[0], "y": r[1],
                                               "button": "left", "clickCount": 2})
        page.call("Input.dispatchMouseEvent", {"type": "mouseReleased", "x": r[0], "y": r[1],
                                               "button": "left", "clickCount": 2})
        page.wait(f"Math.abs(document.querySelector('#picture img').getBoundingClientRect().width - {width}) < 1",
                  "the curve back at its size")
        # Its playback: one SVG per step, each another picture.
        page.js("document.getElementById('play').click() || true")
        page.wait("window.subgram.frameShown !== null", "the curve's frames")
        pictures = {}
        deadline = time.time() + 20
        while len(pictures) < 4 and time.time() < deadline:
            pictures.setdefault(page.js("window.subgram.frameShown"),
                                page.js("document.querySelector('#picture img').src"))
            time.sleep(0.05)
        assert sorted(pictures) == [0, 1, 2, 3], sorted(pictures)
        assert all(p.startswith("data:image/svg+xml") for p in pictures.values())
        assert len(set(pictures.values())) == 4, "the curve's frames are not all different"
        checks += 1
        print(f"view3d: {checks} checks passed; screenshots in {outdir}")
    finally:
        if browser:
            browser.close()
        for s in servers:
            s.kill()
            s.wait()
        log.close()
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
