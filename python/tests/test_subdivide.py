"""subdivide and the mesh files against `subgram subdivide`'s OBJ."""

import numpy as np
import pytest

import subgram


@pytest.mark.parametrize(
    "mesh,grammar,steps",
    [
        ("lsystems/meshes/bunny.obj", "loop", 2),
        ("lsystems/meshes/cube.obj", "catmull-clark", 2),
        ("lsystems/meshes/octahedron.obj", "sqrt3", 3),
        ("lsystems/meshes/cube.obj", "doo-sabin", 2),
        ("lsystems/meshes/tetrahedron.obj", "lsystems/surfaces/sqrt3.lsys", 2),
    ],
)
def test_subdivide_is_the_clis_obj(root, cli, tmp_path, mesh, grammar, steps):
    g = grammar if "/" in grammar else f"lsystems/surfaces/{grammar}.lsys"
    out = tmp_path / "cli.obj"
    cli("subdivide", mesh, "--grammar", g, "-n", steps, "-o", out)
    v, f = subgram.mesh(root / mesh)
    gv, gf = subgram.subdivide(v, f, grammar if "/" not in grammar else root / grammar, steps)
    assert gv.dtype == np.float64 and gv.shape[1] == 3
    # The same OBJ to the byte, written by the library's writer.
    mine = tmp_path / "mine.obj"
    subgram.write_mesh(mine, gv, gf)
    assert mine.read_bytes() == out.read_bytes()
    # And the same arrays as the CLI's file read back.
    cv, cf = subgram.mesh(out)
    assert np.array_equal(cv, gv)
    if isinstance(cf, np.ndarray):
        assert np.array_equal(cf, gf)
    else:
        assert all(np.array_equal(a, b) for a, b in zip(cf, gf))


def test_face_forms(root):
    v, f = subgram.mesh(root / "lsystems/meshes/cube.obj")
    assert isinstance(f, np.ndarray) and f.shape[1] == 4
    a = subgram.subdivide(v, f, "catmull-clark", 1)
    b = subgram.subdivide(v.tolist(), [list(x) for x in f], "catmull-clark", 1)
    c = subgram.subdivide(v, subgram.padded(f), "catmull-clark", 1)
    for x in (b, c):
        assert np.array_equal(a[0], x[0]) and np.array_equal(a[1], x[1])


def test_mixed_polygons(root, cli, tmp_path):
    v, f = subgram.mesh(root / "lsystems/meshes/pentagon-patch.obj")
    out = tmp_path / "cli.obj"
    cli("subdivide", "lsystems/meshes/pentagon-patch.obj", "--grammar", "lsystems/surfaces/catmull-clark.lsys", "-n", 1, "-o", out)
    gv, gf = subgram.subdivide(v, f, "catmull-clark", 1)
    mine = tmp_path / "mine.obj"
    subgram.write_mesh(mine, gv, gf)
    assert mine.read_bytes() == out.read_bytes()
    padded, sizes = subgram.padded(f)
    assert padded.shape[0] == len(sizes)


def test_vv_program(root, cli, tmp_path):
    import glob, os

    progs = sorted(glob.glob(str(root / "lsystems/vv/*.lsys")))
    prog = next(p for p in progs if "butterfly" in p)
    out = tmp_path / "cli.obj"
    cli("subdivide", "lsystems/meshes/octahedron.obj", "--grammar", os.path.relpath(prog, root), "-n", 2, "-o", out)
    v, f = subgram.mesh(root / "lsystems/meshes/octahedron.obj")
    gv, gf = subgram.subdivide(v, f, prog, 2)
    mine = tmp_path / "mine.obj"
    subgram.write_mesh(mine, gv, gf)
    assert mine.read_bytes() == out.read_bytes()


def test_system_mesh(root, cli, tmp_path):
    s = subgram.load(str(root / "lsystems/surfaces/loop.lsys"))
    v, f = s.mesh(2)
    out = tmp_path / "cli.obj"
    cli("subdivide", "--grammar", "lsystems/surfaces/loop.lsys", "-n", 2, "-o", out)
    cv, cf = subgram.mesh(out)
    assert np.array_equal(v, cv) and np.array_equal(f, cf)


def test_unknown_grammar():
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], float)
    with pytest.raises(subgram.Error):
        subgram.subdivide(v, [[0, 1, 2]], "no-such-scheme")
