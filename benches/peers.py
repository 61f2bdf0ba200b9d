"""Peers for the surface and vv benchmarks, and an independent cross-check.

Run after `cargo run --release --example bench_surface /tmp/subgram-bench`
(or `bench_vv`, which writes the same icosphere):

    python3 benches/peers.py [/tmp/subgram-bench]

or let it run the vv benchmark itself, back to back with igl.loop:

    python3 benches/peers.py --bench-vv [--rounds 3] [/tmp/subgram-bench]

Needs `pip install libigl pymeshlab numpy scipy`. Not part of `cargo test`.

It times igl.loop (Warren's beta) and pymeshlab's Loop (Loop's beta,
threshold 0) on the same 81,920-triangle icosphere (`icosphere6.obj`),
best of 7 with the Python <-> C++ conversions included, and compares
pymeshlab's result with subgram's outputs found in the folder: the
grammar's (`icosphere6-loop.obj`, from bench_surface) and the vv
program's (`icosphere6-vvloop.obj`, from bench_vv). Vertices are matched
by nearest position (all keep the original vertices, but new ones come in
different orders).

With `--bench-vv` it runs `target/release/examples/bench_vv FOLDER` (build
it first: `cargo build --release --example bench_vv`; `--bench-bin`
picks another path) and then times igl.loop on the icosphere it just
wrote, `--rounds` times in a row, and prints each round's figures (vv
program, stellar grammar, hand loop, igl.loop) with their ratios to
igl.loop, then the best of each over the rounds.
"""
import argparse
import json
import os
import re
import subprocess
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def read_obj(path):
    """Positions (float64) and faces (int64, 0-based) of an OBJ file whose
    faces all have the same number of corners."""
    v, f = [], []
    for line in open(path):
        if line.startswith("v "):
            v.append([float(x) for x in line.split()[1:4]])
        elif line.startswith("f "):
            f.append([int(x.split("/")[0]) - 1 for x in line.split()[1:]])
    return np.array(v, dtype=np.float64), np.array(f, dtype=np.int64)


def best_of(fn, runs=7):
    best, out = float("inf"), None
    for _ in range(runs):
        t = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t)
    return best, out


def time_igl(v, f):
    import igl

    # The conversion of the faces to int32 is inside the timed call, as
    # are the bindings' numpy <-> Eigen copies.
    return best_of(lambda: igl.loop(v, f.astype(np.int32)))


def time_meshlab(v, f):
    import pymeshlab

    def meshlab():
        ms = pymeshlab.MeshSet()
        ms.add_mesh(pymeshlab.Mesh(v, f))
        ms.meshing_surface_subdivision_loop(
            iterations=1, threshold=pymeshlab.PureValue(0), loopweight="Loop"
        )
        m = ms.current_mesh()
        return m.vertex_matrix(), m.face_matrix()

    return best_of(meshlab)


def peers(folder):
    from scipy.spatial import cKDTree

    v, f = read_obj(f"{folder}/icosphere6.obj")
    t_igl, (vi, fi) = time_igl(v, f)
    t_ml, (vm, fm) = time_meshlab(v, f)
    print(f"input: {len(f)} triangles")
    print(f"igl.loop (Warren's beta): {len(fi)} triangles, best of 7: {t_igl * 1e3:.1f} ms")
    print(f"pymeshlab Loop (Loop's beta): {len(fm)} triangles, best of 7: {t_ml * 1e3:.1f} ms")
    tree = cKDTree(vm)
    for name, file in [("grammar", "icosphere6-loop.obj"), ("vv program", "icosphere6-vvloop.obj")]:
        path = f"{folder}/{file}"
        if not os.path.exists(path):
            print(f"{name} vs pymeshlab: {path} is missing (run the bench example first)")
            continue
        ours, _ = read_obj(path)
        d, idx = tree.query(ours)
        one_to_one = len(ours) == len(vm) and len(set(idx.tolist())) == len(ours)
        print(
            f"{name} vs pymeshlab: {len(ours)} vs {len(vm)} vertices, "
            f"{'one-to-one' if one_to_one else 'NOT one-to-one'}, "
            f"largest distance to the nearest pymeshlab vertex {d.max():.3e}"
        )


BENCH_LINE = re.compile(r"^\s*(vv program|stellar grammar|hand loop):\s+([0-9.]+) ms")


def bench_vv(folder, binary, rounds):
    if not os.access(binary, os.X_OK):
        sys.exit(f"{binary}: not built (cargo build --release --example bench_vv)")
    names = ["vv program", "stellar grammar", "hand loop", "igl.loop"]
    rows = []
    for k in range(rounds):
        r = subprocess.run([binary, folder], capture_output=True, text=True)
        if r.returncode != 0:
            sys.exit(f"{binary} failed ({r.returncode}):\n{r.stdout}{r.stderr}")
        got = {m.group(1): float(m.group(2)) for m in map(BENCH_LINE.match, r.stdout.splitlines()) if m}
        if set(got) != set(names[:3]):
            sys.exit(f"unexpected bench_vv output:\n{r.stdout}")
        if k == 0:
            print(r.stdout.splitlines()[0])
        v, f = read_obj(f"{folder}/icosphere6.obj")
        t_igl, (vi, fi) = time_igl(v, f)
        got["igl.loop"] = t_igl * 1e3
        rows.append(got)
        load = os.getloadavg()[0]
        print(f"round {k + 1} (load {load:.2f}): " + ", ".join(
            f"{n} {got[n]:.1f} ms ({got[n] / got['igl.loop']:.2f}x igl)" for n in names))
    best = {n: min(r[n] for r in rows) for n in names}
    print(f"best of {rounds} rounds (each best of 7; igl.loop {len(f)} -> {len(fi)} triangles, "
          "conversions included):")
    for n in names:
        print(f"  {n:<16} {best[n]:7.1f} ms   {best[n] / best['igl.loop']:.2f}x igl.loop")


def blender_whole(path, runs=7):
    """Blender's Catmull-Clark, faces to faces, cold: run by Blender's own
    Python (`bpy`), printing one JSON line.

    Each run starts from the numpy arrays of the file's positions and quads
    and ends with the evaluated mesh's arrays in numpy: a new mesh filled
    from the arrays (foreach_set, edges computed), a new object with a
    SUBSURF modifier (Catmull-Clark, level 1, boundary_smooth='ALL',
    use_limit_surface=False, no creases, as benches/xcheck.py sets it), the
    depsgraph updated, and the evaluated positions, face starts and sizes
    and loop vertices read out (foreach_get). Every run uses a fresh mesh
    and object, so no refiner is cached. Best of `runs`; `modifier_ms` is
    the best time of the modifier alone (mesh built before the clock
    starts), as benches/xcheck.py times it, with the positions only.
    """
    import json

    import bpy

    v, f = read_obj(path)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    dg = bpy.context.evaluated_depsgraph_get()
    n, k = f.shape
    co32 = np.ascontiguousarray(v, np.float32).ravel()
    idx32 = np.ascontiguousarray(f, np.int32).ravel()
    starts = np.arange(0, n * k, k, dtype=np.int32)

    def build(name):
        me = bpy.data.meshes.new(name)
        me.vertices.add(len(v))
        me.vertices.foreach_set("co", co32)
        me.loops.add(n * k)
        me.loops.foreach_set("vertex_index", idx32)
        me.polygons.add(n)
        me.polygons.foreach_set("loop_start", starts)
        me.update(calc_edges=True)
        ob = bpy.data.objects.new(name, me)
        bpy.context.scene.collection.objects.link(ob)
        return ob

    def subsurf(ob):
        md = ob.modifiers.new("subsurf", "SUBSURF")
        md.subdivision_type = "CATMULL_CLARK"
        md.boundary_smooth = "ALL"
        md.use_limit_surface = False
        md.use_creases = False
        md.levels = 1
        return md

    def fetch(ob, faces=True):
        ev = ob.evaluated_get(dg).data
        co = np.empty(len(ev.vertices) * 3, np.float32)
        ev.vertices.foreach_get("co", co)
        if not faces:
            return co, None
        m = len(ev.polygons)
        ls = np.empty(m, np.int32)
        lt = np.empty(m, np.int32)
        ev.polygons.foreach_get("loop_start", ls)
        ev.polygons.foreach_get("loop_total", lt)
        lv = np.empty(len(ev.loops), np.int32)
        ev.loops.foreach_get("vertex_index", lv)
        return co, (ls, lt, lv)

    def drop(ob):
        me = ob.data
        bpy.data.objects.remove(ob)
        bpy.data.meshes.remove(me)

    whole, modifier = [], []
    for r in range(runs):
        t = time.perf_counter()
        ob = build(f"w{r}")
        subsurf(ob)
        dg.update()
        co, (ls, lt, lv) = fetch(ob)
        whole.append(time.perf_counter() - t)
        assert len(ls) == 4 * n and (lt == 4).all(), "the modifier did not run"
        drop(ob)
        # The modifier alone on a mesh built beforehand.
        ob2 = build(f"m{r}")
        md = subsurf(ob2)
        md.show_viewport = False
        dg.update()
        fetch(ob2, faces=False)
        md.show_viewport = True
        t = time.perf_counter()
        dg.update()
        fetch(ob2, faces=False)
        modifier.append(time.perf_counter() - t)
        drop(ob2)
    print(json.dumps(dict(faces_in=int(n), faces_out=int(len(ls)), verts_out=len(co) // 3,
                          whole_ms=min(whole) * 1e3, modifier_ms=min(modifier) * 1e3,
                          cpus=len(os.sched_getaffinity(0)))))


FACES_LINE = re.compile(r"^(Loop|Catmull-Clark), faces to faces")
PART_LINE = re.compile(r"^\s+(from_soup|grammar|to_soup|to_quad_soup|total|whole)\s+([0-9.]+) ms")


def bench_faces(folder, binaries, rounds, bpy_python):
    """Faces to faces, round after round: each binary's bench_surface (in
    the order given, so that a before and an after alternate), then
    igl.loop on the icosphere and Blender on the torus they wrote."""
    for b in binaries:
        if not os.access(b, os.X_OK):
            sys.exit(f"{b}: not built (cargo build --release --example bench_surface)")
    rows = []
    for k in range(rounds):
        row = {}
        for b in binaries:
            r = subprocess.run([b, folder], capture_output=True, text=True)
            if r.returncode != 0:
                sys.exit(f"{b} failed ({r.returncode}):\n{r.stdout}{r.stderr}")
            scheme = None
            for line in r.stdout.splitlines():
                m = FACES_LINE.match(line)
                if m:
                    scheme = m.group(1)
                    continue
                m = PART_LINE.match(line)
                if m and scheme:
                    part = "out" if m.group(1).startswith("to_") else m.group(1)
                    row[(b, scheme, part)] = float(m.group(2))
        v, f = read_obj(f"{folder}/icosphere6.obj")
        t_igl, _ = time_igl(v, f)
        row["igl.loop"] = t_igl * 1e3
        r = subprocess.run([bpy_python, os.path.abspath(__file__), "--blender-whole",
                            f"{folder}/torus316.obj"], capture_output=True, text=True)
        line = [x for x in r.stdout.splitlines() if x.startswith("{")]
        if not line:
            sys.exit(f"Blender failed:\n{r.stderr[-2000:]}")
        t = json.loads(line[-1])
        row["blender"] = t["whole_ms"]
        row["blender modifier"] = t["modifier_ms"]
        rows.append(row)
        load = os.getloadavg()[0]
        print(f"round {k + 1} (load {load:.2f}): igl.loop {row['igl.loop']:.1f} ms, Blender whole "
              f"{row['blender']:.1f} ms (modifier alone {row['blender modifier']:.1f} ms, "
              f"{t['cpus']} cores)")
        for b in binaries:
            for scheme, peer in (("Loop", "igl.loop"), ("Catmull-Clark", "blender")):
                parts = {p: row.get((b, scheme, p)) for p in
                         ("from_soup", "grammar", "out", "total", "whole")}
                txt = ", ".join(f"{p} {x:.1f}" for p, x in parts.items() if x is not None)
                key = parts["whole"] or parts["total"]
                print(f"  {b}: {scheme}: {txt} ms; {key / row[peer]:.2f}x {peer}")
    print(f"best of {rounds} rounds (each figure best of 7 within its round):")
    best = lambda key: min(r[key] for r in rows if key in r)
    print(f"  igl.loop {best('igl.loop'):.1f} ms; Blender whole {best('blender'):.1f} ms, "
          f"modifier alone {best('blender modifier'):.1f} ms")
    for b in binaries:
        for scheme, peer in (("Loop", "igl.loop"), ("Catmull-Clark", "blender")):
            for part in ("from_soup", "grammar", "out", "total", "whole"):
                if any((b, scheme, part) in r for r in rows):
                    x = best((b, scheme, part))
                    print(f"  {b}: {scheme} {part:<9} {x:7.1f} ms   {x / best(peer):.2f}x {peer}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("folder", nargs="?", default="/tmp/subgram-bench")
    ap.add_argument("--bench-vv", action="store_true",
                    help="run bench_vv and igl.loop back to back, --rounds times")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--bench-bin", default=os.path.join(ROOT, "target", "release", "examples", "bench_vv"))
    ap.add_argument("--faces", nargs="*", metavar="BENCH_SURFACE",
                    help="faces to faces: run these bench_surface binaries (default: "
                         "target/release/examples/bench_surface), igl.loop and Blender, "
                         "--rounds times")
    ap.add_argument("--bpy-python", default=sys.executable,
                    help="a Python with bpy, for --faces (default: this one; Blender runs "
                         "in a process of its own, as bpy cannot load after pymeshlab)")
    ap.add_argument("--blender-whole", metavar="OBJ", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.blender_whole:
        blender_whole(args.blender_whole)
    elif args.faces is not None:
        bins = args.faces or [os.path.join(ROOT, "target", "release", "examples", "bench_surface")]
        bench_faces(args.folder, bins, args.rounds, args.bpy_python)
    elif args.bench_vv:
        bench_vv(args.folder, args.bench_bin, args.rounds)
    else:
        peers(args.folder)


if __name__ == "__main__":
    main()
