#!/usr/bin/env python3
"""Creases of `lsystems/surfaces/catmull-clark.lsys` against Blender's
Subdivision Surface modifier (OpenSubdiv, Catmull-Clark); not part of
`cargo test`.

Each case is a quad mesh with edge sharpness (OpenSubdiv's numbers). subgram
reads it from a `.creases` file beside an OBJ (or from the PLY edge element of
`lsystems/meshes/creased-cube.ply`) and runs the grammar for k = 1..3 steps
(`subgram subdivide -n k`); Blender gets the same polygons, the crease of each
edge in its `crease_edge` attribute, and a Subdivision Surface modifier with
`levels = k`, `use_limit_surface = False` (the k-th refinement itself, not
its limit), `use_creases = True`, `boundary_smooth = 'ALL'` and
`uv_smooth = 'NONE'` (no UVs). `boundary_smooth = 'ALL'` makes a boundary
a crease whose corners of two edges are smoothed too, as the grammar's
boundary rule does; the open grid's cases reach it.

Vertex sharpness goes to the `crease_vert` attribute the same way.

Blender maps a crease c in 0..1 to the sharpness 10 c^2 before OpenSubdiv
sees it (`crease_to_sharpness` in its subdiv code), and OpenSubdiv treats a
sharpness of 10 or more as infinite; so a sharpness s is given as
c = sqrt(min(s, 10) / 10), and `inf` as c = 1. c is stored as a 32-bit
float, so Blender's sharpness differs from s by about 1e-7 relative, which
moves semi-sharp results by as much; the tolerance below allows for it.

Vertices are matched by position: for every vertex of one output the nearest
vertex of the other; the largest such distance (both ways) is the error.
The counts of vertices and faces must agree too.

`--chaikin` runs the grammar with `-D CHAIKIN=1` (OpenSubdiv's Chaikin
creasing, `creasing: chaikin;`) and only reports: Blender's modifier
creases uniformly (it offers no creasing method), so the cases where a
semi-sharp edge meets another of a different sharpness must differ and
the others agree; that is how one sees which method Blender uses.

`--self-test` gives Blender half of every sharpness instead (1.5 for
`inf`): then every
case with creases must differ (at some k), which shows that the comparison
can tell a crease rule from a wrong one.

Usage: python3 benches/crease_xcheck.py [--subgram target/debug/subgram]
[--self-test]
(the Python must have `bpy`, Blender as a module from PyPI, which needs
Python 3.11; and numpy). Exit status 1 when a case differs by more than
the tolerance.
"""

import argparse
import math
import os
import subprocess
import sys
import tempfile

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TOLERANCE = 1e-5

# The cube of lsystems/meshes/cube.obj, vertices from 0.
CUBE_V = [
    (-1, -1, -1), (1, -1, -1), (-1, 1, -1), (1, 1, -1),
    (-1, -1, 1), (1, -1, 1), (-1, 1, 1), (1, 1, 1),
]
CUBE_F = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
RIM = [(4, 5), (5, 7), (7, 6), (6, 4)]
ALL_EDGES = sorted({tuple(sorted((f[i], f[(i + 1) % 4]))) for f in CUBE_F for i in range(4)})
INF = math.inf

# name -> (vertices, faces, {(a, b): sharpness, a: vertex sharpness}); a
# jittered cube keeps
# symmetric cases from hiding a wrong weight.
JITTER = [(0.03 * ((7 * i) % 5 - 2), 0.02 * ((3 * i) % 7 - 3), 0.025 * ((5 * i) % 3 - 1))
          for i in range(8)]
CUBE_J = [tuple(c + d for c, d in zip(p, j)) for p, j in zip(CUBE_V, JITTER)]
# A 4 x 3 grid of quads (an open mesh), ids j * 5 + i, bent in z; its row
# j = 1 (ids 5..9) runs from boundary to boundary.
GRID_V = [(i / 4, j / 3, 0.1 * ((i * 7 + j * 3) % 5) - 0.2) for j in range(4) for i in range(5)]
GRID_F = [(j * 5 + i, j * 5 + i + 1, (j + 1) * 5 + i + 1, (j + 1) * 5 + i)
          for j in range(3) for i in range(4)]
ROW = [(5 + i, 6 + i) for i in range(4)]
CASES = {
    "smooth cube (no creases)": (CUBE_J, CUBE_F, {}),
    "rim sharp for ever": (CUBE_J, CUBE_F, {e: INF for e in RIM}),
    "rim sharpness 2": (CUBE_J, CUBE_F, {e: 2.0 for e in RIM}),
    "rim 1.3, a vertical edge 0.4": (CUBE_J, CUBE_F, {**{e: 1.3 for e in RIM}, (1, 5): 0.4}),
    "every edge 0.5": (CUBE_J, CUBE_F, {e: 0.5 for e in ALL_EDGES}),
    "corner: three edges sharp for ever": (CUBE_J, CUBE_F, {(3, 7): INF, (5, 7): INF, (6, 7): INF}),
    "corner of 3 and 0.7 edges (to a crease)": (
        CUBE_J, CUBE_F, {(3, 7): 3.0, (5, 7): 3.0, (6, 7): 0.7}),
    "vertex 7 sharp for ever": (CUBE_J, CUBE_F, {7: INF}),
    "vertex 7 sharpness 1.5, vertex 0 0.5": (CUBE_J, CUBE_F, {7: 1.5, 0: 0.5}),
    "vertex 0.6 on a crease of 2.5": (CUBE_J, CUBE_F, {**{e: 2.5 for e in RIM}, 5: 0.6}),
    "open grid, smooth": (GRID_V, GRID_F, {}),
    "open grid, a crease across, for ever": (GRID_V, GRID_F, {e: INF for e in ROW}),
    "open grid, a crease across, 0.5": (GRID_V, GRID_F, {e: 0.5 for e in ROW}),
    "open grid, a crease across, 1.5": (GRID_V, GRID_F, {e: 1.5 for e in ROW}),
}


def read_obj(path):
    vs, fs = [], []
    with open(path) as f:
        for line in f:
            w = line.split()
            if not w:
                continue
            if w[0] == "v":
                vs.append([float(x) for x in w[1:4]])
            elif w[0] == "f":
                fs.append([int(x.split("/")[0]) - 1 for x in w[1:]])
    return np.array(vs), fs


def write_case(folder, name, vs, fs, sharp):
    obj = os.path.join(folder, name + ".obj")
    with open(obj, "w") as f:
        for p in vs:
            f.write("v %r %r %r\n" % p)
        for face in fs:
            f.write("f " + " ".join(str(i + 1) for i in face) + "\n")
    with open(os.path.join(folder, name + ".creases"), "w") as f:
        for key, s in sharp.items():
            text = "inf" if s == INF else repr(s)
            if isinstance(key, tuple):
                f.write("e %d %d %s\n" % (key[0] + 1, key[1] + 1, text))
            else:
                f.write("v %d %s\n" % (key + 1, text))
    return obj


def ours(subgram, mesh, k, folder, defines=()):
    out = os.path.join(folder, "out-%d.obj" % k)
    grammar = os.path.join(ROOT, "lsystems", "surfaces", "catmull-clark.lsys")
    subprocess.run([subgram, "subdivide", mesh, "--grammar", grammar, "-n", str(k), "-o", out,
                    "--force"] + [a for d in defines for a in ("-D", d)], check=True)
    return read_obj(out)


def crease_of(s):
    return 1.0 if s == INF else math.sqrt(min(s, 10.0) / 10.0)


def blender(vs, fs, sharp, k):
    import bpy

    bpy.ops.wm.read_factory_settings(use_empty=True)
    mesh = bpy.data.meshes.new("m")
    mesh.from_pydata([list(p) for p in vs], [], [list(f) for f in fs])
    mesh.update()
    attr = mesh.attributes.new("crease_edge", "FLOAT", "EDGE")
    vattr = mesh.attributes.new("crease_vert", "FLOAT", "POINT")
    index = {tuple(sorted(e.vertices)): e.index for e in mesh.edges}
    for key, s in sharp.items():
        if isinstance(key, tuple):
            attr.data[index[tuple(sorted(key))]].value = crease_of(s)
        else:
            vattr.data[key].value = crease_of(s)
    obj = bpy.data.objects.new("o", mesh)
    bpy.context.scene.collection.objects.link(obj)
    mod = obj.modifiers.new("subsurf", "SUBSURF")
    mod.subdivision_type = "CATMULL_CLARK"
    mod.levels = k
    mod.render_levels = k
    mod.use_limit_surface = False
    mod.use_creases = True
    mod.boundary_smooth = "ALL"
    mod.uv_smooth = "NONE"
    dg = bpy.context.evaluated_depsgraph_get()
    ev = obj.evaluated_get(dg).to_mesh()
    pts = np.array([tuple(v.co) for v in ev.vertices])
    nf = len(ev.polygons)
    obj.evaluated_get(dg).to_mesh_clear()
    return pts, nf


def distance(a, b):
    """The largest distance from a point of a to its nearest point of b."""
    worst = 0.0
    for p in a:
        worst = max(worst, float(np.min(np.linalg.norm(b - p, axis=1))))
    return worst


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--subgram", default=os.path.join(ROOT, "target", "debug", "subgram"))
    ap.add_argument("--self-test", action="store_true",
                    help="give Blender half of each sharpness (1.5 for inf): every creased "
                    "case must differ")
    ap.add_argument("--chaikin", action="store_true",
                    help="run the grammar with -D CHAIKIN=1 (OpenSubdiv's Chaikin creasing) and "
                    "report which cases Blender (uniform creasing) differs on; not judged")
    args = ap.parse_args()
    defines = ("CHAIKIN=1",) if args.chaikin else ()
    cases = dict(CASES)
    # The repository's example, read from its PLY edge element.
    ply = os.path.join(ROOT, "lsystems", "meshes", "creased-cube.ply")
    cases["lsystems/meshes/creased-cube.ply"] = (
        CUBE_V, CUBE_F,
        {(4, 5): INF, (5, 7): INF, (7, 6): INF, (6, 4): INF, (1, 5): 2.0, (0, 1): 0.5})
    bad = 0
    differed = 0
    with tempfile.TemporaryDirectory() as folder:
        for n, (name, (vs, fs, sharp)) in enumerate(cases.items()):
            mesh = ply if name.endswith(".ply") else write_case(folder, "case%d" % n, vs, fs, sharp)
            case_bad = 0
            for k in (1, 2, 3):
                p, faces = ours(args.subgram, mesh, k, folder, defines)
                given = ({e: (s / 2 if s != INF else 1.5) for e, s in sharp.items()}
                         if args.self_test else sharp)
                q, nf = blender(vs, fs, given, k)
                err = max(distance(p, q), distance(q, p))
                same = len(p) == len(q) and len(faces) == nf
                ok = same and err <= TOLERANCE
                bad += not ok
                case_bad += not ok
                print("%-42s k=%d  vertices %5d/%5d  faces %5d/%5d  max error %.3g  %s" % (
                    name, k, len(p), len(q), len(faces), nf, err, "ok" if ok else "DIFFERS"))
            differed += case_bad > 0 and bool(sharp)
    if args.self_test:
        # Every creased case must have differed at some k.
        creased = sum(1 for (_, _, sharp) in cases.values() if sharp)
        print("self-test: %d results differ; every one of the %d creased cases must" % (
            bad, creased))
        return 0 if differed == creased else 1
    if args.chaikin:
        print("Chaikin creasing: %d of %d results differ from Blender's (uniform creasing); "
              "only cases whose semi-sharp edges meet others of another sharpness can" % (
                  bad, 3 * len(cases)))
        return 0
    print("%d passed, %d failed" % (3 * len(cases) - bad, bad))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
