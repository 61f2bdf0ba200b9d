"""Subdivide of a welded smoothing group (src/shape/smooth.rs) against CGAL's
Sqrt3_subdivision. Not part of `cargo test`.

    /work/venv-xcheck/bin/python benches/shapes_xcheck.py [--example PATH] [--out DIR]

The group is what splitting a 3 x 1 x 1 box into three unit cubes welds back
to: 16 vertices, the four long sides each cut into three unit quads, the two
end caps; every quad cut along its first diagonal, so 28 triangles (CGAL's
sqrt3 takes triangles). The OBJ is written here by hand. Both sides read it;
subgram's side is `examples/smooth_xcheck.rs` (nothing protected, tags = input
face index), CGAL's is compas_cgal.subdivision.mesh_subdivide_sqrt3, for 1, 2
and 3 steps. Vertices are matched by nearest position (cKDTree); the match
must be one-to-one, the faces written in matched indices must be the same
sets, and the largest distance between matched vertices must be below 1e-12.
Each input triangle must own exactly 3^k output faces (the tags).

Needs numpy, scipy and compas_cgal (/work/venv-xcheck has them).
"""
import argparse
import itertools
import os
import subprocess
import sys
import tempfile

import numpy as np
from scipy.spatial import cKDTree

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from xcheck import read_obj  # noqa: E402  (the benches' one OBJ reader)


def box_of_three():
    v = [(x, y, z) for z in (0, 1) for y in (0, 1) for x in range(4)]
    ix = {p: i for i, p in enumerate(v)}
    quads = []
    for x in range(3):
        for (a, b) in (((0, 0), (1, 0)), ((1, 0), (1, 1)), ((1, 1), (0, 1)), ((0, 1), (0, 0))):
            # the side between (y, z) = a and b, from x to x + 1
            quads.append([ix[(x, *a)], ix[(x + 1, *a)], ix[(x + 1, *b)], ix[(x, *b)]])
    for x in (0, 3):
        quads.append([ix[(x, 0, 0)], ix[(x, 1, 0)], ix[(x, 1, 1)], ix[(x, 0, 1)]])
    v = np.array(v, float)
    centre = v.mean(0)
    out = []
    for q in quads:
        p = v[q]
        if np.dot(np.cross(p[1] - p[0], p[2] - p[0]), p[0] - centre) < 0:
            q = q[::-1]   # counter-clockwise seen from outside
        out += [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]
    return v, out


def write_obj(path, v, f):
    with open(path, "w") as o:
        o.write("# a 3 x 1 x 1 box welded from three unit cubes, quads cut in two\n")
        for p in v:
            o.write("v %r %r %r\n" % tuple(float(x) for x in p))
        for t in f:
            o.write("f " + " ".join(str(i + 1) for i in t) + "\n")


def against_cgal(sub, v, f, vm, fm, k):
    """Ours (vm, fm) against CGAL's sqrt3 of (v, f) after k steps: vertices
    matched by nearest position; (one-to-one, same faces, max distance,
    CGAL's vertex and face counts)."""
    vr, fr = sub.mesh_subdivide_sqrt3((v, np.asarray(f, np.int64)), k)
    vr, fr = np.asarray(vr, float), np.asarray(fr).tolist()
    d, idx = cKDTree(vr).query(vm)
    one_to_one = len(vr) == len(vm) and len(np.unique(idx)) == len(vm)
    same = one_to_one and ({tuple(sorted(t)) for t in fr}
                           == {tuple(sorted(idx[t])) for t in fm})
    return one_to_one, same, d.max(), len(vr), len(fr)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--example", default=None,
                    help="a built smooth_xcheck (default: cargo run --release --example)")
    ap.add_argument("--out", default=tempfile.mkdtemp(prefix="shapes-xcheck-"))
    ap.add_argument("--shapes", nargs="*", default=[],
                    help="shape grammars whose unprotected sqrt3 groups to compare too")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    import compas_cgal
    import compas_cgal.subdivision as sub
    print(f"compas_cgal {compas_cgal.__version__}")
    v, f = box_of_three()
    src = os.path.join(a.out, "box3.obj")
    write_obj(src, v, f)
    print(f"input {src}: {len(v)} vertices, {len(f)} triangles")
    worst = 0.0
    ok = True
    for k in (1, 2, 3):
        dst = os.path.join(a.out, f"box3-sqrt3-{k}.obj")
        cmd = ([a.example] if a.example else
               ["cargo", "run", "-q", "--release", "--example", "smooth_xcheck", "--"])
        subprocess.run(cmd + [src, dst, str(k), "sqrt3"], check=True, cwd=ROOT)
        vm, fm = read_obj(dst)
        tags = [int(x) for x in open(dst + ".tags").read().split()]
        one_to_one, same, dmax, nv, nf = against_cgal(sub, v, f, vm, fm, k)
        counts = np.bincount(tags, minlength=len(f))
        per_face = bool((counts == 3 ** k).all())
        worst = max(worst, dmax)
        good = one_to_one and same and dmax < 1e-12 and per_face
        ok &= good
        print(f"  {k} step(s): ours {len(vm)} vertices {len(fm)} faces, CGAL {nv} vertices"
              f" {nf} faces; one-to-one {one_to_one}; same faces {same};"
              f" max distance {dmax:.3e}; 3^{k} faces per input triangle {per_face}"
              f" -> {'ok' if good else 'DIFFERENT'}")
    print(f"max difference over all steps: {worst:.3e}")
    for g in a.shapes:
        name = os.path.splitext(os.path.basename(g))[0]
        d = os.path.join(a.out, name)
        cmd = ([a.example] if a.example else
               ["cargo", "run", "-q", "--release", "--example", "smooth_xcheck", "--"])
        subprocess.run(cmd + ["--shapes", g, d], check=True, cwd=ROOT)
        k = 1
        while os.path.exists(os.path.join(d, f"group-{k}-welded.obj")):
            steps, protected, scheme = open(os.path.join(d, f"group-{k}-info.txt")).read().split()
            steps, protected = int(steps), int(protected)
            if protected or scheme != "sqrt3":
                print(f"  {name} group {k}: {protected} protected faces, {scheme}: not compared")
                k += 1
                continue
            v, f = read_obj(os.path.join(d, f"group-{k}-welded.obj"))
            vm, fm = read_obj(os.path.join(d, f"group-{k}-ours.obj"))
            one_to_one, same, dmax, nv, nf = against_cgal(sub, v, f, vm, fm, steps)
            good = one_to_one and same and dmax < 1e-12
            ok &= good
            worst = max(worst, dmax)
            print(f"  {name} group {k}: {len(f)} triangles welded, sqrt3 x {steps}: ours {len(vm)}"
                  f" vertices {len(fm)} faces, CGAL {nv} vertices {nf} faces;"
                  f" same faces {same}; max distance {dmax:.3e}"
                  f" -> {'ok' if good else 'DIFFERENT'}")
            k += 1
    print(f"max difference overall: {worst:.3e}")
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
