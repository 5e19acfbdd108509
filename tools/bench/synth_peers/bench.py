#!/usr/bin/env python3
"""Path synthesis side by side: dofplan, Pyslvs, pylinkage and four-bar-rs
in one run, every final four-bar re-checked by dofplan's own simulation.

Run by run.sh (which sets up the peers); see README.md for what each peer
runs.  Needs numpy (the pylinkage venv's python has it).

    bench.py --dofplan BIN --pyslvs-python PY --pylinkage-python PY
             --four-bar BIN --work DIR [--quick]
"""

import argparse
import json
import math
import os
import platform
import resource
import statistics
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.normpath(os.path.join(HERE, "..", "..", ".."))
sys.path.insert(0, HERE)
import recheck  # noqa: E402

TARGETS = [
    ("mkh_18", os.path.join(REPO, "tests", "synth", "targets", "mkh_18.csv"), "free"),
    ("yu_20", os.path.join(REPO, "tests", "synth", "targets", "yu_20.csv"), "free"),
    ("given_fourbar18", os.path.join(HERE, "given_fourbar18.csv"), "given"),
]
# The given-timing case starts dofplan from a drawing with every point moved
# off mechanisms/fourbar.toml (whose coupler point made the targets): the
# search's population is random in the box either way, but the start is not
# the answer.
MOVED_START = {"A": (0.5, 0.5), "B": (1.0, 1.8), "C": (3.5, 2.0), "D": (3.0, -0.5), "P": (2.0, 3.0)}

LOAD_AT_START = os.getloadavg()
FULL = dict(seeds=[1, 2, 3], dofplan_time=10, to_target_limit=60, fb_gen=200, fb_pop=400,
            pyslvs_gen=None, pl_de_maxiter=None, pl_pso_iterations=None, mkh_seeds=10)
QUICK = dict(seeds=[1], dofplan_time=3, to_target_limit=20, fb_gen=50, fb_pop=400,
             pyslvs_gen=200, pl_de_maxiter=100, pl_pso_iterations=50, mkh_seeds=3)


def log(*a):
    print(*a, file=sys.stderr, flush=True)


def run_json(cmd):
    """Run, return (parsed JSON, (wall seconds, the process's CPU seconds: user + sys))."""
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    p = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    wall = (wall, (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime))
    if p.returncode != 0:
        raise RuntimeError("%s failed (%d): %s" % (" ".join(cmd), p.returncode,
                                                   p.stderr.strip()[-500:]))
    try:
        return json.loads(p.stdout), wall  # dofplan: one (multi-line) document
    except json.JSONDecodeError:  # the peers: their last JSON line
        lines = [ln for ln in p.stdout.splitlines() if ln.strip().startswith("{")]
        return json.loads(lines[-1]), wall


class Bench:
    def __init__(self, a):
        self.a = a
        self.cfg = QUICK if a.quick else FULL
        self.work = a.work
        os.makedirs(self.work, exist_ok=True)
        self.records = []

    def path(self, name):
        return os.path.join(self.work, name)

    # -- re-check ---------------------------------------------------------

    def add(self, target, csv, tool, method, threads, run, res, pose_file, kind="fixed"):
        chk = recheck.recheck(self.a.dofplan, pose_file, csv)
        rec = dict(target=target, tool=tool, method=method, threads=threads, run=run, kind=kind,
                   objective=res.get("objective"), seconds=res.get("seconds"),
                   wall=res["wall"][0], cpu=res["wall"][1], load1=os.getloadavg()[0],
                   file=pose_file, **chk)
        for k in ("evaluations", "stopped", "reached", "constraints_kept"):
            if k in res:
                rec[k] = res[k]
        self.records.append(rec)
        log("  %-12s %-22s run %-2s own %-11.4g E %-11.4g %6.2f s  full turn %s%s"
            % (target, tool + " " + method, run, rec["objective"] if rec["objective"] is not None
               else float("nan"), rec["E"], rec["seconds"], rec["full_turn"],
               "" if "constraints_kept" not in rec else "  (dofplan: constraints kept %s, %s evaluations)"
               % (rec["constraints_kept"], rec.get("evaluations"))))
        return rec

    # -- the tools ----------------------------------------------------------

    def dofplan(self, target, csv, timing, seed, time_limit, stop_at=None, tag="fixed"):
        start = os.path.join(REPO, "mechanisms", "fourbar.toml")
        if timing == "given":
            start = recheck.write_fourbar(MOVED_START, self.path("start_moved.toml"),
                                          "the given-timing case's start drawing")
        out = self.path("dofplan_%s_%s_%d.toml" % (target, tag, seed))
        cmd = [self.a.dofplan, "synth", start, "--marker", "coupler.P", "--path", csv,
               "--timing", timing, "--full-turn", "--time-limit", str(time_limit),
               "--seed", str(seed), "--json", "--out", out]
        if stop_at is not None:
            cmd += ["--target", repr(stop_at)]
        d, wall = run_json(cmd)
        # dofplan reports whether its best keeps --full-turn (margin >= 0): a
        # run that found no candidate keeping it returns its best breaking one.
        kept = all(c.get("margin", 0) >= 0 for c in d.get("constraints", []))
        res = {"objective": d["error"]["sum_sq"], "seconds": d["seconds"], "wall": wall,
               "evaluations": d.get("evaluations"), "stopped": d.get("stopped"),
               "constraints_kept": kept}
        if stop_at is not None:
            res["reached"] = kept and d["error"]["sum_sq"] <= stop_at
        method = "DE+LM, %g s" % time_limit if stop_at is None else "to E <= %.4g" % stop_at
        return self.add(target, csv, "dofplan", method, "all (2)", seed, res, out, kind=tag)

    def four_bar(self, target, csv, seed):
        cmd = [self.a.four_bar, csv, "--seed", str(seed), "--pop", str(self.cfg["fb_pop"]),
               "--gen", str(self.cfg["fb_gen"])]
        d, wall = run_json(cmd)
        pose = dict(zip(["A", "D", "B", "C", "P"], d["pose"]))
        f = recheck.write_fourbar(pose, self.path("fourbar_%s_%d.toml" % (target, seed)),
                                  "four-bar-rs, %s, seed %d" % (target, seed))
        res = {"objective": d["objective"], "seconds": d["seconds"], "wall": wall}
        return self.add(target, csv, "four-bar-rs", "DE pop %d, %d gen"
                        % (self.cfg["fb_pop"], self.cfg["fb_gen"]), "all (2)", seed, res, f)

    def pyslvs(self, target, csv, run):
        cmd = [self.a.pyslvs_python, os.path.join(HERE, "pyslvs_peer.py"), csv]
        if self.cfg["pyslvs_gen"] is not None:
            cmd += ["--max-gen", str(self.cfg["pyslvs_gen"])]
        d, wall = run_json(cmd)
        f = recheck.write_fourbar(d["pose"], self.path("pyslvs_%s_%d.toml" % (target, run)),
                                  "Pyslvs, %s, run %d" % (target, run))
        res = {"objective": d["objective"], "seconds": d["seconds"], "wall": wall,
               "evaluations": d["evaluations"]}
        s = d["settings"]
        rec = self.add(target, csv, "Pyslvs", "DE pop %d, %d gen" % (s["pop_num"], s["max_gen"]),
                       "1", run, res, f)
        time.sleep(1.1)  # Pyslvs seeds rand() from time(NULL): a new second, a new run
        return rec

    def pylinkage(self, target, csv, method, seed):
        cmd = [self.a.pylinkage_python, os.path.join(HERE, "pylinkage_peer.py"), csv,
               "--method", method, "--seed", str(seed)]
        if method == "de" and self.cfg["pl_de_maxiter"] is not None:
            cmd += ["--maxiter", str(self.cfg["pl_de_maxiter"])]
        if method == "pso" and self.cfg["pl_pso_iterations"] is not None:
            cmd += ["--iterations", str(self.cfg["pl_pso_iterations"])]
        d, wall = run_json(cmd)
        if d["pose"] is None:
            log("  pylinkage %s %s: no assembly at its own start" % (method, target))
            return None
        f = recheck.write_fourbar(d["pose"], self.path("pylinkage_%s_%s_%d.toml"
                                                       % (method, target, seed)),
                                  "pylinkage %s, %s, run %d" % (method, target, seed))
        res = {"objective": d["objective"], "seconds": d["seconds"], "wall": wall,
               "evaluations": d["evaluations"]}
        s = d["settings"]
        label = ("SciPy DE, maxiter %d" % s["maxiter"] if method == "de"
                 else "PSO %d x %d" % (s["n_particles"], s["iterations"]))
        return self.add(target, csv, "pylinkage", label, "1", seed, res, f)

    # -- the run ------------------------------------------------------------

    def main(self):
        cfg = self.cfg
        seeds = cfg["seeds"]
        for name, csv, timing in TARGETS:
            log("%s (%s timing):" % (name, timing))
            for s in seeds:
                self.dofplan(name, csv, timing, s, cfg["dofplan_time"])
            if timing == "free":
                for s in seeds:
                    self.four_bar(name, csv, s)
                for s in seeds:
                    self.pyslvs(name, csv, s)
            for s in seeds:
                self.pylinkage(name, csv, "de", s)
            for s in seeds:
                self.pylinkage(name, csv, "pso", s)
            peers = [r for r in self.records if r["target"] == name and r["tool"] != "dofplan"
                     and r["full_turn"] and math.isfinite(r["E"])]
            if peers:
                best = min(peers, key=lambda r: r["E"])
                for s in seeds:
                    self.dofplan(name, csv, timing, s, cfg["to_target_limit"], stop_at=best["E"],
                                 tag="to_target")
        # mkh_18 to the published linkage's error, as tools/bench/synth.sh
        log("mkh_18 to 4.96e-3, %d seeds:" % cfg["mkh_seeds"])
        for s in range(1, cfg["mkh_seeds"] + 1):
            self.dofplan("mkh_18", TARGETS[0][1], "free", s, 30, stop_at=4.96e-3, tag="published")
        with open(self.path("results.json"), "w") as f:
            json.dump(self.records, f, indent=1)
        self.report()

    # -- the table -----------------------------------------------------------

    def report(self):
        cfg = self.cfg
        out = []
        p = out.append
        p("## dofplan synth against its peers%s" % (" (--quick: reduced budgets)" if self.a.quick else ""))
        p("")
        p("%s, %d cpus, Python %s; load average (1, 5, 15 min) at the start %.2f %.2f %.2f, "
          "at the end %.2f %.2f %.2f" % (platform.platform(), os.cpu_count(),
                                         platform.python_version(), *LOAD_AT_START, *os.getloadavg()))
        p("E = sum over the targets of the squared distance to the nearest point of the coupler curve "
          "(free timing) or to the coupler point at the target's input (given timing), recomputed by "
          "dofplan simulate on %d crank steps from each tool's final four-bar; own = the tool's own "
          "objective; time = the tool's own search time (s); process CPU = user + system time of the tool's "
          "process (all threads; includes start-up and, for dofplan, verifying its file); runs: seeds for dofplan, four-bar-rs and "
          "SciPy DE, repeats for Pyslvs and PSO (unseeded)." % recheck.DENSE_STEPS)
        p("")
        p("| target | tool | method, budget | threads | runs | own objective, median | "
          "E (dofplan re-check), median | E min - max | time s, median | time min - max | "
          "process CPU s, median | full turn |")
        p("|---|---|---|---|---:|---:|---:|---|---:|---|---:|---|")
        fixed = [r for r in self.records if r["kind"] == "fixed"]
        groups = []
        for r in fixed:
            key = (r["target"], r["tool"], r["method"])
            if key not in groups:
                groups.append(key)
        for name, _, timing in TARGETS:
            for key in [g for g in groups if g[0] == name]:
                rs = [r for r in fixed if (r["target"], r["tool"], r["method"]) == key]
                es = [r["E"] for r in rs]
                ts = [r["seconds"] for r in rs]
                own = [r["objective"] for r in rs if r["objective"] is not None]
                p("| %s | %s | %s | %s | %d | %.4g | %.4g | %.4g - %.4g | %.2f | %.2f - %.2f | %.1f | %d/%d |" % (
                    name, key[1], key[2], rs[0]["threads"], len(rs),
                    statistics.median(own) if own else float("nan"),
                    statistics.median(es), min(es), max(es), statistics.median(ts), min(ts), max(ts),
                    statistics.median(r["cpu"] for r in rs), sum(r["full_turn"] for r in rs), len(rs)))
            if timing == "given":
                p("| %s | four-bar-rs | not run: its objective (Fourier descriptors of the curve's shape) "
                  "has no timing | | | | | | | | | |" % name)
                p("| %s | Pyslvs | not run: FPlanar gives every target its own angle variable "
                  "(free timing only) | | | | | | | | | |" % name)
        p("")
        p("dofplan to the best peer's E (`--target E --time-limit %d`, seeds %s):"
          % (cfg["to_target_limit"], ", ".join(map(str, cfg["seeds"]))))
        p("")
        p("| target | best peer run (E re-checked, its time) | dofplan time s per seed (reached?, evaluations) | "
          "dofplan median s | E re-checked, median | peer time / dofplan median |")
        p("|---|---|---|---:|---:|---:|")
        self.claims = {}
        for name, _, _ in TARGETS:
            peers = [r for r in fixed if r["target"] == name and r["tool"] != "dofplan"
                     and r["full_turn"] and math.isfinite(r["E"])]
            tt = [r for r in self.records if r["target"] == name and r["kind"] == "to_target"]
            if not peers or not tt:
                continue
            best = min(peers, key=lambda r: r["E"])
            times = [r["seconds"] if r.get("reached") else math.inf for r in tt]
            med = statistics.median(times)
            ratio = best["seconds"] / med if med > 0 else math.inf
            p("| %s | %s %s run %s: E %.4g in %.2f s | %s | %s | %.4g | %s |" % (
                name, best["tool"], best["method"], best["run"], best["E"], best["seconds"],
                ", ".join("%.2f (%s, %s)" % (r["seconds"], "yes" if r.get("reached") else "no",
                                              r.get("evaluations")) for r in tt),
                "%.2f" % med if math.isfinite(med) else "not reached",
                statistics.median(r["E"] for r in tt),
                "%.0fx" % ratio if math.isfinite(med) else "-"))
            self.claims[name] = (best, med, ratio, tt)
        p("")
        pub = [r for r in self.records if r["kind"] == "published"]
        if pub:
            ts = sorted(r["seconds"] if r.get("reached") else math.inf for r in pub)
            med = statistics.median(ts)
            evs = sorted(r["evaluations"] if r.get("reached") else math.inf for r in pub)
            p("mkh_18 until E <= 4.96e-3 (`--target 4.96e-3 --time-limit 30`, as tools/bench/synth.sh), "
              "%d seeds: times %s s (a run not reaching it counts as infinite); median %.3f s "
              "(%.3f to %.3f); median evaluations %.0f; re-checked E %.4g to %.4g; reached %d/%d." % (
                  len(pub), ", ".join("%.2f%s" % (r["seconds"], "" if r.get("reached") else " (not reached)")
                                      for r in pub), med, ts[0], ts[-1], statistics.median(evs),
                  min(r["E"] for r in pub), max(r["E"] for r in pub),
                  sum(bool(r.get("reached")) for r in pub), len(pub)))
            p("")
            p("- \"mkh_18 reaches ~4.96e-3 in <= 1 s median over 10 seeds\": **%s** (median %.3f s over %d seeds)"
              % ("holds" if med <= 1.0 and len(pub) >= 10 else
                 ("does not hold" if len(pub) >= 10 else "not decided (fewer than 10 seeds)"), med, len(pub)))
        for name in ("mkh_18", "yu_20"):
            if name not in self.claims:
                continue
            best, med, ratio, tt = self.claims[name]
            good = math.isfinite(med)
            p("- %s: \"a final error at least as good as the best peer's, reached at least 100x sooner\": "
              "as good: **%s**; 100x sooner: **%s** (best peer %s %.4g in %.2f s; dofplan median %s)" % (
                  name, "yes" if good else "no", "yes" if good and ratio >= 100 else "no",
                  best["tool"], best["E"], best["seconds"],
                  "%.2f s, %.0fx" % (med, ratio) if good else "not reached within the limit"))
        text = "\n".join(out)
        print(text)
        with open(self.path("table.md"), "w") as f:
            f.write(text + "\n")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--dofplan", required=True)
    ap.add_argument("--pyslvs-python", required=True)
    ap.add_argument("--pylinkage-python", required=True)
    ap.add_argument("--four-bar", required=True)
    ap.add_argument("--work", required=True)
    ap.add_argument("--quick", action="store_true")
    a = ap.parse_args()
    log("load average at start %.2f %.2f %.2f" % LOAD_AT_START)
    Bench(a).main()


if __name__ == "__main__":
    main()
