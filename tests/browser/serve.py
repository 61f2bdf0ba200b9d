#!/usr/bin/env python3
"""The page of `subgram serve` in a real browser (issue 18).

Starts `subgram serve` on a copy of an L-system with --save, opens its page
in headless Chromium (Debian's `chromium`), driven over the DevTools
protocol on a pipe (--remote-debugging-pipe: no websocket, no package
beyond Python's own library), and checks, as a person would:

1. the picture appears;
2. typing a change (real key events) redraws it;
3. typing an error shows the message at its line (gutter, list) and keeps
   the last picture;
4. deleting the error brings the picture back;
5. the step slider redraws with fewer steps;
6. Save writes the edited text to the file;
7. a page of another origin (a second server on another port) can
   neither write the file (a no-cors text/plain POST, a JSON POST with the
   token, which needs a preflight) nor read the page and its token;
8. DNS rebinding, played with Chromium's --host-resolver-rules (a name of
   the attacker's, evil.test, resolving to 127.0.0.1): the page, read
   under that name, is refused, and so is a save with the right token.

Screenshots of each stage go to OUTDIR (default target/browser). Run by
.ci/run after `cargo build`:

    python3 tests/browser/serve.py [SUBGRAM_BINARY] [OUTDIR]

Exit status 0 when every check passes.
"""

import base64
import http.server
import json
import os
import select
import shutil
import subprocess
import sys
import tempfile
import threading
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

PROGRAM = """// The Koch snowflake (ABOP, Fig. 1.7 family).
#define STEPS 3
angle: 60;
derivation length: STEPS;
Axiom: F--F--F;
F -> F+F--F+F
"""


class Browser:
    """Headless Chromium with its DevTools protocol on fds 3 and 4."""

    def __init__(self, chromium, profile, log, extra=()):
        self.cmd_r, self.cmd_w = os.pipe()
        self.res_r, self.res_w = os.pipe()

        def child():
            # Chromium reads commands from fd 3 and writes replies to fd 4.
            os.dup2(self.cmd_r, 100)
            os.dup2(self.res_w, 101)
            os.dup2(100, 3)
            os.dup2(101, 4)

        self.proc = subprocess.Popen(
            [chromium, "--headless=new", "--remote-debugging-pipe", "--no-sandbox",
             "--disable-gpu", "--no-first-run", "--no-default-browser-check",
             "--disable-extensions", "--hide-scrollbars", f"--user-data-dir={profile}",
             "--window-size=1400,860", *extra, "about:blank"],
            preexec_fn=child, close_fds=False, stdin=subprocess.DEVNULL,
            stdout=log, stderr=log)
        os.close(self.cmd_r)
        os.close(self.res_w)
        self.buf = b""
        self.next_id = 0

    def _message(self, deadline):
        while b"\0" not in self.buf:
            left = deadline - time.time()
            if left <= 0:
                raise TimeoutError("the browser did not answer")
            ready, _, _ = select.select([self.res_r], [], [], left)
            if ready:
                chunk = os.read(self.res_r, 1 << 20)
                if not chunk:
                    raise RuntimeError("the browser closed its pipe")
                self.buf += chunk
        raw, self.buf = self.buf.split(b"\0", 1)
        return json.loads(raw)

    def send(self, method, params=None, session=None, timeout=30):
        self.next_id += 1
        msg = {"id": self.next_id, "method": method, "params": params or {}}
        if session:
            msg["sessionId"] = session
        os.write(self.cmd_w, json.dumps(msg).encode() + b"\0")
        deadline = time.time() + timeout
        while True:
            m = self._message(deadline)
            if m.get("id") == self.next_id:
                if "error" in m:
                    raise RuntimeError(f"{method}: {m['error']}")
                return m.get("result", {})

    def close(self):
        try:
            self.send("Browser.close", timeout=5)
        except Exception:  # noqa: BLE001 (closing anyway)
            pass
        try:
            self.proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.proc.kill()


class Page:
    def __init__(self, browser, url):
        self.b = browser
        target = browser.send("Target.createTarget", {"url": "about:blank"})["targetId"]
        self.s = browser.send("Target.attachToTarget",
                              {"targetId": target, "flatten": True})["sessionId"]
        self.call("Emulation.setDeviceMetricsOverride",
                  {"width": 1400, "height": 860, "deviceScaleFactor": 1, "mobile": False})
        self.call("Page.navigate", {"url": url})

    def call(self, method, params=None):
        return self.b.send(method, params, self.s)

    def js(self, expression):
        r = self.call("Runtime.evaluate", {"expression": expression, "returnByValue": True,
                                           "awaitPromise": True})
        if "exceptionDetails" in r:
            raise RuntimeError(f"{expression}: {r['exceptionDetails']}")
        return r["result"].get("value")

    def wait(self, expression, what, timeout=20):
        deadline = time.time() + timeout
        while time.time() < deadline:
            try:
                if self.js(expression):
                    return
            except RuntimeError:
                pass
            time.sleep(0.05)
        raise AssertionError(f"timed out waiting for {what} ({expression})")

    def caret(self, line, col):
        """Puts the caret before column `col` of line `line` (1-based)."""
        self.js(f"""(() => {{ const t = document.getElementById('text');
            const lines = t.value.split('\\n'); let o = 0;
            for (let i = 0; i < {line} - 1; i++) o += lines[i].length + 1;
            t.focus(); t.setSelectionRange(o + {col} - 1, o + {col} - 1); return true; }})()""")

    def type(self, text):
        for ch in text:
            self.call("Input.dispatchKeyEvent", {"type": "keyDown", "text": ch, "key": ch,
                                                 "unmodifiedText": ch})
            self.call("Input.dispatchKeyEvent", {"type": "keyUp", "key": ch})

    def backspace(self):
        for kind in ("rawKeyDown", "keyUp"):
            self.call("Input.dispatchKeyEvent", {"type": kind, "key": "Backspace",
                                                 "code": "Backspace",
                                                 "windowsVirtualKeyCode": 8})

    def screenshot(self, path):
        data = self.call("Page.captureScreenshot", {"format": "png"})["data"]
        with open(path, "wb") as f:
            f.write(base64.b64decode(data))


class Attacker(http.server.BaseHTTPRequestHandler):
    """Another origin on this host: a page that does nothing by itself."""

    def do_GET(self):  # noqa: N802 (the name http.server calls)
        body = b"<!doctype html><title>another origin</title><p>another origin</p>"
        self.send_response(200)
        self.send_header("Content-Type", "text/html")
        self.send_header("Content-Length", str(len(body)))
        self.end_headers()
        self.wfile.write(body)

    def log_message(self, *args):
        pass


def picture(page):
    return page.js("(document.querySelector('#picture img') || {}).src || ''")


def version(page):
    return page.js("window.subgram ? window.subgram.version : 0") or 0


def main():
    binary = os.path.abspath(sys.argv[1] if len(sys.argv) > 1
                             else os.path.join(ROOT, "target", "debug", "subgram"))
    outdir = os.path.abspath(sys.argv[2] if len(sys.argv) > 2
                             else os.path.join(ROOT, "target", "browser"))
    os.makedirs(outdir, exist_ok=True)
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    if not chromium:
        sys.exit("tests/browser/serve.py: no chromium on PATH (Debian: apt-get install chromium)")
    work = tempfile.mkdtemp(prefix="subgram-browser-")
    program = os.path.join(work, "snowflake.lsys")
    with open(program, "w") as f:
        f.write(PROGRAM)
    log = open(os.path.join(outdir, "chromium.log"), "w")
    server = subprocess.Popen([binary, "serve", program, "--port", "0", "--save"],
                              stdout=subprocess.PIPE, stderr=log, text=True)
    browser = None
    checks = 0
    try:
        line = server.stdout.readline()
        url = next((w for w in line.split() if w.startswith("http://127.0.0.1:")), None)
        assert url, f"the server printed no address: {line!r}"
        browser = Browser(chromium, os.path.join(work, "profile"), log,
                          ["--host-resolver-rules=MAP evil.test 127.0.0.1"])
        page = Page(browser, url)

        # 1. The picture appears.
        page.wait("window.subgram && window.subgram.version >= 1", "the first picture")
        first = picture(page)
        assert first.startswith("data:image/svg+xml"), first[:80]
        assert page.js("document.getElementById('file').textContent") == "snowflake.lsys"
        assert page.js("document.querySelectorAll('#gutter span').length") == PROGRAM.count("\n") + 1
        assert page.js("document.querySelectorAll('#highlight .k').length") > 0, "no colouring"
        page.screenshot(os.path.join(outdir, "1-first.png"))
        checks += 1

        # 2. Typing a change redraws: the rule gains a segment.
        page.caret(6, len("F -> F+F--F+F") + 1)
        n = version(page)
        page.type("+F")
        page.wait(f"window.subgram.version > {n} && !window.subgram.inFlight", "the redraw")
        changed = picture(page)
        assert changed != first, "the picture did not change"
        assert page.js("document.getElementById('messages').children.length") == 0
        page.screenshot(os.path.join(outdir, "2-changed.png"))
        checks += 1

        # 3. An error: its message at its line, the last picture kept.
        page.caret(6, 1)
        page.type("@")
        page.wait("document.querySelector('#gutter [data-line=\"6\"]').className === 'bad'",
                  "the error's line marked in the gutter")
        listed = page.js("[...document.querySelectorAll('#messages li')].map(l => l.textContent)")
        assert any(":6:1: error:" in m and "`@`" in m for m in listed), listed
        assert page.js("document.querySelector('#marks .err') !== null"), "no underline"
        assert picture(page) == changed, "the last good picture was not kept"
        assert page.js("document.getElementById('picture').classList.contains('stale')")
        page.screenshot(os.path.join(outdir, "3-error.png"))
        checks += 1

        # 4. Deleting it brings the picture back.
        n = version(page)
        page.backspace()
        page.wait(f"window.subgram.version > {n}", "the picture back")
        assert picture(page) == changed, "the mended text should draw the same picture"
        assert page.js("document.getElementById('messages').children.length") == 0
        assert page.js("document.querySelectorAll('#gutter .bad').length") == 0
        checks += 1

        # 5. The slider: STEPS is 3; one step fewer is another picture.
        assert page.js("document.getElementById('steps').max") == "3"
        n = version(page)
        page.js("""(() => { const s = document.getElementById('steps'); s.value = 2;
                   s.dispatchEvent(new Event('input')); return true; })()""")
        page.wait(f"window.subgram.version > {n}", "the redraw at 2 steps")
        assert picture(page) not in (changed, first)
        page.screenshot(os.path.join(outdir, "serve.png"))
        checks += 1

        # 6. Save writes the edited text.
        page.js("document.getElementById('save').click() || true")
        page.wait("document.getElementById('status').textContent === 'saved'", "saved")
        with open(program) as f:
            saved = f.read()
        assert saved == PROGRAM.replace("F -> F+F--F+F", "F -> F+F--F+F+F"), saved
        checks += 1

        # 7. Another origin: a page on another port of 127.0.0.1.
        token = page.js("document.querySelector('meta[name=\"subgram-token\"]').content")
        assert len(token) == 64, token
        attacker = http.server.HTTPServer(("127.0.0.1", 0), Attacker)
        threading.Thread(target=attacker.serve_forever, daemon=True).start()
        other = Page(browser, f"http://127.0.0.1:{attacker.server_address[1]}/")
        other.wait("document.title === 'another origin'", "the other origin's page")
        pwned = json.dumps({"text": "pwned"})
        tried = other.js(f"""(async () => {{
            const out = [];
            const save = {json.dumps(url + "api/save")};
            // Sent without a preflight; the reply (403) has
            // Cross-Origin-Resource-Policy: same-origin, so the browser
            // does not even hand over an opaque response.
            try {{
                const r = await fetch(save, {{ method: "POST", mode: "no-cors",
                    headers: {{ "content-type": "text/plain" }}, body: {json.dumps(pwned)} }});
                out.push("no-cors: " + r.type);
            }} catch (e) {{ out.push("no-cors: " + e.name); }}
            try {{
                await fetch(save, {{ method: "POST", body: {json.dumps(pwned)},
                    headers: {{ "content-type": "application/json",
                               "x-subgram-token": {json.dumps(token)} }} }});
                out.push("json: answered");
            }} catch (e) {{ out.push("json: " + e.name); }}
            try {{
                const t = await (await fetch({json.dumps(url)})).text();
                out.push(t.includes({json.dumps(token)}) ? "page: token read" : "page: read");
            }} catch (e) {{ out.push("page: " + e.name); }}
            return out; }})()""")
        assert tried[0] in ("no-cors: opaque", "no-cors: TypeError"), tried
        assert tried[1:] == ["json: TypeError", "page: TypeError"], tried
        with open(program) as f:
            assert f.read() == saved, "another origin wrote the program"
        attacker.shutdown()
        checks += 1

        # 8. DNS rebinding: evil.test resolves to 127.0.0.1; its page, same
        # origin with itself, reads and posts to the server under that name.
        port = url.rstrip("/").rsplit(":", 1)[1]
        rebound = Page(browser, f"http://evil.test:{port}/")
        rebound.wait("document.readyState === 'complete' && !!document.body", "the rebound page")
        html = rebound.js("document.documentElement.outerHTML")
        assert token not in html and "<textarea" not in html, html[:300]
        assert "refused" in html and "Host" in html, html[:300]
        tried = rebound.js(f"""(async () => {{
            const page = await fetch("/");
            const save = await fetch("/api/save", {{ method: "POST", body: {json.dumps(pwned)},
                headers: {{ "content-type": "application/json",
                           "x-subgram-token": {json.dumps(token)} }} }});
            return [page.status, save.status]; }})()""")
        assert tried == [403, 403], tried
        with open(program) as f:
            assert f.read() == saved, "a rebound page wrote the program"
        checks += 1

        # 9. A page opened on a broken program: the error under the editor,
        # and in the picture's place an empty state that says why.
        broken = os.path.join(work, "broken.lsys")
        with open(broken, "w") as f:
            f.write("angle: 60;\nAxiom: F;\nF -> F+F--F+F(\n")
        second = subprocess.Popen([binary, "serve", broken, "--port", "0"],
                                  stdout=subprocess.PIPE, stderr=log, text=True)
        try:
            line = second.stdout.readline()
            url2 = next((w for w in line.split() if w.startswith("http://127.0.0.1:")), None)
            assert url2, f"the second server printed no address: {line!r}"
            page2 = Page(browser, url2)
            page2.wait("document.getElementById('messages').children.length > 0",
                       "the broken program's error")
            status = page2.js("document.getElementById('status').textContent")
            assert status == "the program has errors: nothing drawn yet", status
            empty = page2.js("(document.querySelector('#picture .empty') || {}).textContent || ''")
            assert empty.startswith("No picture yet: the program has errors"), empty
            assert page2.js("document.querySelector('#picture img') === null")
            page2.screenshot(os.path.join(outdir, "9-broken.png"))
        finally:
            second.terminate()
            second.wait(timeout=10)
        checks += 1
        print(f"browser test: {checks} checks passed; screenshots in {outdir}")
    finally:
        if browser:
            browser.close()
        server.terminate()
        server.wait(timeout=10)
        log.close()
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
