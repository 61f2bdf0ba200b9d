"""subgram from Python: L-systems and subdivision grammars, numpy arrays out."""

import os
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

_Path = Union[str, "os.PathLike[str]"]
_Defines = Union[Mapping[str, Any], Sequence[str], None]
_Faces = Union[npt.NDArray[np.int64], List[npt.NDArray[np.int64]]]

__version__: str

class Error(Exception):
    """A subgram error: a program that does not check, a run that failed, a
    file that cannot be read. ``str(err)`` is what the CLI prints (what
    ``subgram check`` prints for a program with errors)."""

    path: Optional[str]
    """The file the error is about (the name given for program text), or None."""
    line: Optional[int]
    """The 1-based line of the first diagnostic, or None where unknown."""
    column: Optional[int]
    """The 1-based column (in characters), or None where unknown."""
    usage: bool
    """True for a request that cannot be carried out as asked (the CLI exits with 2)."""

class Word:
    """A derived word of modules. Its storage stays in Rust: ``params``,
    ``slots``, ``offsets`` and ``symbol_ids`` are numpy arrays made without
    a Python object per module."""

    def __len__(self) -> int:
        """The number of modules."""
    def __getitem__(self, i: int) -> Tuple[str, Tuple[Any, ...]]:
        """Module ``i`` as ``(symbol, params)``; vectors and structs as tuples."""
    @property
    def symbols(self) -> List[str]:
        """Each module's symbol (a list with one str per module)."""
    @property
    def ring(self) -> bool:
        """True for a ring L-system's word."""
    @property
    def step(self) -> int:
        """The derivation steps taken."""
    @property
    def alphabet(self) -> List[str]:
        """The name of each symbol id: ``symbol_ids`` indexes it."""
    @property
    def symbol_ids(self) -> npt.NDArray[np.uint16]:
        """Each module's symbol id (uint16), an index into ``alphabet``."""
    @property
    def slots(self) -> npt.NDArray[np.float64]:
        """Every module's parameter slots in order, one float64 array."""
    @property
    def offsets(self) -> npt.NDArray[np.int64]:
        """Where each module's slots start in ``slots``, then the end (n + 1 values)."""
    def params(self, symbol: str) -> npt.NDArray[np.float64]:
        """The parameters of the modules with ``symbol``: a float64 array,
        one row a module, one column a slot (a 2D vector takes two); NaN
        where a module has fewer slots than the widest. KeyError for a
        symbol the program does not have."""
    def counts(self) -> Dict[str, int]:
        """The number of modules of each symbol present."""
    def to_json(self) -> str:
        """The CLI's ``subgram derive --format json`` output (no final newline)."""
    def to_text(self) -> str:
        """The CLI's ``subgram derive`` output (no final newline)."""

class System:
    """A loaded ``.lsys`` file, model folder or program text."""

    @property
    def kind(self) -> str:
        """``"curve"``, ``"surface"``, ``"vv"`` or ``"shapes"``."""
    @property
    def path(self) -> Optional[str]:
        """The path it was loaded from; None for program text."""
    @property
    def seed(self) -> Optional[int]:
        """The seed given to ``load``."""
    @property
    def defines(self) -> List[str]:
        """The defines given to ``load``, as ``NAME=VALUE``."""
    @property
    def warnings(self) -> List[str]:
        """The checker's warnings, each as the CLI prints it."""
    def derive(
        self,
        steps: Optional[int] = None,
        *,
        seed: Optional[int] = None,
        max_modules: Optional[int] = None,
        timeout: Optional[float] = None,
    ) -> Word:
        """Derives a curve L-system's word as ``subgram derive`` does:
        ``steps`` (default the file's ``derivation length:``), seeded with
        ``seed`` (default the one given to ``load``). The GIL is released;
        Ctrl-C stops the run at its next step (KeyboardInterrupt)."""
    def render(
        self,
        path: Optional[_Path] = None,
        *,
        format: Optional[str] = None,
        size: Optional[Tuple[int, int]] = None,
        view: Optional[str] = None,
        steps: Optional[int] = None,
        seed: Optional[int] = None,
        solid: Optional[bool] = None,
        timeout: Optional[float] = 600.0,
    ) -> Optional[bytes]:
        """The picture ``subgram render`` draws (``format``: ``"png"`` or
        ``"svg"``, else the extension of ``path``): written to ``path``, or
        returned as bytes when ``path`` is None. ``size``: (width, height);
        ``view``: xy, xz, yz for curves, iso, front, ... for meshes;
        ``solid``: force the shaded 3D drawing (True) or the lines (False)."""
    def lines(
        self, steps: Optional[int] = None, *, seed: Optional[int] = None, timeout: Optional[float] = None
    ) -> List[npt.NDArray[np.float64]]:
        """A curve's turtle polylines (the interpreted word, as ``render``
        draws it), each an n×3 float64 array."""
    def bounds(
        self, steps: Optional[int] = None, *, seed: Optional[int] = None, timeout: Optional[float] = None
    ) -> Optional[Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]]:
        """The box around a curve's turtle lines, ``(lo, hi)``, or None when
        it draws none."""
    def mesh(
        self, steps: Optional[int] = None, *, timeout: Optional[float] = None
    ) -> Tuple[npt.NDArray[np.float64], _Faces]:
        """A surface grammar or vv program run on its own ``mesh:``, or a
        shape grammar's terminal shapes: ``(vertices, faces)`` as
        :func:`subdivide` returns them."""
    def _repr_png_(self) -> Optional[bytes]:
        """The PNG picture a notebook shows."""
    def _repr_svg_(self) -> Optional[str]:
        """Curves: the SVG picture a notebook shows."""

def load(
    path_or_text: Union[_Path, str],
    *,
    defines: _Defines = None,
    seed: Optional[int] = None,
    double: bool = False,
    name: Optional[str] = None,
) -> System:
    """Loads a ``.lsys`` file, an lpfg model folder, or program text (a
    string with a newline or ``;`` that names no file) with the CLI's
    loader. ``defines``: ``{"NAME": value}`` or ``["NAME=VALUE"]`` (the
    CLI's ``-D``); ``seed``: the CLI's ``--seed`` for every run; ``double``:
    ``float`` in double precision (``--double``); ``name``: the file name
    that messages give program text. Raises :class:`Error`."""

def check(path: str, *, defines: _Defines = None, double: bool = False) -> str:
    """What ``subgram check`` prints for a file that checks; raises
    :class:`Error` (its ``str`` what the CLI prints) for one that does not."""

def schemes() -> List[str]:
    """The built-in scheme names :func:`subdivide` takes."""

def read_mesh(path: str) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.int64], npt.NDArray[np.int64]]:
    """A mesh file as ``(vertices, flat indices, face sizes)``."""

def mesh(path: _Path) -> Tuple[npt.NDArray[np.float64], _Faces]:
    """Reads a mesh file (.obj, .off, .ply) as the CLI reads it."""

def write_mesh(path: _Path, vertices: Any, faces: Any) -> None:
    """Writes a mesh as the CLI writes it (.obj, .off or .ply)."""

def render_mesh(
    vertices: Any,
    faces: Any,
    path: Optional[_Path] = None,
    *,
    format: Optional[str] = None,
    size: Optional[Tuple[int, int]] = None,
    view: Optional[str] = None,
    wireframe: bool = True,
) -> Optional[bytes]:
    """Draws a mesh as ``subgram render MESH.obj -o OUT`` does: written to
    ``path``, or the PNG/SVG bytes when ``path`` is None."""

def padded(faces: Any, fill: int = -1) -> Tuple[npt.NDArray[np.int64], npt.NDArray[np.int64]]:
    """Faces as ``(padded m×k array, sizes)``."""

def subdivide(
    vertices: Any,
    faces: Any,
    grammar: _Path,
    steps: Optional[int] = 1,
    *,
    defines: _Defines = None,
    timeout: Optional[float] = None,
) -> Tuple[npt.NDArray[np.float64], _Faces]:
    """Subdivides a mesh as ``subgram subdivide MESH --grammar G -n STEPS``:
    ``grammar`` a surface grammar or vv program path, or a name of
    :func:`schemes`. Returns float64 n×3 vertices and the faces (an m×k
    int64 array, or a list of arrays for mixed polygons)."""

def reverse(
    points: Any,
    steps: int,
    *,
    open: bool = False,
    scheme: Optional[_Path] = None,
    timeout: Optional[float] = None,
) -> Tuple[npt.NDArray[np.float64], Dict[str, Any]]:
    """Reverse subdivision (``subgram reverse``): the coarse points and the
    details that restore the input (the ``--details`` JSON, levels' details
    as arrays, and the ``--report`` under ``"report"``)."""

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
    """Productions from a subdivision matrix or mask (``subgram infer``):
    ``{"program": text, "groupings": text of --list or None}``."""

def analyze(
    path: _Path,
    *,
    defines: _Defines = None,
    valences: Optional[Sequence[int]] = None,
) -> Dict[str, Any]:
    """``subgram analyze --format json``, parsed."""
