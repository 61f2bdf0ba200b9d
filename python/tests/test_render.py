"""System.render and the notebook hooks against `subgram render`."""

import pytest

import subgram


@pytest.mark.parametrize(
    "path,fmt,extra",
    [
        ("lsystems/curves/chaikin-13.lsys", "png", []),
        ("lsystems/curves/chaikin-13.lsys", "svg", []),
        ("lsystems/abop/bush.lsys", "png", ["-n", 3]),
        ("lsystems/surfaces/loop.lsys", "png", []),
    ],
)
def test_render_bytes_are_the_clis(root, cli, tmp_path, path, fmt, extra):
    out = tmp_path / f"cli.{fmt}"
    cli("render", path, *extra, "-o", out)
    steps = extra[1] if extra else None
    got = subgram.load(str(root / path)).render(format=fmt, steps=steps)
    assert got == out.read_bytes()


def test_render_to_a_file_with_size(root, cli, tmp_path):
    mine = tmp_path / "mine.png"
    s = subgram.load(str(root / "lsystems/abop/dragon.lsys"))
    assert s.render(mine, size=(200, 150)) is None
    out = tmp_path / "cli.png"
    cli("render", "lsystems/abop/dragon.lsys", "--size", "200x150", "-o", out)
    assert mine.read_bytes() == out.read_bytes()


def test_notebook_hooks(root):
    curve = subgram.load(str(root / "lsystems/curves/chaikin-13.lsys"))
    assert curve._repr_png_().startswith(b"\x89PNG")
    assert curve._repr_svg_().startswith("<svg")
    surface = subgram.load(str(root / "lsystems/surfaces/loop.lsys"))
    assert surface._repr_svg_() is None
    assert surface._repr_png_().startswith(b"\x89PNG")


def test_render_of_program_text():
    text = "module P(float);\nderivation length: 2;\nAxiom: P(1);\nP(x) : produce P(x) P(x);\ninterpretation:\nP(x) : produce F(x) Left(60);\n"
    assert subgram.load(text).render().startswith(b"\x89PNG")


def test_render_mesh_is_the_clis(root, cli, tmp_path):
    v, f = subgram.mesh(root / "lsystems/meshes/octahedron.obj")
    out = tmp_path / "cli.png"
    cli("render", "lsystems/meshes/octahedron.obj", "--size", "200x200", "-o", out)
    assert subgram.render_mesh(v, f, size=(200, 200)) == out.read_bytes()


def test_lines_and_bounds(root):
    import numpy as np

    s = subgram.load(str(root / "examples/python/bush.lsys"), seed=5)
    lines = s.lines()
    assert lines and all(l.ndim == 2 and l.shape[1] == 3 for l in lines)
    pts = np.concatenate(lines)
    lo, hi = s.bounds()
    assert np.allclose(pts.min(axis=0), lo) and np.allclose(pts.max(axis=0), hi)
    with pytest.raises(TypeError):
        subgram.load(str(root / "lsystems/surfaces/loop.lsys")).lines()
