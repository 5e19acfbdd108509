#!/usr/bin/env python3
"""What compiling a generated module costs a user: peak memory and CPU time
of the one rustc run that compiles a user crate whose build.rs compiles a
mechanism file with `dofplan::build` (the README's build.rs), in a debug or
release build.

    cargo run --release -p dofplan-gen -- stress-chain 2000 > /tmp/chain_2000.toml
    tools/bench/build_cost.py /tmp/chain_2000.toml            # debug
    tools/bench/build_cost.py /tmp/chain_2000.toml --release

The crate is made in --dir (default /tmp/dofplan_build_cost), outside the
workspace, with path dependencies on this checkout's `compiler` and
`runtime` and the workspace's Cargo.lock. It is built with
CARGO_BUILD_JOBS=1 (one job, as on a small CI runner); this script is
cargo's RUSTC_WRAPPER and times only the rustc run whose crate is the user
crate's library (GNU time: maximum resident set size, user + system CPU).
The dependencies and the build script are built first, so a first run
takes several minutes more than the figure it prints.
"""

import argparse
import os
import shutil
import subprocess
import sys
import tempfile

CRATE = "build_cost_user"


def wrap(argv):
    """As RUSTC_WRAPPER: argv is rustc and its arguments."""
    log = os.environ["BUILD_COST_LOG"]
    if "--crate-name" in argv and argv[argv.index("--crate-name") + 1] == CRATE and "build.rs" not in argv:
        fmt = "%M KB peak, %U s user, %S s sys, %e s wall"
        # close_fds=False: rustc must inherit cargo's jobserver, or it runs
        # LLVM on every core and its peak is not the one-job build's.
        return subprocess.call(["/usr/bin/time", "-a", "-o", log, "-f", fmt] + argv, close_fds=False)
    return subprocess.call(argv, close_fds=False)


def main():
    if os.environ.get("BUILD_COST_LOG") and len(sys.argv) > 1 and not sys.argv[1].endswith(".toml"):
        sys.exit(wrap(sys.argv[1:]))
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("mechanism", help="the mechanism file the crate compiles")
    ap.add_argument("--release", action="store_true", help="a release build (default: debug)")
    ap.add_argument("--dir", default="/tmp/dofplan_build_cost", help="where the crate is made")
    args = ap.parse_args()
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    d = args.dir
    os.makedirs(os.path.join(d, "src"), exist_ok=True)
    shutil.rmtree(os.path.join(d, "mechanisms"), ignore_errors=True)
    os.makedirs(os.path.join(d, "mechanisms"))
    shutil.copy(args.mechanism, os.path.join(d, "mechanisms"))
    shutil.copy(os.path.join(root, "Cargo.lock"), d)
    with open(os.path.join(d, "Cargo.toml"), "w") as f:
        f.write(
            f'[package]\nname = "{CRATE}"\nversion = "0.1.0"\nedition = "2021"\npublish = false\n\n'
            "# Not a member of any workspace.\n[workspace]\n\n"
            f'[dependencies]\ndofplan-runtime = {{ path = "{root}/runtime" }}\n\n'
            f'[build-dependencies]\ndofplan = {{ path = "{root}/compiler", default-features = false }}\n'
        )
    with open(os.path.join(d, "build.rs"), "w") as f:
        f.write(
            "fn main() -> Result<(), Box<dyn std::error::Error>> {\n"
            '    dofplan::build::Config::new().compile_dir("mechanisms")?;\n    Ok(())\n}\n'
        )
    with open(os.path.join(d, "src", "lib.rs"), "w") as f:
        f.write('include!(concat!(env!("OUT_DIR"), "/mechanisms.rs"));\n')
    log = tempfile.NamedTemporaryFile(prefix="build_cost_", suffix=".log", delete=False).name
    env = dict(os.environ, CARGO_BUILD_JOBS="1", RUSTC_WRAPPER=os.path.abspath(__file__), BUILD_COST_LOG=log)
    env.pop("RUSTFLAGS", None)
    cmd = ["cargo", "build", "--offline"] + (["--release"] if args.release else [])
    # The library is rebuilt every run (its build script reruns when the
    # mechanism file changes; touching lib.rs covers the rest).
    os.utime(os.path.join(d, "src", "lib.rs"))
    done = subprocess.run(cmd, cwd=d, env=env)
    if done.returncode != 0:
        sys.exit(f"cargo build failed in {d}")
    with open(log) as f:
        lines = f.read().strip().splitlines()
    os.unlink(log)
    if not lines:
        sys.exit("the user crate's library was not rebuilt")
    peak_kb, rest = lines[-1].split(" KB peak, ")
    profile = "release" if args.release else "debug"
    print(f"{os.path.basename(args.mechanism)} {profile}: rustc peak {int(peak_kb) / 1024:.0f} MiB, {rest}")


if __name__ == "__main__":
    main()
