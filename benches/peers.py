"""Peers for the surface benchmarks, and an independent cross-check.

Run after `cargo run --release --example bench_surface /tmp/subgram-bench`:

    python3 benches/peers.py /tmp/subgram-bench

Needs `pip install libigl pymeshlab numpy scipy`. Not part of `cargo test`.
It times igl.loop and pymeshlab's Loop (Loop's beta, threshold 0) on the
same 81,920-triangle icosphere, best of 7 with conversions included, and
compares pymeshlab's result with the grammar's output written by the
example: vertices are matched by nearest position (both keep the original
vertices, but new ones come in different orders).
"""
import sys
import time

import numpy as np
from scipy.spatial import cKDTree


from xcheck import read_obj as read_obj_list  # the same folder


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


def main(folder):
    v, f = read_obj(f"{folder}/icosphere6.obj")
    import igl
    t_igl, (vi, fi) = best_of(lambda: igl.loop(v, f.astype(np.int32)))
    import pymeshlab

    def meshlab():
        ms = pymeshlab.MeshSet()
        ms.add_mesh(pymeshlab.Mesh(v, f))
        ms.meshing_surface_subdivision_loop(
            iterations=1, threshold=pymeshlab.PureValue(0), loopweight="Loop"
        )
        m = ms.current_mesh()
        return m.vertex_matrix(), m.face_matrix()

    t_ml, (vm, fm) = best_of(meshlab)
    ours, our_faces = read_obj(f"{folder}/icosphere6-loop.obj")
    d, _ = cKDTree(vm).query(ours)
    print(f"input: {len(f)} triangles")
    print(f"igl.loop (Warren's beta): {len(fi)} triangles, best of 7: {t_igl * 1e3:.1f} ms")
    print(f"pymeshlab Loop (Loop's beta): {len(fm)} triangles, best of 7: {t_ml * 1e3:.1f} ms")
    print(
        f"grammar vs pymeshlab: {len(ours)} vs {len(vm)} vertices, "
        f"largest distance to the nearest pymeshlab vertex {d.max():.3e}"
    )


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "/tmp/subgram-bench")
