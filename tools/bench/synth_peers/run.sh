#!/usr/bin/env bash
# Path synthesis side by side, in one run: dofplan synth, Pyslvs 22.7 (its DE,
# its defaults, its own objective), pylinkage 1.3.0 (SciPy DE and its PSO) and
# four-bar-rs 7.0.5 (its DE on its Fourier-descriptor objective), on
# tests/synth/targets/mkh_18.csv and yu_20.csv (free timing) and on
# given_fourbar18.csv (given timing; dofplan and pylinkage: the others have
# no given timing). Every tool's final four-bar is re-checked by dofplan's
# own simulation (recheck.py). Prints one table (also written to
# $PEERS_DIR/work/table.md, every run's record to results.json there).
#
#   tools/bench/synth_peers/run.sh [--quick] [path/to/dofplan]
#
# DOFPLAN (or the argument) is the dofplan binary; default target/release/dofplan,
# built if missing. PEERS_DIR (default /tmp/dofplan-peers) holds the peers'
# venvs, four-bar-peer's target dir and the work files; they are set up on
# the first run. Pyslvs and four-bar-rs are AGPL: they run from here only,
# never linked into anything shipped (README.md).
set -euo pipefail
HERE=$(cd "$(dirname "$0")" && pwd)
REPO=$(cd "$HERE/../../.." && pwd)
QUICK=()
BIN=${DOFPLAN:-}
for arg in "$@"; do
  case "$arg" in
    --quick) QUICK=(--quick) ;;
    -h|--help) sed -n '2,18p' "$0"; exit 0 ;;
    *) BIN=$arg ;;
  esac
done
PEERS_DIR=${PEERS_DIR:-/tmp/dofplan-peers}
mkdir -p "$PEERS_DIR"
PY310=${PY310:-$HOME/.pyenv/versions/3.10.13/bin/python}
PY311=${PY311:-$HOME/.pyenv/versions/3.11.7/bin/python}

# dofplan, as tools/bench/synth.sh
if [ -z "$BIN" ]; then
  BIN=$REPO/target/release/dofplan
  [ -x "$BIN" ] || (cd "$REPO" && cargo build --release -q -p dofplan)
fi
BIN=$(cd "$(dirname "$BIN")" && pwd)/$(basename "$BIN")

# Pyslvs 22.7.0: plain pip fails under today's Cython; this is the recipe
# that works (Cython 3.0.0b3, no build isolation, the cpow directive).
PS=$PEERS_DIR/pyslvs
if ! "$PS/venv/bin/python" -c "import pyslvs" 2>/dev/null; then
  echo "setting up Pyslvs 22.7.0 in $PS" >&2
  mkdir -p "$PS"
  "$PY310" -m venv "$PS/venv"
  "$PS/venv/bin/pip" install -q "cython==3.0.0b3" wheel setuptools numpy scipy lark-parser
  "$PS/venv/bin/pip" download -q --no-deps --no-binary :all: pyslvs==22.7.0 -d "$PS/dl"
  (cd "$PS" && tar xzf dl/pyslvs-22.7.0.tar.gz)
  sed -i "s/ext.cython_directives = {'binding': True, 'cdivision': True}/ext.cython_directives = {'binding': True, 'cdivision': True, 'cpow': True}/" \
    "$PS/pyslvs-22.7.0/setup.py"
  (cd "$PS/pyslvs-22.7.0" && nice ../venv/bin/pip install -q --no-build-isolation .)
  "$PS/venv/bin/python" -c "import pyslvs; print('pyslvs', pyslvs.__version__)" >&2
fi

# pylinkage 1.3.0 (numba for its compiled kernel, SciPy for its DE); this
# venv's python (3.11: tomllib) also runs bench.py and recheck.py (numpy).
PL=$PEERS_DIR/pylinkage
if ! "$PL/bin/python" -c "import pylinkage, numba, scipy" 2>/dev/null; then
  echo "setting up pylinkage 1.3.0 in $PL" >&2
  "$PY311" -m venv "$PL"
  "$PL/bin/pip" install -q pylinkage==1.3.0 numba scipy
fi

# four-bar-rs: its own crate, its own workspace and target dir.
FB=$PEERS_DIR/four-bar-target/release/four-bar-peer
(cd "$HERE/four-bar-peer" && CARGO_TARGET_DIR=$PEERS_DIR/four-bar-target nice cargo build --release -q)

echo "dofplan: $BIN ($("$BIN" --version)); this checkout: $(git -C "$REPO" rev-parse --short HEAD 2>/dev/null || echo '?')" >&2
exec "$PL/bin/python" "$HERE/bench.py" --dofplan "$BIN" \
  --pyslvs-python "$PS/venv/bin/python" --pylinkage-python "$PL/bin/python" \
  --four-bar "$FB" --work "$PEERS_DIR/work" "${QUICK[@]}"
