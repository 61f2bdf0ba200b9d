#!/usr/bin/env bash
# The Python package's checks, as .ci/run runs them: a fresh virtual
# environment in a temporary folder, `pip install .` from the root (maturin
# builds python/Cargo.toml in release), the pinned test requirements, the
# CLI built (`cargo build`, debug) for the tests to compare against, and
# pytest on python/tests. Needs python3 (3.9 or later) with venv, and cargo.
#
#   python/run_tests.sh            # everything
#   python/run_tests.sh -k derive  # pytest's arguments pass through
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
cd "$root"
python="${PYTHON:-python3}"
venv="$(mktemp -d "${TMPDIR:-/tmp}/subgram-py-venv.XXXXXX")"
trap 'rm -rf "$venv"' EXIT
"$python" -m venv "$venv"
"$venv/bin/python" -m pip install -q --upgrade pip
# The package, from the root (its extension built in release into
# python/target, which later runs reuse).
CARGO_TARGET_DIR="$root/python/target" "$venv/bin/python" -m pip install -q "$root"
"$venv/bin/python" -m pip install -q -r python/requirements-test.txt
# The kernel the notebook test runs in: this environment's Python.
"$venv/bin/python" -m ipykernel install --prefix "$venv" --name python3 >/dev/null
cargo build --quiet
export SUBGRAM_CLI="$root/target/debug/subgram"
export JUPYTER_PATH="$venv/share/jupyter"
# Tested from outside the source tree, so that `import subgram` is the
# installed package, not python/subgram without its extension.
cd "$venv"
"$venv/bin/python" -m pytest "$root/python/tests" -q -p no:cacheprovider "$@"
