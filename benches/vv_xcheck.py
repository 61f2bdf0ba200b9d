"""Cross-checks of the vertex-vertex programs (paper 001) against peers.
Not part of `cargo test`.

    python3 benches/vv_xcheck.py [--bin target/release/subgram] [--out DIR]

Needs numpy, scipy, vtk and pymeshlab (`pip install numpy scipy vtk
pymeshlab`). Either peer may be missing: its checks are then skipped with a
note.

What it does
------------
a. Butterfly. `subgram subdivide MESH --grammar lsystems/vv/butterfly.lsys
   --steps 1` against VTK's vtkButterflySubdivisionFilter (one subdivision)
   on the same OBJ file, for a bumpy regular triangle grid written here, an
   icosphere (valences 5 and 6) and lsystems/meshes/octahedron.obj.
   Both outputs keep the base vertices first, in order (checked: a base
   vertex's neighbours are all new, a new vertex has exactly two base
   neighbours and they are an edge of the base mesh); a new vertex is
   matched by that parent edge.
   The program is the original butterfly of Dyn, Levin and Gregory; VTK's
   is Zorin's modified butterfly. They are the same 8-point mask
   1/2 (p + q) + 1/8 (r + s) - 1/16 (t1 + t2 + t3 + t4) where the edge's
   stencil is regular: p, q and the six other stencil vertices all interior
   and of valence 6. Only those edges are held to agreement (VTK stores
   float32, so ~1e-7 is agreement; a difference above 1e-5 fails); the
   other new vertices are reported, not judged: there the two schemes
   differ by design. A third column computes the original mask here, in
   float64 from the base mesh, for every interior edge whose eight stencil
   vertices exist, and holds the program to it (1e-9).
b. Loop. `lsystems/vv/loop.lsys` against pymeshlab's Loop (Loop's beta:
   loopweight='Loop', threshold PureValue(0), so that every edge splits)
   on closed meshes: icosphere levels 3 and 4, the octahedron and the
   tetrahedron, one step matched by parent edge and two steps matched by
   nearest position (one-to-one, and the faces must be the same vertex
   sets). Every vertex is held to agreement (1e-5): both are the same
   scheme. The stellar grammar lsystems/surfaces/loop.lsys, a different
   topology for the same scheme (paper 000), is compared the same way.

It prints a table per part and exits 1 if a judged comparison fails (a
regular butterfly edge, the original mask, a Loop vertex), 0 otherwise.

`--self-test` shows that the checks can fail: it runs both parts on copies
of the programs with a wrong weight (the butterfly's w = 1/17 instead of
1/16; Loop with Warren's beta 3/(8n) instead of Loop's) and exits 1 unless
the regular butterfly edges, the original mask and the Loop vertices of
valence other than 6 are all reported as failures.
"""
import argparse
import math
import os
import subprocess
import sys
import tempfile

import numpy as np
from scipy.spatial import cKDTree

from xcheck import icosphere, read_obj, write_obj  # the same folder

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MESHES = os.path.join(ROOT, "lsystems", "meshes")
BUTTERFLY = os.path.join(ROOT, "lsystems", "vv", "butterfly.lsys")
VV_LOOP = os.path.join(ROOT, "lsystems", "vv", "loop.lsys")
GRAMMAR_LOOP = os.path.join(ROOT, "lsystems", "surfaces", "loop.lsys")

REGULAR_TOL = 1e-5  # vv against VTK where both are the 8-point mask
MASK_TOL = 1e-9  # vv against the original mask computed here in float64
LOOP_TOL = 1e-5  # vv Loop against pymeshlab's Loop, every vertex

failures = []


# ---------------------------------------------------------------- meshes
def bumpy_grid(n=14, m=12):
    """A regular triangle grid of n x m squares, each cut by the same
    diagonal, so that every interior vertex has valence 6; heights
    z = 0.15 sin(2x) cos(3y) + 0.05 x y make every stencil different."""
    v, f = [], []
    for i in range(n + 1):
        for j in range(m + 1):
            x, y = i / n * 2.0, j / m * 1.7
            v.append([x, y, 0.15 * math.sin(2 * x) * math.cos(3 * y) + 0.05 * x * y])
    idx = lambda i, j: i * (m + 1) + j
    for i in range(n):
        for j in range(m):
            a, b, c, d = idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1)
            f += [[a, b, c], [a, c, d]]
    return np.array(v), f


# ---------------------------------------------------------------- topology
class Topology:
    """A triangle mesh's directed edges: opp[(a, b)] is the third vertex of
    the face in which a -> b runs counter-clockwise."""

    def __init__(self, n, faces):
        self.n = n
        self.opp = {}
        for f in faces:
            if len(f) != 3:
                raise ValueError(f"face {f} is not a triangle")
            for k in range(3):
                a, b, c = f[k], f[(k + 1) % 3], f[(k + 2) % 3]
                if (a, b) in self.opp:
                    raise ValueError(f"edge {a}->{b} is used twice")
                self.opp[(a, b)] = c
        self.nbrs = [set() for _ in range(n)]
        for a, b in self.opp:
            self.nbrs[a].add(b)
            self.nbrs[b].add(a)
        self.boundary = set()
        for a, b in self.opp:
            if (b, a) not in self.opp:
                self.boundary.update((a, b))
        self.edges = sorted({(min(a, b), max(a, b)) for a, b in self.opp})

    def valence(self, v):
        return len(self.nbrs[v])

    def regular(self, v):
        return v is not None and v not in self.boundary and self.valence(v) == 6

    def stencil(self, p, q):
        """The butterfly stencil of edge (p, q): r, s across it, t1..t4 across
        the other edges of those two triangles; None where missing."""
        r = self.opp.get((p, q))
        s = self.opp.get((q, p))
        if r is None or s is None:
            return r, s, [None] * 4
        t = [self.opp.get((r, q)), self.opp.get((p, r)),
             self.opp.get((s, p)), self.opp.get((q, s))]
        return r, s, t


def parent_edges(n_base, base, out_faces):
    """Checks that an output of one 1-to-4 step keeps the n_base base
    vertices first, and returns {base edge: output index of its new
    vertex}. Raises ValueError with what is wrong."""
    n_out = 1 + max(max(f) for f in out_faces)
    nb = [set() for _ in range(n_out)]
    for f in out_faces:
        for k in range(len(f)):
            a, b = f[k], f[(k + 1) % len(f)]
            nb[a].add(b)
            nb[b].add(a)
    for v in range(n_base):
        if any(w < n_base for w in nb[v]):
            raise ValueError(f"output vertex {v} has a base neighbour: base vertices are not first")
        if len(nb[v]) != base.valence(v):
            raise ValueError(f"output vertex {v} has valence {len(nb[v])}, base {base.valence(v)}")
    edges = {}
    for x in range(n_base, n_out):
        old = sorted(w for w in nb[x] if w < n_base)
        if len(old) != 2 or old[1] not in base.nbrs[old[0]]:
            raise ValueError(f"output vertex {x} has base neighbours {old}, not an edge")
        key = (old[0], old[1])
        if key in edges:
            raise ValueError(f"edge {key} has two new vertices")
        edges[key] = x
    if len(edges) != len(base.edges):
        raise ValueError(f"{len(edges)} new vertices for {len(base.edges)} edges")
    return edges


# ---------------------------------------------------------------- runs
def subgram(binary, mesh, grammar, steps, out):
    cmd = [binary, "subdivide", mesh, "--grammar", grammar, "--steps", str(steps), "-o", out]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)}: exit {r.returncode}\n{r.stderr}")
    return read_obj(out)


def vtk_butterfly(v, f):
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy

    pts = vtk.vtkPoints()
    pts.SetDataTypeToDouble()
    for p in v:
        pts.InsertNextPoint(*p)
    cells = vtk.vtkCellArray()
    for face in f:
        cells.InsertNextCell(len(face))
        for i in face:
            cells.InsertCellPoint(int(i))
    pd = vtk.vtkPolyData()
    pd.SetPoints(pts)
    pd.SetPolys(cells)
    flt = vtk.vtkButterflySubdivisionFilter()
    flt.SetInputData(pd)
    flt.SetNumberOfSubdivisions(1)
    flt.Update()
    o = flt.GetOutput()
    P = vtk_to_numpy(o.GetPoints().GetData()).astype(np.float64)
    offs = vtk_to_numpy(o.GetPolys().GetOffsetsArray())
    conn = vtk_to_numpy(o.GetPolys().GetConnectivityArray())
    faces = [conn[offs[k]:offs[k + 1]].tolist() for k in range(len(offs) - 1)]
    return P, faces


def meshlab_loop(v, f, steps):
    import pymeshlab

    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(np.asarray(v, np.float64), np.asarray(f, np.int32)))
    ms.meshing_surface_subdivision_loop(
        iterations=steps, threshold=pymeshlab.PureValue(0), loopweight="Loop"
    )
    m = ms.current_mesh()
    return m.vertex_matrix().astype(np.float64), m.face_matrix().tolist()


def have(module):
    try:
        __import__(module)
        return True
    except ImportError:
        return False


# ---------------------------------------------------------------- reports
def fmt(d):
    return "-" if d is None else f"{d:.2e}"


def maxdiff(a, b):
    return float(np.abs(np.asarray(a) - np.asarray(b)).max()) if len(a) else None


def judge(what, d, tol):
    if d is not None and d > tol:
        failures.append(f"{what}: {d:.3e} > {tol:.0e}")
        return "FAIL"
    return "ok" if d is not None else "-"


# ---------------------------------------------------------------- a. butterfly
def original_mask(v, p, q, r, s, t):
    return (0.5 * (v[p] + v[q]) + 0.125 * (v[r] + v[s])
            - 0.0625 * (v[t[0]] + v[t[1]] + v[t[2]] + v[t[3]]))


def part_a(binary, out, program=BUTTERFLY):
    print("a. butterfly (lsystems/vv/butterfly.lsys) against VTK's modified butterfly, 1 step")
    if not have("vtk"):
        print("   vtk is missing (pip install vtk): skipped")
    cases = [
        ("bumpy grid 14x12", bumpy_grid()),
        ("icosphere 3", icosphere(3)),
        ("octahedron", read_obj(os.path.join(MESHES, "octahedron.obj"))),
    ]
    head = (f"   {'mesh':<17} {'edges':>5} {'regular':>7} {'vv-vtk':>9} {'':>4}"
            f" {'8-pt':>5} {'vv-mask':>9} {'':>4} {'other':>5} {'vv-vtk':>9}"
            f" {'old vv':>9} {'old vtk':>9}")
    print(head)
    for name, (v, f) in cases:
        path = os.path.join(out, name.replace(" ", "-") + ".obj")
        write_obj(path, v, f, name)
        v, f = read_obj(path)  # what both sides read
        base = Topology(len(v), f)
        vo, fo = subgram(binary, path, program, 1, os.path.join(out, "vv-butterfly-" + os.path.basename(path)))
        e_vv = parent_edges(len(v), base, fo)
        old_vv = maxdiff(vo[: len(v)], v)
        vtk_ok = have("vtk")
        if vtk_ok:
            vt, ft = vtk_butterfly(v, f)
            e_vtk = parent_edges(len(v), base, ft)
            old_vtk = maxdiff(vt[: len(v)], v)
        reg, full, other = [], [], []
        for e in base.edges:
            p, q = e
            r, s, t = base.stencil(p, q)
            x = vo[e_vv[e]]
            y = vt[e_vtk[e]] if vtk_ok else None
            if None not in (r, s, *t):
                mask = original_mask(v, p, q, r, s, t)
                full.append((x, mask))
                if all(base.regular(w) for w in (p, q, r, s, *t)):
                    reg.append((x, y))
                    continue
            other.append((x, y))
        d_mask = maxdiff(*zip(*full)) if full else None
        m_mask = judge(f"butterfly {name}: vv against the original mask", d_mask, MASK_TOL)
        if vtk_ok:
            d_reg = maxdiff(*zip(*reg)) if reg else None
            d_other = maxdiff(*zip(*other)) if other else None
            m_reg = judge(f"butterfly {name}: vv against VTK at regular edges", d_reg, REGULAR_TOL)
        else:
            d_reg = d_other = old_vtk = None
            m_reg = "-"
        old_vv_mark = judge(f"butterfly {name}: base vertices moved", old_vv, MASK_TOL)
        print(f"   {name:<17} {len(base.edges):>5} {len(reg):>7} {fmt(d_reg):>9} {m_reg:>4}"
              f" {len(full):>5} {fmt(d_mask):>9} {m_mask:>4} {len(other):>5} {fmt(d_other):>9}"
              f" {fmt(old_vv):>9} {fmt(old_vtk):>9}" + ("" if old_vv_mark != "FAIL" else " FAIL"))
    print("   regular: edges whose 8 stencil vertices are interior of valence 6 (judged, 1e-5);")
    print("   8-pt: interior edges with all 8 stencil vertices, vv against the original mask")
    print("   computed here in float64 (judged, 1e-9); other: the remaining new vertices,")
    print("   where the original and the modified butterfly differ by design (reported only);")
    print("   old: the largest move of a base vertex (both schemes interpolate).")


# ---------------------------------------------------------------- b. Loop
def match_by_position(ref, mine, ref_f, mine_f):
    """Nearest-position matching, one-to-one, with the same faces."""
    d, idx = cKDTree(ref).query(mine)
    if len(ref) != len(mine) or len(set(idx.tolist())) != len(mine):
        raise ValueError(f"no one-to-one match ({len(mine)} against {len(ref)} vertices)")
    mapped = {frozenset(int(idx[i]) for i in face) for face in mine_f}
    if mapped != {frozenset(face) for face in ref_f}:
        raise ValueError("matched vertices do not give the same faces")
    return float(d.max())


def part_b(binary, out, program=VV_LOOP):
    print()
    print("b. Loop (lsystems/vv/loop.lsys) against pymeshlab's Loop (Loop's beta, threshold 0)")
    ml = have("pymeshlab")
    if not ml:
        print("   pymeshlab is missing (pip install pymeshlab): skipped; the grammar is still compared")
    cases = [
        ("icosphere 3", icosphere(3)),
        ("icosphere 4", icosphere(4)),
        ("octahedron", read_obj(os.path.join(MESHES, "octahedron.obj"))),
        ("tetrahedron", read_obj(os.path.join(MESHES, "tetrahedron.obj"))),
    ]
    print(f"   {'mesh':<12} {'steps':>5} {'vertices':>8} {'match':>9} {'vv-meshlab':>10} {'':>4}"
          f" {'vv-grammar':>10} {'':>4}")
    for name, (v, f) in cases:
        path = os.path.join(out, "loop-" + name.replace(" ", "-") + ".obj")
        write_obj(path, v, f, name)
        v, f = read_obj(path)
        base = Topology(len(v), f)
        for steps in (1, 2):
            stem = os.path.join(out, f"{os.path.basename(path)[:-4]}-{steps}")
            vo, fo = subgram(binary, path, program, steps, stem + "-vv.obj")
            vg, fg = subgram(binary, path, GRAMMAR_LOOP, steps, stem + "-grammar.obj")
            results = []
            peers = [("pymeshlab", lambda: meshlab_loop(v, f, steps))] if ml else []
            peers.append(("grammar", lambda: (vg, fg)))
            for peer, get in peers:
                pv, pf = get()
                if steps == 1:
                    e_vv = parent_edges(len(v), base, fo)
                    e_p = parent_edges(len(v), base, pf)
                    old = maxdiff(vo[: len(v)], pv[: len(v)])
                    new = maxdiff(vo[[e_vv[e] for e in base.edges]], pv[[e_p[e] for e in base.edges]])
                    d = max(old, new)
                    how = "edge"
                else:
                    d = match_by_position(pv, vo, pf, fo)
                    how = "position"
                results.append((d, judge(f"Loop {name}, {steps} steps: vv against {peer}", d, LOOP_TOL)))
            if not ml:
                results.insert(0, (None, "-"))
            (d1, m1), (d2, m2) = results
            print(f"   {name:<12} {steps:>5} {len(vo):>8} {how:>9} {fmt(d1):>10} {m1:>4}"
                  f" {fmt(d2):>10} {m2:>4}")
    print("   match: one step by parent edge (base vertices first, checked), two steps by")
    print("   nearest position (one-to-one, same faces); every vertex judged (1e-5).")


def mutated(src, old, new, out):
    """A copy of program src in folder out with old replaced by new."""
    text = open(src).read()
    if old not in text:
        sys.exit(f"{src} no longer contains {old!r}: update --self-test")
    path = os.path.join(out, "mutated-" + os.path.basename(src))
    with open(path, "w") as f:
        f.write(text.replace(old, new))
    return path


def self_test(binary, out):
    bad_butterfly = mutated(BUTTERFLY, "const double w = 1.0 / 16;", "const double w = 1.0 / 17;", out)
    bad_loop = mutated(
        VV_LOOP,
        "double beta(int n) { return (5.0/8 - pow(3.0/8 + 0.25*cos(2*PI/n), 2)) / n; }",
        "double beta(int n) { return 3.0 / (8 * n); }",
        out,
    )
    part_a(binary, out, bad_butterfly)
    part_b(binary, out, bad_loop)
    print()
    expected = [
        "butterfly bumpy grid 14x12: vv against the original mask",
        "butterfly icosphere 3: vv against the original mask",
        "butterfly octahedron: vv against the original mask",
        "Loop icosphere 3, 1 steps: vv against grammar",
        "Loop octahedron, 1 steps: vv against grammar",
        "Loop tetrahedron, 1 steps: vv against grammar",
    ]
    if have("vtk"):
        expected += [
            "butterfly bumpy grid 14x12: vv against VTK at regular edges",
            "butterfly icosphere 3: vv against VTK at regular edges",
        ]
    if have("pymeshlab"):
        expected += [f"Loop {m}, 1 steps: vv against pymeshlab"
                     for m in ("icosphere 3", "octahedron", "tetrahedron")]
    missed = [e for e in expected if not any(x.startswith(e + ":") for x in failures)]
    if missed:
        print("self-test: these wrong programs were not caught:")
        for e in missed:
            print("  ", e)
        sys.exit(1)
    print(f"self-test: the wrong weights were caught ({len(failures)} failed comparisons, as they must)")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bin", default=os.path.join(ROOT, "target", "release", "subgram"))
    ap.add_argument("--out", help="folder for the meshes (default: a temporary one)")
    ap.add_argument("--self-test", action="store_true",
                    help="run on programs with wrong weights; succeed only if every check fails")
    args = ap.parse_args()
    binary = os.path.abspath(args.bin)
    if not os.access(binary, os.X_OK):
        sys.exit(f"{binary}: not an executable (cargo build --release first, or --bin PATH)")
    with tempfile.TemporaryDirectory(prefix="vv-xcheck-") as tmp:
        out = args.out or tmp
        os.makedirs(out, exist_ok=True)
        if args.self_test:
            self_test(binary, out)
            return
        part_a(binary, out)
        part_b(binary, out)
    print()
    if failures:
        print(f"{len(failures)} judged comparison(s) failed:")
        for x in failures:
            print("  ", x)
        sys.exit(1)
    print("every judged comparison agrees")


if __name__ == "__main__":
    main()
