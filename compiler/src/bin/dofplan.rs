//! The dofplan command line: check, explain, emit and simulate mechanism
//! files.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand, ValueEnum};
use codespan_reporting::diagnostic::{Diagnostic as Snippet, Label};
use codespan_reporting::files::SimpleFile;
use codespan_reporting::term::{self, termcolor};
use serde_json::{json, Map, Value};

use dofplan::analysis::rank::rank_mobility;
use dofplan::analysis::{analyse, Analysis, Class};
use dofplan::emit::emit;
use dofplan::interp::Interpreter;
use dofplan::model::{load_file, Location, MarkerId, Mechanism, ModelError, MAX_STEPS};
use dofplan::numeric::drag::Drag;
use dofplan::numeric::PureNewton;
use dofplan::plan::{num, Plan};
use dofplan::simulate::{marker_positions, run, sweep_inputs, Frame};
use dofplan::svg::{render, SvgOptions};
use dofplan_runtime::{BranchPolicy, BreakPolicy, FrameStatus, Options};

/// Plan, explain and simulate mechanisms.
#[derive(Parser)]
#[command(name = "dofplan", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Validate a file and report its mobility, classification and plan.
    Check {
        /// Mechanism file (TOML, or JSON with a .json extension).
        file: PathBuf,
    },
    /// Print the explained plan, one line per step.
    Plan {
        /// Mechanism file.
        file: PathBuf,
    },
    /// Print the generated Rust module of the plan.
    Emit {
        /// Mechanism file.
        file: PathBuf,
    },
    /// Drag a marker to a target point (the file's inputs are released): the
    /// mechanism follows with the least motion its joints allow.
    Drag {
        /// Mechanism file (it may have no inputs at all).
        file: PathBuf,
        /// The marker to drag, "body.marker".
        #[arg(long)]
        marker: String,
        /// The last target, "X,Y".
        #[arg(long, value_parser = parse_point, allow_hyphen_values = true)]
        to: [f64; 2],
        /// The first target, "X,Y" (default: the marker's drawn position).
        #[arg(long, value_parser = parse_point, allow_hyphen_values = true)]
        from: Option<[f64; 2]>,
        /// Number of targets, evenly spaced from --from to --to, both included.
        #[arg(long, default_value_t = 50, value_parser = steps_parser())]
        steps: usize,
        /// What to do when a target is out of reach: stretch (the default)
        /// relaxes the drag, so the marker comes as close as the joints allow
        /// — a one-DOF linkage then follows its own curve; limit stays at
        /// the last pose that met its target; search finds where the path to
        /// the target leaves the reachable set.
        #[arg(long, value_enum, default_value_t = PolicyArg::Stretch)]
        policy: PolicyArg,
        /// Print one JSON document {"frames": [...]} (as simulate's).
        #[arg(long, conflicts_with = "csv")]
        json: bool,
        /// Print CSV, one row per frame.
        #[arg(long)]
        csv: bool,
        /// Draw the poses and the dragged marker's path into this SVG file.
        #[arg(long, value_name = "OUT")]
        svg: Option<PathBuf>,
    },
    /// Run the file's sweep and print or draw every frame.
    Simulate {
        /// Mechanism file.
        file: PathBuf,
        /// Override the sweep's number of steps.
        #[arg(long, value_parser = steps_parser())]
        steps: Option<usize>,
        /// What to do when an input cannot be met.
        #[arg(long, value_enum, default_value_t = PolicyArg::Limit)]
        policy: PolicyArg,
        /// How intersections pick their root at move time.
        #[arg(long, value_enum, default_value_t = BranchArg::Keep)]
        branch: BranchArg,
        /// Which solver places the bodies: the closed-form plan, or pure
        /// Newton–Raphson (3 unknowns per mobile link, no analysis).
        #[arg(long, value_enum, default_value_t = SolverArg::Plan)]
        solver: SolverArg,
        /// Print one JSON document {"frames": [...]}.
        #[arg(long, conflicts_with = "csv")]
        json: bool,
        /// Print CSV, one row per frame.
        #[arg(long)]
        csv: bool,
        /// Draw the mechanism at several poses and the traces into this SVG file.
        #[arg(long, value_name = "OUT")]
        svg: Option<PathBuf>,
    },
}

#[derive(Clone, Copy, ValueEnum)]
enum PolicyArg {
    /// Stay at the last valid pose.
    Limit,
    /// Move to the break point (found to 1e-9).
    Search,
    /// Relax the failing step and report the residual.
    Stretch,
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
enum SolverArg {
    /// The plan: closed-form steps.
    Plan,
    /// Newton–Raphson on every mobile link, the baseline of Brunkhart's Figure 30.
    Newton,
}

impl From<PolicyArg> for BreakPolicy {
    fn from(p: PolicyArg) -> BreakPolicy {
        match p {
            PolicyArg::Limit => BreakPolicy::Limit,
            PolicyArg::Search => BreakPolicy::Search,
            PolicyArg::Stretch => BreakPolicy::Stretch,
        }
    }
}

#[derive(Clone, Copy, ValueEnum)]
enum BranchArg {
    /// Keep the branch of the drawn pose.
    Keep,
    /// Take the root nearest the previous frame.
    Nearest,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Command::Check { file } => check(&file),
        Command::Plan { file } => with_plan(&file, |_, plan| {
            print!("{}", plan.explain_all());
            ExitCode::SUCCESS
        }),
        Command::Emit { file } => with_plan(&file, |_, plan| {
            print!("{}", emit(plan));
            ExitCode::SUCCESS
        }),
        Command::Drag {
            file,
            marker,
            to,
            from,
            steps,
            policy,
            json,
            csv,
            svg,
        } => {
            let options = Options {
                breaking: policy.into(),
                ..Options::default()
            };
            drag(
                &file,
                &marker,
                from,
                to,
                steps,
                options,
                json,
                csv,
                svg.as_deref(),
            )
        }
        Command::Simulate {
            file,
            steps,
            policy,
            branch,
            solver,
            json,
            csv,
            svg,
        } => with_plan(&file, |m, plan| {
            let options = Options {
                breaking: policy.into(),
                branch: match branch {
                    BranchArg::Keep => BranchPolicy::Keep,
                    BranchArg::Nearest => BranchPolicy::Nearest,
                },
                ..Options::default()
            };
            simulate(m, plan, steps, options, solver, json, csv, svg.as_deref())
        }),
    }
}

/// Prints model errors, with source snippets where there are spans.
fn report_model_error(err: &ModelError) {
    let writer = termcolor::StandardStream::stderr(termcolor::ColorChoice::Auto);
    let config = term::Config::default();
    for d in &err.diagnostics {
        match &d.location {
            Location::Span(span) => {
                let file = SimpleFile::new(d.file.name.clone(), d.file.text.to_string());
                let mut labels = vec![Label::primary((), span.clone())];
                for n in &d.notes {
                    if let Location::Span(s) = &n.location {
                        labels.push(Label::secondary((), s.clone()).with_message(n.message.clone()));
                    }
                }
                // The plain "file:line:col" line first, so editors and
                // scripts can jump to it; the snippet follows.
                eprintln!("{}: error: {}", d.position(&d.location), d.message);
                let mut report = Snippet::error()
                    .with_message(d.message.clone())
                    .with_labels(labels);
                if let Some(help) = &d.help {
                    report = report.with_notes(vec![format!("help: {help}")]);
                }
                let _ = term::emit_to_write_style(&mut writer.lock(), &config, &file, &report);
            }
            _ => eprintln!("{d}"),
        }
    }
}

fn load(file: &Path) -> Result<Mechanism, ExitCode> {
    load_file(file).map_err(|e| {
        report_model_error(&e);
        ExitCode::FAILURE
    })
}

fn with_plan(file: &Path, f: impl FnOnce(&Mechanism, &Plan) -> ExitCode) -> ExitCode {
    let m = match load(file) {
        Ok(m) => m,
        Err(code) => return code,
    };
    let analysis = analyse(&m);
    match &analysis.plan {
        Ok(plan) => f(&m, plan),
        Err(e) => {
            eprintln!("{}: error: {e}", file.display());
            ExitCode::FAILURE
        }
    }
}

fn check(file: &Path) -> ExitCode {
    let m = match load(file) {
        Ok(m) => m,
        Err(code) => return code,
    };
    let Analysis {
        mobility: mob,
        plan,
        unused,
        ..
    } = analyse(&m);
    let fixed = m.bodies.iter().filter(|b| b.fixed).count();
    println!("{} ({})", m.name, file.display());
    println!(
        "  bodies: {} ({} fixed, {} mobile), joints: {}, constraints: {}, inputs: {}",
        m.bodies.len(),
        fixed,
        m.bodies.len() - fixed,
        m.joints.len(),
        m.constraints.len(),
        m.inputs.len()
    );
    for input in &m.inputs {
        println!(
            "    input {}: {} at joint {}",
            input.name,
            input.kind.name(),
            m.joints[input.joint].name
        );
    }
    let extra = if mob.constraint_equations > 0 {
        format!(" − {}", mob.constraint_equations)
    } else {
        String::new()
    };
    println!(
        "  mobility (Grübler): D = 3(L−1) − 2J{} = 3·{} − 2·{}{} = {}",
        if mob.constraint_equations > 0 {
            " − (constraint equations)"
        } else {
            ""
        },
        mob.links - 1,
        mob.joints,
        extra,
        mob.dof
    );
    let by_rank = rank_mobility(&m);
    println!(
        "  mobility (Jacobian rank at the drawn pose): {} unknowns − rank {} = {}",
        by_rank.unknowns, by_rank.rank, by_rank.dof
    );
    if by_rank.dof == mob.dof {
        println!("  Grübler's count and the Jacobian agree");
    } else {
        let dependent: usize = by_rank.redundant.iter().map(|(_, n)| n).sum();
        println!(
            "  they differ by {}: the mechanism is non-generic — {} equation(s) depend on the others, \
             which Grübler's count takes as independent",
            by_rank.dof - mob.dof,
            dependent
        );
    }
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
        println!(
            "  redundant (dependent on the joints before them in the file): {}",
            list.join(", ")
        );
    }
    if by_rank.dof < m.inputs.len() as i64 {
        println!(
            "  locked: the joints leave {} DOF for {} input(s), so the mechanism cannot move and driving it breaks \
             at once (inconsistent); remove a joint, or make a redundant link consistent (e.g. parallel)",
            by_rank.dof,
            m.inputs.len()
        );
    }
    for (body, n) in &by_rank.idle {
        println!("  idle: body {body} can move on its own ({n} DOF) while every other body stays put");
    }
    if by_rank.dof == mob.dof {
        println!(
            "  with {} input(s): {} ({} free DOF)",
            mob.inputs,
            mob.class().name(),
            mob.free()
        );
    } else {
        // A non-generic mechanism: the rank says how it really moves.
        let free = by_rank.dof - mob.inputs as i64;
        let class = match free {
            0 => Class::Well,
            f if f > 0 => Class::Under,
            _ => Class::Over,
        };
        println!(
            "  with {} input(s): {} by Grübler's count ({} free DOF), {} by the Jacobian's rank ({free} free DOF)",
            mob.inputs,
            mob.class().name(),
            mob.free(),
            class.name(),
        );
    }
    if m.inputs.is_empty() {
        // Valid: a file meant for dragging only.
        println!(
            "  plan: no inputs, so nothing to plan — drag a marker with `dofplan drag {} --marker BODY.MARKER --to X,Y`",
            file.display()
        );
        return ExitCode::SUCCESS;
    }
    let code = match &plan {
        Ok(p) => {
            let (u, e) = p.numeric_size();
            let kind = if p.clusters() == 0 {
                "closed form".to_string()
            } else {
                format!(
                    "mixed: {} numeric cluster(s) with {u} unknowns and {e} equations for Newton–Raphson",
                    p.clusters()
                )
            };
            println!(
                "  plan: {kind}, {} steps, {} branch slot(s) — `dofplan plan {}` explains it",
                p.steps.len(),
                p.branches.len(),
                file.display()
            );
            ExitCode::SUCCESS
        }
        Err(e) => {
            println!("  plan: {e}");
            ExitCode::FAILURE
        }
    };
    if !unused.is_empty() {
        println!(
            "  equations no step uses (redundant or on unplaced bodies): {}",
            unused.join(", ")
        );
    }
    code
}

/// What the output of a run of frames needs besides the frames: how to
/// name the inputs, how to explain a step, which markers to trace.
struct Report<'a> {
    m: &'a Mechanism,
    input_names: Vec<String>,
    explain: Box<dyn Fn(u32) -> String + 'a>,
    trace: Vec<MarkerId>,
}

fn status_json(r: &Report, status: &FrameStatus) -> (Value, Option<(&'static str, Value)>) {
    let brk = |b: &dofplan_runtime::Break| {
        json!({
            "step": b.step,
            "explanation": (r.explain)(b.step),
            "reason": b.kind.describe(),
            "gap": b.gap,
        })
    };
    let detail = match status {
        FrameStatus::Solved => None,
        FrameStatus::Limited { brk: b } => Some(("break", brk(b))),
        FrameStatus::Searched { brk: b, reached } => Some(("break", {
            let mut v = brk(b);
            v["reached"] = json!(reached);
            v
        })),
        FrameStatus::Stretched { step, residual } => Some((
            "stretch",
            json!({"step": step, "explanation": (r.explain)(*step), "residual": residual}),
        )),
    };
    (json!(status.name()), detail)
}

#[allow(clippy::too_many_arguments)]
fn simulate(
    m: &Mechanism,
    plan: &Plan,
    steps: Option<usize>,
    options: Options,
    solver: SolverArg,
    json: bool,
    csv: bool,
    svg: Option<&Path>,
) -> ExitCode {
    if m.sweep.is_none() {
        eprintln!("{}: error: the file has no [sweep] to simulate", m.source.name);
        eprintln!("  help: add [sweep] with input, from, to, steps (and optionally trace)");
        return ExitCode::FAILURE;
    }
    let requested = sweep_inputs(m, steps);
    let frames = match solver {
        SolverArg::Plan => run(Interpreter::new(plan.clone()), options, &requested),
        SolverArg::Newton => run(PureNewton::new(m), options, &requested),
    };
    let report = Report {
        m,
        input_names: m.inputs.iter().map(|i| i.name.clone()).collect(),
        explain: Box::new(move |step| match solver {
            SolverArg::Plan => plan.explain(step as usize),
            SolverArg::Newton => "Newton-Raphson on every mobile link".to_string(),
        }),
        trace: m.sweep.as_ref().map(|s| s.trace.clone()).unwrap_or_default(),
    };
    output(&report, &frames, json, csv, svg)
}

/// `--steps`: as many frames as a file's sweep may have (10^12 frames
/// would exhaust memory before the first is drawn).
fn steps_parser() -> clap::builder::RangedU64ValueParser<usize> {
    clap::builder::RangedU64ValueParser::new().range(1..=MAX_STEPS as u64)
}

/// Parses "X,Y" into a finite point.
fn parse_point(text: &str) -> Result<[f64; 2], String> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    let [x, y] = parts.as_slice() else {
        return Err(format!("expected X,Y (two numbers), got `{text}`"));
    };
    let x: f64 = x.parse().map_err(|_| format!("`{x}` is not a number"))?;
    let y: f64 = y.parse().map_err(|_| format!("`{y}` is not a number"))?;
    if !x.is_finite() || !y.is_finite() {
        return Err(format!("`{text}` is not a finite point"));
    }
    Ok([x, y])
}

#[allow(clippy::too_many_arguments)]
fn drag(
    file: &Path,
    marker: &str,
    from: Option<[f64; 2]>,
    to: [f64; 2],
    steps: usize,
    options: Options,
    json: bool,
    csv: bool,
    svg: Option<&Path>,
) -> ExitCode {
    let m = match load(file) {
        Ok(m) => m,
        Err(code) => return code,
    };
    let Some(id) = m.find_marker(marker) else {
        let names: Vec<String> = m.all_markers().map(|id| m.marker_name(id)).collect();
        eprintln!("{}: error: no marker `{marker}` to drag", file.display());
        eprintln!("  help: markers are: {}", names.join(", "));
        return ExitCode::FAILURE;
    };
    let solver = match Drag::new(&m, id) {
        Ok(d) => d,
        Err(e) => {
            eprintln!("{}: error: {e}", file.display());
            return ExitCode::FAILURE;
        }
    };
    let from = from.unwrap_or(m.marker(id).at);
    let steps = steps.max(1);
    let targets: Vec<Vec<f64>> = (0..steps)
        .map(|i| {
            let t = if steps == 1 {
                1.0
            } else {
                i as f64 / (steps - 1) as f64
            };
            vec![from[0] + t * (to[0] - from[0]), from[1] + t * (to[1] - from[1])]
        })
        .collect();
    let frames = run(solver, options, &targets);
    let report = Report {
        m: &m,
        input_names: vec![format!("{marker}.x"), format!("{marker}.y")],
        explain: Box::new(|_| format!("drag of {marker}")),
        trace: vec![id],
    };
    output(&report, &frames, json, csv, svg)
}

fn output(r: &Report, frames: &[Frame], json: bool, csv: bool, svg: Option<&Path>) -> ExitCode {
    let m = r.m;
    if json {
        let frames_json: Vec<Value> = frames
            .iter()
            .map(|f| {
                let mut o = Map::new();
                let named = |vals: &[f64]| -> Value {
                    Value::Object(
                        r.input_names
                            .iter()
                            .zip(vals)
                            .map(|(n, v)| (n.clone(), json!(v)))
                            .collect(),
                    )
                };
                o.insert("inputs".into(), named(&f.requested));
                o.insert("reached".into(), named(&f.inputs));
                let (status, detail) = status_json(r, &f.status);
                o.insert("status".into(), status);
                if let Some((k, v)) = detail {
                    o.insert(k.into(), v);
                }
                if let Some(n) = &f.numeric {
                    o.insert(
                        "newton".into(),
                        json!({
                            "outcome": format!("{:?}", n.outcome).to_lowercase(),
                            "iterations": n.iterations,
                            "residual": n.residual,
                            "rank": n.rank,
                        }),
                    );
                }
                o.insert(
                    "markers".into(),
                    Value::Object(
                        marker_positions(m, &f.poses)
                            .into_iter()
                            .map(|(k, p)| (k, json!(p)))
                            .collect(),
                    ),
                );
                Value::Object(o)
            })
            .collect();
        let doc = json!({ "mechanism": m.name, "frames": frames_json });
        println!(
            "{}",
            serde_json::to_string_pretty(&doc).expect("JSON of plain values")
        );
    } else if csv {
        print_csv(r, frames);
    } else if svg.is_none() {
        print_summary(r, frames);
    }
    if let Some(out) = svg {
        let text = render(m, frames, &r.trace, &SvgOptions::default());
        if let Err(e) = std::fs::write(out, text) {
            eprintln!("{}: error: cannot write the SVG: {e}", out.display());
            return ExitCode::FAILURE;
        }
        if !json && !csv {
            print_summary(r, frames);
            println!("wrote {}", out.display());
        }
    }
    ExitCode::SUCCESS
}

fn print_csv(r: &Report, frames: &[Frame]) {
    let m = r.m;
    let mut header = vec!["frame".to_string()];
    header.extend(r.input_names.iter().cloned());
    header.push("status".into());
    for id in m.all_markers() {
        let n = m.marker_name(id);
        header.push(format!("{n}.x"));
        header.push(format!("{n}.y"));
    }
    println!("{}", header.join(","));
    for (i, f) in frames.iter().enumerate() {
        let mut row = vec![i.to_string()];
        row.extend(f.requested.iter().map(|v| v.to_string()));
        row.push(f.status.name().to_string());
        for (_, p) in marker_positions(m, &f.poses) {
            row.push(p[0].to_string());
            row.push(p[1].to_string());
        }
        println!("{}", row.join(","));
    }
}

fn print_summary(r: &Report, frames: &[Frame]) {
    let count = |name: &str| frames.iter().filter(|f| f.status.name() == name).count();
    println!(
        "{}: {} frames — {} solved, {} limited, {} searched, {} stretched",
        r.m.name,
        frames.len(),
        count("solved"),
        count("limited"),
        count("searched"),
        count("stretched")
    );
    let mut last: Option<&str> = None;
    for (i, f) in frames.iter().enumerate() {
        let name = f.status.name();
        if name != "solved" && last != Some(name) {
            let detail = match &f.status {
                FrameStatus::Limited { brk } | FrameStatus::Searched { brk, .. } => format!(
                    "step {} broke ({}, gap {}): {}",
                    brk.step,
                    brk.kind.describe(),
                    num(brk.gap),
                    (r.explain)(brk.step)
                ),
                FrameStatus::Stretched { step, residual } => format!(
                    "step {step} stretched, residual {}: {}",
                    num(*residual),
                    (r.explain)(*step)
                ),
                FrameStatus::Solved => String::new(),
            };
            let inputs: Vec<String> = f.requested.iter().map(|v| num(*v)).collect();
            println!("  frame {i} (inputs {}): {name} — {detail}", inputs.join(", "));
        }
        last = Some(name);
    }
}
