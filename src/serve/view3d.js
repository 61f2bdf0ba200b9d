// The 3D view of `subgram serve`'s page: a small WebGL viewer of the
// binary glTF that `subgram render -o model.glb` writes (one primitive per
// look, and for meshes the polygons' edges as a LINES primitive), with the
// command line's camera as its first view. Orbit (drag), pan (right or
// shift drag), zoom (wheel), reset (double click), a wireframe and a flat
// toggle; the light follows the camera. Nothing here is fetched from
// anywhere: the page's own server sends the geometry.
"use strict";

// The binary glTF's primitives as typed arrays over its BIN chunk.
function parseGlb(buffer) {
  const dv = new DataView(buffer);
  if (buffer.byteLength < 20 || dv.getUint32(0, true) !== 0x46546c67) throw new Error("not a binary glTF file");
  const jsonLength = dv.getUint32(12, true);
  if (dv.getUint32(16, true) !== 0x4e4f534a) throw new Error("the glTF file has no JSON chunk first");
  const doc = JSON.parse(new TextDecoder().decode(new Uint8Array(buffer, 20, jsonLength)));
  const binAt = 20 + jsonLength;
  const binStart = binAt + 8;
  const accessor = (k) => {
    const a = doc.accessors[k];
    const v = doc.bufferViews[a.bufferView];
    const offset = binStart + (v.byteOffset || 0) + (a.byteOffset || 0);
    const width = { SCALAR: 1, VEC3: 3 }[a.type];
    if (a.componentType === 5126) return new Float32Array(buffer, offset, a.count * width);
    if (a.componentType === 5125) return new Uint32Array(buffer, offset, a.count * width);
    throw new Error(`unexpected accessor component type ${a.componentType}`);
  };
  const prims = [];
  for (const mesh of doc.meshes || []) {
    for (const p of mesh.primitives) {
      const m = doc.materials[p.material] || {};
      const pbr = m.pbrMetallicRoughness || {};
      prims.push({
        mode: p.mode === undefined ? 4 : p.mode,
        positionAccessor: p.attributes.POSITION,
        positions: accessor(p.attributes.POSITION),
        normals: p.attributes.NORMAL === undefined ? null : accessor(p.attributes.NORMAL),
        indices: accessor(p.indices),
        color: pbr.baseColorFactor || [0.8, 0.8, 0.8, 1],
        emissive: m.emissiveFactor || [0, 0, 0],
      });
    }
  }
  return prims;
}

// Area-weighted vertex normals of an indexed triangle list.
function smoothNormals(pos, idx) {
  const n = new Float32Array(pos.length);
  for (let t = 0; t < idx.length; t += 3) {
    const a = idx[t] * 3, b = idx[t + 1] * 3, c = idx[t + 2] * 3;
    const ux = pos[b] - pos[a], uy = pos[b + 1] - pos[a + 1], uz = pos[b + 2] - pos[a + 2];
    const vx = pos[c] - pos[a], vy = pos[c + 1] - pos[a + 1], vz = pos[c + 2] - pos[a + 2];
    const x = uy * vz - uz * vy, y = uz * vx - ux * vz, z = ux * vy - uy * vx;
    for (const k of [a, b, c]) { n[k] += x; n[k + 1] += y; n[k + 2] += z; }
  }
  for (let i = 0; i < n.length; i += 3) {
    const l = Math.hypot(n[i], n[i + 1], n[i + 2]) || 1;
    n[i] /= l; n[i + 1] /= l; n[i + 2] /= l;
  }
  return n;
}

// Each edge of a triangle list once (the wireframe of a plant).
function triangleEdges(idx, vertices) {
  const seen = new Set();
  const out = [];
  for (let t = 0; t < idx.length; t += 3) {
    for (let e = 0; e < 3; e++) {
      const a = idx[t + e], b = idx[t + (e + 1) % 3];
      const lo = Math.min(a, b), hi = Math.max(a, b);
      const key = lo * vertices + hi;
      if (!seen.has(key)) { seen.add(key); out.push(lo, hi); }
    }
  }
  return new Uint32Array(out);
}

const v3 = {
  sub: (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]],
  add: (a, b) => [a[0] + b[0], a[1] + b[1], a[2] + b[2]],
  scale: (a, s) => [a[0] * s, a[1] * s, a[2] * s],
  dot: (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2],
  cross: (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]],
  norm: (a) => { const l = Math.hypot(a[0], a[1], a[2]) || 1; return [a[0] / l, a[1] / l, a[2] / l]; },
  // `a` turned by `angle` about the unit axis `k` (Rodrigues).
  turn: (a, k, angle) => {
    const c = Math.cos(angle), s = Math.sin(angle);
    const kxa = v3.cross(k, a), kda = v3.dot(k, a);
    return [0, 1, 2].map((i) => a[i] * c + kxa[i] * s + k[i] * kda * (1 - c));
  },
};

const VERTEX = `#version 300 es
in vec3 aPos; in vec3 aNrm;
uniform mat4 uView; uniform mat4 uProj;
out vec3 vEye; out vec3 vNrm;
void main() {
  vec4 e = uView * vec4(aPos, 1.0);
  vEye = e.xyz;
  vNrm = mat3(uView) * aNrm;
  gl_Position = uProj * e;
}`;

// Two lights fixed to the camera (a key from the upper left and a fill
// from the lower right) and an ambient term; both sides lit, as lpfg
// lights them.
const FRAGMENT = `#version 300 es
precision highp float;
in vec3 vEye; in vec3 vNrm;
uniform vec4 uColor; uniform vec3 uEmissive; uniform int uLit; uniform int uFlat; uniform int uOrtho;
out vec4 outColor;
void main() {
  if (uLit == 0) { outColor = uColor; return; }
  vec3 n = uFlat == 1 ? normalize(cross(dFdx(vEye), dFdy(vEye))) : normalize(vNrm);
  vec3 toEye = uOrtho == 1 ? vec3(0.0, 0.0, 1.0) : normalize(-vEye);
  if (dot(n, toEye) < 0.0) n = -n;
  vec3 key = normalize(vec3(-0.45, 0.55, 1.0));
  vec3 fill = normalize(vec3(0.5, -0.35, 0.8));
  float d = 0.32 + 0.62 * max(dot(n, key), 0.0) + 0.22 * max(dot(n, fill), 0.0);
  vec3 h = normalize(key + toEye);
  float spec = 0.08 * pow(max(dot(n, h), 0.0), 40.0);
  outColor = vec4(min(uColor.rgb * d + spec + uEmissive, vec3(1.0)), uColor.a);
}`;

class View3D {
  // `canvas`: the <canvas> to draw in; `info`: the render's scene reply.
  constructor(canvas) {
    this.canvas = canvas;
    const gl = canvas.getContext("webgl2", { antialias: true, preserveDrawingBuffer: false });
    if (!gl) throw new Error("this browser has no WebGL 2, which the 3D view needs");
    this.gl = gl;
    this.program = this.link(VERTEX, FRAGMENT);
    this.prims = [];
    this.wireframe = false;
    this.flat = false;
    this.frames = 0;
    this.dirty = false;
    this.pointer = null;
    this.bindInput();
    new ResizeObserver(() => this.redraw()).observe(canvas);
  }

  link(vs, fs) {
    const gl = this.gl;
    const shader = (type, src) => {
      const s = gl.createShader(type);
      gl.shaderSource(s, src);
      gl.compileShader(s);
      if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s));
      return s;
    };
    const p = gl.createProgram();
    gl.attachShader(p, shader(gl.VERTEX_SHADER, vs));
    gl.attachShader(p, shader(gl.FRAGMENT_SHADER, fs));
    gl.bindAttribLocation(p, 0, "aPos");
    gl.bindAttribLocation(p, 1, "aNrm");
    gl.linkProgram(p);
    if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(p));
    this.u = {};
    for (const name of ["uView", "uProj", "uColor", "uEmissive", "uLit", "uFlat", "uOrtho"]) this.u[name] = gl.getUniformLocation(p, name);
    return p;
  }

  // Replaces the geometry with a GLB's; the camera is kept when
  // `keepCamera` (an edit of the same model), else set from the reply's.
  show(buffer, info, keepCamera) {
    if (this.owned) this.free(this.owned);
    this.owned = this.load(buffer);
    this.use(this.owned, info, keepCamera);
  }

  // A GLB's geometry on the GPU, to draw with `use` (a playback keeps one
  // per frame) and free with `free`.
  load(buffer) {
    const gl = this.gl;
    const prims = [];
    const parsed = parseGlb(buffer);
    const vaos = new Map(); // position accessor -> {vao, count}
    for (const p of parsed) {
      if (p.mode === 4) {
        const normals = p.normals || smoothNormals(p.positions, p.indices);
        const vao = gl.createVertexArray();
        gl.bindVertexArray(vao);
        const pb = gl.createBuffer();
        gl.bindBuffer(gl.ARRAY_BUFFER, pb);
        gl.bufferData(gl.ARRAY_BUFFER, p.positions, gl.STATIC_DRAW);
        gl.enableVertexAttribArray(0);
        gl.vertexAttribPointer(0, 3, gl.FLOAT, false, 0, 0);
        const nb = gl.createBuffer();
        gl.bindBuffer(gl.ARRAY_BUFFER, nb);
        gl.bufferData(gl.ARRAY_BUFFER, normals, gl.STATIC_DRAW);
        gl.enableVertexAttribArray(1);
        gl.vertexAttribPointer(1, 3, gl.FLOAT, false, 0, 0);
        const ib = gl.createBuffer();
        gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, ib);
        gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, p.indices, gl.STATIC_DRAW);
        gl.bindVertexArray(null);
        const prim = {
          kind: "triangles", vao, ib, count: p.indices.length, color: p.color, emissive: p.emissive,
          indices: p.indices, vertices: p.positions.length / 3, edges: null,
          free: () => { gl.deleteVertexArray(vao); for (const b of [pb, nb, ib]) gl.deleteBuffer(b); if (prim.edges) prim.edges.free(); },
        };
        vaos.set(p.positionAccessor, prim);
        prims.push(prim);
      }
    }
    // LINES primitives: the polygon edges over their triangles' positions.
    for (const p of parsed) {
      if (p.mode !== 1) continue;
      const tri = vaos.get(p.positionAccessor);
      if (tri) tri.edges = this.edgeBuffer(tri, p.indices);
    }
    return { prims, hasEdges: parsed.some((p) => p.mode === 1) };
  }

  free(model) {
    for (const p of model.prims) p.free();
    model.prims = [];
    if (this.owned === model) this.owned = null;
  }

  // Draws `model` (from `load`) from now on.
  use(model, info, keepCamera) {
    if (this.owned && this.owned !== model) this.free(this.owned);
    this.prims = model.prims;
    this.hasEdges = model.hasEdges;
    this.info = info;
    this.lit = info.lit;
    this.background = info.background.map((c) => c / 255);
    if (!keepCamera || !this.home) {
      this.home = this.cameraOf(info);
      this.camera = { ...this.home };
    } else {
      this.home = this.cameraOf(info);
    }
    this.redraw();
  }

  // A LINES index buffer drawn with a triangle primitive's vertex array.
  // (The vertex array keeps the triangles' element buffer; the edges' is
  // bound in its place for their draw, and the triangles' put back.)
  edgeBuffer(tri, indices) {
    const gl = this.gl;
    gl.bindVertexArray(null);
    const eb = gl.createBuffer();
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, eb);
    gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, indices, gl.STATIC_DRAW);
    gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, null);
    return { buffer: eb, count: indices.length, free: () => gl.deleteBuffer(eb) };
  }

  // The command line's camera: eye, frame, projection; the point turned
  // about is the one on the line of sight nearest the geometry's centre.
  cameraOf(info) {
    const centre = v3.scale(v3.add(info.bounds[0], info.bounds[1]), 0.5);
    const radius = Math.max(1e-6, 0.5 * Math.hypot(...v3.sub(info.bounds[1], info.bounds[0])));
    const perspective = info.projection === "perspective";
    let dist = Math.max(v3.dot(v3.sub(centre, info.eye), info.dir), radius * 0.05);
    const target = v3.add(info.eye, v3.scale(info.dir, dist));
    // In parallel projection the eye's distance only clips: well outside.
    if (!perspective) dist = 3 * radius;
    return {
      target, dist, dir: info.dir.slice(), up: info.up.slice(),
      perspective,
      halfHeight: info.half_height, radius, axis: v3.norm(info.turn_axis),
    };
  }

  reset() { if (this.home) { this.camera = { ...this.home }; this.redraw(); } }
  setWireframe(on) { this.wireframe = on; this.redraw(); }
  setFlat(on) { this.flat = on; this.redraw(); }

  redraw() {
    if (this.dirty) return;
    this.dirty = true;
    requestAnimationFrame(() => { this.dirty = false; this.draw(); });
  }

  matrices() {
    const c = this.camera;
    const w = this.canvas.width, h = this.canvas.height;
    const aspect = w / Math.max(h, 1);
    const dir = v3.norm(c.dir);
    const right = v3.norm(v3.cross(dir, c.up));
    const up = v3.cross(right, dir);
    const eye = v3.sub(c.target, v3.scale(dir, c.dist));
    // Column-major: rows right, up, -dir.
    const t = [-v3.dot(right, eye), -v3.dot(up, eye), v3.dot(dir, eye)];
    const view = new Float32Array([
      right[0], up[0], -dir[0], 0, right[1], up[1], -dir[1], 0, right[2], up[2], -dir[2], 0,
      t[0], t[1], t[2], 1,
    ]);
    // The picture fits the command line's square: the shorter side sees
    // what its side saw.
    const fitH = aspect >= 1 ? 1 : 1 / aspect;
    const far = c.dist + 4 * c.radius;
    let proj;
    if (c.perspective) {
      const near = Math.max(far * 1e-4, c.dist - 4 * c.radius);
      const f = 1 / (c.halfHeight * fitH);
      proj = new Float32Array([f / aspect, 0, 0, 0, 0, f, 0, 0, 0, 0, (far + near) / (near - far), -1, 0, 0, 2 * far * near / (near - far), 0]);
    } else {
      const near = c.dist - 4 * c.radius;
      const hh = c.halfHeight * fitH * (c.zoom || 1);
      proj = new Float32Array([1 / (hh * aspect), 0, 0, 0, 0, 1 / hh, 0, 0, 0, 0, -2 / (far - near), 0, 0, 0, -(far + near) / (far - near), 1]);
    }
    return { view, proj, right, up, dir, aspect };
  }

  draw() {
    const gl = this.gl, canvas = this.canvas;
    const ratio = window.devicePixelRatio || 1;
    const w = Math.max(1, Math.round(canvas.clientWidth * ratio)), h = Math.max(1, Math.round(canvas.clientHeight * ratio));
    if (canvas.width !== w || canvas.height !== h) { canvas.width = w; canvas.height = h; }
    gl.viewport(0, 0, w, h);
    const bg = this.background || [1, 1, 1];
    gl.clearColor(bg[0], bg[1], bg[2], 1);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    if (!this.camera) return;
    const m = this.matrices();
    gl.useProgram(this.program);
    gl.uniformMatrix4fv(this.u.uView, false, m.view);
    gl.uniformMatrix4fv(this.u.uProj, false, m.proj);
    gl.uniform1i(this.u.uOrtho, this.camera.perspective ? 0 : 1);
    gl.enable(gl.DEPTH_TEST);
    gl.disable(gl.CULL_FACE);
    gl.enable(gl.POLYGON_OFFSET_FILL);
    gl.polygonOffset(1, 1);
    const opaque = this.prims.filter((p) => p.color[3] >= 1);
    const clear = this.prims.filter((p) => p.color[3] < 1);
    const tris = (p) => {
      gl.uniform4fv(this.u.uColor, p.color);
      gl.uniform3fv(this.u.uEmissive, p.emissive);
      gl.uniform1i(this.u.uLit, this.lit ? 1 : 0);
      gl.uniform1i(this.u.uFlat, this.flat ? 1 : 0);
      gl.bindVertexArray(p.vao);
      gl.drawElements(gl.TRIANGLES, p.count, gl.UNSIGNED_INT, 0);
    };
    for (const p of opaque) tris(p);
    if (clear.length) {
      gl.enable(gl.BLEND);
      gl.blendFunc(gl.SRC_ALPHA, gl.ONE_MINUS_SRC_ALPHA);
      gl.depthMask(false);
      for (const p of clear) tris(p);
      gl.depthMask(true);
      gl.disable(gl.BLEND);
    }
    gl.disable(gl.POLYGON_OFFSET_FILL);
    if (this.wireframe) {
      const dark = bg[0] + bg[1] + bg[2] < 1.5;
      gl.uniform4fv(this.u.uColor, dark ? [0.85, 0.88, 0.92, 1] : [0.15, 0.18, 0.24, 1]);
      gl.uniform3fv(this.u.uEmissive, [0, 0, 0]);
      gl.uniform1i(this.u.uLit, 0);
      for (const p of this.prims) {
        if (!p.edges) {
        p.edges = this.edgeBuffer(p, triangleEdges(p.indices, p.vertices));
      }
        gl.bindVertexArray(p.vao);
        gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, p.edges.buffer);
        gl.drawElements(gl.LINES, p.edges.count, gl.UNSIGNED_INT, 0);
        gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, p.ib);
      }
    }
    gl.bindVertexArray(null);
    this.frames += 1;
  }

  // Waits for the GPU to finish what was drawn (reading a pixel back
  // does; gl.finish need not).
  settle() {
    const gl = this.gl;
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, new Uint8Array(4));
  }

  // Draws now and reads the picture back: how many pixels differ from
  // the background, and a checksum (the browser tests' eyes).
  sample() {
    this.draw();
    const gl = this.gl, w = this.canvas.width, h = this.canvas.height;
    const px = new Uint8Array(w * h * 4);
    gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, px);
    const bg = (this.background || [1, 1, 1]).map((c) => Math.round(c * 255));
    let ink = 0, sum = 0;
    for (let i = 0; i < px.length; i += 4) {
      if (Math.abs(px[i] - bg[0]) + Math.abs(px[i + 1] - bg[1]) + Math.abs(px[i + 2] - bg[2]) > 24) ink += 1;
      sum = (sum * 31 + px[i] + 7 * px[i + 1] + 13 * px[i + 2]) >>> 0;
    }
    return { width: w, height: h, ink, sum };
  }

  bindInput() {
    const c = this.canvas;
    c.addEventListener("contextmenu", (e) => e.preventDefault());
    c.addEventListener("pointerdown", (e) => {
      c.setPointerCapture(e.pointerId);
      this.pointer = { x: e.clientX, y: e.clientY, pan: e.button === 2 || e.button === 1 || e.shiftKey };
    });
    c.addEventListener("pointerup", () => { this.pointer = null; });
    c.addEventListener("pointercancel", () => { this.pointer = null; });
    c.addEventListener("pointermove", (e) => {
      if (!this.pointer || !this.camera) return;
      const dx = e.clientX - this.pointer.x, dy = e.clientY - this.pointer.y;
      this.pointer.x = e.clientX; this.pointer.y = e.clientY;
      if (this.pointer.pan) this.pan(dx, dy); else this.orbit(dx, dy);
    });
    c.addEventListener("wheel", (e) => {
      e.preventDefault();
      this.zoom(Math.exp(Math.sign(e.deltaY) * Math.min(Math.abs(e.deltaY), 200) * 0.002));
    }, { passive: false });
    c.addEventListener("dblclick", () => this.reset());
  }

  // A drag of (dx, dy) pixels turns the view about the model's up axis
  // and about the screen's horizontal axis.
  orbit(dx, dy) {
    const c = this.camera;
    let dir = v3.norm(c.dir), up = c.up;
    const yaw = -dx * 0.01, pitch = -dy * 0.01;
    dir = v3.turn(dir, c.axis, yaw); up = v3.turn(up, c.axis, yaw);
    const right = v3.norm(v3.cross(dir, up));
    const nextDir = v3.turn(dir, right, pitch);
    // Not over the pole: the view stays upright about its axis.
    if (Math.abs(v3.dot(nextDir, c.axis)) < 0.995) { dir = nextDir; up = v3.turn(up, right, pitch); }
    c.dir = dir; c.up = v3.norm(v3.cross(right, dir));
    this.redraw();
  }

  pan(dx, dy) {
    const c = this.camera, m = this.matrices();
    const worldPerPixel = 2 * (c.perspective ? c.halfHeight * c.dist : c.halfHeight * (c.zoom || 1)) *
      (m.aspect >= 1 ? 1 : 1 / m.aspect) / Math.max(this.canvas.clientHeight, 1);
    c.target = v3.add(c.target, v3.add(v3.scale(m.right, -dx * worldPerPixel), v3.scale(m.up, dy * worldPerPixel)));
    this.redraw();
  }

  zoom(factor) {
    const c = this.camera;
    if (c.perspective) c.dist = Math.max(c.radius * 1e-3, c.dist * factor);
    else c.zoom = Math.min(1e3, Math.max(1e-3, (c.zoom || 1) * factor));
    this.redraw();
  }
}

window.View3D = View3D;
