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
