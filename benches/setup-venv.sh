#!/bin/sh
# Makes the virtual environment of the benches' Python scripts and installs
# benches/requirements.txt into it: `benches/setup-venv.sh [DIR]`
# (default .venv-benches at the top of the clone). Needs Python 3.11
# (`python3.11`, or `PYTHON=...`), which bpy requires.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
dir=${1:-"$here/../.venv-benches"}
py=${PYTHON:-python3.11}
if ! command -v "$py" >/dev/null 2>&1; then
    py=python3
fi
version=$("$py" -c 'import sys; print("%d.%d" % sys.version_info[:2])')
if [ "$version" != "3.11" ]; then
    echo "benches/setup-venv.sh: $py is Python $version; bpy needs 3.11 (set PYTHON=/path/to/python3.11)" >&2
    exit 1
fi
"$py" -m venv "$dir"
"$dir/bin/pip" install --upgrade pip
"$dir/bin/pip" install -r "$here/requirements.txt"
echo "ready: run the scripts with $dir/bin/python benches/SCRIPT.py"
