//! What the planar and spatial `check` reports write alike: the mobility
//! by the Jacobian's rank, the dependent rows of `--json` and the JSON
//! object itself.

use std::io::{self, Write};

use serde_json::{json, Value};

/// The mobility line of the Jacobian's rank at the drawn pose.
pub(crate) fn write_rank_mobility(
    out: &mut dyn Write,
    unknowns: usize,
    rank: usize,
    dof: i64,
) -> io::Result<()> {
    writeln!(
        out,
        "  mobility (Jacobian rank at the drawn pose): {unknowns} unknowns − rank {rank} = {dof}"
    )
}

/// The dependent rows of `check --json`, one entry per (origin, primitive,
/// rows): the joint is named without its kind ("joint B" is "B").
pub(crate) fn redundant_json(rows: &[(String, String, usize)]) -> Vec<Value> {
    (rows.iter())
        .map(|(o, p, n)| {
            json!({
                "joint": o.split_once(' ').map_or(o.as_str(), |x| x.1),
                "origin": o,
                "primitive": p,
                "rows": n,
            })
        })
        .collect()
}

/// Writes the report of `check --json`, pretty-printed.
pub(crate) fn write_json(out: &mut dyn Write, value: &Value) -> io::Result<()> {
    writeln!(out, "{}", serde_json::to_string_pretty(value).unwrap_or_default())
}

/// The loads line of a file that gives masses, gravity or loads (nothing
/// otherwise): what `analyze --forces` will work from, so a reader of
/// `check` sees the file's loads were read.
pub(crate) fn write_loads<S: crate::model::loads::Space>(
    loads: &crate::model::loads::Loads<S>,
    out: &mut dyn Write,
) -> io::Result<()> {
    if loads.is_empty() {
        return Ok(());
    }
    let mut parts = Vec::new();
    if loads.gravity.is_some() {
        parts.push("gravity".to_string());
    }
    let masses = loads.masses.iter().flatten().count();
    if masses > 0 {
        parts.push(format!(
            "mass on {masses} bod{}",
            if masses == 1 { "y" } else { "ies" }
        ));
    }
    if !loads.applied.is_empty() {
        let named: Vec<String> = (loads.applied.iter())
            .map(|l| format!("{} {}", l.kind.name(), l.name))
            .collect();
        parts.push(format!(
            "{} ({})",
            plural(loads.applied.len(), "load"),
            named.join(", ")
        ));
    }
    writeln!(
        out,
        "  loads: {} — `analyze --forces` computes from them",
        parts.join(", ")
    )
}

/// "1 load", "3 loads".
fn plural(n: usize, what: &str) -> String {
    format!("{n} {what}{}", if n == 1 { "" } else { "s" })
}
