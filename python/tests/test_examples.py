"""The Dask sweep on a LocalCluster of two worker processes, and the
notebook run top to bottom."""

import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "python"


def test_sweep_on_a_local_cluster(tmp_path):
    pytest.importorskip("dask.distributed")
    pytest.importorskip("pandas")
    import pandas as pd

    out, png = tmp_path / "sweep.csv", tmp_path / "sweep.png"
    argv = ["--workers", "2", "--seeds", "6", "--p-branch", "0.5", "0.7", "--angle", "25",
            "--out", str(out), "--plot", str(png)]
    # Run as a user runs it: a script (its task function travels by value).
    r = subprocess.run([sys.executable, str(EXAMPLES / "sweep_dask.py"), *argv],
                       capture_output=True, text=True, timeout=240)
    assert r.returncode == 0, r.stderr
    assert "12 runs in" in r.stdout
    df = pd.read_csv(out)
    assert len(df) == 12
    assert set(df.columns) >= {"seed", "p_branch", "modules", "branches", "width", "height"}
    # The same run on a worker and here: the same statistics.
    row = df[(df.seed == 3) & (df.p_branch == 0.7)].iloc[0]
    sys.path.insert(0, str(EXAMPLES))
    try:
        import sweep_dask
    finally:
        sys.path.remove(str(EXAMPLES))
    here = sweep_dask.run_one(str(EXAMPLES / "bush.lsys"), 3, 0.7, 25.0)
    assert row["modules"] == here["modules"] and row["branches"] == here["branches"]
    assert png.read_bytes().startswith(b"\x89PNG")
    # More branching, more modules.
    means = df.groupby("p_branch")["modules"].mean()
    assert means[0.7] > means[0.5]


def test_notebook_runs_top_to_bottom():
    nbformat = pytest.importorskip("nbformat")
    nbclient = pytest.importorskip("nbclient")
    nb = nbformat.read(EXAMPLES / "tour.ipynb", as_version=4)
    client = nbclient.NotebookClient(
        nb, timeout=300, kernel_name="python3", resources={"metadata": {"path": str(EXAMPLES)}}
    )
    client.execute()
    outputs = [o for c in nb.cells if c.cell_type == "code" for o in c.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    pictures = [o for o in outputs if "image/png" in o.get("data", {})]
    assert len(pictures) >= 4
