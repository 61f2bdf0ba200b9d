"""The modified butterfly vv program (lsystems/vv/modified-butterfly.lsys)
against VTK's vtkButterflySubdivisionFilter. Not part of `cargo test`.

    python3 benches/butterfly_xcheck.py [--bin target/debug/subgram] [--out DIR]
    python3 benches/butterfly_xcheck.py --self-test

Needs numpy, scipy and vtk (benches/requirements.txt).

What it does
------------
For each mesh (closed and open, with valences other than 6: the
tetrahedron (3), the octahedron (4), an icosphere (5 and 6),
lsystems/meshes/pentagon-patch.obj, lsystems/meshes/grid.obj cut into
triangles and lifted off its plane, a bumpy triangle grid, the scanned
Stanford bunny lsystems/meshes/bunny.obj (closed) and the same bunny cut
open (the faces within a ball taken out: a boundary through vertices of
every valence), it
runs one step of the program (`subgram subdivide MESH --grammar ...
--steps 1`) and one subdivision of VTK's filter on the same OBJ file,
then one more step of each on its own first result: two steps. (That a
second step on the written result is `--steps 2` is checked too, by
position, to 1e-12.)

Both keep the old vertices first, in order (checked from the faces: an
old vertex's neighbours are all new, a new vertex has exactly two old
neighbours and they are an edge), so a new vertex is matched by its
parent edge, and at the second step through the first step's match. Every
vertex is judged: the largest difference per vertex (max abs over x, y, z)
must stay under 1e-5 (VTK writes float32: about 1e-7 relative to the
mesh's size is agreement). The table also shows the largest difference
among the new vertices of each kind of edge at the first step:
  regular   both ends with 6 triangles, interior, all 8 stencil vertices
  extraord. interior edge with an end of another valence, no end on the
            boundary (Zorin's stencil, or the average of two)
  boundary  a boundary edge (the four-point rule)
  near bnd  an interior edge with an end on the boundary (VTK's rules:
            triangles counted, the 8-point mask with missing wings
            replaced)

`--self-test` runs the same on copies of the program with a wrong weight
(Zorin's 1/2 cos(4 pi j/K) term as 0.4) and with a missing wing t1
replaced by r instead of VTK's s, and exits 1 unless both
are caught (on the extraordinary edges and near the boundary
respectively).
"""
import argparse
import os
import subprocess
import sys
import tempfile

import numpy as np

from xcheck import icosphere, read_obj, write_obj  # the same folder
from vv_xcheck import Topology, bumpy_grid, parent_edges, vtk_butterfly

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MESHES = os.path.join(ROOT, "lsystems", "meshes")
PROGRAM = os.path.join(ROOT, "lsystems", "vv", "modified-butterfly.lsys")
TOL = 1e-5

failures = []


def lifted_grid():
    """lsystems/meshes/grid.obj (4 x 4 quads), each quad cut along a
    diagonal, lifted by z = 0.3 sin(3x) cos(2y) + 0.1 x so that no mask is
    trivially exact on it."""
    v, f = read_obj(os.path.join(MESHES, "grid.obj"))
    v = v.copy()
    v[:, 2] = 0.3 * np.sin(3 * v[:, 0]) * np.cos(2 * v[:, 1]) + 0.1 * v[:, 0]
    tris = []
    for q in f:
        tris += [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]
    return v, tris


def cut_bunny():
    """The bunny without its faces whose centroid lies within 2.5 of
    (0, 5, 0), its unused vertices dropped: a boundary loop through
    scanned vertices of any valence. Raises if that leaves a vertex
    where two boundary loops touch (neither side defines that)."""
    v, f = read_obj(os.path.join(MESHES, "bunny.obj"))
    keep = [t for t in f if np.linalg.norm(v[t].mean(axis=0) - [0.0, 5.0, 0.0]) > 2.5]
    used = sorted({i for t in keep for i in t})
    new = {o: k for k, o in enumerate(used)}
    f = [[new[i] for i in t] for t in keep]
    top = Topology(len(used), f)
    for x in top.boundary:
        out = sum(1 for (a, b) in top.opp if a == x and (b, a) not in top.opp)
        if out != 1:
            raise ValueError(f"cut bunny: vertex {x} is on {out} boundary loops")
    return v[used], f


def subgram(binary, mesh, program, steps, out):
    cmd = [binary, "subdivide", mesh, "--grammar", program, "--steps", str(steps), "-o", out]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)}: exit {r.returncode}\n{r.stderr}")
    return read_obj(out)


def triangles_at(top, v):
    return top.valence(v) - (1 if v in top.boundary else 0)


def kind(top, p, q):
    if (p, q) not in top.opp or (q, p) not in top.opp:
        return "boundary"
    if p in top.boundary or q in top.boundary:
        return "near bnd"
    r, s, t = top.stencil(p, q)
    if triangles_at(top, p) == 6 and triangles_at(top, q) == 6 and None not in t:
        return "regular"
    return "extraord."


def step_match(top, n_base, fa, fb):
    """A map from the vertices of output a to those of output b (both one
    step from the same base with topology top)."""
    ea = parent_edges(n_base, top, fa)
    eb = parent_edges(n_base, top, fb)
    m = np.arange(n_base + len(ea))
    for e, x in ea.items():
        m[x] = eb[e]
    return m, ea


def same_by_position(a, b, fa, fb):
    from scipy.spatial import cKDTree

    d, idx = cKDTree(b).query(a)
    if len(a) != len(b) or len(set(idx.tolist())) != len(a):
        return None
    if {frozenset(int(idx[i]) for i in f) for f in fa} != {frozenset(f) for f in fb}:
        return None
    return float(d.max())


def fmt(d):
    return "-" if d is None else f"{d:.1e}"


def judge(what, d):
    if d is not None and d > TOL:
        failures.append(f"{what}: {d:.3e} > {TOL:.0e}")
        return "FAIL"
    return "ok"


def run(binary, out, program=PROGRAM, quiet=False):
    import vtk

    if not quiet:
        print(f"modified butterfly ({os.path.relpath(program, ROOT)}) against VTK {vtk.vtkVersion.GetVTKVersion()}'s"
              " vtkButterflySubdivisionFilter")
    cases = [
        ("tetrahedron", read_obj(os.path.join(MESHES, "tetrahedron.obj"))),
        ("octahedron", read_obj(os.path.join(MESHES, "octahedron.obj"))),
        ("icosphere 2", icosphere(2)),
        ("pentagon-patch", read_obj(os.path.join(MESHES, "pentagon-patch.obj"))),
        ("grid (lifted)", lifted_grid()),
        ("bumpy grid", bumpy_grid(10, 8)),
        ("bunny", read_obj(os.path.join(MESHES, "bunny.obj"))),
        ("bunny cut open", cut_bunny()),
    ]
    kinds = ["regular", "extraord.", "boundary", "near bnd"]
    print(f"   {'mesh':<15} {'verts':>6} {'vals':>9} {'step 1':>8} {'':>4} {'step 2':>8} {'':>4}"
          + "".join(f" {k:>14}" for k in kinds) + f" {'--steps 2':>9}")
    results = {}
    for name, (v, f) in cases:
        stem = os.path.join(out, name.replace(" ", "-").replace("(", "").replace(")", ""))
        path = stem + ".obj"
        write_obj(path, v, f, name)
        v, f = read_obj(path)  # what both sides read
        top = Topology(len(v), f)
        vals = sorted({triangles_at(top, x) for x in range(len(v))})
        # Step 1.
        s1, sf1 = subgram(binary, path, program, 1, stem + "-vv1.obj")
        k1, kf1 = vtk_butterfly(v, f)
        m1, e1 = step_match(top, len(v), sf1, kf1)
        d1 = np.abs(s1 - k1[m1]).max(axis=1)
        by_kind = {k: [] for k in kinds}
        for e, x in e1.items():
            by_kind[kind(top, *e)].append(d1[x])
        # Step 2: each side again on its own first result.
        top1 = Topology(len(s1), sf1)
        s2, sf2 = subgram(binary, stem + "-vv1.obj", program, 1, stem + "-vv2.obj")
        k2, kf2 = vtk_butterfly(k1, kf1)
        # Map VTK's step-1 faces into subgram's numbering, then match step 2.
        inv = np.empty(len(m1), dtype=np.int64)
        inv[m1] = np.arange(len(m1))
        kf2_in_s = [[int(inv[i]) if i < len(inv) else i for i in face] for face in kf2]
        ea = parent_edges(len(s1), top1, sf2)
        eb = parent_edges(len(s1), top1, kf2_in_s)
        m2 = np.arange(len(s2))
        for e, x in ea.items():
            m2[x] = eb[e]
        k2_in_s = k2.copy()
        k2_in_s[: len(s1)] = k1[m1]  # old vertices: VTK's step-1 points in subgram's order
        d2 = np.abs(s2 - k2_in_s[m2]).max(axis=1)
        direct, df = subgram(binary, path, program, 2, stem + "-vv2direct.obj")
        same = same_by_position(direct, s2, df, sf2)
        if same is None or same > 1e-12:
            failures.append(f"{name}: --steps 2 is not two steps of --steps 1 ({same})")
        a = judge(f"{name}, step 1", float(d1.max()))
        b = judge(f"{name}, step 2", float(d2.max()))
        for k in kinds:
            if by_kind[k]:
                results.setdefault(k, []).append(max(by_kind[k]))
        cols = "".join(
            f" {fmt(max(by_kind[k]) if by_kind[k] else None):>8} ({len(by_kind[k]):>4})" for k in kinds
        )
        vs = ",".join(str(x) for x in vals)
        vs = vs if len(vs) <= 9 else vs[:8] + "+"
        print(f"   {name:<15} {len(v):>6} {vs:>9} {fmt(float(d1.max())):>8} {a:>4}"
              f" {fmt(float(d2.max())):>8} {b:>4}{cols} {fmt(same):>9}")
    if not quiet:
        print("   vals: triangles at a vertex; step 1, step 2: the largest difference of a vertex")
        print("   (max abs over x, y, z), every vertex judged (1e-5); the kinds: the largest")
        print("   difference among step 1's new vertices of that kind (and how many);")
        print("   --steps 2: two steps at once against two runs of one step, by position.")
    return results


def mutated(src, old, new, out):
    text = open(src).read()
    if old not in text:
        sys.exit(f"{src} no longer contains {old!r}: update --self-test")
    path = os.path.join(out, "mutated-" + os.path.basename(src))
    with open(path, "w") as f:
        f.write(text.replace(old, new))
    return path


def self_test(binary, out):
    global failures
    bad = mutated(PROGRAM, "+ 0.5 * cos(4 * PI * j / K)", "+ 0.4 * cos(4 * PI * j / K)", out)
    print("a wrong weight (0.4 cos(4 pi j/K)):")
    r = run(binary, out, bad, quiet=True)
    ok1 = max(r.get("extraord.", [0])) > TOL
    failures = []
    bad = mutated(
        PROGRAM,
        "  V3d t1 = wing(nextto r in 'p, s);",
        "  V3d t1 = wing(nextto r in 'p, r);",
        out,
    )
    print("a missing wing t1 replaced by r instead of s:")
    r = run(binary, out, bad, quiet=True)
    ok2 = max(r.get("near bnd", [0])) > TOL
    if ok1 and ok2:
        print("self-test: both wrong programs were caught, as they must be")
        return
    print(f"self-test: not caught (weight: {ok1}, wings: {ok2})")
    sys.exit(1)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bin", default=os.path.join(ROOT, "target", "debug", "subgram"))
    ap.add_argument("--out", help="folder for the meshes (default: a temporary one)")
    ap.add_argument("--self-test", action="store_true",
                    help="run on programs with a wrong rule; succeed only if both are caught")
    args = ap.parse_args()
    binary = os.path.abspath(args.bin)
    if not os.access(binary, os.X_OK):
        sys.exit(f"{binary}: not an executable (cargo build first, or --bin PATH)")
    with tempfile.TemporaryDirectory(prefix="butterfly-xcheck-") as tmp:
        out = args.out or tmp
        os.makedirs(out, exist_ok=True)
        if args.self_test:
            self_test(binary, out)
            return
        run(binary, out)
    print()
    if failures:
        print(f"{len(failures)} judged comparison(s) failed:")
        for x in failures:
            print("  ", x)
        sys.exit(1)
    print("every vertex agrees")


if __name__ == "__main__":
    main()
