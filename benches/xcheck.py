"""Independent cross-checks of the surface grammars against CGAL and Blender,
and peer timings. Not part of `cargo test`.

    python3 benches/xcheck.py [--bin target/release/subgram] [--out /tmp/xcheck]
                              [--bench-dir /tmp/subgram-bench] [--no-bench]

Needs numpy, scipy, `compas_cgal` (CGAL's Subdivision_method_3 through
pybind) and `bpy` (Blender as a Python module, whose SUBSURF modifier is
OpenSubdiv). With Python 3.11, `pip install compas_cgal bpy==5.0.1` in a
venv works (bpy pins numpy 1.26). Either peer may be missing: its checks
are then skipped with a note.

What it does
------------
a. Catmull-Clark (lsystems/surfaces/catmull-clark.lsys) against Blender's
   SUBSURF modifier (CATMULL_CLARK, boundary_smooth='ALL' so that boundary
   corners are smoothed like other boundary vertices, use_limit_surface=False,
   so the control points of level n are compared, not limit positions) on
   cube.obj, torus.obj, grid.obj (1 and 2 levels) and on a generated
   316 x 316 quad torus (1 level). Both sides read the same OBJ file.
   Vertices are matched by nearest position (cKDTree): the point sets must
   agree, the match must be one-to-one, and the faces, written in matched
   indices, must be the same sets of vertices. Distances are relative to the
   bounding-box diagonal; Blender stores float32, so ~1e-7 is agreement.
   CGAL's Catmull-Clark is run too, as a third opinion.
b. Timing, Blender on the 316 x 316 torus, level 1. Blender defers the
   refinement of a last-in-stack SUBSURF modifier to the first read of the
   evaluated mesh, so every Blender time is depsgraph update + reading the
   evaluated positions into numpy (the copy alone is printed too). "Cold":
   a fresh object, the modifier just switched on (OpenSubdiv topology
   refiner built from the mesh, refinement, evaluated mesh built): the first
   one in the process, and the best of 3 fresh objects. "Warm": best of 3
   re-evaluations after tagging the mesh data as changed (same topology, so
   Blender reuses its cached refiner). Blender runs with all cores and, in a
   second process, pinned to one core (taskset), since the grammar engine
   is single-threaded.
   The grammar side is `cargo run --release --example bench_surface`,
   whose best-of-3 timings cover the grammar run on an in-memory mesh only
   (no file IO, no parsing); run in the same session.
c. sqrt(3) (lsystems/surfaces/sqrt3.lsys) against CGAL's
   Sqrt3_subdivision (via compas_cgal) on octahedron.obj and a 320-triangle
   icosphere, 1 and 2 steps; and CGAL's time for one step on the
   81,920-triangle icosphere written by the bench example (best of 3,
   including compas_cgal's numpy <-> Surface_mesh conversions).
d. CGAL's sqrt(3) on the open grid.obj (triangulated), 1 and 2 steps:
   outputs saved to OUT/cgal-grid-sqrt3-{1,2}.obj (input as
   OUT/grid-tri.obj); boundary vertices counted; the linear map from input
   to output positions fitted by least squares from random inputs, and the
   boundary vertices' weights printed.
"""
import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time

import numpy as np
from scipy.spatial import cKDTree

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MESHES = os.path.join(ROOT, "lsystems", "meshes")
SURF = os.path.join(ROOT, "lsystems", "surfaces")


# ---------------------------------------------------------------- mesh IO
def read_obj(path):
    v, f = [], []
    for line in open(path):
        if line.startswith("v "):
            v.append([float(x) for x in line.split()[1:4]])
        elif line.startswith("f "):
            f.append([int(x.split("/")[0]) - 1 for x in line.split()[1:]])
    return np.array(v, dtype=np.float64), f


def write_obj(path, v, f, comment=None):
    with open(path, "w") as out:
        if comment:
            out.write(f"# {comment}\n")
        for p in v:
            out.write(f"v {p[0]!r} {p[1]!r} {p[2]!r}\n")
        for face in f:
            out.write("f " + " ".join(str(int(i) + 1) for i in face) + "\n")


def quad_torus(n, m, big=1.0, small=0.35):
    """An n x m quad torus; vertex (i, j) at index i*m + j."""
    u = np.arange(n) / n * 2 * np.pi
    w = np.arange(m) / m * 2 * np.pi
    uu, ww = np.meshgrid(u, w, indexing="ij")
    r = big + small * np.cos(ww)
    v = np.stack([r * np.cos(uu), r * np.sin(uu), small * np.sin(ww)], -1).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(n), np.arange(m), indexing="ij")
    i, j = i.ravel(), j.ravel()
    idx = lambda a, b: (a % n) * m + (b % m)
    f = np.stack([idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1)], -1)
    return v, f.tolist()


def icosphere(levels):
    t = (1 + 5 ** 0.5) / 2
    v = [[-1, t, 0], [1, t, 0], [-1, -t, 0], [1, -t, 0], [0, -1, t], [0, 1, t],
         [0, -1, -t], [0, 1, -t], [t, 0, -1], [t, 0, 1], [-t, 0, -1], [-t, 0, 1]]
    v = [list(np.array(p, float) / np.linalg.norm(p)) for p in v]
    f = [[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9],
         [5, 11, 4], [11, 10, 2], [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2],
         [3, 2, 6], [3, 6, 8], [3, 8, 9], [4, 9, 5], [2, 4, 11], [6, 2, 10],
         [8, 6, 7], [9, 8, 1]]
    for _ in range(levels):
        mid, nf = {}, []

        def m(a, b):
            k = (min(a, b), max(a, b))
            if k not in mid:
                p = (np.array(v[a]) + np.array(v[b])) / 2
                v.append(list(p / np.linalg.norm(p)))
                mid[k] = len(v) - 1
            return mid[k]

        for a, b, c in f:
            ab, bc, ca = m(a, b), m(b, c), m(c, a)
            nf += [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]
        f = nf
    return np.array(v), f


def boundary_vertices(f):
    count = {}
    for face in f:
        for a, b in zip(face, face[1:] + face[:1]):
            k = (min(a, b), max(a, b))
            count[k] = count.get(k, 0) + 1
    return sorted({x for k, c in count.items() if c == 1 for x in k})


# ---------------------------------------------------------------- ours
def ours(binary, mesh, grammar, steps):
    with tempfile.TemporaryDirectory() as d:
        out = os.path.join(d, "out.obj")
        subprocess.run([binary, "subdivide", mesh, "--grammar", os.path.join(SURF, grammar),
                        "-n", str(steps), "-o", out], check=True, capture_output=True)
        return read_obj(out)


# ---------------------------------------------------------------- compare
def compare(name, ref, mine, show=5):
    """ref, mine: (V, F). Returns max distance / bbox diagonal."""
    (vr, fr), (vm, fm) = ref, mine
    diag = np.linalg.norm(vr.max(0) - vr.min(0))
    d, idx = cKDTree(vr).query(vm)
    rel = d / diag
    one_to_one = len(vr) == len(vm) and len(np.unique(idx)) == len(vm)
    faces_same = None
    if one_to_one:
        a = {tuple(sorted(face)) for face in fr}
        b = {tuple(sorted(idx[face])) for face in fm}
        faces_same = a == b
    print(f"  {name}: verts ref {len(vr)} ours {len(vm)}; faces ref {len(fr)} ours {len(fm)}"
          f" ({'agree' if len(fr) == len(fm) else 'DIFFER'}); max dist/diag {rel.max():.2e};"
          f" one-to-one {one_to_one}; same faces {faces_same}")
    bad = np.argsort(-rel)[:show]
    if rel.max() > 1e-5:
        for k in bad:
            if rel[k] <= 1e-5:
                break
            print(f"      ours #{k} {np.round(vm[k], 6)} nearest ref {np.round(vr[idx[k]], 6)}"
                  f" (rel {rel[k]:.2e})")
    return rel.max()


# ---------------------------------------------------------------- Blender
def bpy_mesh(v, f, name="m"):
    import bpy
    me = bpy.data.meshes.new(name)
    sizes = np.array([len(x) for x in f], dtype=np.int32)
    me.vertices.add(len(v))
    me.vertices.foreach_set("co", np.asarray(v, np.float32).ravel())
    me.loops.add(int(sizes.sum()))
    me.loops.foreach_set("vertex_index", np.concatenate([np.asarray(x, np.int32) for x in f]))
    me.polygons.add(len(f))
    me.polygons.foreach_set("loop_start", np.concatenate([[0], np.cumsum(sizes)[:-1]]).astype(np.int32))
    me.update(calc_edges=True)
    me.validate()
    ob = bpy.data.objects.new(name, me)
    bpy.context.scene.collection.objects.link(ob)
    return ob


def blender_fetch(ob, dg, faces=True):
    ev = ob.evaluated_get(dg).data
    co = np.empty(len(ev.vertices) * 3, np.float32)
    ev.vertices.foreach_get("co", co)
    if not faces:
        return co.reshape(-1, 3), None
    n = len(ev.polygons)
    start = np.empty(n, np.int32)
    total = np.empty(n, np.int32)
    ev.polygons.foreach_get("loop_start", start)
    ev.polygons.foreach_get("loop_total", total)
    lv = np.empty(len(ev.loops), np.int32)
    ev.loops.foreach_get("vertex_index", lv)
    f = [lv[s:s + t].tolist() for s, t in zip(start, total)]
    return co.reshape(-1, 3).astype(np.float64), f


def subsurf(ob, levels, **settings):
    """A Catmull-Clark Subdivision Surface modifier of `levels` on `ob`
    (`boundary_smooth='ALL'`, no limit surface, no creases unless
    `settings` say otherwise), evaluated: the depsgraph to read it from."""
    import bpy
    md = ob.modifiers.new("subsurf", "SUBSURF")
    md.subdivision_type = "CATMULL_CLARK"
    md.boundary_smooth = "ALL"
    md.use_limit_surface = False
    md.use_creases = False
    for name, value in settings.items():
        setattr(md, name, value)
    md.levels = levels
    md.render_levels = levels
    dg = bpy.context.evaluated_depsgraph_get()
    dg.update()
    return dg


def blender_cc(v, f, levels, boundary="ALL"):
    import bpy
    bpy.ops.wm.read_factory_settings(use_empty=True)
    ob = bpy_mesh(v, f)
    return blender_fetch(ob, subsurf(ob, levels, boundary_smooth=boundary))


def blender_timing(path, runs=3):
    """Timing mode, run in a child process so that it can be pinned.

    Blender (3.1 on) defers the subdivision of a last-in-stack SUBSURF
    modifier: the depsgraph update only wraps the mesh, and the refinement
    runs when the evaluated mesh's data is first read. So every time here is
    depsgraph update + reading the positions into numpy, and the modifier's
    `execution_time` (~0.01 ms) is meaningless. The copy alone is timed too.
    """
    import bpy
    v, f = read_obj(path)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    dg = bpy.context.evaluated_depsgraph_get()
    colds = []
    ob = None
    for r in range(runs):
        if ob is not None:
            ob.hide_viewport = True   # keep later updates to the newest object
        ob = bpy_mesh(v, f, f"m{r}")
        md = ob.modifiers.new("subsurf", "SUBSURF")
        md.subdivision_type = "CATMULL_CLARK"
        md.boundary_smooth = "ALL"
        md.use_limit_surface = False
        md.use_creases = False
        md.levels = 1
        md.show_viewport = False
        dg.update()
        blender_fetch(ob, dg, faces=False)
        md.show_viewport = True
        t = time.perf_counter()
        dg.update()
        co, _ = blender_fetch(ob, dg, faces=False)
        colds.append(time.perf_counter() - t)
    warm = []
    for _ in range(runs):
        ob.data.update_tag()
        t = time.perf_counter()
        dg.update()
        co, _ = blender_fetch(ob, dg, faces=False)
        warm.append(time.perf_counter() - t)
    t = time.perf_counter()
    co, _ = blender_fetch(ob, dg, faces=False)
    copy = time.perf_counter() - t
    ev = ob.evaluated_get(dg).data
    assert len(ev.polygons) == 4 * len(f), "the modifier did not run"
    return dict(faces_in=len(f), faces_out=len(ev.polygons), verts_out=len(co),
                first_cold_ms=colds[0] * 1e3, best_cold_ms=min(colds) * 1e3,
                warm_ms=min(warm) * 1e3, copy_ms=copy * 1e3,
                cpus=len(os.sched_getaffinity(0)))


# ---------------------------------------------------------------- CGAL
def cgal(kind, v, f, k):
    import compas_cgal.subdivision as s
    fn = {"sqrt3": s.mesh_subdivide_sqrt3, "cc": s.mesh_subdivide_catmull_clark}[kind]
    vo, fo = fn((np.asarray(v, float), np.asarray(f, np.int64)), k)
    return np.asarray(vo, float), np.asarray(fo).tolist()


def fit_linear(kind, f, n_in, k, trials=None, seed=1):
    """CGAL's output positions are linear in its inputs: fit W (out x in)."""
    rng = np.random.default_rng(seed)
    trials = trials or (n_in // 3 + 4)
    xs, ys, faces = [], [], None
    for _ in range(trials):
        x = rng.normal(size=(n_in, 3))
        y, fo = cgal(kind, x, f, k)
        if faces is None:
            faces = fo
        assert fo == faces, "output topology depends on positions"
        xs.append(x)
        ys.append(y)
    X, Y = np.hstack(xs), np.hstack(ys)          # n_in x 3T, n_out x 3T
    W = np.linalg.lstsq(X.T, Y.T, rcond=None)[0].T
    resid = np.abs(W @ X - Y).max()
    return W, faces, resid


# ---------------------------------------------------------------- main parts
def part_a(binary, out):
    print("\n== a. Catmull-Clark: grammar vs Blender SUBSURF (OpenSubdiv) and CGAL ==")
    try:
        import bpy
        print(f"  bpy {bpy.app.version_string}")
    except ImportError as e:
        print(f"  bpy missing ({e}): skipped")
        bpy = None
    torus_path = os.path.join(out, "torus316.obj")
    v, f = quad_torus(316, 316)
    write_obj(torus_path, v, f, "316 x 316 quad torus, R = 1, r = 0.35")
    cases = [(os.path.join(MESHES, m), (1, 2)) for m in
             ("cube.obj", "torus.obj", "grid.obj", "tetrahedron.obj", "octahedron.obj")]
    cases.append((torus_path, (1,)))
    worst = {}
    for path, levels in cases:
        v, f = read_obj(path)
        for n in levels:
            mine = ours(binary, path, "catmull-clark.lsys", n)
            name = f"{os.path.basename(path)} n={n}"
            if bpy is not None:
                worst["blender " + name] = compare("Blender " + name, blender_cc(v, f, n), mine)
            if len(f) < 1000:
                try:
                    worst["cgal " + name] = compare("CGAL    " + name, cgal("cc", v, f, n), mine)
                except Exception as e:  # noqa: BLE001
                    print(f"  CGAL CC on {name} failed: {e}")
    if bpy is not None:
        # The other convention: OpenSubdiv's VTX_BOUNDARY_EDGE_AND_CORNER keeps
        # a boundary vertex with one face (the grid's corners) fixed.
        path = os.path.join(MESHES, "grid.obj")
        v, f = read_obj(path)
        print("  (convention check, expected to differ at the 4 corners only:)")
        compare("Blender PRESERVE_CORNERS grid.obj n=1", blender_cc(v, f, 1, "PRESERVE_CORNERS"),
                ours(binary, path, "catmull-clark.lsys", 1))
    return worst


def part_b(bench_dir, run_bench, out):
    print("\n== b. timing, Catmull-Clark one level on the 316 x 316 quad torus ==")
    if run_bench:
        r = subprocess.run(["cargo", "run", "--release", "--example", "bench_surface", bench_dir],
                           cwd=ROOT, capture_output=True, text=True)
        print("  grammar (cargo run --release --example bench_surface):")
        for line in r.stdout.splitlines():
            print("    " + line)
        if r.returncode:
            print(r.stderr[-2000:])
    torus_path = os.path.join(out, "torus316.obj")
    for pin in (False, True):
        cmd = [sys.executable, os.path.abspath(__file__), "--blender-timing", torus_path]
        if pin:
            if not shutil.which("taskset"):
                continue
            cmd = ["taskset", "-c", "0"] + cmd
        r = subprocess.run(cmd, capture_output=True, text=True)
        line = [x for x in r.stdout.splitlines() if x.startswith("{")]
        if not line:
            print(f"  Blender timing failed: {r.stderr[-1500:]}")
            continue
        t = json.loads(line[-1])
        print(f"  Blender SUBSURF level 1, {t['cpus']} core(s): {t['faces_in']} -> {t['faces_out']}"
              f" quads; cold: first {t['first_cold_ms']:.1f} ms, best of 3 fresh objects"
              f" {t['best_cold_ms']:.1f} ms; warm (cached refiner) best of 3 {t['warm_ms']:.1f} ms;"
              f" of which copying positions to numpy {t['copy_ms']:.1f} ms")


def part_c(binary, out, bench_dir):
    print("\n== c. sqrt(3): grammar vs CGAL Sqrt3_subdivision ==")
    try:
        import compas_cgal
        print(f"  compas_cgal {compas_cgal.__version__}")
    except ImportError as e:
        print(f"  compas_cgal missing ({e}): skipped")
        return {}
    ico = os.path.join(out, "icosphere2.obj")
    v, f = icosphere(2)
    write_obj(ico, v, f, "icosphere, 320 triangles")
    worst = {}
    for path in (os.path.join(MESHES, "octahedron.obj"), ico):
        v, f = read_obj(path)
        for n in (1, 2):
            name = f"{os.path.basename(path)} n={n}"
            worst[name] = compare("CGAL " + name, cgal("sqrt3", v, f, n),
                                  ours(binary, path, "sqrt3.lsys", n))
    big = os.path.join(bench_dir, "icosphere6.obj")
    if os.path.exists(big):
        v, f = read_obj(big)
        f = np.asarray(f, np.int64)
        best = float("inf")
        for _ in range(3):
            t = time.perf_counter()
            vo, fo = cgal("sqrt3", v, f, 1)
            best = min(best, time.perf_counter() - t)
        print(f"  CGAL sqrt3 one step on {big}: {len(f)} -> {len(fo)} triangles,"
              f" best of 3 {best * 1e3:.1f} ms (with numpy <-> Surface_mesh conversion)")
    else:
        print(f"  {big} missing: run the bench example first")
    return worst


def part_d(binary, out):
    print("\n== d. CGAL sqrt(3) on the open grid (boundary behaviour) ==")
    v, q = read_obj(os.path.join(MESHES, "grid.obj"))
    f = [t for a, b, c, d in q for t in ([a, b, c], [a, c, d])]
    tri = os.path.join(out, "grid-tri.obj")
    write_obj(tri, v, f, "grid.obj, quads split a-b-c, a-c-d")
    bin_ = set(boundary_vertices(f))
    print(f"  input: {len(v)} vertices, {len(f)} triangles, {len(bin_)} boundary vertices;"
          " corner triangles: " + ", ".join(
              f"({v[c][0]:g},{v[c][1]:g}) {sum(c in t for t in f)}" for c in (0, 4, 20, 24)))
    label = lambda i: f"({v[i][0]:g},{v[i][1]:g})"

    def weights(i, W):
        nz = [j for j in np.argsort(-np.abs(W[i])) if abs(W[i, j]) > 1e-9]
        return ", ".join(f"{W[i, j] * 27:.3f}/27 {label(j)}" for j in nz)

    for k in (1, 2):
        vo, fo = cgal("sqrt3", v, f, k)
        path = os.path.join(out, f"cgal-grid-sqrt3-{k}.obj")
        write_obj(path, vo, fo, f"CGAL Sqrt3_subdivision of grid-tri.obj, {k} step(s)")
        bv = boundary_vertices(fo)
        W, fw, resid = fit_linear("sqrt3", f, len(v), k)
        assert fw == fo
        np.save(os.path.join(out, f"cgal-grid-sqrt3-{k}-weights.npy"), W)
        print(f"  {k} step(s): {len(vo)} vertices, {len(fo)} triangles, {len(bv)} boundary"
              f" vertices -> {path}; linear map (out x in) -> cgal-grid-sqrt3-{k}-weights.npy"
              f" (fit residual {resid:.1e}, max |row sum - 1| {np.abs(W.sum(1) - 1).max():.1e})")
        # boundary outputs driven mostly by the corner (0,0) (2 triangles),
        # the corner (1,0) (1 triangle) and the edge vertex (0.25,0)
        for j in (0, 4, 1):
            rows = [i for i in bv if W[i, j] > 0.3]
            for i in sorted(rows, key=lambda i: tuple(vo[i][:2])):
                print(f"    out #{i} at ({vo[i][0]:.4f},{vo[i][1]:.4f}): {weights(i, W)}")
        if k == 1:
            moved = [i for i in bin_ if abs(W[i, i] - 1) > 1e-9]
            print(f"    old boundary vertices moved by step 1: {len(moved)}")
    # The flat grid hides differences (straight boundaries, planar rings):
    # compare with the grammar on the same grid, jittered and lifted.
    rng = np.random.default_rng(7)
    vj = v + np.c_[rng.uniform(-0.03, 0.03, (len(v), 2)), rng.uniform(-0.1, 0.1, len(v))]
    trij = os.path.join(out, "grid-tri-jitter.obj")
    write_obj(trij, vj, f, "grid-tri.obj with random jitter, z in [-0.1, 0.1]")
    for k in (1, 2, 3, 4):
        vo, fo = cgal("sqrt3", vj, f, k)
        write_obj(os.path.join(out, f"cgal-grid-jitter-sqrt3-{k}.obj"), vo, fo,
                  f"CGAL Sqrt3_subdivision of grid-tri-jitter.obj, {k} step(s)")
        mine = ours(binary, trij, "sqrt3.lsys", k)
        compare(f"ours (Kobbelt's boundary rule) vs CGAL, jittered grid n={k}", (vo, fo), mine, show=0)
        bv = set(boundary_vertices(fo))
        d, _ = cKDTree(mine[0]).query(vo)
        miss = set(np.nonzero(d > 1e-9)[0].tolist())
        # ring distance from the boundary in CGAL's output
        adj = {}
        for t in fo:
            for a_, b_ in zip(t, t[1:] + t[:1]):
                adj.setdefault(a_, set()).add(b_)
                adj.setdefault(b_, set()).add(a_)
        dist, front = {i: 0 for i in bv}, list(bv)
        while front:
            nxt = []
            for i in front:
                for j in adj[i]:
                    if j not in dist:
                        dist[j] = dist[i] + 1
                        nxt.append(j)
            front = nxt
        hist = {}
        for i in miss:
            hist[dist[i]] = hist.get(dist[i], 0) + 1
        print(f"    CGAL vertices with no grammar vertex at them: {len(miss)} of {len(vo)};"
              f" by ring distance from the boundary: {dict(sorted(hist.items()))}")
        d2, _ = cKDTree(vo).query(mine[0])
        print(f"    grammar vertices with no CGAL vertex at them: {int((d2 > 1e-9).sum())} of {len(mine[0])}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bin", default=os.path.join(ROOT, "target", "release", "subgram"))
    ap.add_argument("--out", default="/tmp/xcheck")
    ap.add_argument("--bench-dir", default="/tmp/subgram-bench")
    ap.add_argument("--no-bench", action="store_true", help="skip the cargo bench example")
    ap.add_argument("--blender-timing", help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.blender_timing:
        print(json.dumps(blender_timing(a.blender_timing)))
        return
    os.makedirs(a.out, exist_ok=True)
    binary = os.path.abspath(a.bin)
    print(f"binary {binary}; python {sys.version.split()[0]}; numpy {np.__version__};"
          f" cores {len(os.sched_getaffinity(0))}")
    part_a(binary, a.out)
    part_b(a.bench_dir, not a.no_bench, a.out)
    part_c(binary, a.out, a.bench_dir)
    part_d(binary, a.out)


if __name__ == "__main__":
    main()
