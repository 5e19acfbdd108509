//! The inputs' assembly ranges as `check` prints them in either dimension:
//! a line per input as text, an object by input name in JSON.

use super::precise;
use crate::analysis::ranges::{self, InputRanges};
use crate::model::{Input, InputKind};
use serde_json::{json, Value};
use std::io::{self, Write};

/// The assembly ranges of `check`: per input, where the mechanism
/// assembles with the others at 0, each end a break point with the step
/// that breaks beyond it.
/// `shown` gives the number `dofplan plan` lists a break's step under.
pub fn write_ranges(
    inputs: &[Input],
    ranges: &[InputRanges],
    shown: &dyn Fn(u32) -> usize,
    out: &mut dyn Write,
) -> io::Result<()> {
    if ranges.is_empty() {
        return Ok(());
    }
    writeln!(
        out,
        "  assembly ranges (each input alone, the others at 0; break points to 1e-9):"
    )?;
    for r in ranges {
        let input = &inputs[r.input];
        let unit = match input.kind {
            InputKind::Angle => "°",
            InputKind::Slide => "",
        };
        if r.full_turn() {
            writeln!(out, "    {}: turns fully", input.name)?;
            continue;
        }
        let end = |e: &ranges::End| match &e.brk {
            Some(b) => format!(
                "{}{unit} (step {} breaks beyond: {})",
                precise(e.at),
                shown(b.step),
                b.kind.describe()
            ),
            None => format!("{}{unit} (end of the range searched)", precise(e.at)),
        };
        let intervals: Vec<String> = r
            .intervals
            .iter()
            .map(|(a, b)| format!("from {} to {}", end(a), end(b)))
            .collect();
        writeln!(out, "    {}: {}", input.name, intervals.join("; "))?;
    }
    Ok(())
}

/// `"ranges"` of `check --json`: by input name, the intervals `[from, to]`.
pub fn ranges_json(inputs: &[Input], ranges: &[InputRanges]) -> Value {
    Value::Object(
        ranges
            .iter()
            .map(|r| {
                let intervals: Vec<Value> = r.intervals.iter().map(|(a, b)| json!([a.at, b.at])).collect();
                (inputs[r.input].name.clone(), json!(intervals))
            })
            .collect(),
    )
}
