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
# The extremes of scale the loader accepts, and a huge sweep: the fuzzer
# rarely rescales every coordinate of a file at once.
python3 - <<'PY'
import re
def scale(text, k):
    def line(l):
        if not l.startswith("markers = {"):
            return l
        def rep(m):
            if l[:m.start()].rstrip().endswith("dir ="):
                return m.group(0)
            return "[" + ", ".join(repr(float(x) * k) for x in m.group(1).split(",")) + "]"
        return re.sub(r"\[([^\[\]]*)\]", rep, l)
    return "\n".join(line(l) for l in text.splitlines()) + "\n"
for n in ["fourbar", "slider_crank", "trammel"]:
    text = open(f"../mechanisms/{n}.toml").read()
    for k, tag in [(1e45, "huge"), (1e-45, "tiny")]:
        for t in ["plan", "interpret"]:
            open(f"corpus/{t}/{n}_{tag}.toml", "w").write(scale(text, k))
sweep = open("../mechanisms/fourbar.toml").read().replace("to = 360.0", "to = 1e300")
open("corpus/interpret/fourbar_huge_sweep.toml", "w").write(sweep)
PY
for t in load_toml load_json plan interpret; do
    echo "corpus/$t: $(ls "corpus/$t" | wc -l) files"
done
