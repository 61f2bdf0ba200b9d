"""Cost that grows as the work does (issue 42, item 4): the whole command a
user runs, on generated inputs of growing size, with its wall time, its
CPU time (user + system) and its peak resident memory, and the log-log
slope between sizes (1 is linear; n log n reads a little above 1).

    python3 benches/growth.py [--binary target/release/subgram]
                              [--only mesh|adaptive|png] [--sizes ...]
                              [--pixels ...] [--timeout 300]

Python's own library only: the meshes are written as OBJ text, the images
as 8-bit grey PNGs by zlib, and each command's resources are read from
`os.wait4` (the child's own peak RSS, not the largest of all children).

1. C4's pairing (`init: match_blocks`): `subgram subdivide MESH --grammar
   lsystems/surfaces/c4.lsys -n 0 -o out.obj` (read, pair, write) on
   triangle meshes of 12.5k, 50k, 200k and 800k faces:
   * `fan`: one interior centre joined to a rim of n vertices (the known
     worst case: the centre has valence n);
   * `grid`: a square grid, each square cut by a diagonal, the inner
     vertices jiggled;
   * `sphere`: a latitude-longitude sphere (two poles of valence about
     the square root of n).
   And `-n 2` on the grid (one level of the box spline after the pairing).
2. Adaptive 4-8 (`lsystems/surfaces/four-eight-adaptive.lsys`, `adaptive;`,
   and the same with `adaptive: incremental;`) on a quad grid of n
   triangles in [-1, 1]^2 (its quads are the blocks), 4 steps, refining
   the disc of radius 0.5 at the centre (`-D PX=0 -D R=0.5`), so that the
   work grows with the mesh.
3. PNG tracing for `subgram reverse IMAGE -n 1 -o out.csv` on 1024^2 to
   8192^2 pixels: `checker` (a checkerboard of 2-pixel squares: a segment
   in every cell, no loop larger than a square), `spiral` (one square
   spiral 2 pixels wide: a single outline through the whole image, which
   past 8M points is refused with a message after it was traced), `noise`
   (random pixels).

`--timeout S` is given to every command (300 s by default); a command
that stops at it says so in the last column, and its wall time shows how
long after the limit it stopped (`--timeout 1` checks that every path
stops within a second of the limit).
"""
import argparse
import math
import os
import random
import struct
import subprocess
import sys
import tempfile
import time
import zlib

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def measure(cmd):
    """Runs `cmd`; (wall s, user+sys s, peak RSS MiB, exit code, stderr tail).
    posix_spawn (a vfork) rather than fork, so that the child's peak RSS is
    its own and not this script's copied image."""
    with tempfile.TemporaryFile() as err, open(os.devnull, "wb") as null:
        t = time.perf_counter()
        pid = os.posix_spawn(cmd[0], cmd, os.environ, file_actions=[
            (os.POSIX_SPAWN_DUP2, null.fileno(), 1), (os.POSIX_SPAWN_DUP2, err.fileno(), 2)])
        _, status, ru = os.wait4(pid, 0)
        wall = time.perf_counter() - t
        err.seek(0)
        tail = err.read().decode(errors="replace")[-300:]
    # ru_maxrss is in KiB on Linux.
    return wall, ru.ru_utime + ru.ru_stime, ru.ru_maxrss / 1024, os.waitstatus_to_exitcode(status), tail


def write_obj(path, verts, faces):
    with open(path, "w") as f:
        f.write("".join(f"v {x:.9g} {y:.9g} {z:.9g}\n" for x, y, z in verts))
        f.write("".join("f " + " ".join(str(i + 1) for i in face) + "\n" for face in faces))


def fan(n):
    """An interior centre of valence n on a disc of n triangles."""
    verts = [(0.0, 0.0, 0.0)]
    for i in range(n):
        a = 2 * math.pi * i / n
        verts.append((math.cos(a), math.sin(a), 0.0))
    faces = [(0, 1 + i, 1 + (i + 1) % n) for i in range(n)]
    return verts, faces


def grid(n, quads=False, jiggle=0.3, seed=1):
    """A k x k grid in [-1, 1]^2 with about n triangles (2 k^2)."""
    k = max(1, round(math.sqrt(n / 2)))
    rnd = random.Random(seed)
    h = 2.0 / k
    verts = []
    for j in range(k + 1):
        for i in range(k + 1):
            x, y = -1 + i * h, -1 + j * h
            if 0 < i < k and 0 < j < k and jiggle:
                x += (rnd.random() - 0.5) * jiggle * h
                y += (rnd.random() - 0.5) * jiggle * h
            verts.append((x, y, 0.0))
    faces = []
    for j in range(k):
        for i in range(k):
            a = j * (k + 1) + i
            b, c, d = a + 1, a + k + 2, a + k + 1
            if quads:
                faces.append((a, b, c, d))
            else:
                faces += [(a, b, c), (a, c, d)]
    return verts, faces


def sphere(n):
    """A latitude-longitude sphere of about n triangles: m rings of 2m
    segments, fans at the poles (4 m^2 - 4 m triangles)."""
    m = max(3, round((1 + math.sqrt(1 + n)) / 2))
    seg = 2 * m
    verts = [(0.0, 0.0, 1.0)]
    for r in range(1, m):
        t = math.pi * r / m
        for s in range(seg):
            p = 2 * math.pi * s / seg
            verts.append((math.sin(t) * math.cos(p), math.sin(t) * math.sin(p), math.cos(t)))
    verts.append((0.0, 0.0, -1.0))
    south = len(verts) - 1
    ring = lambda r, s: 1 + (r - 1) * seg + s % seg
    faces = [(0, ring(1, s), ring(1, s + 1)) for s in range(seg)]
    for r in range(1, m - 1):
        for s in range(seg):
            a, b = ring(r, s), ring(r, s + 1)
            c, d = ring(r + 1, s + 1), ring(r + 1, s)
            faces += [(a, d, c), (a, c, b)]
    faces += [(south, ring(m - 1, s + 1), ring(m - 1, s)) for s in range(seg)]
    return verts, faces


def write_png(path, w, h, row_of):
    """An 8-bit grey PNG, rows from `row_of(y)` (bytes of length w)."""
    def chunk(kind, data):
        c = struct.pack(">I", len(data)) + kind + data
        return c + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    z = zlib.compressobj(6)
    parts = []
    for y in range(h):
        parts.append(z.compress(b"\0" + row_of(y)))
    parts.append(z.flush())
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n")
        f.write(chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 0, 0, 0, 0)))
        f.write(chunk(b"IDAT", b"".join(parts)))
        f.write(chunk(b"IEND", b""))


def checker_rows(n):
    """2-pixel black and white squares inside a white frame of 4 pixels."""
    row = lambda phase: bytes(255 if x < 4 or x >= n - 4 else (0, 0, 255, 255)[(x + phase) % 4]
                              for x in range(n))
    a, b, white = row(0), row(2), b"\xff" * n
    return lambda y: white if y < 4 or y >= n - 4 else (a if (y // 2) % 2 == 0 else b)


def spiral_rows(n):
    """A square spiral of black 2-pixel-wide lines with 2-pixel gaps,
    inside a white 4-pixel frame: one outline through the whole image."""
    img = bytearray(b"\xff" * (n * n))
    lo, hi = 4, n - 5  # the spiral's box, inclusive
    x, y = lo, lo
    # Walk the spiral: right, down, left, up, each leg 4 shorter every two.
    legs = [(1, 0), (0, 1), (-1, 0), (0, -1)]
    length = hi - lo
    d = 0
    first = True
    while length > 2:
        dx, dy = legs[d % 4]
        # The leg as a 2-pixel-wide rectangle from (x, y), `length` long.
        x0, x1 = min(x, x + dx * length), max(x, x + dx * length) + 2
        y0, y1 = min(y, y + dy * length), max(y, y + dy * length) + 2
        for yy in range(max(y0, 0), min(y1, n)):
            img[yy * n + max(x0, 0):yy * n + min(x1, n)] = b"\0" * (min(x1, n) - max(x0, 0))
        x += dx * length
        y += dy * length
        d += 1
        if first:
            first = False
        elif d % 2 == 1:
            length -= 4
    return lambda y: bytes(img[y * n:(y + 1) * n])


def noise_rows(n, seed=7):
    """Random grey levels inside a white frame of 4 pixels."""
    rnd = random.Random(seed)
    white = b"\xff" * n
    return lambda y: white if y < 4 or y >= n - 4 else b"\xff" * 4 + rnd.randbytes(n - 8) + b"\xff" * 4


INPUTS = {
    "fan": lambda n, path: write_obj(path, *fan(n)),
    "grid": lambda n, path: write_obj(path, *grid(n)),
    "sphere": lambda n, path: write_obj(path, *sphere(n)),
    "quads": lambda n, path: write_obj(path, *grid(n, quads=True, jiggle=0)),
    "checker": lambda n, path: write_png(path, n, n, checker_rows(n)),
    "spiral": lambda n, path: write_png(path, n, n, spiral_rows(n)),
    "noise": lambda n, path: write_png(path, n, n, noise_rows(n)),
}


def make(kind, n, path):
    """Writes the input `kind` of size `n` to `path` in another process."""
    subprocess.run([sys.executable, os.path.abspath(__file__), "--make", kind, str(n), path],
                   check=True)


def slope(rows):
    """Log-log slopes between consecutive finished sizes (CPU time: user +
    system, which another process on the machine disturbs less than the
    wall time)."""
    out = []
    for (n0, t0), (n1, t1) in zip(rows, rows[1:]):
        if t0 and t1 and t0 > 0.02:
            out.append(f"{math.log(t1 / t0) / math.log(n1 / n0):.2f}")
        else:
            out.append("-")
    return " ".join(out)


def table(title, size_name, sizes, cases, run, timeout, units=lambda n: n):
    """One row per case and size; the slopes are against `units(n)` (faces,
    or pixels for an image's side), and so is the peak memory per unit."""
    print(f"\n{title}")
    print(f"{'case':24s} {size_name:>10s} {'wall s':>9s} {'cpu s':>9s} {'peak MiB':>9s} "
          f"{'B/unit':>7s}  note")
    for name, kind in cases:
        done = []
        for n in sizes:
            wall, cpu, rss, code, err = run(kind, n)
            over = code != 0 and "time limit" in err
            last = err.strip().splitlines()[-1] if err.strip() else ""
            note = "" if code == 0 else (f"stopped at --timeout {timeout}" if over
                                         else f"exit {code}: {last[-90:]}")
            shown = f"{wall:9.2f}"
            per = rss * 2**20 / units(n)
            print(f"{name:24s} {n:>10d} {shown:>9s} {cpu:9.2f} {rss:9.1f} {per:7.1f}  {note}",
                  flush=True)
            done.append((units(n), None if code != 0 else cpu))
        print(f"{'':24s} log-log slope of CPU time against {size_name if units(2) == 2 else 'pixels'}: "
              f"{slope(done)}")


def main():
    if sys.argv[1:2] == ["--make"]:
        kind, n, path = sys.argv[2:5]
        INPUTS[kind](int(n), path)
        return
    ap = argparse.ArgumentParser()
    ap.add_argument("--binary", default=os.path.join(ROOT, "target/release/subgram"))
    ap.add_argument("--only", choices=["mesh", "adaptive", "png"], action="append")
    ap.add_argument("--sizes", type=int, nargs="+", default=[12_500, 50_000, 200_000, 800_000])
    ap.add_argument("--pixels", type=int, nargs="+", default=[1024, 2048, 4096, 8192])
    ap.add_argument("--cases", nargs="+", help="only these cases (e.g. fan grid)")
    ap.add_argument("--timeout", type=int, default=300, help="subgram's --timeout for each command")
    a = ap.parse_args()
    sg = a.binary
    only = a.only or ["mesh", "adaptive", "png"]
    want = lambda name: not a.cases or name.split()[0] in a.cases
    with tempfile.TemporaryDirectory() as tmp:
        out_obj = os.path.join(tmp, "out.obj")
        if "mesh" in only:
            def run_c4(kind, n, steps=0):
                path = os.path.join(tmp, "in.obj")
                make(kind, n, path)
                return measure([sg, "subdivide", path, "--grammar", os.path.join(ROOT, "lsystems/surfaces/c4.lsys"),
                                "-n", str(steps), "-o", out_obj, "--timeout", str(a.timeout)])

            cases = [(c, c) for c in ["fan", "grid", "sphere"] if want(c)]
            table("C4 pairing: subdivide --grammar c4.lsys -n 0 (read, pair, write)", "faces",
                  a.sizes, cases, run_c4, a.timeout)
            if want("grid"):
                table("C4, one level: subdivide --grammar c4.lsys -n 2", "faces", a.sizes,
                      [("grid -n 2", "grid")], lambda m, n: run_c4(m, n, 2), a.timeout)
        if "adaptive" in only:
            src = open(os.path.join(ROOT, "lsystems/surfaces/four-eight-adaptive.lsys")).read()
            grammars = {}
            for kind, line in [("adaptive", "adaptive;"), ("incremental", "adaptive: incremental;")]:
                g = os.path.join(tmp, f"{kind}.lsys")
                with open(g, "w") as f:
                    f.write(src.replace("\nadaptive;\n", f"\n{line}\n"))
                grammars[kind] = g

            def run_adaptive(kind, n):
                path = os.path.join(tmp, "quads.obj")
                make("quads", n, path)
                return measure([sg, "subdivide", path, "--grammar", grammars[kind], "-n", "4",
                                "-D", "PX=0", "-D", "R=0.5", "-o", out_obj,
                                "--timeout", str(a.timeout)])

            cases = [(f"{k} 4 steps", k) for k in grammars if want(k)]
            table("Adaptive 4-8: four-eight-adaptive.lsys, disc of radius 0.5, -n 4", "faces",
                  a.sizes, cases, run_adaptive, a.timeout)
        if "png" in only:
            def run_png(kind, n):
                path = os.path.join(tmp, "in.png")
                make(kind, n, path)
                return measure([sg, "reverse", path, "-n", "1", "-o", os.path.join(tmp, "out.csv"),
                                "--timeout", str(a.timeout), "--max-input-size", "1G"])

            cases = [(c, c) for c in ["checker", "spiral", "noise"] if want(c)]
            table("PNG tracing: reverse IMAGE -n 1 -o out.csv", "side px", a.pixels, cases, run_png,
                  a.timeout, units=lambda n: n * n)


if __name__ == "__main__":
    sys.exit(main())
