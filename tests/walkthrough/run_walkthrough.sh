#!/usr/bin/env bash
# Runs docs/first-calibration.md: every ```sh block in order, as one script (a block may use
# what an earlier one wrote or defined), under `set -euo pipefail`, in a fresh temporary
# directory with the given eical first on PATH. Fails when any command fails; a command whose
# non-zero exit the walkthrough expects is written there as `eical ... || test $? -eq N`.
#
#   tests/walkthrough/run_walkthrough.sh build/ci/tools/eical
#
# Prints each block's wall time on stderr. The directory is removed on success and kept
# (and named) on failure.
set -euo pipefail

if [[ $# -ne 1 || ! -x "$1" ]]; then
  echo "usage: $0 EICAL_BINARY (the built eical, executable)" >&2
  exit 2
fi
eical_bin=$(readlink -f "$1")
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
doc=$(readlink -f "$here/../../docs/first-calibration.md")
[[ -f "$doc" ]] || { echo "$0: $doc not found" >&2; exit 2; }

# The script: each ```sh block, preceded by a line that names it and followed by its time.
script_text=$(awk -v doc="$doc" '
  BEGIN {
    print "set -euo pipefail"
    print "__us() { echo \"${EPOCHREALTIME/[.,]/}\"; }"
    print "__since() { local d=$(( $(__us) - $1 )); printf %d.%d $((d / 1000000)) $((d / 100000 % 10)); }"
    print "__t0=$(__us)"
    print "__block() { __n=$1; __start=$(__us); echo \"== block $1 (docs/first-calibration.md:$2)\" >&2; }"
    print "__done() { echo \"== block $__n: $(__since \"$__start\") s\" >&2; }"
  }
  /^```sh[[:space:]]*$/ { inside = 1; n++; printf "__block %d %d\n", n, NR; next }
  inside && /^```[[:space:]]*$/ { inside = 0; print "__done"; next }
  inside { print }
  END {
    if (inside) { print doc ": its sh block " n " is not closed" > "/dev/stderr"; exit 1 }
    if (n == 0) { print doc ": no sh block" > "/dev/stderr"; exit 1 }
    printf "echo \"== %d blocks, all done in $(__since \"$__t0\") s\" >&2\n", n
  }' "$doc")

work=$(mktemp -d "${TMPDIR:-/tmp}/eical-walkthrough.XXXXXX")
mkdir "$work/bin"
ln -s "$eical_bin" "$work/bin/eical"
script="$work/walkthrough.sh"
printf '%s\n' "$script_text" >"$script"

status=0
(cd "$work" && PATH="$work/bin:$PATH" bash "$script" </dev/null) || status=$?
if [[ $status -ne 0 ]]; then
  echo "FAIL: a command of docs/first-calibration.md failed (exit $status); its files are in $work" >&2
  exit 1
fi

# What the walkthrough promises to leave behind.
missing=0
for f in calibration.toml report-circle-1/report.html report-circle-1/result.json comp/comp.json \
  comp/linuxcnc/dmu50.ini comp/sinumerik/AX_EEC.INI comp/fanuc/pitch_error_table.txt history.db; do
  if [[ ! -s "$work/$f" ]]; then
    echo "FAIL: the walkthrough did not write $f" >&2
    missing=1
  fi
done
if [[ $missing -ne 0 ]]; then
  echo "its files are in $work" >&2
  exit 1
fi
rm -rf "$work"
echo "walkthrough docs/first-calibration.md: ok"
