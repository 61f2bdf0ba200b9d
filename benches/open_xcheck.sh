#!/usr/bin/env bash
# Every open L-system that vlab ships for lpfg (issue 36), against lpfg
# itself: lpfg 9bf820d with vlab's own honda81 (../shared/tools/lpfg,
# under $LPFG_HOME) gives the word; subgram gives its word twice, with its
# built-in honda81 and with vlab's honda81 as a process (--env-process).
# Both must be lpfg's, every parameter within 1e-5 relative.
# Usage, from the clone's root (after cargo build --release):
#   benches/open_xcheck.sh VLAB_GIT_DIR
# VLAB_GIT_DIR: a git dir of github.com/AlgorithmicBotany/vlab.
set -u
VLAB=${1:?usage: benches/open_xcheck.sh VLAB_GIT_DIR}
LPFG_HOME=${LPFG_HOME:-/opt/lpfg}
ROOT=$(pwd); BIN=$ROOT/target/release/subgram
WORK=$(mktemp -d); trap 'rm -rf "$WORK"' EXIT
git -C "$VLAB" archive HEAD oofs/ext/12-LPFG/ext/07-Open \
  oofs/ext/10-manuals/ext/20-EnviroPgms/ext/LPFG-FibonacciFlorets \
  oofs/ext/10-manuals/ext/20-EnviroPgms/ext/LPFG-Sierpinski-EA20 \
  oofs/ext/10-manuals/ext/20-EnviroPgms/ext/LPFG-Sierpinski | tar -x -C "$WORK"
compare() {
  python3 - "$1" "$2" <<'PY'
import re, sys
def mods(path):
    s = open(path).read().replace(", ", ",").replace("{", "").replace("}", "")
    out = []
    for t in s.split():
        m = re.match(r"^([^()]+)(?:\((.*)\))?$", t)
        out.append((m.group(1), [float(x) for x in m.group(2).split(",")] if m.group(2) else []))
    return out
a, b = mods(sys.argv[1]), mods(sys.argv[2])
bad = len(a) != len(b) or any(
    x[0] != y[0] or len(x[1]) != len(y[1])
    or any(abs(p - q) > 1e-5 * max(1, abs(p), abs(q)) for p, q in zip(x[1], y[1]))
    for x, y in zip(a, b))
print(f"{len(a)} modules, lpfg {len(b)}: {'DIFFERENT' if bad else 'same'}")
PY
}
for e in $(find "$WORK" -name '*.e' | sort); do
  d=$(dirname "$e"); l=$(ls "$d"/*.l | head -1); n=${d#"$WORK"/oofs/ext/}
  echo "== $n"
  LPFG_NO_IMAGE=1 "$ROOT/../shared/tools/lpfg/run_lpfg.sh" "$l" "$WORK/lpfg" > /dev/null 2>&1
  mkdir -p "$WORK/writes"
  "$BIN" derive "$d" --allow-writes "$WORK/writes" -o "$WORK/built-in.txt" 2> /dev/null
  echo -n "  built-in honda81:   "; compare "$WORK/built-in.txt" "$WORK/lpfg/string.txt"
  PATH="$LPFG_HOME/bin:$PATH" "$BIN" derive "$d" --env-process --allow-writes "$WORK/writes" \
    -o "$WORK/process.txt" 2> /dev/null
  echo -n "  vlab honda81 (process): "; compare "$WORK/process.txt" "$WORK/lpfg/string.txt"
  ls -a "$d" | grep -q '^\.\(to\|from\)_field' && echo "  LEFT: channel files in $d"
  rm -rf "$WORK/lpfg" "$WORK/writes"
done
