//! `dofplan check` of a spatial file: the mobility counted two ways,
//! redundant equations and idle freedoms, the plan and the inputs' assembly
//! ranges; as text or as one JSON object.

use crate::analysis::ranges::spatial_assembly_ranges;
use crate::analysis::spatial::{analyse, count::count};
use crate::model::spatial::Mechanism;
use crate::plan::spatial::step_number;
use crate::report::ranges::{ranges_json, write_ranges};
use serde_json::json;
use std::io::{self, Write};

/// `dofplan check` of a spatial file.
/// `false` when the analysis found no plan (the command fails).
pub fn check(m: &Mechanism, json_out: bool, out: &mut dyn Write) -> io::Result<bool> {
    let c = count(m);
    let plan = analyse(m);
    // Each input's assembly range, as planar `check` reports them (no
    // Grashof classes: those are planar four-bar notions).
    let ranges = plan.as_ref().ok().map(|p| spatial_assembly_ranges(m, p));
    if json_out {
        let (steps, cu, ce) = match &plan {
            Ok(p) => {
                let (u, e) = p.cluster_size();
                (p.steps.len(), u, e)
            }
            Err(_) => (0, 0, 0),
        };
        let value = json!({
            "name": m.name,
            "dimension": 3,
            "bodies": m.bodies.len(),
            "moving": c.moving,
            "joints": m.joints.len(),
            "equations": c.equations,
            "mobility": {"grubler": c.grubler, "rank": c.mobility},
            "redundant_equations": c.redundant_equations,
            "redundant": c.redundant.iter().map(|(o, p, n)| json!({
                "joint": o.split_once(' ').map_or(o.as_str(), |x| x.1),
                "origin": o,
                "primitive": p,
                "rows": n,
            })).collect::<Vec<_>>(),
            "idle_freedoms": c.idle_freedoms,
            "plan": match &plan {
                Ok(p) => json!({
                    "steps": steps,
                    "cluster_unknowns": cu,
                    "cluster_equations": ce,
                    "checked_rows": p.redundant().iter().map(|(_, n)| n).sum::<usize>(),
                    "idle": p.idle.iter().map(|(b, n, _)| json!({"body": p.bodies[*b], "freedoms": n})).collect::<Vec<_>>(),
                }),
                Err(e) => json!({"error": e.to_string()}),
            },
            "ranges": match &ranges {
                Some(r) => ranges_json(&m.inputs, r),
                None => json!(null),
            },
        });
        writeln!(
            out,
            "{}",
            serde_json::to_string_pretty(&value).unwrap_or_default()
        )?;
        return Ok(plan.is_ok());
    }
    writeln!(out, "{} ({}) — spatial", m.name, m.source.name)?;
    writeln!(
        out,
        "  bodies: {} ({} moving), joints: {}, constraints: {}, inputs: {}",
        m.bodies.len(),
        c.moving,
        m.joints.len(),
        m.constraints.len(),
        m.inputs.len()
    )?;
    writeln!(
        out,
        "  mobility (Grübler–Kutzbach): 6·{} − {} = {}",
        c.moving, c.equations, c.grubler
    )?;
    writeln!(
        out,
        "  mobility (Jacobian rank at the drawn pose): {} unknowns − rank {} = {}",
        6 * c.moving,
        c.rank,
        c.mobility
    )?;
    writeln!(
        out,
        "  redundant equations: {} − {} = {}",
        c.equations, c.rank, c.redundant_equations
    )?;
    for (o, p, n) in &c.redundant {
        writeln!(out, "    {o} {p}: {n} row{}", if *n == 1 { "" } else { "s" })?;
    }
    writeln!(
        out,
        "  idle freedoms (with the {} input(s) added): {}",
        c.inputs, c.idle_freedoms
    )?;
    match &plan {
        Ok(p) => {
            let (u, e) = p.cluster_size();
            let kind = if u == 0 {
                "closed form".to_string()
            } else {
                format!("mixed: numeric cluster(s) with {u} unknowns and {e} equations")
            };
            let checked: usize = p.redundant().iter().map(|(_, n)| n).sum();
            writeln!(
                out,
                "  plan: {kind}, {} steps, {} branch slot(s), {checked} row(s) only checked — `dofplan plan {}` explains it",
                p.steps.len(),
                p.branches.len(),
                m.source.name
            )?;
            for (b, n, why) in &p.idle {
                writeln!(
                    out,
                    "  idle: {} keeps {n} freedom(s) at minimum motion ({why})",
                    p.bodies[*b]
                )?;
            }
            if let Some(r) = &ranges {
                write_ranges(&m.inputs, r, &|id| step_number(id), out)?;
            }
            Ok(true)
        }
        Err(e) => {
            writeln!(out, "  plan: {e}")?;
            Ok(false)
        }
    }
}
