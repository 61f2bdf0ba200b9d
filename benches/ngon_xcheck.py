"""Catmull-Clark on polygons of any number of sides (issue 43, item 3):
lsystems/surfaces/catmull-clark.lsys against Blender's Subdivision Surface
modifier (OpenSubdiv inside). Not part of `cargo test`.

    python3 benches/ngon_xcheck.py [--bin target/debug/subgram] [--out DIR]
    python3 benches/ngon_xcheck.py --self-test

Needs numpy, scipy and bpy (Python 3.11; benches/requirements.txt).

Meshes with faces of 5 to 8 sides, closed and open: convex polyhedra made
here from their vertices (a pentagonal prism with its top tilted, the
dodecahedron, the truncated tetrahedron (triangles and hexagons), the
truncated octahedron (squares and hexagons)), an open heptagon ringed by
quads, an open cup under an octagon, and an open mesh of a pentagon and a
hexagon among quads and triangles. Each is jiggled (a fixed seed) so that no weight hides behind a
symmetry, written as OBJ, subdivided 1, 2 and 3 levels by
`subgram subdivide --grammar lsystems/surfaces/catmull-clark.lsys` and
by Blender (`boundary_smooth='ALL'`, `use_limit_surface=False`, no
creases), and matched by position: one-to-one, and the faces must be the
same vertex sets. The largest distance between matched vertices, relative
to the mesh's size, is judged at 1e-5 (Blender stores float32).

`--self-test` runs a copy of the grammar whose face point is the centroid
of the fan's first triangle (`avg(f)`, what the face split gave a polygon
before this item) and must report a difference.
"""
import argparse
import os
import subprocess
import sys
import tempfile

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
GRAMMAR = os.path.join(ROOT, "lsystems", "surfaces", "catmull-clark.lsys")
TOL = 1e-5

# bpy first: pymeshlab's Embree would keep it from loading (requirements.txt).
import bpy  # noqa: E402,F401
from scipy.spatial import ConvexHull, cKDTree  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from xcheck import blender_cc, read_obj, write_obj  # noqa: E402


def polyhedron(points):
    """The convex hull of `points` with its coplanar triangles merged into
    polygons, each counter-clockwise seen from outside."""
    p = np.asarray(points, float)
    hull = ConvexHull(p)
    groups = {}
    for simplex, eq in zip(hull.simplices, hull.equations):
        key = tuple(np.round(eq, 6))
        groups.setdefault(key, set()).update(simplex.tolist())
    faces = []
    for eq, ids in groups.items():
        n = np.array(eq[:3])
        ids = list(ids)
        c = p[ids].mean(axis=0)
        u = p[ids[0]] - c
        u /= np.linalg.norm(u)
        w = np.cross(n, u)
        ang = [np.arctan2((p[i] - c) @ w, (p[i] - c) @ u) for i in ids]
        faces.append([ids[k] for k in np.argsort(ang)])
    return p, faces


def prism(n=5):
    a = 2 * np.pi * np.arange(n) / n
    bottom = np.stack([np.cos(a), np.sin(a), np.zeros(n)], -1)
    top = np.stack([np.cos(a), np.sin(a), 1 + 0.3 * np.cos(a)], -1)
    return polyhedron(np.vstack([bottom, top]))


def dodecahedron():
    t = (1 + 5 ** 0.5) / 2
    pts = [[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]
    for a in (-1, 1):
        for b in (-1, 1):
            pts += [[0, a / t, b * t], [a / t, b * t, 0], [a * t, 0, b / t]]
    return polyhedron(pts)


def permutations_with_signs(base, even_minus=None):
    import itertools

    out = set()
    for perm in itertools.permutations(base):
        for signs in itertools.product((-1, 1), repeat=3):
            if even_minus is not None and (signs.count(-1) % 2 == 1) == even_minus:
                continue
            out.add(tuple(s * x for s, x in zip(signs, perm)))
    return sorted(out)


def truncated_tetrahedron():
    return polyhedron(permutations_with_signs((3, 1, 1), even_minus=True))


def truncated_octahedron():
    return polyhedron(permutations_with_signs((0, 1, 2)))


def ringed_heptagon():
    n = 7
    a = 2 * np.pi * np.arange(n) / n
    inner = np.stack([np.cos(a), np.sin(a), 0.2 * np.ones(n)], -1)
    outer = np.stack([2 * np.cos(a), 2 * np.sin(a), np.zeros(n)], -1)
    v = np.vstack([inner, outer])
    f = [list(range(n))] + [[i, n + i, n + (i + 1) % n, (i + 1) % n] for i in range(n)]
    return v, f


def mixed_patch():
    """A pentagon and a hexagon among quads and triangles, with
    one boundary loop."""
    v = np.array([
        [0, 0, 0], [1, 0, 0.1], [2, 0, 0], [3, 0, 0.2],          # 0-3
        [0, 1, 0.1], [1, 1, 0.3], [2, 1, 0.2], [3, 1, 0],        # 4-7
        [0.5, 1.8, 0], [1.5, 2.1, 0.2], [2.5, 1.8, 0.1],         # 8-10
        [3.6, 0.5, 0.1], [1.5, 2.9, 0], [0.3, 2.6, 0.1],         # 11-13
        [-0.6, 0.5, 0], [2.6, 2.7, 0.2],                         # 14-15
    ], float)
    f = [
        [0, 1, 5, 4],                # quad
        [1, 2, 6, 5],                # quad
        [2, 3, 11, 7, 6],            # pentagon
        [4, 5, 6, 10, 9, 8],         # hexagon
        [8, 9, 12, 13],              # quad
        [0, 4, 14],                  # triangle
        [4, 8, 13, 14],              # quad
        [6, 7, 10],                  # triangle
        [9, 10, 15, 12],             # quad
    ]
    return v, f


def octagon_cap():
    """An octagon on a cube-like cup: closed except one square."""
    n = 8
    a = 2 * np.pi * np.arange(n) / n
    top = np.stack([np.cos(a), np.sin(a), np.ones(n)], -1)
    low = np.stack([np.cos(a), np.sin(a), np.zeros(n)], -1)
    v = np.vstack([top, low])
    f = [list(range(n))] + [[n + i, n + (i + 1) % n, (i + 1) % n, i] for i in range(n - 1)]
    return v, f


def jiggle(v, seed):
    rng = np.random.default_rng(seed)
    size = np.ptp(v, axis=0).max()
    return v + 0.03 * size * rng.standard_normal(v.shape)


def subgram(binary, mesh, grammar, levels, out):
    cmd = [binary, "subdivide", mesh, "--grammar", grammar, "-n", str(levels), "-o", out]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)}: exit {r.returncode}\n{r.stderr}")
    return read_obj(out)


def match(ref, ref_f, mine, mine_f):
    """The largest distance between matched vertices, or None when the
    meshes do not match one-to-one with the same faces."""
    d, idx = cKDTree(ref).query(mine)
    if len(ref) != len(mine) or len(set(idx.tolist())) != len(mine):
        return None
    mapped = {frozenset(int(idx[i]) for i in face) for face in mine_f}
    if mapped != {frozenset(face) for face in ref_f}:
        return None
    return float(d.max())


def run(binary, out, grammar=GRAMMAR):
    cases = [
        ("pentagonal prism", prism(5)),
        ("dodecahedron", dodecahedron()),
        ("trunc. tetrahedron", truncated_tetrahedron()),
        ("trunc. octahedron", truncated_octahedron()),
        ("ringed heptagon", ringed_heptagon()),
        ("mixed patch", mixed_patch()),
        ("open octagon cup", octagon_cap()),
    ]
    print(f"Catmull-Clark on polygons: {os.path.relpath(grammar, ROOT)} against Blender "
          f"{bpy.app.version_string} (OpenSubdiv), relative to each mesh's size")
    print(f"   {'mesh':<19} {'sides':>9} {'open':>4} {'level 1':>9} {'level 2':>9} {'level 3':>9}")
    worst = 0.0
    failed = []
    for k, (name, (v, f)) in enumerate(cases):
        v = jiggle(v, k + 1)
        path = os.path.join(out, name.replace(" ", "-").replace(".", "") + ".obj")
        write_obj(path, v, f, name)
        v, f = read_obj(path)
        size = float(np.ptp(v, axis=0).max())
        sides = sorted({len(x) for x in f})
        edges = {}
        for face in f:
            for i in range(len(face)):
                e = tuple(sorted((face[i], face[(i + 1) % len(face)])))
                edges[e] = edges.get(e, 0) + 1
        open_ = any(c == 1 for c in edges.values())
        cols = []
        for levels in (1, 2, 3):
            mv, mf = subgram(binary, path, grammar, levels, path[:-4] + f"-{levels}.obj")
            bv, bf = blender_cc(v, f, levels)
            d = match(bv, bf, mv, mf)
            if d is None:
                failed.append(f"{name}, level {levels}: no one-to-one match with the same faces")
                cols.append("no match")
                continue
            rel = d / size
            worst = max(worst, rel)
            if rel > TOL:
                failed.append(f"{name}, level {levels}: {rel:.2e} > {TOL:.0e}")
            cols.append(f"{rel:.1e}")
        print(f"   {name:<19} {','.join(map(str, sides)):>9} {'yes' if open_ else 'no':>4}"
              + "".join(f" {c:>9}" for c in cols))
    return worst, failed


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bin", default=os.path.join(ROOT, "target", "debug", "subgram"))
    ap.add_argument("--out", help="folder for the meshes (default: a temporary one)")
    ap.add_argument("--self-test", action="store_true",
                    help="run a grammar with the old face point; succeed only if it is caught")
    args = ap.parse_args()
    binary = os.path.abspath(args.bin)
    if not os.access(binary, os.X_OK):
        sys.exit(f"{binary}: not an executable (cargo build first, or --bin PATH)")
    with tempfile.TemporaryDirectory(prefix="ngon-xcheck-") as tmp:
        out = args.out or tmp
        os.makedirs(out, exist_ok=True)
        if args.self_test:
            text = open(GRAMMAR).read()
            old = "F(f; !block(f)) -> V(v = avg(ring(v))) || E^3 F^3;"
            if old not in text:
                sys.exit(f"{GRAMMAR} no longer contains {old!r}: update --self-test")
            bad = os.path.join(out, "mutated-catmull-clark.lsys")
            with open(bad, "w") as fh:
                fh.write(text.replace(old, "F(f; !block(f)) -> V(v = avg(f)) || E^3 F^3;"))
            _, failed = run(binary, out, bad)
            if failed:
                print(f"self-test: the wrong face point was caught ({len(failed)} failures), as it must be")
                return
            print("self-test: the wrong face point was not caught")
            sys.exit(1)
        _, failed = run(binary, out)
    print()
    if failed:
        print(f"{len(failed)} comparison(s) failed:")
        for x in failed:
            print("  ", x)
        sys.exit(1)
    print("every vertex agrees")


if __name__ == "__main__":
    main()
