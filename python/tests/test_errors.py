"""subgram.Error: the CLI's message, and where."""

import subprocess

import pytest

import subgram

BAD = "module P;\nAxiom: P;\nP -> Q;\n"


def test_error_message_and_place_are_the_clis(tmp_path, cli):
    f = tmp_path / "bad.lsys"
    f.write_text(BAD)
    with pytest.raises(subgram.Error) as e:
        subgram.load(str(f))
    r = cli("check", f, check=False)
    assert r.returncode == 1
    assert str(e.value) + "\n" == r.stderr
    assert e.value.path == str(f)
    assert (e.value.line, e.value.column) == (3, 6)
    assert isinstance(e.value, Exception)


def test_program_text_is_named(tmp_path):
    with pytest.raises(subgram.Error) as e:
        subgram.load(BAD, name="mine.lsys")
    assert str(e.value).startswith("mine.lsys:3:6: error: undeclared module `Q`")
    assert e.value.path == "mine.lsys" and e.value.line == 3


def test_missing_file(tmp_path, cli):
    missing = tmp_path / "nope.lsys"
    with pytest.raises(subgram.Error) as e:
        subgram.load(str(missing))
    r = cli("check", missing, check=False)
    assert str(e.value) + "\n" == r.stderr
    assert e.value.line is None and e.value.column is None


def test_run_errors_have_no_place_when_none(root):
    s = subgram.load(str(root / "lsystems/abop/dragon.lsys"))
    with pytest.raises(subgram.Error) as e:
        s.derive(2_000_000)
    assert e.value.usage
    assert e.value.line is None
    with pytest.raises(subgram.Error) as e:
        s.derive(30, max_modules=1000)
    assert str(e.value).startswith(("error: ", str(root)))


def test_bad_mesh_for_subdivide():
    import numpy as np

    v = np.zeros((3, 3))
    with pytest.raises(ValueError):
        subgram.subdivide(v, [[0, 1, 7]], "loop")
