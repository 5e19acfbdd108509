//! `dofplan synth`'s report, what both dimensions print alike: a
//! solution's error, parameters and constraints as JSON, the JSON
//! document, and the text's last lines (the other distinct solutions,
//! those left out, the search's cost).

use std::io::{self, Write};

use serde_json::{json, Map, Value};

use crate::format::rounded;
use crate::model::{Format, Model};
use crate::synth::search::Stop;
use crate::synth::solution::{ErrorStats, Solution, Synthesis};

/// A solution's written file loaded as any file is (the dimension read
/// off it), or the first diagnostic's message: what its picture is drawn
/// from.
pub fn load_solution(name: &str, solution: &Solution, format: Format) -> Result<Model, String> {
    crate::load_any_str(name, &solution.text, format).map_err(|e| {
        e.diagnostics
            .first()
            .map_or_else(String::new, |d| d.message.clone())
    })
}

fn error_json(e: &ErrorStats) -> Value {
    json!({ "sum_sq": e.sum_sq, "rms": e.rms, "max": e.max })
}

fn solution_json(s: &Synthesis, sol: &Solution) -> Value {
    let parameters: Map<String, Value> = (s.names.iter().zip(&sol.values))
        .map(|(n, v)| (n.clone(), json!(v)))
        .collect();
    let constraints: Vec<Value> = (sol.margins.iter())
        .map(|m| json!({ "name": m.name, "value": m.value, "margin": m.margin }))
        .collect();
    let mut v = json!({
        "error": error_json(&sol.error),
        "search_error": error_json(&sol.searched),
        "parameters": parameters,
        "constraints": constraints,
    });
    if let Some(inputs) = &sol.inputs {
        v["inputs"] = json!(inputs);
        v["order_kept"] = json!(sol.order_kept);
    }
    v
}

fn stop_words(stop: Stop) -> &'static str {
    match stop {
        Stop::Target => "the target error was reached",
        Stop::Time => "the time limit",
        Stop::Stagnation => "no progress",
        Stop::Cancelled => "cancelled",
        Stop::Budget => "the evaluation budget",
    }
}

/// Prints the synthesis as one JSON document: the best solution's fields,
/// the mechanism, the goal (`goal`, in words), what was varied, the
/// search's cost and every distinct solution.
pub fn write_json(mechanism: &str, goal: &str, s: &Synthesis, out: &mut dyn Write) -> io::Result<()> {
    let best = &s.solutions[0];
    let mut doc = solution_json(s, best);
    doc["mechanism"] = json!(mechanism);
    doc["goal"] = json!(goal);
    doc["varied"] = json!(s.varied.iter().map(|&k| s.names[k].clone()).collect::<Vec<_>>());
    doc["evaluations"] = json!(s.evaluations);
    doc["seconds"] = json!(s.seconds);
    doc["stopped"] = json!(stop_words(s.stop));
    doc["solutions"] = json!(s
        .solutions
        .iter()
        .map(|sol| solution_json(s, sol))
        .collect::<Vec<_>>());
    writeln!(
        out,
        "{}",
        serde_json::to_string_pretty(&doc).expect("JSON of plain values")
    )
}

/// Whether free timing's inputs pass the targets in their order (a line,
/// or nothing for given timing).
pub fn write_order(best: &Solution, out: &mut dyn Write) -> io::Result<()> {
    match best.order_kept {
        Some(true) => writeln!(out, "  the inputs found pass the targets in their order"),
        Some(false) => writeln!(out, "  the inputs found do not pass the targets in their order"),
        None => Ok(()),
    }
}

/// Each constraint's value at the solution, kept or broken, and its
/// margin: a line each.
pub fn write_margins(best: &Solution, out: &mut dyn Write) -> io::Result<()> {
    for c in &best.margins {
        let state = if c.margin >= 0.0 { "kept" } else { "BROKEN" };
        writeln!(
            out,
            "  {}: {} ({state}, margin {})",
            c.name,
            rounded(c.value, 4),
            rounded(c.margin, 4)
        )?;
    }
    Ok(())
}

/// The text's last lines: the other distinct solutions, the solutions
/// left out and why, and the search's cost.
pub fn write_tail(s: &Synthesis, out: &mut dyn Write) -> io::Result<()> {
    if s.solutions.len() > 1 {
        let others: Vec<String> = s.solutions[1..].iter().map(|o| short(o.error.sum_sq)).collect();
        writeln!(
            out,
            "other distinct solutions: sum of squares {}",
            others.join(", ")
        )?;
    }
    for r in &s.rejected {
        writeln!(out, "left out: {r}")?;
    }
    writeln!(
        out,
        "{} evaluations in {} s (stopped: {})",
        s.evaluations,
        rounded(s.seconds, 2),
        stop_words(s.stop)
    )
}

/// A sum of squares for people: four significant digits.
pub fn short(x: f64) -> String {
    if x == 0.0 {
        "0".into()
    } else if (1e-3..1e6).contains(&x.abs()) {
        rounded(x, (3 - x.abs().log10().floor() as i64).max(0) as usize)
    } else {
        format!("{x:.3e}")
    }
}
