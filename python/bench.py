#!/usr/bin/env python3
"""The figures of the Python bindings (issue 39): medians of a few runs.

1. A word of about 4 million modules reaching numpy, against its
   derivation (the same run): fig01-chaikin-square -n 20 (4 points doubled
   20 times: 4,194,308 modules, `params("P")` a 4,194,304×2 array) and the
   dragon -n 20 (4,194,302 modules without parameters: `symbol_ids`,
   `offsets`, `slots`).
2. Loop subdivision of the bunny, 3 steps: through Python (numpy in, numpy
   out; and with the OBJ written, as the CLI does) against the CLI
   (`subgram subdivide ... -o OUT.obj`, a release binary: SUBGRAM_CLI).

    python python/bench.py [--runs 5]
"""

import argparse
import os
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

import subgram

ROOT = Path(__file__).resolve().parents[1]


def median_of(runs, f):
    times = []
    for _ in range(runs):
        times.append(f())
    return statistics.median(times)


def word_to_numpy(runs):
    out = []
    for path, n, take in [
        ("lsystems/figures/fig01-chaikin-square.lsys", 20, lambda w: [w.params("P")]),
        ("lsystems/abop/dragon.lsys", 20, lambda w: [w.symbol_ids, w.offsets, w.slots]),
    ]:
        s = subgram.load(str(ROOT / path))
        derive, numpy_ = [], []
        for _ in range(runs):
            t = time.perf_counter()
            w = s.derive(n)
            t1 = time.perf_counter()
            arrays = take(w)
            t2 = time.perf_counter()
            derive.append(t1 - t)
            numpy_.append(t2 - t1)
            modules = len(w)
            shapes = [a.shape for a in arrays]
            del w, arrays
        d, m = statistics.median(derive), statistics.median(numpy_)
        out.append((f"{path} -n {n}", modules, shapes, d, m))
        print(f"{path} -n {n}: {modules:,} modules; derive {d:.3f} s, to numpy {m:.3f} s "
              f"({m / d:.2f}x the derivation) {shapes}")
    return out


def subdivide_vs_cli(runs, cli):
    mesh = ROOT / "lsystems/meshes/bunny.obj"
    grammar = ROOT / "lsystems/surfaces/loop.lsys"
    v, f = subgram.mesh(mesh)
    with tempfile.TemporaryDirectory() as d:
        out = Path(d) / "cli.obj"
        mine = Path(d) / "py.obj"

        def py_arrays():
            t = time.perf_counter()
            subgram.subdivide(v, f, "loop", 3)
            return time.perf_counter() - t

        def py_file():
            t = time.perf_counter()
            gv, gf = subgram.subdivide(*subgram.mesh(mesh), "loop", 3)
            subgram.write_mesh(mine, gv, gf)
            return time.perf_counter() - t

        def cli_run():
            t = time.perf_counter()
            subprocess.run([cli, "subdivide", str(mesh), "--grammar", str(grammar), "-n", "3",
                            "-o", str(out), "--force"], check=True, capture_output=True)
            return time.perf_counter() - t

        a = median_of(runs, py_arrays)
        b = median_of(runs, py_file)
        c = median_of(runs, cli_run) if cli else float("nan")
        same = cli and mine.read_bytes() == out.read_bytes()
        gv, gf = subgram.subdivide(v, f, "loop", 3)
        print(f"bunny, Loop, 3 steps ({len(v):,} -> {len(gv):,} vertices, {len(gf):,} faces): "
              f"Python arrays {a:.3f} s, Python file to file {b:.3f} s, CLI {c:.3f} s; "
              f"the same OBJ: {same}")
    return a, b, c


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=5)
    args = ap.parse_args()
    word_to_numpy(args.runs)
    subdivide_vs_cli(args.runs, os.environ.get("SUBGRAM_CLI"))


if __name__ == "__main__":
    main()
