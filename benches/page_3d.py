#!/usr/bin/env python3
"""The live page's 3D view, timed (issue 38): from an edit to the new view.

For a plant of 131,071 cylinders (a binary tree 17 steps deep, `line
style: cylinder`) and a mesh of about a million triangles (Loop on the
Stanford bunny, 4 steps: 3,674 · 4^4 = 940,544), with a release binary:

* the server: POST /api/render (derive, build the geometry, write the GLB)
  and GET /api/blob/ID (the bytes sent), over HTTP from Python, median of
  REPEAT runs;
* the page, in headless Chromium: an edit typed, to the view drawn (the
  page's own `state.timing`: the request, the answer, the fetch, the GLB
  parsed and uploaded, one frame drawn and read back), median of
  REPEAT / 2 edits;
* the frame time while turning the view (10 drags, each frame drawn and
  read back; the median).

Chromium here draws WebGL with SwiftShader, a CPU renderer: the page's
figures are an upper bound of what a machine with a GPU takes.

    python3 benches/page_3d.py [SUBGRAM_RELEASE_BINARY] [REPEAT] [plant|bunny|both]
"""

import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
import urllib.request

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tests", "browser"))
from serve import Browser, Page  # noqa: E402

# SwiftShader draws a million triangles on the CPU: give the browser's
# answers minutes, not the tests' 30 s.
Browser.send.__defaults__ = (None, None, 900)

PLANT = """// 2^17 - 1 = 131,071 cylinders: a binary tree 17 steps deep.
#include <lpfgall.h>
derivation length: 17;
module A();
Axiom: SetWidth(0.05) F(2) A();
A() : { produce F(1) SB() Down(28) RollR(90) A() EB() RollR(137.5) SB() Down(-28) A() EB(); }
"""

VIEW = "projection: parallel\nrender mode: shaded\nline style: cylinder\n"


def post(url, token, path, body):
    req = urllib.request.Request(url + path.lstrip("/"), data=json.dumps(body).encode(),
                                 headers={"X-Subgram-Token": token,
                                          "Content-Type": "application/json"})
    with urllib.request.urlopen(req, timeout=600) as r:
        return json.loads(r.read())


def get(url, token, path):
    req = urllib.request.Request(url + path.lstrip("/"), headers={"X-Subgram-Token": token})
    with urllib.request.urlopen(req, timeout=600) as r:
        return r.read()


def bench(binary, path, text, repeat, browser, extra_args=(), frames_n=10):
    server = subprocess.Popen([binary, "serve", path, "--port", "0", "--timeout", "600",
                               *extra_args], stdout=subprocess.PIPE, text=True)
    line = server.stdout.readline()
    url = line[line.index("http://"):].split()[0]
    try:
        page_html = urllib.request.urlopen(url, timeout=60).read().decode()
        at = page_html.index('name="subgram-token" content="') + len('name="subgram-token" content="')
        token = page_html[at:at + 64]
        server_s, fetch_s, size = [], [], 0
        for _ in range(repeat):
            t = time.perf_counter()
            r = post(url, token, "/api/render", {"text": text})
            server_s.append(time.perf_counter() - t)
            assert r["ok"], r
            t = time.perf_counter()
            size = len(get(url, token, f"/api/blob/{r['scene']['blob']}"))
            fetch_s.append(time.perf_counter() - t)
        triangles = r["scene"]["triangles"]
        page = Page(browser, url)
        page.wait("window.subgram && window.subgram.version >= 1 && window.subgram.mode === '3d'",
                  "the first view", timeout=600)
        edits = []
        for k in range(max(1, repeat // 2)):
            n = page.js("window.subgram.version")
            page.caret(1, 3)
            page.type("x")
            page.wait(f"window.subgram.version > {n}", "the edit's view", timeout=600)
            t = page.js("window.subgram.timing")
            edits.append({key: (t[key] - t["asked"]) / 1000 for key in ("answered", "fetched", "drawn")})
        frames = page.js("""(() => { const v = window.subgram.view3d; const out = [];
            for (let i = 0; i < FRAMES; i++) { const t = performance.now(); v.orbit(6, 1); v.draw();
              v.settle(); out.push(performance.now() - t); }
            out.sort((a, b) => a - b); return out[out.length >> 1]; })()""".replace("FRAMES", str(frames_n)))
        med = lambda xs: statistics.median(xs)  # noqa: E731
        return {
            "triangles": triangles, "glb_mb": size / 1e6,
            "server_s": med(server_s), "fetch_s": med(fetch_s),
            "edit_answered_s": med([e["answered"] for e in edits]),
            "edit_fetched_s": med([e["fetched"] for e in edits]),
            "edit_drawn_s": med([e["drawn"] for e in edits]),
            "frame_ms": frames,
        }
    finally:
        server.kill()
        server.wait()


def main():
    binary = os.path.abspath(sys.argv[1] if len(sys.argv) > 1
                             else os.path.join(ROOT, "target", "release", "subgram"))
    repeat = int(sys.argv[2]) if len(sys.argv) > 2 else 3
    work = tempfile.mkdtemp(prefix="subgram-page3d-")
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    browser = Browser(chromium, os.path.join(work, "profile"), open(os.devnull, "w"),
                      ["--enable-unsafe-swiftshader", "--use-angle=swiftshader",
                       "--ignore-gpu-blocklist"])
    try:
        plant = os.path.join(work, "plant")
        os.mkdir(plant)
        with open(os.path.join(plant, "lsystem.l"), "w") as f:
            f.write(PLANT)
        with open(os.path.join(plant, "view.v"), "w") as f:
            f.write(VIEW)
        bunny = os.path.join(ROOT, "lsystems", "meshes", "bunny.obj")
        loop = open(os.path.join(ROOT, "lsystems", "surfaces", "loop.lsys")).read()
        loop = loop.replace('mesh: "../meshes/octahedron.obj";', f"mesh: {json.dumps(bunny)};")
        loop = loop.replace("derivation length: 3;", "derivation length: 4;")
        grammar = os.path.join(work, "bunny-loop.lsys")
        with open(grammar, "w") as f:
            f.write(loop)
        results = {}
        which = sys.argv[3] if len(sys.argv) > 3 else "both"
        for name, path, text in [("plant (131,071 cylinders)", plant, PLANT),
                                 ("bunny, Loop 4 steps", grammar, loop)]:
            if which != "both" and not name.startswith(which):
                continue
            results[name] = bench(binary, path, text, repeat, browser)
            print(name, json.dumps(results[name]), flush=True)
        print(json.dumps(results, indent=2))
        print("\n| model | triangles | GLB sent | server: derive + GLB | fetch | edit → view drawn "
              "(SwiftShader) | frame while turning (SwiftShader) |")
        print("|---|---|---|---|---|---|---|")
        for name, r in results.items():
            print(f"| {name} | {r['triangles']:,} | {r['glb_mb']:.0f} MB | {r['server_s']:.2f} s | "
                  f"{r['fetch_s']:.2f} s | {r['edit_drawn_s']:.2f} s | {r['frame_ms']:.0f} ms |")
    finally:
        browser.close()
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
