"""subgram from Python: L-systems and subdivision grammars, numpy arrays out.

The heavy lifting is the Rust library (the same loader and commands as the
``subgram`` CLI, so that results are the CLI's to the bit); this module adds
argument coercion, plain dicts and the notebook hooks.

    >>> import subgram
    >>> curve = subgram.load("lsystems/curves/chaikin-13.lsys")
    >>> word = curve.derive(3)
    >>> word.params("P").shape          # one row a module, one column a slot
    (48, 2)
"""

from __future__ import annotations

import json as _json
import os as _os
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as _np

from . import _subgram
from ._subgram import Error, System, Word, check, load, read_mesh, schemes

__all__ = [
    "Error",
    "System",
    "Word",
    "load",
    "check",
    "schemes",
    "subdivide",
    "padded",
    "mesh",
    "read_mesh",
    "write_mesh",
    "render_mesh",
    "reverse",
    "infer",
    "analyze",
    "__version__",
]

__version__ = _subgram.__version__


# ---------------------------------------------------------------------------
# Notebook hooks on System


def _repr_png_(self: System) -> Optional[bytes]:
    """The picture a notebook shows: ``render(format="png")``."""
    return self.render(format="png")


def _repr_svg_(self: System) -> Optional[str]:
    """Curves only: ``render(format="svg")`` as text."""
    if self.kind != "curve":
        return None
    return self.render(format="svg").decode("utf-8")


System._repr_png_ = _repr_png_  # type: ignore[attr-defined]
System._repr_svg_ = _repr_svg_  # type: ignore[attr-defined]


def _system_mesh(self: System, steps: Optional[int] = None, *, timeout: Optional[float] = None):
    """A surface grammar or vv program run on its own base mesh (its
    ``mesh:``), or a shape grammar's terminal shapes: ``(vertices, faces)``
    as :func:`subdivide` gives them."""
    v, idx, sizes = self._mesh(steps, timeout=timeout)
    return v, _faces_out(idx, sizes)


System.mesh = _system_mesh  # type: ignore[attr-defined]


# ---------------------------------------------------------------------------
# Meshes


def _faces_in(faces: Any) -> Tuple[_np.ndarray, _np.ndarray]:
    """Faces as flat indices and sizes: an m×k int array (triangles, quads),
    a list of index sequences (polygons of any size), or ``(padded, sizes)``
    (an m×k array padded with anything past each face's size)."""
    if isinstance(faces, tuple) and len(faces) == 2 and not _np.isscalar(faces[0]):
        padded = _np.asarray(faces[0])
        sizes = _np.asarray(faces[1], dtype=_np.int64)
        if padded.ndim == 2 and sizes.ndim == 1 and len(sizes) == len(padded):
            mask = _np.arange(padded.shape[1])[None, :] < sizes[:, None]
            return _np.ascontiguousarray(padded[mask], dtype=_np.int64), sizes
    if isinstance(faces, _np.ndarray) and faces.ndim == 2:
        arr = _np.ascontiguousarray(faces, dtype=_np.int64)
        sizes = _np.full(arr.shape[0], arr.shape[1], dtype=_np.int64)
        return arr.reshape(-1), sizes
    lists = [_np.asarray(f, dtype=_np.int64).reshape(-1) for f in faces]
    sizes = _np.array([len(f) for f in lists], dtype=_np.int64)
    flat = _np.concatenate(lists) if lists else _np.zeros(0, dtype=_np.int64)
    return _np.ascontiguousarray(flat), sizes


def _faces_out(indices: _np.ndarray, sizes: _np.ndarray):
    """An m×k int64 array when every face has k corners, else a list of
    int64 arrays (one per face)."""
    if len(sizes) == 0:
        return _np.zeros((0, 3), dtype=_np.int64)
    k = int(sizes[0])
    if bool(_np.all(sizes == k)):
        return indices.reshape(-1, k)
    return _np.split(indices, _np.cumsum(sizes)[:-1])


def padded(faces: Any, fill: int = -1) -> Tuple[_np.ndarray, _np.ndarray]:
    """Faces of mixed sizes as ``(padded, sizes)``: an m×k int64 array, each
    row a face padded with ``fill``, and each face's size."""
    idx, sizes = _faces_in(faces)
    k = int(sizes.max()) if len(sizes) else 0
    out = _np.full((len(sizes), k), fill, dtype=_np.int64)
    mask = _np.arange(k)[None, :] < sizes[:, None]
    out[mask] = idx
    return out, sizes


def subdivide(
    vertices: Any,
    faces: Any,
    grammar: Union[str, "_os.PathLike[str]"],
    steps: Optional[int] = 1,
    *,
    defines: Optional[Union[Dict[str, Any], Sequence[str]]] = None,
    timeout: Optional[float] = None,
):
    """Subdivides a mesh with a surface grammar or vv program, as
    ``subgram subdivide MESH --grammar GRAMMAR -n STEPS`` does.

    ``vertices``: an n×3 array (float64). ``faces``: an m×k int array, a list
    of index sequences, or ``(padded, sizes)``. ``grammar``: a path to a
    ``.lsys`` surface grammar or vv program, or a built-in scheme name (see
    :func:`schemes`: ``"loop"``, ``"catmull-clark"``, ``"sqrt3"``, ...; the
    grammars of ``lsystems/surfaces``). ``steps=None``: the grammar's
    ``derivation length:`` (else 1).

    Returns ``(vertices, faces)``: float64 n×3, and faces as an m×k int64
    array when they all have k corners (triangles for Loop and sqrt3, quads
    for Catmull-Clark), else a list of int64 arrays; :func:`padded` turns
    that into ``(padded array, sizes)``.
    """
    v = _np.ascontiguousarray(vertices, dtype=_np.float64)
    if v.ndim != 2 or v.shape[1] != 3:
        raise ValueError(f"vertices: an n×3 array, not {v.shape}")
    idx, sizes = _faces_in(faces)
    names = _define_list(defines)
    out_v, out_idx, out_sizes = _subgram._subdivide(
        v, idx, sizes, _os.fspath(grammar), steps, names, timeout
    )
    return out_v, _faces_out(out_idx, out_sizes)


def mesh(path: Union[str, "_os.PathLike[str]"]):
    """Reads a mesh file (.obj, .off, .ply) as the CLI reads it:
    ``(vertices, faces)`` as :func:`subdivide` returns them."""
    v, idx, sizes = read_mesh(_os.fspath(path))
    return v, _faces_out(idx, sizes)


def write_mesh(path: Union[str, "_os.PathLike[str]"], vertices: Any, faces: Any) -> None:
    """Writes a mesh as the CLI writes it (.obj, .off or .ply, by the
    extension)."""
    v = _np.ascontiguousarray(vertices, dtype=_np.float64)
    idx, sizes = _faces_in(faces)
    _subgram._write_mesh(_os.fspath(path), v, idx, sizes)


def render_mesh(
    vertices: Any,
    faces: Any,
    path: Optional[Union[str, "_os.PathLike[str]"]] = None,
    *,
    format: Optional[str] = None,
    size: Optional[Tuple[int, int]] = None,
    view: Optional[str] = None,
    wireframe: bool = True,
) -> Optional[bytes]:
    """Draws a mesh as ``subgram render MESH.obj -o OUT`` does (PNG or SVG;
    ``view``: iso, front, back, left, right, top or bottom): written to
    ``path``, or returned as bytes when ``path`` is None."""
    import tempfile

    fmt = (format or (_os.path.splitext(_os.fspath(path))[1][1:] if path is not None else "png")).lower()
    with tempfile.TemporaryDirectory(prefix="subgram-py-") as d:
        obj = _os.path.join(d, "mesh.obj")
        write_mesh(obj, vertices, faces)
        out = _os.fspath(path) if path is not None else _os.path.join(d, f"picture.{fmt}")
        _subgram._render_mesh_file(obj, out, size, view, wireframe)
        if path is not None:
            return None
        with open(out, "rb") as f:
            return f.read()


def _define_list(defines: Any) -> List[str]:
    if defines is None:
        return []
    if isinstance(defines, dict):
        out = []
        for k, val in defines.items():
            if isinstance(val, bool):
                val = int(val)
            out.append(f"{k}={val}")
        return out
    return [str(d) for d in defines]


# ---------------------------------------------------------------------------
# Reverse subdivision, inference, analysis


def reverse(
    points: Any,
    steps: int,
    *,
    open: bool = False,
    scheme: Optional[Union[str, "_os.PathLike[str]"]] = None,
    timeout: Optional[float] = None,
):
    """Reverse subdivision of a contour, as ``subgram reverse`` does
    (Chaikin's reverse by default; ``scheme``: a scheme file).

    ``points``: an n×2 array; the contour is closed unless ``open``.
    Returns ``(coarse, details)``: the coarse points (float64 m×2) and the
    details that restore the input exactly (the CLI's ``--details`` JSON as
    a dict; each level's ``"details"`` as a float64 k×2 array), with the
    CLI's ``--report`` under ``details["report"]``.
    """
    p = _np.ascontiguousarray(points, dtype=_np.float64)
    if p.ndim != 2 or p.shape[1] != 2:
        raise ValueError(f"points: an n×2 array, not {p.shape}")
    coarse, details_json, report_json = _subgram._reverse(
        p, int(steps), bool(open), None if scheme is None else _os.fspath(scheme), timeout
    )
    details = _json.loads(details_json) or {}
    for level in details.get("levels", []):
        level["details"] = _np.asarray(level["details"], dtype=_np.float64).reshape(-1, 2)
    details["report"] = _json.loads(report_json)
    return coarse, details


def infer(
    rows: Optional[Union[str, Sequence[Sequence[float]]]] = None,
    *,
    mask: Optional[Union[str, Sequence[float]]] = None,
    arity: Optional[int] = None,
    open: bool = False,
    reverse: bool = False,
    shift: Optional[int] = None,
    ordered: bool = False,
    rows_file: Optional[str] = None,
) -> Dict[str, Any]:
    """L-system productions from a subdivision matrix or mask, as
    ``subgram infer`` finds them (paper 002).

    ``rows``: the matrix as text (``"0.75 0.25; 0.25 0.75"``) or as a list
    of rows; ``mask``: a mask's weights instead. Returns a plain dict:
    ``{"program": the .lsys text the CLI prints, "groupings": the text of
    --list (every grouping)}``.
    """
    def text(m: Any, sep: str) -> Optional[str]:
        if m is None or isinstance(m, str):
            return m
        arr = _np.asarray(m, dtype=_np.float64)
        if arr.ndim == 1:
            return " ".join(repr(float(x)) for x in arr)
        return sep.join(" ".join(repr(float(x)) for x in row) for row in arr)

    args = dict(
        rows=text(rows, "; "),
        rows_file=rows_file,
        mask=text(mask, " "),
        arity=arity,
        open=open,
        reverse=reverse,
        shift=shift,
        ordered=ordered,
    )
    program = _subgram._infer(list=False, **args)
    try:
        groupings = _subgram._infer(list=True, **args)
    except Error:
        groupings = None
    return {"program": program, "groupings": groupings}


def analyze(
    path: Union[str, "_os.PathLike[str]"],
    *,
    defines: Optional[Union[Dict[str, Any], Sequence[str]]] = None,
    valences: Optional[Sequence[int]] = None,
) -> Dict[str, Any]:
    """What a subdivision scheme is, as ``subgram analyze --format json``
    reports it (its JSON parsed into a dict)."""
    out = _subgram._analyze(
        _os.fspath(path),
        _define_list(defines),
        None if valences is None else [int(v) for v in valences],
    )
    return _json.loads(out)
