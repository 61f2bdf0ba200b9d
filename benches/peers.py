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
import os
import re
import subprocess
import sys
import time

import numpy as np
from scipy.spatial import cKDTree

from xcheck import read_obj as read_obj_list  # the same folder

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def read_obj(path):
    v, f = read_obj_list(path)
    return v, np.array(f, dtype=np.int64)


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


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("folder", nargs="?", default="/tmp/subgram-bench")
    ap.add_argument("--bench-vv", action="store_true",
                    help="run bench_vv and igl.loop back to back, --rounds times")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--bench-bin", default=os.path.join(ROOT, "target", "release", "examples", "bench_vv"))
    args = ap.parse_args()
    if args.bench_vv:
        bench_vv(args.folder, args.bench_bin, args.rounds)
    else:
        peers(args.folder)


if __name__ == "__main__":
    main()
