#!/usr/bin/env python3
"""The exporters of 3D scenes (issue 17, item 3) against independent readers.

subgram writes a synthetic plant (examples/bench_raster.rs --export: tubes
of two looks with smooth normals) as OBJ+MTL, PLY and GLB, and a surface
(`subdivide` of a cube by catmull-clark.lsys) as OBJ and GLB. trimesh
reads each file back; the vertex and triangle counts and the bounding box
must be those subgram reports (plant.json) or those of the OBJ that the
mesh writer wrote. With --blender PYTHON (a Python with `bpy`), Blender
imports the OBJ and the GLB too and the same is checked.

Usage (from the repository root, after
`cargo build --release --example bench_raster` and `cargo build --release`):

    /work/venv-xcheck/bin/python benches/export_xcheck.py [SEGMENTS] [--blender /tmp/venv-bpy/bin/python] [--models MODEL_DIR...]

With --models, each lpfg model folder is rendered to OBJ, PLY and GLB
(`subgram render MODEL -o m.EXT`) and every file is held against the
counts and bounds of the OBJ's own lines.

Exit status 0 when everything agrees. Not part of `cargo test`.
"""

import json
import os
import warnings
import subprocess
import sys
import tempfile

import numpy as np
import trimesh

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BENCH = os.path.join(ROOT, "target/release/examples/bench_raster")
SUBGRAM = os.path.join(ROOT, "target/release/subgram")

BLENDER_SCRIPT = r"""
import bpy, json, sys
path = sys.argv[-1]
bpy.ops.wm.read_factory_settings(use_empty=True)
if path.endswith('.obj'):
    bpy.ops.wm.obj_import(filepath=path)
else:
    bpy.ops.import_scene.gltf(filepath=path)
v = t = 0
lo = [float('inf')] * 3
hi = [float('-inf')] * 3
for o in bpy.context.scene.objects:
    if o.type != 'MESH':
        continue
    m = o.data
    m.calc_loop_triangles()
    v += len(m.vertices)
    t += len(m.loop_triangles)
    for vert in m.vertices:
        p = o.matrix_world @ vert.co
        for k in range(3):
            lo[k] = min(lo[k], p[k]); hi[k] = max(hi[k], p[k])
print('RESULT ' + json.dumps({'vertices': v, 'triangles': t, 'min': lo, 'max': hi}))
"""


def counts_trimesh(path):
    """Vertices, triangles and bounds as trimesh reads the file (no merging).
    Its OBJ reader keeps each object's referenced vertices only unless
    told to keep the order, which would give every object all of them."""
    loaded = trimesh.load(path, process=False)
    geoms = list(loaded.geometry.values()) if isinstance(loaded, trimesh.Scene) else [loaded]
    # World bounds (the GLB's node has no transform).
    bounds = loaded.bounds
    v = sum(len(g.vertices) for g in geoms)
    t = sum(len(g.faces) for g in geoms)
    return {"vertices": v, "triangles": t, "min": list(bounds[0]), "max": list(bounds[1]), "parts": len(geoms)}


def counts_blender(python, path):
    out = subprocess.run([python, "-c", BLENDER_SCRIPT, path], capture_output=True, text=True)
    for line in out.stdout.splitlines():
        if line.startswith("RESULT "):
            r = json.loads(line[7:])
            # Blender's OBJ and glTF importers turn y up into z up.
            if path.endswith(".obj") or path.endswith(".glb"):
                lo, hi = r["min"], r["max"]
                r["min"] = [lo[0], lo[2], -hi[1]]
                r["max"] = [hi[0], hi[2], -lo[1]]
            return r
    raise RuntimeError(f"blender failed on {path}: {out.stderr[-2000:]}")


def same(what, got, want, tol=1e-5):
    ok = got["vertices"] == want["vertices"] and got["triangles"] == want["triangles"]
    scale = max(1.0, float(np.max(np.abs(want["max"]))), float(np.max(np.abs(want["min"]))))
    ok = ok and np.allclose(got["min"], want["min"], atol=tol * scale)
    ok = ok and np.allclose(got["max"], want["max"], atol=tol * scale)
    print(
        f"{'ok  ' if ok else 'FAIL'} {what}: {got['vertices']} vertices, {got['triangles']} triangles, "
        f"bounds {np.round(got['min'], 6).tolist()} .. {np.round(got['max'], 6).tolist()}"
        + ("" if ok else f" (expected {want})")
    )
    return ok


def main():
    # trimesh warns about the materials' missing textures.
    warnings.filterwarnings("ignore", category=RuntimeWarning)
    args = sys.argv[1:]
    blender = None
    if "--blender" in args:
        i = args.index("--blender")
        blender = args[i + 1]
        del args[i : i + 2]
    models = []
    if "--models" in args:
        i = args.index("--models")
        models = args[i + 1 :]
        del args[i:]
    segments = args[0] if args else "20000"
    ok = True
    with tempfile.TemporaryDirectory() as d:
        subprocess.run([BENCH, segments, "--export", d, "--only", "export"], check=True)
        want = json.load(open(os.path.join(d, "plant.json")))
        print(f"plant: {want['vertices']} vertices, {want['triangles']} triangles, {want['looks']} looks")
        for name in ["plant.obj", "plant.ply", "plant.glb"]:
            ok &= same(f"trimesh {name}", counts_trimesh(os.path.join(d, name)), want)
        # A surface from subdivide: the GLB against the OBJ the mesh
        # writer makes of the same run, its quads fanned into triangles.
        grammar = os.path.join(ROOT, "lsystems/surfaces/catmull-clark.lsys")
        cube = os.path.join(ROOT, "lsystems/meshes/cube.obj")
        for ext in ["obj", "glb"]:
            subprocess.run([SUBGRAM, "subdivide", "--grammar", grammar, cube, "-n", "3", "-o", os.path.join(d, f"cube.{ext}")], check=True)
        ref = trimesh.load(os.path.join(d, "cube.obj"), process=False)
        want_cube = {"vertices": len(ref.vertices), "triangles": len(ref.faces), "min": list(ref.bounds[0]), "max": list(ref.bounds[1])}
        ok &= same("trimesh cube.glb (subdivide) against cube.obj", counts_trimesh(os.path.join(d, "cube.glb")), want_cube)
        if blender:
            for name in ["plant.obj", "plant.glb"]:
                ok &= same(f"blender {name}", counts_blender(blender, os.path.join(d, name)), want)
        # Real models through `render MODEL -o plant.EXT`: every file against
        # the counts and bounds of the OBJ's own text.
        for m in models:
            name = os.path.basename(os.path.normpath(m))
            for ext in ["obj", "ply", "glb"]:
                subprocess.run([SUBGRAM, "render", m, "-o", os.path.join(d, f"{name}.{ext}")],
                               check=True, stderr=subprocess.DEVNULL)
            vs, fs = [], 0
            for line in open(os.path.join(d, f"{name}.obj")):
                if line.startswith("v "):
                    vs.append([float(x) for x in line.split()[1:4]])
                elif line.startswith("f "):
                    fs += 1
            vs = np.array(vs)
            want_m = {"vertices": len(vs), "triangles": fs, "min": list(vs.min(0)), "max": list(vs.max(0))}
            print(f"{name}: {want_m['vertices']} vertices, {want_m['triangles']} triangles (the OBJ's text)")
            for ext in ["obj", "ply", "glb"]:
                ok &= same(f"trimesh {name}.{ext}", counts_trimesh(os.path.join(d, f"{name}.{ext}")), want_m)
            if blender:
                for ext in ["obj", "glb"]:
                    ok &= same(f"blender {name}.{ext}", counts_blender(blender, os.path.join(d, f"{name}.{ext}")), want_m)
    print("all agree" if ok else "DIFFERENCES")
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
