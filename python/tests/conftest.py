"""Shared fixtures: the repository root and the CLI binary the API is
checked against (SUBGRAM_CLI, else target/debug/subgram, built by
`cargo build`)."""

import os
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def cli_path() -> Path:
    env = os.environ.get("SUBGRAM_CLI")
    if env:
        return Path(env)
    for p in (ROOT / "target" / "debug" / "subgram", ROOT / "target" / "release" / "subgram"):
        if p.exists():
            return p
    pytest.skip("no subgram binary: run `cargo build` (or set SUBGRAM_CLI)")


@pytest.fixture(scope="session")
def root() -> Path:
    return ROOT


@pytest.fixture(scope="session")
def cli():
    """cli(*args) → CompletedProcess of the binary, text mode."""
    binary = cli_path()

    def run(*args, check=True):
        r = subprocess.run(
            [str(binary), *map(str, args)],
            cwd=ROOT,
            capture_output=True,
            text=True,
        )
        if check and r.returncode != 0:
            raise AssertionError(f"subgram {' '.join(map(str, args))} failed:\n{r.stderr}")
        return r

    return run
