//! `dofplan check` of a spatial file: the mobility counted two ways,
//! redundant equations and idle freedoms, the plan and the inputs' assembly
//! ranges; as text or as one JSON object.

use crate::analysis::ranges::{spatial_assembly_ranges, InputRanges};
use crate::analysis::spatial::count::{count, Count};
use crate::analysis::spatial::{analyse, PlanError};
use crate::model::spatial::Mechanism;
use crate::plan::spatial::{step_number, Plan};
use crate::report::check::{redundant_json, write_json, write_rank_mobility};
use crate::report::ranges::{ranges_json, write_ranges};
use serde_json::{json, Value};
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
        write_json(out, &check_json(m, &c, &plan, ranges.as_deref()))?;
        return Ok(plan.is_ok());
    }
    write_counts(m, &c, out)?;
    match &plan {
        Ok(p) => {
            write_plan(m, p, ranges.as_deref(), out)?;
            Ok(true)
        }
        Err(e) => {
            writeln!(out, "  plan: {e}")?;
            Ok(false)
        }
    }
}

/// `dofplan check --json` of a spatial file: the counts, the plan's size
/// (or why there is none) and the inputs' assembly ranges.
fn check_json(
    m: &Mechanism,
    c: &Count,
    plan: &Result<Plan, PlanError>,
    ranges: Option<&[InputRanges]>,
) -> Value {
    let (steps, cu, ce) = match plan {
        Ok(p) => {
            let (u, e) = p.cluster_size();
            (p.steps.len(), u, e)
        }
        Err(_) => (0, 0, 0),
    };
    json!({
        "name": m.name,
        "dimension": 3,
        "bodies": m.bodies.len(),
        "moving": c.moving,
        "joints": m.joints.len(),
        "equations": c.equations,
        "mobility": {"grubler": c.grubler, "rank": c.mobility},
        "redundant_equations": c.redundant_equations,
        "redundant": redundant_json(&c.redundant),
        "idle_freedoms": c.idle_freedoms,
        "plan": match plan {
            Ok(p) => json!({
                "steps": steps,
                "cluster_unknowns": cu,
                "cluster_equations": ce,
                "checked_rows": p.redundant().iter().map(|(_, n)| n).sum::<usize>(),
                "idle": p.idle.iter().map(|(b, n, _)| json!({"body": p.bodies[*b], "freedoms": n})).collect::<Vec<_>>(),
            }),
            Err(e) => json!({"error": e.to_string()}),
        },
        "ranges": match ranges {
            Some(r) => ranges_json(&m.inputs, r),
            None => json!(null),
        },
    })
}

/// The report's head and counts: what the mechanism is made of, its
/// mobility counted two ways, its redundant rows and idle freedoms.
fn write_counts(m: &Mechanism, c: &Count, out: &mut dyn Write) -> io::Result<()> {
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
    crate::report::check::write_loads(&m.loads, out)?;
    writeln!(
        out,
        "  mobility (Grübler–Kutzbach): 6·{} − {} = {}",
        c.moving, c.equations, c.grubler
    )?;
    write_rank_mobility(out, 6 * c.moving, c.rank, c.mobility)?;
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
    )
}

/// The plan found: its kind and size, the bodies it leaves freedoms to,
/// and the inputs' assembly ranges.
fn write_plan(
    m: &Mechanism,
    p: &Plan,
    ranges: Option<&[InputRanges]>,
    out: &mut dyn Write,
) -> io::Result<()> {
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
    if let Some(r) = ranges {
        write_ranges(&m.inputs, r, &|id| step_number(id), out)?;
    }
    Ok(())
}
