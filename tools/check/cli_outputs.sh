#!/usr/bin/env bash
# Every CLI output on every bundled file, written to a folder, so that two
# builds can be compared byte for byte (a redesign must leave them equal):
#   bash tools/check/cli_outputs.sh BIN OUT     # e.g. target/release/dofplan /tmp/before
#   diff -r /tmp/before /tmp/after
# Each command's stdout, stderr and exit code go to OUT/<file>/<command>.
# Pictures are written to a scratch folder first and then copied to OUT, so
# the path a command is given never shows in what is compared.
set -euo pipefail
bin=$(realpath "$1")
out=$(realpath -m "$2")
cd "$(dirname "$0")/../.."
rm -rf "$out"
mkdir -p "$out"
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT

# run NAME FILE ARGS...: `dofplan ARGS...`, recorded as OUT/FILE/NAME.
run() {
  local name=$1 file=$2
  shift 2
  local dir="$out/$file"
  mkdir -p "$dir"
  local code=0
  (cd "$scratch" && "$bin" "$@") >"$dir/$name.out" 2>"$dir/$name.err" || code=$?
  echo "$code" >"$dir/$name.code"
  if [ -f "$scratch/picture.svg" ]; then
    mv "$scratch/picture.svg" "$dir/$name.svg"
  fi
}

files=$(find mechanisms tests/fixtures compiler/tests/data -name '*.toml' -o -name '*.json' | grep -v '/rough/' | sort)
for f in $files; do
  p=$(realpath "$f")
  run check "$f" check "$p"
  run plan "$f" plan "$p"
  run emit "$f" emit "$p"
  run simulate "$f" simulate "$p"
  run simulate_search "$f" simulate "$p" --policy search --steps 41
  run simulate_stretch "$f" simulate "$p" --policy stretch --steps 41
  run simulate_csv "$f" simulate "$p" --csv --steps 21
  run simulate_json "$f" simulate "$p" --json --steps 21
  run simulate_svg "$f" simulate "$p" --steps 21 --svg picture.svg
  run analyze "$f" analyze "$p" --steps 21
  run analyze_csv "$f" analyze "$p" --steps 21 --csv
  run analyze_json "$f" analyze "$p" --steps 21 --json
  run analyze_svg "$f" analyze "$p" --steps 21 --svg picture.svg
done
for f in mechanisms/rough/*.toml; do
  run assemble "$f" assemble "$(realpath "$f")"
done
run fragments fragments fragments
echo "$(find "$out" -name '*.code' | wc -l) outputs written to $out"
