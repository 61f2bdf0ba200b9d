#!/usr/bin/env python3
"""Makes the README's screenshots of the live page's 3D view
(docs/img/view-plant.png, view-mesh.png, view-building.png): `subgram
serve` on a model, the page in headless Chromium (WebGL through
SwiftShader), the picture pane captured.

    python3 docs/img/view_shots.py [SUBGRAM_BINARY]
"""

import base64
import json
import os
import shutil
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "tests", "browser"))
from serve import Browser, Page  # noqa: E402


def shot(browser, binary, path, out, turn=None, wire=None):
    server = subprocess.Popen([binary, "serve", path, "--port", "0", "--timeout", "120"],
                              stdout=subprocess.PIPE, text=True)
    line = server.stdout.readline()
    url = line[line.index("http://"):].split()[0]
    try:
        page = Page(browser, url)
        page.wait("window.subgram && window.subgram.version >= 1 && window.subgram.mode === '3d'",
                  "the view", timeout=300)
        if wire is not None:
            page.js(f"(() => {{ const w = document.getElementById('wire'); if (w.checked !== {json.dumps(wire)}) w.click(); return true; }})()")
        if turn:
            page.js(f"window.subgram.view3d.orbit({turn[0]}, {turn[1]}) || true")
        page.js("window.subgram.view3d.draw() || true")
        r = page.js("(() => { const r = document.getElementById('picture-pane').getBoundingClientRect();"
                    " return [r.left, r.top, r.width, r.height]; })()")
        data = page.call("Page.captureScreenshot", {"format": "png", "clip": {
            "x": r[0], "y": r[1], "width": r[2], "height": r[3], "scale": 1}})["data"]
        with open(out, "wb") as f:
            f.write(base64.b64decode(data))
    finally:
        server.kill()
        server.wait()


def main():
    binary = os.path.abspath(sys.argv[1] if len(sys.argv) > 1
                             else os.path.join(ROOT, "target", "debug", "subgram"))
    work = tempfile.mkdtemp(prefix="subgram-shots-")
    browser = Browser(shutil.which("chromium"), os.path.join(work, "profile"), open(os.devnull, "w"),
                      ["--enable-unsafe-swiftshader", "--use-angle=swiftshader", "--ignore-gpu-blocklist"])
    try:
        img = os.path.join(ROOT, "docs", "img")
        shot(browser, binary, os.path.join(ROOT, "lsystems", "open", "shade-tree"),
             os.path.join(img, "view-plant.png"), turn=(60, -20))
        bunny = os.path.join(ROOT, "lsystems", "meshes", "bunny.obj")
        loop = open(os.path.join(ROOT, "lsystems", "surfaces", "loop.lsys")).read()
        loop = loop.replace('mesh: "../meshes/octahedron.obj";', f"mesh: {json.dumps(bunny)};")
        loop = loop.replace("derivation length: 3;", "derivation length: 1;")
        grammar = os.path.join(work, "bunny-loop.lsys")
        with open(grammar, "w") as f:
            f.write(loop)
        shot(browser, binary, grammar, os.path.join(img, "view-mesh.png"))
        shot(browser, binary, os.path.join(ROOT, "lsystems", "shapes", "building.lsys"),
             os.path.join(img, "view-building.png"), turn=(-80, 10), wire=False)
    finally:
        browser.close()
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
