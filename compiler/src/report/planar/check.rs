//! `dofplan check` of a planar file: its mobility counted two ways,
//! its classification, its plan, the inputs' assembly ranges and the
//! Grashof classes of its four-bar loops; as text or as one JSON object.

use std::io::{self, Write};

use serde_json::json;

use crate::analysis::planar::grashof::{four_bars, Class as GrashofClass};
use crate::analysis::planar::rank::{idle_freedoms, rank_mobility_with, RankMobility};
use crate::analysis::ranges::assembly_ranges;
use crate::analysis::{analyse_with, Analysis, Class, Mobility, Progress};
use crate::model::Mechanism;
use crate::plan::{num, Plan};

use crate::report::check::{redundant_json, write_json, write_rank_mobility};
use crate::report::ranges::{ranges_json, write_ranges};

/// What `dofplan check` reports of a planar mechanism: its analysis (none
/// for a file without inputs, which is for dragging: its search for
/// numeric clusters is the costly part), its mobility by Grübler's count
/// and by the Jacobian's rank.
pub struct Check {
    analysis: Option<Analysis>,
    mobility: Mobility,
    by_rank: RankMobility,
}

impl Check {
    /// Analyses `m`, telling `progress` how far the analysis is (the CLI
    /// shows it for large files).
    pub fn of(m: &Mechanism, progress: &mut dyn FnMut(Progress)) -> Check {
        let analysis = (!m.inputs.is_empty()).then(|| analyse_with(m, progress));
        let mobility = analysis
            .as_ref()
            .map_or_else(|| Mobility::of(m), |a| a.mobility.clone());
        let by_rank = rank_mobility_with(m, progress);
        Check {
            analysis,
            mobility,
            by_rank,
        }
    }

    /// Writes the report of `m` (the mechanism this was made of), `place`
    /// naming its file (the editor shows it for a document that may have no
    /// file yet), as text or as one JSON object. `false` when the analysis
    /// found no plan (the command fails).
    pub fn write(self, m: &Mechanism, place: &str, json_out: bool, out: &mut dyn Write) -> io::Result<bool> {
        let Check {
            analysis,
            mobility: mob,
            by_rank,
        } = self;
        if json_out {
            return check_json(m, &mob, &by_rank, analysis.as_ref(), out);
        }
        write_counts(m, place, out)?;
        write_mobility(&mob, &by_rank, out)?;
        write_dependencies(m, &by_rank, out)?;
        write_class(&mob, &by_rank, out)?;
        let Some(Analysis { plan, unused, .. }) = analysis else {
            // Valid: a file meant for dragging only.
            writeln!(
                out,
                "  plan: no inputs, so nothing to plan — drag a marker with `dofplan drag {} --marker BODY.MARKER --to X,Y`",
                place
            )?;
            write_four_bars(m, out)?;
            return Ok(true);
        };
        let code = match &plan {
            Ok(p) => {
                write_plan(m, p, place, out)?;
                true
            }
            Err(e) => {
                writeln!(out, "  plan: {e}")?;
                false
            }
        };
        if !unused.is_empty() {
            writeln!(
                out,
                "  equations no step uses (redundant or on unplaced bodies): {}",
                unused.join(", ")
            )?;
        }
        write_four_bars(m, out)?;
        Ok(code)
    }
}

/// The report's head: the mechanism and its file, what it is made of, and
/// its inputs.
fn write_counts(m: &Mechanism, place: &str, out: &mut dyn Write) -> io::Result<()> {
    let fixed = m.bodies.iter().filter(|b| b.fixed).count();
    writeln!(out, "{} ({})", m.name, place)?;
    writeln!(
        out,
        "  bodies: {} ({} fixed, {} mobile), joints: {}{}, constraints: {}, inputs: {}",
        m.bodies.len(),
        fixed,
        m.bodies.len() - fixed,
        m.joints.len(),
        match (m.gears.len(), m.slots.len()) {
            (0, 0) => String::new(),
            (g, 0) => format!(" and {g} gear pair(s)"),
            (0, s) => format!(" and {s} slot(s)"),
            (g, s) => format!(", {g} gear pair(s) and {s} slot(s)"),
        },
        m.constraints.len(),
        m.inputs.len()
    )?;
    for input in &m.inputs {
        writeln!(
            out,
            "    input {}: {} at joint {}",
            input.name,
            input.kind.name(),
            m.joints[input.joint].name
        )?;
    }
    crate::report::check::write_loads(&m.loads, out)
}

/// The mobility counted two ways, by Grübler's formula and by the
/// Jacobian's rank, and whether they agree: where they do not, the
/// mechanism is non-generic.
fn write_mobility(mob: &Mobility, by_rank: &RankMobility, out: &mut dyn Write) -> io::Result<()> {
    // Gear pairs and slots are higher pairs: one equation each (H).
    let (gear_term, gears) = if mob.gears > 0 {
        (" − H", format!(" − {}", mob.gears))
    } else {
        (Default::default(), String::new())
    };
    let extra = if mob.constraint_equations > 0 {
        format!(" − {}", mob.constraint_equations)
    } else {
        String::new()
    };
    writeln!(
        out,
        "  mobility (Grübler): D = 3(L−1) − 2J{gear_term}{} = 3·{} − 2·{}{gears}{} = {}",
        if mob.constraint_equations > 0 {
            " − (constraint equations)"
        } else {
            ""
        },
        mob.links - 1,
        mob.joints,
        extra,
        mob.dof
    )?;
    write_rank_mobility(out, by_rank.unknowns, by_rank.rank, by_rank.dof)?;
    if by_rank.dof == mob.dof {
        writeln!(out, "  Grübler's count and the Jacobian agree")?;
    } else {
        let dependent: usize = by_rank.redundant.iter().map(|(_, n)| n).sum();
        writeln!(
            out,
            "  they differ by {}: the mechanism is non-generic — {} equation(s) depend on the others, \
             which Grübler's count takes as independent",
            by_rank.dof - mob.dof,
            dependent
        )?;
    }
    Ok(())
}

/// What the rank finds beyond the count: the redundant equations, a
/// mechanism locked with fewer freedoms than inputs, and idle bodies.
fn write_dependencies(m: &Mechanism, by_rank: &RankMobility, out: &mut dyn Write) -> io::Result<()> {
    if !by_rank.redundant.is_empty() {
        let list: Vec<String> = by_rank
            .redundant
            .iter()
            .map(|(o, n)| {
                if *n == 1 {
                    o.clone()
                } else {
                    format!("{o} ({n} equations)")
                }
            })
            .collect();
        writeln!(
            out,
            "  redundant (dependent on the joints before them in the file): {}",
            list.join(", ")
        )?;
    }
    if by_rank.dof < m.inputs.len() as i64 {
        writeln!(
            out,
            "  locked: the joints leave {} DOF for {} input(s), so the mechanism cannot move and driving it breaks \
             at once (inconsistent); remove a joint, or make a redundant link consistent (e.g. parallel)",
            by_rank.dof,
            m.inputs.len()
        )?;
    }
    for (body, n) in &by_rank.idle {
        writeln!(
            out,
            "  idle: body {body} can move on its own ({n} DOF) while every other body stays put"
        )?;
    }
    Ok(())
}

/// The class with the inputs given: by the count alone when the rank
/// agrees, else by both (the rank says how a non-generic mechanism really
/// moves).
fn write_class(mob: &Mobility, by_rank: &RankMobility, out: &mut dyn Write) -> io::Result<()> {
    if by_rank.dof == mob.dof {
        return writeln!(
            out,
            "  with {} input(s): {} ({} free DOF)",
            mob.inputs,
            mob.class().name(),
            mob.free()
        );
    }
    let free = by_rank.dof - mob.inputs as i64;
    let class = match free {
        0 => Class::Well,
        f if f > 0 => Class::Under,
        _ => Class::Over,
    };
    writeln!(
        out,
        "  with {} input(s): {} by Grübler's count ({} free DOF), {} by the Jacobian's rank ({free} free DOF)",
        mob.inputs,
        mob.class().name(),
        mob.free(),
        class.name(),
    )
}

/// The plan found: its kind and size, the steps that only check what
/// earlier ones decided, and the inputs' assembly ranges.
fn write_plan(m: &Mechanism, p: &Plan, place: &str, out: &mut dyn Write) -> io::Result<()> {
    let (u, e) = p.numeric_size();
    let kind = if p.clusters() == 0 {
        "closed form".to_string()
    } else {
        format!(
            "mixed: {} numeric cluster(s) with {u} unknowns and {e} equations for Newton–Raphson",
            p.clusters()
        )
    };
    writeln!(
        out,
        "  plan: {kind}, {} steps, {} branch slot(s) — `dofplan plan {}` explains it",
        p.steps.len(),
        p.branches.len(),
        place
    )?;
    // The DOF analysis's own view of redundancy, beside the rank's:
    // steps that can only check what earlier steps decided.
    let checks: Vec<String> = (p.steps.iter().enumerate())
        .filter(|(_, s)| s.kind.only_checks())
        .map(|(i, s)| format!("step {i} [{}]", s.serves.join(", ")))
        .collect();
    if !checks.is_empty() {
        writeln!(
            out,
            "  redundant by the plan (steps that only check a distance earlier steps decided): {}",
            checks.join("; ")
        )?;
    }
    write_ranges(&m.inputs, &assembly_ranges(m, p), &|id| id as usize, out)
}

/// The four-bar loops of `check` with their Grashof class (at most 12
/// listed; `--json` has them all).
fn write_four_bars(m: &Mechanism, out: &mut dyn Write) -> io::Result<()> {
    const LISTED: usize = 12;
    let loops = four_bars(m);
    for f in loops.iter().take(LISTED) {
        let names: Vec<&str> = f.bodies.iter().map(|&b| m.bodies[b].name.as_str()).collect();
        let (sl, pq) = f.sums;
        let relation = if f.class == GrashofClass::ChangePoint {
            "="
        } else if f.grashof {
            "<"
        } else {
            ">"
        };
        // Sums that print alike but differ (a loop a hair from its change
        // point, as synthesis can leave one) say by how much.
        let by = if relation != "=" && num(sl) == num(pq) {
            format!(", by {:.1e}", (sl - pq).abs())
        } else {
            String::new()
        };
        writeln!(
            out,
            "  four-bar {}: {} (s + l = {} {relation} p + q = {}{by}{})",
            names.join("–"),
            f.class.name(),
            num(sl),
            num(pq),
            if f.grashof || f.class == GrashofClass::ChangePoint {
                ""
            } else {
                "; non-Grashof: no link turns fully"
            }
        )?;
    }
    if loops.len() > LISTED {
        writeln!(
            out,
            "  … and {} more four-bar loops (`dofplan check --json` lists them all)",
            loops.len() - LISTED
        )?;
    }
    Ok(())
}

/// `dofplan check --json` of a planar file: the keys of the spatial report,
/// in the plane (3 unknowns per mobile body).
fn check_json(
    m: &Mechanism,
    mob: &Mobility,
    by_rank: &RankMobility,
    analysis: Option<&Analysis>,
    out: &mut dyn Write,
) -> io::Result<bool> {
    let plan = analysis.map(|a| &a.plan);
    let plan_json = match plan {
        None => json!(null),
        Some(Ok(p)) => {
            let (u, e) = p.numeric_size();
            json!({"steps": p.steps.len(), "cluster_unknowns": u, "cluster_equations": e})
        }
        Some(Err(e)) => json!({"error": e.to_string()}),
    };
    let value = json!({
        "name": m.name,
        "dimension": 2,
        "bodies": m.bodies.len(),
        "joints": m.joints.len(),
        "gears": m.gears.len(),
        "slots": m.slots.len(),
        "equations": by_rank.equations,
        "mobility": {"grubler": mob.dof, "rank": by_rank.dof},
        "redundant_equations": by_rank.equations - by_rank.rank,
        "redundant": redundant_json(&by_rank.redundant_rows),
        "idle_freedoms": idle_freedoms(m),
        "plan": plan_json,
        "ranges": match plan {
            Some(Ok(p)) => ranges_json(&m.inputs, &assembly_ranges(m, p)),
            _ => json!(null),
        },
        "grashof": four_bars(m).iter().map(|f| json!({
            "loop": f.bodies.iter().map(|&b| m.bodies[b].name.as_str()).collect::<Vec<_>>(),
            "class": f.class.name(),
            "grashof": f.grashof,
            "lengths": f.lengths,
        })).collect::<Vec<_>>(),
    });
    write_json(out, &value)?;
    Ok(!matches!(plan, Some(Err(_))))
}
