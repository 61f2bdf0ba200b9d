"""load / derive / Word against `subgram derive` (text and JSON)."""

import json

import numpy as np
import pytest

import subgram

CASES = [
    ("lsystems/curves/chaikin-13.lsys", 3, None, []),
    ("lsystems/abop/dragon.lsys", 8, None, []),
    ("lsystems/abop/bush.lsys", 3, None, []),
    ("lsystems/lplusc/table-tree.lsys", None, None, ["STEPS=5"]),
    ("examples/python/bush.lsys", None, 7, ["P_BRANCH=0.5"]),
]


def cli_args(path, steps, seed, defines):
    args = ["derive", path]
    if steps is not None:
        args += ["-n", steps]
    if seed is not None:
        args += ["--seed", seed]
    for d in defines:
        args += ["-D", d]
    return args


@pytest.mark.parametrize("path,steps,seed,defines", CASES)
def test_word_text_and_json_are_the_clis(root, cli, path, steps, seed, defines):
    system = subgram.load(str(root / path), seed=seed, defines=defines)
    word = system.derive(steps)
    # The CLI is run from the root with the relative path; the text and the
    # JSON do not name the file.
    text = cli(*cli_args(path, steps, seed, defines)).stdout
    assert word.to_text() + "\n" == text
    js = cli(*cli_args(path, steps, seed, defines), "--format", "json").stdout
    assert word.to_json() + "\n" == js
    parsed = json.loads(js)
    assert len(word) == len(parsed["modules"])
    assert word.symbols == [m["symbol"] for m in parsed["modules"]]
    assert word.ring == parsed["ring"]
    assert word.step == parsed["step"]


def test_params_are_the_json_params(root, cli):
    word = subgram.load(str(root / "lsystems/curves/chaikin-13.lsys")).derive(4)
    parsed = json.loads(cli("derive", "lsystems/curves/chaikin-13.lsys", "-n", 4, "--format", "json").stdout)
    p = word.params("P")
    want = np.array([m["params"][0] for m in parsed["modules"] if m["symbol"] == "P"])
    assert p.dtype == np.float64
    assert p.shape == want.shape
    assert np.array_equal(p, want)
    sym, params = word[0]
    assert sym == "P" and params == (tuple(want[0]),)
    assert word[-1][1] == (tuple(want[-1]),)
    with pytest.raises(IndexError):
        word[len(word)]
    with pytest.raises(KeyError):
        word.params("NoSuchModule")


def test_flat_storage(root):
    word = subgram.load(str(root / "examples/python/bush.lsys"), seed=3).derive()
    slots, offsets, ids = word.slots, word.offsets, word.symbol_ids
    assert len(offsets) == len(word) + 1 and offsets[-1] == len(slots)
    names = word.alphabet
    assert [names[i] for i in ids] == word.symbols
    i = word.symbols.index("I")
    assert slots[offsets[i]:offsets[i + 1]].tolist() == list(word[i][1])
    counts = word.counts()
    assert counts["I"] == len(word.params("I"))
    assert sum(counts.values()) == len(word)


def test_program_text_and_defines():
    text = "#define N 3\nmodule P(float);\nderivation length: N;\nAxiom: P(1);\nP(x) : produce P(x) P(x + 1);\n"
    word = subgram.load(text).derive()
    assert len(word) == 8
    assert subgram.load(text, defines={"N": 2}).derive().to_text() == "P(1) P(2) P(2) P(3)"
    assert len(subgram.load(text).derive(1)) == 2


def test_seed_changes_a_stochastic_run(root):
    s = subgram.load(str(root / "examples/python/bush.lsys"))
    a, b = s.derive(seed=1), s.derive(seed=2)
    assert a.to_text() != b.to_text()
    assert s.derive(seed=1).to_text() == a.to_text()


def test_derive_of_a_surface_is_a_type_error(root):
    with pytest.raises(TypeError):
        subgram.load(str(root / "lsystems/surfaces/loop.lsys")).derive()


def test_check_is_the_clis(root, cli):
    assert subgram.check(str(root / "lsystems/abop/dragon.lsys")).endswith(
        cli("check", str(root / "lsystems/abop/dragon.lsys")).stdout.strip().split(": ", 1)[1]
    )
