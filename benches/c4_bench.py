"""C4 benchmark (issue 15): the whole path a user pays for, files in and
files out, best of N runs, all measured in the same run.

    python3 benches/c4_bench.py [--binary target/release/subgram] [-n 5]

The mesh: the Stanford bunny (lsystems/meshes/bunny.obj) after three steps
of lsystems/surfaces/sqrt3.lsys, 99,198 triangles, written once to a
temporary folder. On it, `subgram subdivide MESH --grammar G -n K -o
out.obj` for:

* c4.lsys, 0 steps: reading, pairing the triangles (the maximum matching)
  and writing the quads;
* c4.lsys, 2 steps (one level of the box spline: 4 times the faces);
* loop.lsys, 1 step (one level of Loop: 4 times the faces), the
  reference;
* c4.lsys, 4 steps, against loop.lsys, 2 steps (16 times the faces);
* `subgram mesh convert MESH out.obj`: the floor of reading and writing.
"""
import argparse
import os
import subprocess
import tempfile

# The same timing as the shape benchmark: best of n, files in and out.
from shapes_bench import ROOT, best


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--binary", default=os.path.join(ROOT, "target/release/subgram"))
    ap.add_argument("-n", type=int, default=5)
    a = ap.parse_args()
    sg = a.binary
    with tempfile.TemporaryDirectory() as tmp:
        mesh = os.path.join(tmp, "bunny-99k.obj")
        subprocess.run(
            [sg, "subdivide", "lsystems/meshes/bunny.obj", "--grammar",
             "lsystems/surfaces/sqrt3.lsys", "-n", "3", "-o", mesh],
            check=True, cwd=ROOT)
        faces = sum(1 for line in open(mesh) if line.startswith("f "))
        out = os.path.join(tmp, "out.obj")

        def sub(grammar, steps):
            return [sg, "subdivide", mesh, "--grammar", f"lsystems/surfaces/{grammar}",
                    "-n", str(steps), "-o", out]

        rows = [
            ("mesh convert (read + write)", [sg, "mesh", "convert", mesh, out]),
            ("c4, 0 steps (pairing)", sub("c4.lsys", 0)),
            ("c4, 2 steps", sub("c4.lsys", 2)),
            ("loop, 1 step", sub("loop.lsys", 1)),
            ("c4, 4 steps", sub("c4.lsys", 4)),
            ("loop, 2 steps", sub("loop.lsys", 2)),
        ]
        times = {}
        print(f"mesh: {faces} triangles; best of {a.n}")
        for name, cmd in rows:
            times[name] = best(cmd, a.n)
            print(f"{name:32s} {times[name] * 1000:9.1f} ms")
        print(f"c4 2 steps / loop 1 step: {times['c4, 2 steps'] / times['loop, 1 step']:.2f}x")
        print(f"c4 4 steps / loop 2 steps: {times['c4, 4 steps'] / times['loop, 2 steps']:.2f}x")


if __name__ == "__main__":
    main()
