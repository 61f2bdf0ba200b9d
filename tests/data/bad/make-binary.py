#!/usr/bin/env python3
"""Writes the binary cases of this folder: ply-binary/*.ply and png/*.png.

The files are committed; this script says exactly what is in them and
remakes them byte for byte (python3, no packages): `python3 make-binary.py`.
Each case's `.run` file is written too.
"""
import os
import struct
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))


def put(kind, name, data, run, extra=""):
    d = os.path.join(HERE, kind)
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, name), "wb") as f:
        f.write(data)
    stem = name.rsplit(".", 1)[0]
    with open(os.path.join(d, stem + ".run"), "w") as f:
        f.write("run: " + run + "\n" + extra)


# --- binary little-endian PLY: a tetrahedron, float x y z, uchar/int lists

TET_V = [(1, 1, 1), (1, -1, -1), (-1, 1, -1), (-1, -1, 1)]
TET_F = [(0, 1, 2), (0, 3, 1), (0, 2, 3), (1, 3, 2)]
VERT = "element vertex {n}\nproperty float x\nproperty float y\nproperty float z\n"
FACE = "element face {n}\nproperty list uchar int vertex_indices\n"


def header(elements, fmt="binary_little_endian"):
    return ("ply\nformat %s 1.0\n%send_header\n" % (fmt, elements)).encode()


def verts(vs, fmt="<fff"):
    return b"".join(struct.pack(fmt, *v) for v in vs)


def faces(fs, count="<B", item="<i"):
    out = b""
    for f in fs:
        out += struct.pack(count, len(f)) + b"".join(struct.pack(item, i) for i in f)
    return out


def tet_header(nv=4, nf=4, face=FACE):
    return header(VERT.format(n=nv) + face.format(n=nf))


GOOD = tet_header() + verts(TET_V) + faces(TET_F)
BINARY_DATA = "no-line: the error is in binary data, which has no lines\n"


def ply(name, data, extra=BINARY_DATA):
    put("ply-binary", name, data, "mesh info $IN", extra)


ply("element-without-properties-huge-count.ply",
    header("comment an element with no properties: nothing is read per instance\n"
           "element nothing 18446744073709551615\n"
           + VERT.format(n=4) + FACE.format(n=4)) + verts(TET_V) + faces(TET_F),
    extra="")
ply("truncated-vertex-data.ply", tet_header() + verts(TET_V)[:30])
ply("truncated-face-list.ply", GOOD[:-6])
ply("huge-list-length.ply",
    tet_header(face="element face {n}\nproperty list uint int vertex_indices\n")
    + verts(TET_V) + faces(TET_F, count="<I")[:0]
    + struct.pack("<I", 0xFFFFFFFF) + struct.pack("<iii", 0, 1, 2)
    + faces(TET_F[1:], count="<I"))
ply("negative-list-length.ply",
    tet_header(face="element face {n}\nproperty list int int vertex_indices\n")
    + verts(TET_V) + struct.pack("<i", -1) + struct.pack("<iii", 0, 1, 2)
    + faces(TET_F[1:], count="<i"))
ply("negative-vertex-index.ply", tet_header() + verts(TET_V) + faces([(0, 1, 2), (0, -3, 1)] + TET_F[2:]))
ply("face-index-out-of-range.ply", tet_header() + verts(TET_V) + faces([(0, 1, 2), (0, 9, 1)] + TET_F[2:]))
ply("nan-coordinate.ply", tet_header() + verts([TET_V[0], (1, float("nan"), -1)] + TET_V[2:]) + faces(TET_F))
ply("infinite-coordinate.ply", tet_header() + verts([TET_V[0], (1, float("inf"), -1)] + TET_V[2:]) + faces(TET_F))
ply("face-with-two-vertices.ply", tet_header() + verts(TET_V) + faces([(0, 1, 2), (0, 3)] + TET_F[2:]))
ply("huge-vertex-count.ply", tet_header(nv=18446744073709551615) + verts(TET_V) + faces(TET_F))
ply("header-not-text.ply",
    b"ply\nformat binary_little_endian 1.0\ncomment caf\xe9\n"
    + (VERT.format(n=4) + FACE.format(n=4) + "end_header\n").encode() + verts(TET_V) + faces(TET_F),
    extra="")
ply("face-indices-of-floats.ply",
    tet_header(face="element face {n}\nproperty list uchar float vertex_indices\n")
    + verts(TET_V) + faces(TET_F, item="<f"), extra="")
ply("big-endian.ply",
    header(VERT.format(n=4) + FACE.format(n=4), fmt="binary_big_endian")
    + verts(TET_V, fmt=">fff") + faces(TET_F, count=">B", item=">i"), extra="")
ply("no-end-header.ply",
    ("ply\nformat binary_little_endian 1.0\n" + VERT.format(n=4) + FACE.format(n=4)).encode()
    + verts(TET_V) + faces(TET_F),
    extra="no-line: the header never ends, so the file has no line to point at\n")
ply("no-vertex-element.ply", header(FACE.format(n=4)) + faces(TET_F), extra="")

# --- PNG images: 8-bit greyscale or RGBA, no interlace


def chunk(kind, data):
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))


def png(width, height, rows, colour=0, depth=8, ihdr=None):
    """rows: a list of byte strings, one per row, without filter bytes."""
    raw = b"".join(b"\x00" + r for r in rows)
    ihdr = ihdr or struct.pack(">IIBBBBB", width, height, depth, colour, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr)
            + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


def disc(n, r):
    """An n x n grey image, black inside a disc of radius r, white outside."""
    c = (n - 1) / 2
    return [bytes(0 if (x - c) ** 2 + (y - c) ** 2 <= r * r else 255 for x in range(n))
            for y in range(n)]


NO_LINE = "no-line: a PNG image has no lines\n"


def image(name, data, run="reverse $IN -n 1 -o out.csv", extra=NO_LINE):
    put("png", name, data, run, extra)


GOOD_PNG = png(32, 32, disc(32, 10))
image("not-a-png.png", b"this is a text file named .png\n")
image("empty.png", b"")
image("truncated.png", GOOD_PNG[:40])
image("all-white.png", png(16, 16, [b"\xff" * 16] * 16))
image("fully-transparent.png", png(16, 16, [b"\x00\x00\x00\x00" * 16] * 16, colour=6))
image("huge-dimensions.png", png(100000, 100000, [b"\xff" * 4]))
image("zero-width.png", png(0, 16, [b""] * 16))
bad_crc = bytearray(GOOD_PNG)
bad_crc[29] ^= 0xFF  # the last byte of IHDR's CRC
image("bad-crc.png", bytes(bad_crc))
image("single-dark-pixel.png", png(8, 8, [b"\xff" * 8] * 3 + [b"\xff" * 3 + b"\x00" + b"\xff" * 4] + [b"\xff" * 8] * 4))
image("bit-depth-3.png", png(16, 16, [b"\x00" * 6] * 16, ihdr=struct.pack(">IIBBBBB", 16, 16, 3, 0, 0, 0, 0)))
image("figure-over-the-input.png", GOOD_PNG, run="reverse $IN -n 1 -o out.csv --figure $IN")
image("idat-missing.png", b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", 16, 16, 8, 0, 0, 0, 0)) + chunk(b"IEND", b""))
