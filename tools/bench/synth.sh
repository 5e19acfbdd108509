#!/usr/bin/env bash
# Path synthesis on the standard targets (tests/synth/targets, or $TARGETS):
# mkh_18 to the error of the linkage published with it (4.96e-3), ten seeds,
# the median and range of the time it takes; yu_20 for a fixed time, three
# seeds, the error reached, and for 60 s, one seed. Free timing, the crank turning fully; every
# error is the one recomputed from the file dofplan writes.
#   tools/bench/synth.sh [path/to/dofplan]   (default: target/release/dofplan)
set -euo pipefail
cd "$(dirname "$0")/../.."
BIN=${1:-target/release/dofplan}
TARGETS=${TARGETS:-tests/synth/targets}
[ -x "$BIN" ] || cargo build --release -q -p dofplan
field() { python3 -c "import json,sys; d=json.load(sys.stdin); print(d$1)"; }
echo "mkh_18, free timing, --full-turn, until sum of squares <= 4.96e-3:"
times=()
for seed in 1 2 3 4 5 6 7 8 9 10; do
  out=$("$BIN" synth mechanisms/fourbar.toml --marker coupler.P --path "$TARGETS/mkh_18.csv" \
        --full-turn --target 4.96e-3 --time-limit 30 --seed "$seed" --json)
  s=$(echo "$out" | field '["seconds"]'); e=$(echo "$out" | field '["error"]["sum_sq"]')
  echo "  seed $seed: $e in $s s"
  times+=("$s")
done
printf '%s\n' "${times[@]}" | sort -g | awk '{a[NR]=$1} END {printf "  median %.3f s (%.3f to %.3f)\n", (a[5]+a[6])/2, a[1], a[NR]}'
echo "yu_20, free timing, --full-turn, 10 s:"
for seed in 1 2 3; do
  out=$("$BIN" synth mechanisms/fourbar.toml --marker coupler.P --path "$TARGETS/yu_20.csv" \
        --full-turn --time-limit 10 --seed "$seed" --json)
  echo "  seed $seed: sum of squares $(echo "$out" | field '["error"]["sum_sq"]') in $(echo "$out" | field '["seconds"]') s"
done
echo "yu_20, free timing, --full-turn, 60 s:"
out=$("$BIN" synth mechanisms/fourbar.toml --marker coupler.P --path "$TARGETS/yu_20.csv" \
      --full-turn --time-limit 60 --seed 1 --json)
echo "  seed 1: sum of squares $(echo "$out" | field '["error"]["sum_sq"]') in $(echo "$out" | field '["seconds"]') s"
