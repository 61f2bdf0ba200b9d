"""Shape grammar benchmark (issue 14): the whole path a user pays for,
files in and files out, best of N runs, all measured in the same run.

    python3 benches/shapes_bench.py [--binary target/release/subgram] [-n 5]

1. The city block (benches/data/city-block.lsys, about 11,000 terminal
   shapes): `subgram subdivide --grammar city-block.lsys -o city.obj`
   (load, check, derive, OBJ and MTL written), against a reference in the
   same run: `smooth_xcheck --obj-copy`, a hand loop that reads the written
   OBJ into arrays and writes it back (no derivation, no checks), the floor
   of files in and out for that output.
2. A smoothing group of 99,500 triangles (benches/data/smooth-group.lsys: a
   sphere split into four shapes, one sqrt(3) step as one group):
   `subgram subdivide --grammar smooth-group.lsys -o out.obj`, against the
   surface grammar lsystems/surfaces/sqrt3.lsys run by `subgram subdivide`
   on the same welded mesh (written by examples/smooth_xcheck --shapes), one
   step, to OBJ.
"""
import argparse
import os
import subprocess
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def best(cmd, n):
    times = []
    for _ in range(n):
        t = time.perf_counter()
        subprocess.run(cmd, check=True, cwd=ROOT, stdout=subprocess.DEVNULL)
        times.append(time.perf_counter() - t)
    return min(times)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--binary", default=os.path.join(ROOT, "target/release/subgram"))
    ap.add_argument("--example", default=os.path.join(ROOT, "target/release/examples/smooth_xcheck"))
    ap.add_argument("-n", type=int, default=5)
    a = ap.parse_args()
    out = tempfile.mkdtemp(prefix="shapes-bench-")
    b = a.binary
    city = os.path.join(out, "city.obj")
    t_city = best([b, "subdivide", "--grammar", "benches/data/city-block.lsys", "-o", city], a.n)
    derive = subprocess.run([b, "derive", "benches/data/city-block.lsys"], cwd=ROOT,
                            capture_output=True, text=True, check=True).stdout
    counts = dict(l.split(": ") for l in derive.splitlines()[-4:])
    t_copy = best([a.example, "--obj-copy", city, os.path.join(out, "copy.obj")], a.n)
    print(f"city block: {counts['shapes']} shapes, {counts['terminal shapes']} terminal,"
          f" {counts['faces']} faces, OBJ {os.path.getsize(city)} bytes")
    print(f"  derive + OBJ/MTL: {t_city * 1e3:.1f} ms; a hand loop reading and writing the"
          f" same OBJ: {t_copy * 1e3:.1f} ms; ratio {t_city / t_copy:.2f}")
    groups = os.path.join(out, "groups")
    subprocess.run([a.example, "--shapes", "benches/data/smooth-group.lsys", groups],
                   check=True, cwd=ROOT, stdout=subprocess.DEVNULL)
    welded = os.path.join(groups, "group-1-welded.obj")
    t_shape = best([b, "subdivide", "--grammar", "benches/data/smooth-group.lsys",
                    "-o", os.path.join(out, "group.obj")], a.n)
    t_surface = best([b, "subdivide", welded, "--grammar", "lsystems/surfaces/sqrt3.lsys",
                      "-n", "1", "-o", os.path.join(out, "surface.obj")], a.n)
    tris = sum(1 for l in open(welded) if l.startswith("f "))
    print(f"smoothing group: {tris} triangles welded from 4 shapes, one sqrt3 step")
    print(f"  shape grammar (sphere, split, weld, Subdivide, OBJ): {t_shape * 1e3:.1f} ms;"
          f" surface grammar on the welded OBJ (read, subdivide, write): {t_surface * 1e3:.1f} ms;"
          f" ratio {t_shape / t_surface:.2f}")
    print(f"  cpus {len(os.sched_getaffinity(0))}, load {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
