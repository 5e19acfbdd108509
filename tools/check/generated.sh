#!/usr/bin/env bash
# The generated files in the tree are what their generators write: every
# script in tools/generate/ is run into a fresh temporary directory and each
# file it writes is compared byte for byte with the committed one. Fails on a
# difference, on a written file that is not committed, and on a generator
# that fails or writes nothing. Run from anywhere:
#   bash tools/check/generated.sh
# Needs python3 (standard library only). $PYTHON overrides the interpreter.
set -euo pipefail
cd "$(dirname "$0")/../.."

python=${PYTHON:-python3}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

compared=0
failed=0

fail() {
  echo "FAIL: $*" >&2
  failed=$((failed + 1))
}

# check NAME DEST [OUTPUT]: run tools/generate/NAME.py with OUTPUT (default:
# a fresh directory) as its argument, then compare every file it wrote with
# the same name in DEST.
check() {
  local name=$1 dest=$2 out=$tmp/$1
  mkdir -p "$out"
  local arg=${3:-$out}
  if ! "$python" "tools/generate/$name.py" "$arg" >"$tmp/$name.log" 2>&1; then
    fail "tools/generate/$name.py failed:"
    cat "$tmp/$name.log" >&2
    return
  fi
  local n=0 f committed
  while IFS= read -r f; do
    n=$((n + 1))
    committed=$dest/$(basename "$f")
    if [ ! -f "$committed" ] || { git rev-parse --is-inside-work-tree >/dev/null 2>&1 &&
      ! git ls-files --error-unmatch -- "$committed" >/dev/null 2>&1; }; then
      fail "tools/generate/$name.py writes $committed, which is not committed"
      continue
    fi
    compared=$((compared + 1))
    if ! cmp -s "$f" "$committed"; then
      fail "$committed is not what tools/generate/$name.py writes (- committed, + generated):"
      diff -u --label "$committed" --label "tools/generate/$name.py" "$committed" "$f" | head -40 >&2 || true
    fi
  done < <(find "$out" -type f | sort)
  if [ "$n" = 0 ]; then
    fail "tools/generate/$name.py wrote no file"
  fi
}

check mechanisms mechanisms
check stress mechanisms
check clusters mechanisms
check overconstrained mechanisms
check spatial mechanisms/spatial
check turn_table runtime/src/planar "$tmp/turn_table/turn_table.rs"

if [ "$failed" != 0 ]; then
  echo "$failed problem(s) in the generated files ($compared compared); regenerate them with tools/generate/ (see tools/README.md)" >&2
  exit 1
fi
echo "$compared generated files are what tools/generate/ writes"
