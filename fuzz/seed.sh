#!/bin/sh
# Seeds the fuzz corpora from the bundled mechanisms, so the fuzzer starts
# from valid files and reaches the planner and the interpreter at once:
# every mechanisms/**/*.toml, and its JSON conversion for the JSON loader
# (and for the planner and interpreter, whose targets read JSON when the
# text starts with `{`). Run from the repository root or from fuzz/.
set -eu
cd "$(dirname "$0")"
for t in load_toml load_json plan interpret; do mkdir -p "corpus/$t"; done
for f in ../mechanisms/*.toml ../mechanisms/*/*.toml ../tests/fixtures/*.toml; do
    [ -f "$f" ] || continue
    n=$(basename "$f" .toml)
    for t in load_toml plan interpret; do cp "$f" "corpus/$t/$n.toml"; done
    python3 -c '
import json, sys, tomllib
print(json.dumps(tomllib.load(open(sys.argv[1], "rb")), indent=1))
' "$f" > "corpus/load_json/$n.json"
done
# A few JSON files for the planner and the interpreter: the small classics.
for n in fourbar slider_crank inverted_slider_crank trammel sixbar_a; do
    for t in plan interpret; do cp "corpus/load_json/$n.json" "corpus/$t/$n.json"; done
done
for t in load_toml load_json plan interpret; do
    echo "corpus/$t: $(ls "corpus/$t" | wc -l) files"
done
