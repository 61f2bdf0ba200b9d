"""reverse, infer and analyze against the CLI."""

import json

import numpy as np
import pytest

import subgram


def contour(n=96):
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    r = 1 + 0.3 * np.cos(5 * t)
    return np.stack([r * np.cos(t), r * np.sin(t)], axis=1)


@pytest.mark.parametrize("open_", [False, True])
def test_reverse_is_the_clis_csv(cli, tmp_path, open_):
    pts = contour()
    inp = tmp_path / "in.csv"
    inp.write_text("x,y\n" + "".join(f"{float(x)!r},{float(y)!r}\n" for x, y in pts))
    out, det = tmp_path / "coarse.csv", tmp_path / "details.json"
    args = ["reverse", inp, "-n", 3, "-o", out, "--details", det, "--report", "--format", "json"]
    if open_:
        args.append("--open")
    r = cli(*args)
    coarse, details = subgram.reverse(pts, 3, open=open_)
    rows = [l.split(",") for l in out.read_text().splitlines()[1:]]
    want = np.array([[float(a), float(b)] for a, b in rows])
    assert np.array_equal(coarse, want)
    cli_details = json.loads(det.read_text())
    assert details["coarse_points"] == cli_details["coarse_points"] == len(coarse)
    for mine, theirs in zip(details["levels"], cli_details["levels"]):
        assert np.array_equal(mine["details"], np.array(theirs["details"]).reshape(-1, 2))
        assert mine["shift"] == theirs["shift"]
    report = json.loads(r.stdout)
    # The same report; only its description of the input differs (a file
    # for the CLI, an array here).
    assert details["report"].pop("source") == "points"
    report.pop("source")
    assert details["report"] == report


def test_infer_is_the_clis(cli):
    rows = "1/4 3/4 0; 0 3/4 1/4"
    got = subgram.infer(rows)
    assert got["program"] + "\n" == cli("infer", "--rows", rows).stdout
    assert got["groupings"] + "\n" == cli("infer", "--rows", rows, "--list").stdout
    mask = "-1/16 0 9/16 1 9/16 0 -1/16"
    assert subgram.infer(mask=mask)["program"] + "\n" == cli("infer", "--mask", mask).stdout
    assert isinstance(subgram.infer([[0.25, 0.75, 0], [0, 0.75, 0.25]])["program"], str)


def test_analyze_is_the_clis(root, cli):
    got = subgram.analyze(root / "lsystems/curves/chaikin-13.lsys")
    want = json.loads(cli("analyze", "lsystems/curves/chaikin-13.lsys", "--format", "json").stdout)
    assert got.pop("file") == str(root / "lsystems/curves/chaikin-13.lsys")
    assert want.pop("file") == "lsystems/curves/chaikin-13.lsys"
    assert got == want
    assert isinstance(got, dict)
