#!/usr/bin/env bash
# Every output a user sees, from one binary, into a folder; run it for two
# binaries and `diff -r` the folders to show that a refactor changed no
# output (issue 41): the word of every lsystems/ file and every lpfg
# program and vlab model of ../shared/corpus, its PNG and SVG pictures,
# the OBJ of every surface grammar, vv program and shape grammar, `check`
# of every bad input in tests/data/bad/, and every --help text. The
# binary must be named `subgram` (clap prints its name in the help).
# Usage: benches/same_outputs.sh PATH/TO/subgram OUTDIR   (from the clone's root)
set -u
BIN=$(realpath "$1"); rm -rf "$2"; mkdir -p "$2"; OUT=$(realpath "$2")
cd "$(dirname "$0")/.."
i=0
for f in $(find lsystems -name '*.lsys' | sort) $(ls ../shared/corpus/lpfg/*.l | sort) $(ls -d ../shared/corpus/vlab-models/*/ | sort); do
  i=$((i+1)); n=$(echo "$f" | tr '/.' '__')
  timeout 120 $BIN derive "$f" > $OUT/$n.word 2> $OUT/$n.derive.err; echo "rc=$?" >> $OUT/$n.derive.err
  timeout 120 $BIN render "$f" -o $OUT/$n.png > /dev/null 2> $OUT/$n.png.err; echo "rc=$?" >> $OUT/$n.png.err
  timeout 120 $BIN render "$f" -o $OUT/$n.svg > /dev/null 2> $OUT/$n.svg.err; echo "rc=$?" >> $OUT/$n.svg.err
done
for f in $(find lsystems/surfaces lsystems/vv lsystems/shapes -name '*.lsys' | sort); do
  n=$(echo "$f" | tr '/.' '__')
  timeout 120 $BIN render "$f" -o $OUT/$n.obj > /dev/null 2> $OUT/$n.obj.err; echo "rc=$?" >> $OUT/$n.obj.err
done
for f in $(find tests/data/bad tests/data/err -type f \( -name '*.lsys' -o -name '*.obj' -o -name '*.off' -o -name '*.ply' \) | sort); do
  n=$(echo "$f" | tr '/.' '__')
  case "$f" in
    *.lsys) timeout 60 $BIN check "$f" > $OUT/$n.check 2>&1 ;;
    *) timeout 60 $BIN mesh info "$f" > $OUT/$n.check 2>&1 ;;
  esac
  echo "rc=$?" >> $OUT/$n.check
done
$BIN --help > $OUT/help.txt 2>&1
for c in $($BIN --help | sed -n '/^Commands:/,/^Options:/p' | awk 'NF>0 && $1!="Commands:" && $1!="Options:" {print $1}'); do
  $BIN $c --help > $OUT/help-$c.txt 2>&1
done
$BIN mesh --help > $OUT/help-mesh.txt 2>&1
for c in info convert; do $BIN mesh $c --help > $OUT/help-mesh-$c.txt 2>&1; done
echo "files: $(ls $OUT | wc -l)"
