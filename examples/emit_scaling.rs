//! Emit time against size: stress chains of 10 to 2,000 four-bar loops,
//! loaded, planned and emitted in process; prints a Markdown table of medians of
//! three runs — wall time, and the process's CPU time (user + system, from
//! /proc on Linux), which a loaded machine inflates less — with the size of
//! the generated source and its largest function.
//! `cargo run --release --example emit_scaling [LOOPS...]`.

use std::time::Instant;

use dofplan::analysis::analyse;
use dofplan::emit::emit;
use dofplan::load_file;

/// CPU seconds this process has used (0 where /proc is missing).
fn cpu() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    // Fields after the command's closing parenthesis, from the state: utime
    // and stime are the 12th and 13th, in clock ticks (100 per second).
    let rest = stat.rsplit(')').next().unwrap_or("");
    let f: Vec<&str> = rest.split_whitespace().collect();
    let tick = |i: usize| f.get(i).and_then(|s| s.parse::<f64>().ok()).unwrap_or(0.0);
    (tick(11) + tick(12)) / 100.0
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let sizes: Vec<usize> = {
        let args: Vec<usize> = std::env::args().skip(1).filter_map(|a| a.parse().ok()).collect();
        if args.is_empty() {
            vec![10, 100, 500, 1000, 2000]
        } else {
            args
        }
    };
    println!(
        "| loops | steps | load s (wall / cpu) | plan s (wall / cpu) | emit s (wall / cpu) | lines | largest function (lines) |"
    );
    println!("|---:|---:|---:|---:|---:|---:|---:|");
    for loops in sizes {
        let path = std::env::temp_dir().join(format!("dofplan_emit_scaling_{loops}.toml"));
        std::fs::write(&path, dofplan_tests::stress::stress_chain(loops)).expect("write the chain");
        let (mut load_wall, mut load_cpu) = (vec![], vec![]);
        let mut m = None;
        for _ in 0..3 {
            let (t, c) = (Instant::now(), cpu());
            m = Some(load_file(&path).unwrap_or_else(|e| panic!("{e}")));
            load_wall.push(t.elapsed().as_secs_f64());
            load_cpu.push(cpu() - c);
        }
        let m = m.expect("loaded");
        let (mut plan_wall, mut plan_cpu, mut emit_wall, mut emit_cpu) = (vec![], vec![], vec![], vec![]);
        let mut source = String::new();
        let mut steps = 0;
        for _ in 0..3 {
            let (t, c) = (Instant::now(), cpu());
            let plan = analyse(&m).plan.unwrap_or_else(|e| panic!("{e}"));
            plan_wall.push(t.elapsed().as_secs_f64());
            plan_cpu.push(cpu() - c);
            let (t, c) = (Instant::now(), cpu());
            source = emit(&plan);
            emit_wall.push(t.elapsed().as_secs_f64());
            emit_cpu.push(cpu() - c);
            steps = plan.steps.len();
        }
        // Functions (at the top level, or alone in a chunk's module) start
        // with `fn`, `pub fn` or `pub(super) fn` and end at the `}` of
        // their indentation.
        let (mut largest, mut start) = (0, None);
        for (i, line) in source.lines().enumerate() {
            let body = line.trim_start();
            let indent = line.len() - body.len();
            if ["fn ", "pub fn ", "pub(super) fn "]
                .iter()
                .any(|f| body.starts_with(f))
            {
                start = Some((i, indent));
            } else if body == "}" {
                if let Some((s, _)) = start.filter(|&(_, at)| at == indent) {
                    largest = largest.max(i - s + 1);
                    start = None;
                }
            }
        }
        println!(
            "| {loops} | {steps} | {:.3} / {:.2} | {:.3} / {:.2} | {:.3} / {:.2} | {} | {largest} |",
            median(load_wall),
            median(load_cpu),
            median(plan_wall),
            median(plan_cpu),
            median(emit_wall),
            median(emit_cpu),
            source.lines().count()
        );
        let _ = std::fs::remove_file(&path);
    }
}
