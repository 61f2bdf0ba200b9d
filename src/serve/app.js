// The page of `subgram serve`: an editor for the program, the picture
// re-derived a moment after each edit, the diagnostics at their places, a
// step slider and the #define values. Everything is computed by the
// server (POST /api/render); nothing is fetched from anywhere else.
"use strict";

// The run's token, written into the page by the server. The API refuses a
// call without it; a page of another origin cannot read this one, so it
// cannot get the token.
const API_TOKEN = document.querySelector('meta[name="subgram-token"]').content;

// A call to the API, with the token; a body goes as JSON (POST). Answers
// the status and the reply's JSON, or, when the reply is not JSON, an
// error of the same shape ({ok: false, message}).
async function api(path, body, signal) {
  const headers = { "x-subgram-token": API_TOKEN };
  const init = { headers, signal, cache: "no-store", credentials: "omit" };
  if (body !== undefined) {
    init.method = "POST";
    init.body = JSON.stringify(body);
    headers["content-type"] = "application/json";
  }
  const r = await fetch(path, init);
  let reply;
  try {
    reply = await r.json();
  } catch (e) {
    if (e.name === "AbortError") throw e;
    reply = { ok: false, message: `the server answered ${r.status} ${r.statusText}` };
  }
  if (!r.ok && reply.ok === undefined) reply.ok = false;
  return { status: r.status, reply };
}

const $ = (id) => document.getElementById(id);
const text = $("text"), highlight = $("highlight"), gutter = $("gutter");
const picture = $("picture"), messages = $("messages"), status = $("status");
const steps = $("steps"), stepsOut = $("steps-out"), definesBox = $("defines");
const wire = $("wire"), flat = $("flat"), viewHint = $("view-hint");

const state = {
  overrides: new Map(), // define name -> value typed in its field
  stepsTouched: false,  // the slider was moved away from the last step
  inFlight: null,       // the AbortController of the running request
  timer: null,
  version: 0,           // renders shown so far (the browser test reads it)
  marks: [],            // [{line, col, endLine, endCol, severity}] in the program
  mode: null,           // "2d" (an SVG), "3d" (WebGL), "png" (the server's picture)
  view3d: null,         // the View3D, made on the first 3D render
  flat2d: { zoom: 1, x: 0, y: 0 }, // the 2D picture's zoom and pan
  scene: null,          // the last 3D render's scene reply
  play: null,           // the growth being played (see `startPlay`)
  frameShown: null,     // the step of the frame on show while playing
};
window.subgram = state;

const KEYWORDS = new Set(("Axiom axiom module produce nproduce derivation length ring L-system " +
  "interpretation decomposition homomorphism maximum depth ignore consider group endgroup " +
  "vgroup Start StartEach EndEach End if else for while do return switch case default break " +
  "continue struct typedef const static mesh init adaptive define attr").split(" "));
const TYPES = new Set("int float double bool void char V2f V3f V2d V3d vertex edge face".split(" "));

const esc = (s) => s.replace(/&/g, "&amp;").replace(/</g, "&lt;").replace(/>/g, "&gt;");

// One pass of a sticky regex over the text: comments, strings, the
// preprocessor, numbers, words, arrows; everything else is plain.
const TOKEN = /(\/\/[^\n]*|\/\*[\s\S]*?(?:\*\/|$))|("(?:\\.|[^"\\\n])*"?)|(^[ \t]*#[ \t]*\w+)|(\b\d+(?:\.\d*)?(?:[eE][+-]?\d+)?[fFuUlL]?\b|\.\d+(?:[eE][+-]?\d+)?[fF]?)|([A-Za-z_][\w]*)|(-->|->|~>|<<|>>|<|>|:)/gmy;

function colour(src) {
  let out = "", at = 0;
  TOKEN.lastIndex = 0;
  while (at < src.length) {
    TOKEN.lastIndex = at;
    const m = TOKEN.exec(src);
    if (!m) { out += esc(src[at]); at += 1; continue; }
    const [all, comment, string, pre, number, word, punct] = m;
    let cls = "";
    if (comment) cls = "c";
    else if (string) cls = "s";
    else if (pre) cls = "k";
    else if (number) cls = "n";
    else if (word) cls = KEYWORDS.has(word) ? "k" : TYPES.has(word) ? "t" : /^[A-Z]/.test(word) ? "m" : "";
    else if (punct) cls = "p";
    out += cls ? `<span class="${cls}">${esc(all)}</span>` : esc(all);
    at += all.length;
  }
  return out;
}

// The text with the marked ranges underlined, the rest invisible: a layer
// over the coloured one.
function marked(src) {
  const lines = src.split("\n");
  const offset = (line, col) => {
    let o = 0;
    for (let i = 0; i < line - 1 && i < lines.length; i++) o += lines[i].length + 1;
    return Math.min(src.length, o + Math.max(0, col - 1));
  };
  const ranges = state.marks
    .map((m) => {
      const a = offset(m.line, m.col);
      const b = Math.max(a + 1, offset(m.endLine, m.endCol));
      return [a, Math.min(b, Math.max(a + 1, src.length))];
    })
    .sort((x, y) => x[0] - y[0]);
  let out = "", at = 0;
  for (const [a, b] of ranges) {
    if (a < at) continue;
    out += esc(src.slice(at, a)) + `<span class="err">${esc(src.slice(a, b) || " ")}</span>`;
    at = b;
  }
  return out + esc(src.slice(at));
}

function paint() {
  const src = text.value;
  highlight.innerHTML = colour(src) + "\n";
  let errs = $("marks");
  if (!errs) {
    errs = document.createElement("pre");
    errs.id = "marks";
    errs.setAttribute("aria-hidden", "true");
    errs.className = "overlay";
    // Under the coloured text: the underline shows, the glyphs stay on top.
    highlight.before(errs);
  }
  errs.innerHTML = marked(src) + "\n";
  const n = src.split("\n").length;
  const bad = new Map(state.marks.map((m) => [m.line, m.severity]));
  let g = "";
  for (let i = 1; i <= n; i++) {
    const sev = bad.get(i);
    g += sev ? `<span class="${sev === "error" ? "bad" : "warn"}" data-line="${i}">${i}</span>\n`
             : `<span data-line="${i}">${i}</span>\n`;
  }
  gutter.innerHTML = g;
  text.style.height = (n + 1) * 18 + 12 + "px";
  const longest = Math.max(...src.split("\n").map((l) => l.length));
  text.style.width = `max(100%, ${longest + 4}ch)`;
}

// `#define NAME VALUE` lines with a number: fields for `-D NAME=VALUE`.
function defines(src) {
  const found = [];
  for (const m of src.matchAll(/^[ \t]*#[ \t]*define[ \t]+([A-Za-z_]\w*)[ \t]+(-?[\d.]+(?:[eE][+-]?\d+)?)[ \t]*(?:\/\/.*)?$/gm)) {
    found.push([m[1], m[2]]);
  }
  const key = found.map((d) => d[0]).join(" ");
  if (definesBox.dataset.key !== key) {
    definesBox.dataset.key = key;
    definesBox.innerHTML = "";
    for (const [name, value] of found) {
      const label = document.createElement("label");
      label.textContent = name + " ";
      const input = document.createElement("input");
      input.name = name;
      input.value = state.overrides.get(name) ?? value;
      input.placeholder = value;
      input.addEventListener("input", () => {
        if (input.value === "" || input.value === input.placeholder) state.overrides.delete(name);
        else state.overrides.set(name, input.value);
        schedule(0);
      });
      label.append(input);
      definesBox.append(label);
    }
  }
  for (const input of definesBox.querySelectorAll("input")) {
    const d = found.find((f) => f[0] === input.name);
    if (d) input.placeholder = d[1];
  }
  return new Map(found);
}

// The slider goes from 0 to the derivation length (a number, or a define).
function lengthOf(src, defs) {
  const m = src.match(/derivation\s+length\s*:\s*([A-Za-z_]\w*|\d+)/);
  if (!m) return null;
  const v = /^\d+$/.test(m[1]) ? m[1] : state.overrides.get(m[1]) ?? defs.get(m[1]);
  const n = Number.parseInt(v, 10);
  return Number.isFinite(n) && n >= 0 ? n : null;
}

// What a render or a playback of the text as it stands asks for.
function requestBody() {
  const src = text.value;
  const n = lengthOf(src, defines(src));
  return {
    text: src,
    steps: n === null ? null : Number(steps.value),
    defines: [...state.overrides].map(([k, v]) => `${k}=${v}`),
  };
}

function schedule(ms) {
  clearTimeout(state.timer);
  state.timer = setTimeout(render, ms);
}

async function render() {
  // A playback of this very text goes on; any change ends it.
  if (state.play && state.play.key === JSON.stringify(requestBody())) return;
  stopPlay();
  const src = text.value;
  const defs = defines(src);
  const n = lengthOf(src, defs);
  if (n !== null) {
    const atEnd = !state.stepsTouched;
    steps.max = Math.max(n, 0);
    if (atEnd) steps.value = steps.max;
  }
  stepsOut.textContent = steps.value;
  if (state.inFlight) state.inFlight.abort();
  const ctl = new AbortController();
  state.inFlight = ctl;
  status.className = "";
  status.textContent = "deriving…";
  const body = requestBody();
  let reply, code;
  try {
    state.timing = { asked: performance.now() };
    ({ status: code, reply } = await api("/api/render", body, ctl.signal));
    state.timing.answered = performance.now();
  } catch (e) {
    if (e.name === "AbortError") return;
    reply = { ok: false, messages: [{ severity: "error", message: `the server did not answer: ${e}` }] };
  }
  if (state.inFlight !== ctl) return;
  state.inFlight = null;
  if (code === 503) {
    // Busy with earlier renders (each runs to its end): again in a moment.
    status.textContent = "the server is busy; trying again…";
    schedule(500);
    return;
  }
  // A refusal (403, 415, ...) is {ok: false, message}: shown as a message.
  if (!reply.messages && reply.message) {
    reply.messages = [{ severity: "error", file: "", message: reply.message }];
  }
  show(reply);
}

function show(reply) {
  const list = (reply.messages || []).concat(
    reply.scene?.note ? [{ severity: "warning", file: "", message: reply.scene.note }] : []);
  state.marks = list.filter((m) => m.line && m.program).map((m) => ({
    line: m.line, col: m.col, endLine: m.end_line || m.line, endCol: m.end_col || m.col + 1,
    severity: m.severity,
  }));
  messages.innerHTML = "";
  for (const m of list) {
    const li = document.createElement("li");
    li.className = m.severity;
    const where = m.line ? `${m.file}:${m.line}:${m.col}: ` : m.file ? `${m.file}: ` : "";
    li.textContent = `${where}${m.severity}: ${m.message}`;
    if (m.line) li.dataset.line = m.line;
    li.addEventListener("click", () => goTo(m.line, m.col));
    messages.append(li);
  }
  if (reply.ok) {
    if (reply.scene) {
      showScene(reply);
    } else {
      showFlat("data:image/svg+xml;charset=utf-8," + encodeURIComponent(reply.svg));
      shown(`drawn in ${reply.seconds.toFixed(2)} s`);
    }
  } else {
    status.className = "error";
    const drawn = state.mode !== null;
    if (drawn) picture.classList.add("stale");
    const why = reply.limit ? `stopped by the ${reply.limit} limit` : "the program has errors";
    status.textContent = drawn ? `${why}: the last good picture is kept` : `${why}: nothing drawn yet`;
    if (!drawn) {
      // An empty state that says why, in place of a blank pane.
      let empty = picture.querySelector(".empty");
      if (!empty) { empty = document.createElement("p"); empty.className = "empty"; picture.append(empty); }
      empty.textContent = reply.limit
        ? `No picture yet: the render was ${why}. Lower the steps, or edit the program.`
        : "No picture yet: the program has errors (listed under the editor). Fix them and the picture appears here.";
    }
  }
  paint();
}

// A picture has been put in place: the counter the browser tests read.
function shown(text) {
  picture.classList.remove("stale");
  state.version += 1;
  picture.dataset.version = state.version;
  status.className = "";
  status.textContent = text;
}

// The pane holds one kind of picture at a time.
function setMode(mode) {
  if (state.mode === mode) return;
  state.mode = mode;
  picture.querySelector(".empty")?.remove();
  for (const el of picture.querySelectorAll("img, canvas")) el.hidden = true;
  $("wire-box").hidden = mode !== "3d";
  $("flat-box").hidden = mode !== "3d";
  viewHint.textContent = mode === "3d"
    ? "drag: turn · right or shift drag: pan · wheel: zoom · double-click: reset"
    : mode === "2d" ? "drag: pan · wheel: zoom · double-click: reset" : "";
}

// A 2D picture (an SVG, or the server's PNG of a large scene), zoomed and
// panned by the page: the image is laid out at its zoomed size, so that
// an SVG stays sharp.
function showFlat(url, mode = "2d") {
  setMode(mode);
  let img = picture.querySelector("img");
  if (!img) {
    img = document.createElement("img");
    img.alt = "the picture";
    img.draggable = false;
    picture.append(img);
    bindFlat(img);
  }
  img.hidden = false;
  if (img.dataset.blob) URL.revokeObjectURL(img.dataset.blob);
  img.dataset.blob = url.startsWith("blob:") ? url : "";
  img.onload = () => placeFlat();
  img.src = url;
}

function placeFlat() {
  const img = picture.querySelector("img");
  if (!img || !img.naturalWidth) return;
  const pw = picture.clientWidth, ph = picture.clientHeight;
  const fit = Math.min(pw / img.naturalWidth, ph / img.naturalHeight);
  const v = state.flat2d;
  const w = img.naturalWidth * fit * v.zoom, h = img.naturalHeight * fit * v.zoom;
  img.style.width = `${w}px`;
  img.style.height = `${h}px`;
  img.style.left = `${(pw - w) / 2 + v.x}px`;
  img.style.top = `${(ph - h) / 2 + v.y}px`;
}

function bindFlat(img) {
  let drag = null;
  picture.addEventListener("pointerdown", (e) => {
    if (state.mode === "3d") return;
    drag = { x: e.clientX, y: e.clientY };
    picture.setPointerCapture(e.pointerId);
  });
  picture.addEventListener("pointermove", (e) => {
    if (!drag || state.mode === "3d") return;
    state.flat2d.x += e.clientX - drag.x;
    state.flat2d.y += e.clientY - drag.y;
    drag = { x: e.clientX, y: e.clientY };
    placeFlat();
  });
  picture.addEventListener("pointerup", () => { drag = null; });
  picture.addEventListener("wheel", (e) => {
    if (state.mode === "3d") return;
    e.preventDefault();
    // Zoom about the point under the cursor.
    const v = state.flat2d, r = picture.getBoundingClientRect();
    const cx = e.clientX - r.left - r.width / 2 - v.x, cy = e.clientY - r.top - r.height / 2 - v.y;
    const f = Math.exp(-Math.sign(e.deltaY) * Math.min(Math.abs(e.deltaY), 200) * 0.002);
    const zoom = Math.min(64, Math.max(0.1, v.zoom * f));
    const k = zoom / v.zoom;
    v.x -= cx * (k - 1); v.y -= cy * (k - 1); v.zoom = zoom;
    placeFlat();
  }, { passive: false });
  picture.addEventListener("dblclick", () => { if (state.mode !== "3d") resetView(); });
  new ResizeObserver(() => placeFlat()).observe(picture);
}

function resetView() {
  if (state.mode === "3d") state.view3d?.reset();
  else { state.flat2d = { zoom: 1, x: 0, y: 0 }; placeFlat(); }
}

// A file a render kept on the server (`/api/blob/ID`), with the token.
function fetchBlob(id) {
  return fetch(`/api/blob/${id}`, { headers: { "x-subgram-token": API_TOKEN }, cache: "no-store", credentials: "omit" });
}

// 3D geometry: the GLB fetched and drawn by the page's own viewer, or the
// server's PNG when the geometry is too large to send.
async function showScene(reply) {
  const info = reply.scene;
  const took = reply.seconds;
  let r;
  try {
    r = await fetchBlob(info.blob);
    if (!r.ok) throw new Error(`the server answered ${r.status}`);
  } catch (e) {
    status.className = "error";
    status.textContent = `cannot fetch the geometry: ${e.message}`;
    return;
  }
  const bytes = await r.arrayBuffer();
  if (info.kind === "png") {
    showFlat(URL.createObjectURL(new Blob([bytes], { type: "image/png" })), "png");
    state.scene = null;
    shown(`drawn in ${took.toFixed(2)} s`);
    return;
  }
  if (!ensureView3d()) return;
  const sameKind = state.scene && state.scene.turn_axis.join() === info.turn_axis.join() &&
    state.scene.projection === info.projection;
  const first = state.mode !== "3d";
  setMode("3d");
  state.view3d.canvas.hidden = false;
  if (first && !state.scene) {
    // The first 3D render: a mesh shows its edges, a plant does not.
    wire.checked = info.edges;
    flat.checked = !info.smooth;
    state.view3d.setWireframe(wire.checked);
    state.view3d.setFlat(flat.checked);
  }
  const fetched = performance.now();
  state.view3d.show(bytes, info, sameKind);
  // Drawn now, not at the next animation frame: the time an edit takes
  // to become a view (the status says it; the benchmark reads it).
  state.view3d.draw();
  state.view3d.settle();
  if (state.timing) Object.assign(state.timing, { fetched, drawn: performance.now() });
  state.scene = info;
  const mb = (info.bytes / 1e6).toFixed(info.bytes < 1e7 ? 1 : 0);
  const page = state.timing?.drawn ? ` + ${((state.timing.drawn - state.timing.answered) / 1000).toFixed(2)} s in the page` : "";
  shown(`drawn in ${took.toFixed(2)} s${page} · ${info.triangles.toLocaleString()} triangles, ${mb} MB`);
}

wire.addEventListener("change", () => state.view3d?.setWireframe(wire.checked));
flat.addEventListener("change", () => state.view3d?.setFlat(flat.checked));
$("reset").addEventListener("click", resetView);

// Growth playback: every step derived once by the server (POST
// /api/play, then its progress polled), each frame fetched once and kept
// (an SVG's URL, or a GLB on the GPU), so that scrubbing back needs no
// request; play, pause, one frame back or on, loop and speed. An edit
// ends it (the still picture of the edited text comes back).
const playButton = $("play"), frameSlider = $("frame"), frameOut = $("frame-out");
const playStatus = $("play-status");

function playMessage(text, error = false) {
  playStatus.className = error ? "error" : "";
  playStatus.textContent = text;
}

async function startPlay() {
  const body = requestBody();
  const key = JSON.stringify(body);
  const play = { key, frames: [], index: 0, playing: false, timer: null, ready: false, intervalMs: 250 };
  stopPlay();
  state.play = play;
  playButton.disabled = true;
  playMessage("deriving…");
  let reply, code;
  try {
    ({ status: code, reply } = await api("/api/play", body));
  } catch (e) {
    reply = { ok: false, message: `the server did not answer: ${e}` };
  }
  if (state.play !== play) return;
  if (!reply.ok) {
    playButton.disabled = false;
    state.play = null;
    playMessage(code === 503 ? `busy: ${reply.message}` : `cannot play: ${reply.message}`, true);
    return;
  }
  let job;
  for (;;) {
    await new Promise((r) => setTimeout(r, 200));
    if (state.play !== play) return;
    try {
      ({ reply: job } = await api(`/api/play/${reply.job}`));
    } catch (e) {
      job = { phase: "failed", messages: [{ message: `the server did not answer: ${e}` }] };
    }
    if (state.play !== play) return;
    if (job.phase === "deriving") {
      playMessage(job.steps ? `deriving step ${job.step} of ${job.steps} · ${job.modules.toLocaleString()} modules` : "deriving…");
    } else if (job.phase === "drawing") {
      playMessage("drawing the frames…");
    } else break;
  }
  if (job.phase !== "done") {
    playButton.disabled = false;
    state.play = null;
    const why = job.limit ? `stopped by the ${job.limit} limit: ` : "";
    const first = (job.messages || [])[0];
    playMessage(`cannot play: ${why}${first ? first.message : "the run failed"}`, true);
    return;
  }
  if (job.interval_ms) play.intervalMs = job.interval_ms;
  for (const [i, f] of job.frames.entries()) {
    playMessage(`loading frame ${i + 1} of ${job.frames.length}`);
    const r = await fetchBlob(f.blob);
    if (state.play !== play) return;
    if (!r.ok) { stopPlay(); playMessage(`cannot fetch frame ${i + 1}: the server answered ${r.status}`, true); return; }
    if (f.kind === "svg") {
      play.frames.push({ step: f.step, kind: "svg", url: "data:image/svg+xml;charset=utf-8," + encodeURIComponent(await r.text()) });
    } else {
      const bytes = await r.arrayBuffer();
      if (state.play !== play) return;
      if (!ensureView3d()) { stopPlay(); return; }
      const model = bytes.byteLength ? state.view3d.load(bytes) : { prims: [], hasEdges: false };
      play.frames.push({ step: f.step, kind: "glb", model, info: f.scene || job.frames.find((g) => g.scene)?.scene });
    }
  }
  play.ready = true;
  playButton.disabled = false;
  frameSlider.disabled = false;
  frameSlider.max = play.frames.length - 1;
  const warn = (job.messages || []).length ? ` · ${job.messages[0].message}` : "";
  playMessage(`${play.frames.length} frames, derived in ${job.seconds.toFixed(2)} s${warn}`);
  showFrame(0);
  setPlaying(true);
}

// The 3D view, made when first needed.
function ensureView3d() {
  if (state.view3d) return true;
  let canvas;
  try {
    canvas = document.createElement("canvas");
    canvas.className = "view3d";
    picture.append(canvas);
    state.view3d = new View3D(canvas);
    state.view3d.setWireframe(wire.checked);
    return true;
  } catch (e) {
    canvas?.remove();
    state.view3d = null;
    status.className = "error";
    status.textContent = `cannot draw in 3D here: ${e.message}`;
    return false;
  }
}

function showFrame(i) {
  const play = state.play;
  if (!play || !play.ready) return;
  play.index = Math.max(0, Math.min(play.frames.length - 1, i));
  const f = play.frames[play.index];
  if (f.kind === "svg") {
    showFlat(f.url);
  } else {
    const first = state.mode !== "3d";
    setMode("3d");
    state.view3d.canvas.hidden = false;
    // One camera for every frame: the frames' own (fitted to them all),
    // set by the first frame shown and kept after.
    state.view3d.use(f.model, f.info, !first && play.cameraSet);
    play.cameraSet = true;
  }
  frameSlider.value = play.index;
  frameOut.textContent = `step ${f.step} (${play.index + 1}/${play.frames.length})`;
  state.frameShown = f.step;
  picture.classList.remove("stale");
}

function setPlaying(on) {
  const play = state.play;
  if (!play) return;
  play.playing = on;
  clearTimeout(play.timer);
  playButton.innerHTML = on ? "&#10074;&#10074; Pause" : "&#9654; Play";
  if (on) tick();
}

function tick() {
  const play = state.play;
  if (!play || !play.playing) return;
  play.timer = setTimeout(() => {
    if (state.play !== play || !play.playing) return;
    if (play.index + 1 < play.frames.length) showFrame(play.index + 1);
    else if ($("loop").checked) showFrame(0);
    else { setPlaying(false); return; }
    tick();
  }, play.intervalMs / Number($("speed").value));
}

// Ends the playback: its frames freed, the controls back to their rest.
function stopPlay() {
  const play = state.play;
  if (!play) return;
  state.play = null;
  clearTimeout(play.timer);
  for (const f of play.frames) if (f.model && state.view3d) state.view3d.free(f.model);
  // The view drew a frame: nothing until the still picture comes back.
  if (state.view3d && !state.view3d.owned) { state.view3d.prims = []; state.view3d.redraw(); }
  playButton.innerHTML = "&#9654; Play";
  playButton.disabled = false;
  frameSlider.disabled = true;
  frameSlider.max = 0;
  frameOut.textContent = "";
  state.frameShown = null;
  playMessage("");
}

playButton.addEventListener("click", () => {
  const play = state.play;
  if (play && play.ready && play.key === JSON.stringify(requestBody())) setPlaying(!play.playing);
  else if (!play || play.ready) startPlay();
});
frameSlider.addEventListener("input", () => { setPlaying(false); showFrame(Number(frameSlider.value)); });
$("back").addEventListener("click", () => { setPlaying(false); showFrame((state.play?.index ?? 0) - 1); });
$("fwd").addEventListener("click", () => { setPlaying(false); showFrame((state.play?.index ?? 0) + 1); });

function goTo(line, col) {
  if (!line) return;
  const lines = text.value.split("\n");
  let o = 0;
  for (let i = 0; i < line - 1 && i < lines.length; i++) o += lines[i].length + 1;
  o += Math.max(0, (col || 1) - 1);
  text.focus();
  text.setSelectionRange(o, o);
}

text.addEventListener("input", () => { paint(); schedule(150); });
text.addEventListener("keydown", (e) => {
  if (e.key === "Tab" && !e.ctrlKey && !e.metaKey) {
    e.preventDefault();
    const a = text.selectionStart;
    text.setRangeText("    ", a, text.selectionEnd, "end");
    paint(); schedule(150);
  }
});
steps.addEventListener("input", () => {
  state.stepsTouched = Number(steps.value) !== Number(steps.max);
  stepsOut.textContent = steps.value;
  schedule(0);
});
$("save").addEventListener("click", async () => {
  let reply;
  try {
    ({ reply } = await api("/api/save", { text: text.value }));
  } catch (e) {
    reply = { ok: false, message: `the server did not answer: ${e}` };
  }
  status.className = reply.ok ? "" : "error";
  status.textContent = reply.ok ? "saved" : `not saved: ${reply.message}`;
});

(async () => {
  const { status: code, reply: src } = await api("/api/source");
  if (code !== 200) {
    status.className = "error";
    status.textContent = `cannot read the program: ${src.message}`;
    return;
  }
  $("file").textContent = src.name;
  document.title = `${src.name} — subgram`;
  $("save").hidden = !src.save;
  text.value = src.text;
  paint();
  render();
})();
