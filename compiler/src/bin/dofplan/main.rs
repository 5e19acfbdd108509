//! The dofplan command line: check, explain, emit, simulate and assemble
//! mechanism files.
//!
//! Output goes to standard output through one writer; a reader that goes
//! away (`dofplan simulate … | head`) ends the command quietly. Errors go to
//! standard error once each, coloured only on a terminal without
//! `NO_COLOR`.

use std::io::{self, BufWriter, IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Args, Parser, Subcommand, ValueEnum};

use dofplan::analysis::analyse_with;
use dofplan::assemble::assemble_file;
use dofplan::emit::emit;
use dofplan::model::Model;

use dofplan::model::{Mechanism, Sweep, MAX_STEPS};
use dofplan::plan::Plan;
use dofplan::report::forces::{Plots, Running};
use dofplan::report::planar::analyze;
use dofplan::report::planar::check::Check;
use dofplan::report::planar::frames::{self, Solver};
use dofplan::report::planar::sensitivity::{self, Study};
use dofplan::report::spatial as spatial_report;
use dofplan::report::spatial::analyze as spatial_analyze;
use dofplan::report::{Form, Outcome};
use dofplan::simulate::{sweep_to_run, SweepSource};
use dofplan_runtime::{BranchPolicy, BreakPolicy, Options, StartPolicy};

mod import;
mod progress;
mod synth;

mod edit;

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
        /// Print one JSON object instead of text (mobility, redundancy, idle freedoms, plan size).
        #[arg(long)]
        json: bool,
    },
    /// Print the spatial plan-fragment table the planner reads.
    Fragments,
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
        /// The last target, "X,Y" ("X,Y,Z" for a spatial file).
        #[arg(long, value_parser = parse_point, allow_hyphen_values = true)]
        to: Target,
        /// The first target, "X,Y" or "X,Y,Z" (default: the marker's drawn
        /// position).
        #[arg(long, value_parser = parse_point, allow_hyphen_values = true)]
        from: Option<Target>,
        /// Number of targets, evenly spaced from --from to --to, both included.
        #[arg(long, default_value_t = 50, value_parser = clap::value_parser!(u32).range(1..=MAX_STEPS))]
        steps: u32,
        /// What to do when a target is out of reach: stretch (the default)
        /// relaxes the drag, so the marker comes as close as the joints allow
        /// — a one-DOF linkage then follows its own curve; limit stays at
        /// the last pose that met its target; search finds where the path to
        /// the target leaves the reachable set.
        #[arg(long, value_enum, default_value_t = PolicyArg::Stretch)]
        policy: PolicyArg,
        /// Print one JSON document with simulate's fields (`dofplan simulate
        /// --help` lists them); the inputs are the target, "BODY.M.x" and
        /// "BODY.M.y".
        #[arg(long, conflicts_with = "csv")]
        json: bool,
        /// Print CSV, one row per frame (as simulate's).
        #[arg(long)]
        csv: bool,
        /// Draw the poses and the dragged marker's path into this SVG file.
        #[arg(long, value_name = "OUT")]
        svg: Option<PathBuf>,
    },
    /// Run the file's sweep, or one given here, and print or draw every
    /// frame.
    ///
    /// The sweep is the file's [sweep] with --input, --from, --to and
    /// --steps replacing its fields; a file without [sweep] is simulated
    /// with --from and --to (and --input when it has several inputs).
    /// Frames are written as they are solved.
    Simulate {
        /// Mechanism file.
        file: PathBuf,
        #[command(flatten)]
        sweep: SweepArgs,
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
        /// Print one JSON document, one frame a line (--help lists the fields).
        ///
        /// Top level: "mechanism" (its name) and "frames", one object per
        /// frame with:
        ///   "inputs"   the requested value of each input, by name;
        ///   "reached"  the input values of the pose shown (after a break:
        ///              the last valid values, or the break point under
        ///              search);
        ///   "status"   "solved", "limited", "searched", "stretched" or
        ///              "unreached" (the sweep started out of reach and
        ///              has no pose yet: "reached", "markers" and
        ///              "bodies" are null);
        ///   "break"    when limited, searched or unreached: step, explanation,
        ///              reason, gap (and "reached", the fraction of the way
        ///              to the request, under search);
        ///   "stretch"  when stretched: step, explanation, residual;
        ///   "newton"   when Newton–Raphson placed the frame: outcome,
        ///              iterations, residual, rank;
        ///   "markers"  every marker's world position [x, y], by
        ///              "body.marker";
        ///   "bodies"   every body's pose by name: "angle" (degrees from
        ///              the drawn pose, in (−180, 180]) and "x", "y" (where
        ///              the drawing's origin moved with the body), so a
        ///              point drawn at (px, py) is at (x + px·cos(angle) −
        ///              py·sin(angle), y + px·sin(angle) + py·cos(angle)).
        #[arg(long, conflicts_with = "csv", verbatim_doc_comment)]
        json: bool,
        /// Print CSV, one row per frame: frame, the requested inputs,
        /// status, every marker's x and y, then every body's angle, x and y
        /// (as in --json's "bodies").
        #[arg(long)]
        csv: bool,
        /// Draw the mechanism at several poses and the traces into this SVG file.
        #[arg(long, value_name = "OUT")]
        svg: Option<PathBuf>,
    },
    /// Run the sweep with exact velocities and accelerations (forward-mode
    /// differentiation through the plan, not finite differences): every
    /// marker's position, velocity and acceleration, every body's angular
    /// velocity and acceleration, and each four-bar loop's transmission
    /// angle.
    ///
    /// The sweep is simulate's (the file's [sweep] with --input, --from, --to
    /// and --steps replacing its fields); its first input moves at --rate,
    /// the others in proportion. A frame at a dead point, where a rate is
    /// infinite, reports its rates as singular (null in JSON, empty in CSV),
    /// never as a huge number. A planar numeric cluster's rates come from
    /// the implicit function theorem on its Jacobian (singular where it
    /// loses rank). Spatial files give 3-vectors (no transmission angle);
    /// a spatial plan with a numeric cluster runs with its positions only,
    /// its rates null ("unavailable" in JSON) as its rates are not computed
    /// yet.
    Analyze {
        /// Mechanism file.
        file: PathBuf,
        #[command(flatten)]
        sweep: SweepArgs,
        /// The first swept input's rate, constant: radians per second for an
        /// angle, length units per second for a slide [default: 1]. With
        /// --forces: run at this rate (kinetostatics: the bodies' inertia
        /// and the dampers count); without it, --forces is statics.
        #[arg(long, allow_hyphen_values = true, value_parser = parse_finite)]
        rate: Option<f64>,
        /// With --forces --rate: the first swept input's acceleration,
        /// constant (radians per second squared for an angle, length units
        /// for a slide; the others in proportion): the inertia of the
        /// speeding up or slowing down counts [default: 0].
        #[arg(long, value_name = "A", requires_all = ["forces", "rate"], allow_hyphen_values = true, value_parser = parse_finite)]
        acceleration: Option<f64>,
        /// One JSON document: simulate's frames plus "velocity" and
        /// "acceleration" (by "body.marker", like "markers"), "angular"
        /// (each body's "omega" and "alpha", radians per second and per
        /// second squared), "transmission" (each four-bar loop's angle in
        /// degrees) and "singular" at a dead point; "rates" at the top gives
        /// each input's rate (degrees per second for angles). Spatial:
        /// spatial simulate's frames with "velocity", "acceleration" and
        /// "angular" ("omega", "alpha" vectors) added.
        #[arg(long, conflicts_with = "csv")]
        json: bool,
        /// CSV, one row per frame: frame, inputs, status, every marker's x, y,
        /// vx, vy, ax, ay, every body's omega and alpha, each loop's
        /// transmission angle. Spatial: frame, status, inputs, every
        /// marker's x, y, z, vx, vy, vz, ax, ay, az, every body's omega and
        /// alpha (x, y, z), the residual.
        #[arg(long)]
        csv: bool,
        /// Draw plots into this SVG file: the traced markers' paths, their
        /// position, velocity and acceleration against the input, and the
        /// transmission angles with their extremes. Spatial: position,
        /// speed and acceleration magnitude against the input (`simulate
        /// --svg` draws the paths in space).
        #[arg(long, value_name = "OUT")]
        svg: Option<PathBuf>,
        /// Instead of rates: how each traced marker's path depends on the
        /// design parameters (every joint's drawn position, JOINT.x and
        /// JOINT.y (and JOINT.z in space), and every free marker's,
        /// body.marker.x): its exact derivative with respect to each over
        /// the sweep, the parameters ranked by their largest effect. With
        /// --json, every frame's derivatives. Planar and spatial files.
        #[arg(long, conflicts_with_all = ["csv", "svg"])]
        sensitivity: bool,
        /// Instead of rates: the force (slide) or torque (angle, per
        /// radian) each input must supply at every frame, from the file's
        /// masses, [gravity] and [loads.NAME], by virtual work with the
        /// plan's exact rates, and every joint's reaction from the bodies'
        /// equilibrium. Statics (held at each pose), or kinetostatics with
        /// --rate. A summary (each input's peak, the most loaded joint), or
        /// --json (simulate's frames with "input_force": input -> value,
        /// "reactions": joint -> [fx, fy] ([fx, fy, fz] in space), the
        /// force its first body exerts on its second, "reaction_moments"
        /// for the joints that carry one, "shaking") or --csv; --svg plots
        /// each input's force, each joint's reaction and one joint's
        /// reaction as a polar diagram. Planar and spatial files.
        #[arg(long, conflicts_with = "sensitivity")]
        forces: bool,
        /// With --forces --svg: the joint whose reaction the polar diagram
        /// draws [default: the most loaded].
        #[arg(long, value_name = "JOINT", requires_all = ["forces", "svg"])]
        polar: Option<String>,
        /// With --sensitivity: the worst-case first-order deviation of
        /// each traced marker when every parameter may be off by ±T
        /// (length units).
        #[arg(long, value_name = "T", requires = "sensitivity", allow_hyphen_values = true, value_parser = parse_positive)]
        tolerance: Option<f64>,
        /// With --tolerance: also run N candidates with every parameter
        /// drawn uniformly within ±T and report the largest and mean
        /// deviation they reach, beside the first-order bound.
        #[arg(long, value_name = "N", requires = "tolerance")]
        monte_carlo: Option<usize>,
        /// The Monte-Carlo candidates' seed (the same seed, the same
        /// candidates).
        #[arg(long, default_value_t = 1, requires = "monte_carlo")]
        seed: u64,
    },
    /// Open the mechanism in the interactive editor: a local web page that
    /// draws it, animates its inputs and lets any moving body be dragged.
    ///
    /// Serves on 127.0.0.1 only and prints the page's address, with its
    /// access token, as the first line of standard output; every request
    /// needs the token. Stop it with Ctrl+C.
    Edit {
        /// Mechanism file (planar; a spatial one is shown read-only);
        /// without it, an empty document (ground only). A file that does
        /// not exist yet is a new document saved under that name; one that
        /// does not load opens with its errors, to be fixed in the page.
        file: Option<PathBuf>,
        /// The port to listen on (default: a free one).
        #[arg(long)]
        port: Option<u16>,
        /// Also open the page in the default browser (xdg-open or open).
        #[arg(long)]
        open: bool,
    },
    /// Find dimensions: path, function or motion generation on the file's
    /// topology, by a global search over a box of joint positions polished
    /// with exact gradients; the best solutions verified from the file
    /// written.
    ///
    /// Path: `--marker BODY.M --path TARGET.csv [--timing given|free]`;
    /// function: `--function PAIRS.csv --output JOINT`; motion: `--motion
    /// POSES.csv --body NAME [--marker BODY.M]`. Every parameter the
    /// drawing has is varied unless `--vary` names some; the drawing must
    /// lie inside `--bounds`.
    Synth(Box<synth::SynthArgs>),
    /// Write a Pyslvs (PMKS) mechanism expression as a mechanism file.
    ///
    /// FILE holds the expression, `M[J[R, P[0, 0], L[ground, L1]], ...]`,
    /// optionally followed by its input pairs, `((0, 1),)`. Each point Pk
    /// becomes a marker Pk on every link it lists, and its joints; the
    /// header of the file written says how every name maps.
    Import(import::ImportArgs),
    /// Move every marker to where the joints close: author a file from
    /// approximate coordinates.
    ///
    /// Runs the least-squares assembly from the drawn pose and prints the
    /// file with the assembled coordinates (standard output), and how far
    /// each marker moved (standard error). Each mobile body moves rigidly:
    /// its markers keep their distances and angles, so draw every body with
    /// its true shape, roughly in place. Fixed bodies never move; inputs are
    /// free while assembling, so a crank may turn a little (in a spatial
    /// file they are held at their drawn values unless the joints cannot
    /// close so, and written axes turn with their bodies). The assembly
    /// starts from the drawn pose, so it is the nearest one, in the assembly
    /// mode drawn. Joints that cannot all close are an error naming them.
    Assemble {
        /// Mechanism file (TOML, or JSON with a .json extension).
        file: PathBuf,
        /// Write the result back into FILE instead of printing it. Only the
        /// numbers of a TOML file change (comments, order and layout are
        /// kept); a JSON file keeps its key order but is re-indented.
        #[arg(long)]
        write: bool,
    },
}

/// The sweep a command runs: the file's `[sweep]` with these replacing its
/// fields (`simulate`, `analyze`).
#[derive(Args)]
struct SweepArgs {
    /// The input to sweep (default: the sweep's, or the file's only
    /// input).
    #[arg(long, value_name = "NAME")]
    input: Option<String>,
    /// The swept input's first value (degrees for an angle input).
    #[arg(long, value_name = "A", value_parser = parse_finite, allow_hyphen_values = true)]
    from: Option<f64>,
    /// The swept input's last value.
    #[arg(long, value_name = "B", value_parser = parse_finite, allow_hyphen_values = true)]
    to: Option<f64>,
    /// Number of frames, evenly spaced from --from to --to, both
    /// included (default: the sweep's, or 101).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=MAX_STEPS))]
    steps: Option<u32>,
}

impl SweepArgs {
    /// The sweep to run on `m`, or `None` when there is none (said on
    /// standard error).
    fn of(&self, m: &dyn SweepSource) -> Option<Sweep> {
        let sweep = sweep_to_run(
            m,
            self.input.as_deref(),
            self.from,
            self.to,
            self.steps.map(|n| n as usize),
        );
        sweep
            .map_err(|(message, help)| error(m.file_name(), &message, &help))
            .ok()
    }
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

impl From<SolverArg> for Solver {
    fn from(s: SolverArg) -> Solver {
        match s {
            SolverArg::Plan => Solver::Plan,
            SolverArg::Newton => Solver::Newton,
        }
    }
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
    let stdout = io::stdout();
    // Line by line on a terminal, in blocks into a pipe or file.
    let mut out: Box<dyn Write> = if stdout.is_terminal() {
        Box::new(stdout.lock())
    } else {
        Box::new(BufWriter::new(stdout.lock()))
    };
    match run(cli.command, &mut out).and_then(|code| out.flush().map(|()| code)) {
        Ok(code) => code,
        // The reader has gone (`| head`): it wants nothing more, which is
        // not an error.
        Err(e) if e.kind() == io::ErrorKind::BrokenPipe => ExitCode::SUCCESS,
        Err(e) => {
            report(&format!("error: cannot write the output: {e}"));
            ExitCode::FAILURE
        }
    }
}

/// Runs one command, writing its output to `out`. An error about the input
/// is reported on standard error and gives a failing code; an `Err` is a
/// failure to write the output.
fn run(command: Command, out: &mut dyn Write) -> io::Result<ExitCode> {
    if let Some(m) = spatial_file(&command) {
        return spatial_command(command, &m, out);
    }
    match command {
        Command::Fragments => fragments(out),
        Command::Check { file, json } => check(&file, json, out),
        Command::Plan { file } => with_plan(&file, |_, plan| print(out, &plan.explain_all())),
        Command::Emit { file } => with_plan(&file, |_, plan| print(out, &emit(plan))),
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
            let place = file.display().to_string();
            let (Ok(to), Ok(from)) = (to.of(2, &place), from.map(|f| f.of(2, &place)).transpose()) else {
                return Ok(ExitCode::FAILURE);
            };
            let Some(m) = load(&progress::Bar::for_file(&file), &file) else {
                return Ok(ExitCode::FAILURE);
            };
            let options = Options {
                breaking: policy.into(),
                ..Options::default()
            };
            let mut bar = progress::Frames::default();
            outcome(frames::drag(
                &m,
                &place,
                &marker,
                from.map(|f| [f[0], f[1]]),
                [to[0], to[1]],
                steps as usize,
                options,
                Form::of(json, csv),
                svg.as_deref(),
                &mut bar,
                out,
            ))
        }
        Command::Simulate {
            file,
            sweep: sweep_args,
            policy,
            branch,
            solver,
            json,
            csv,
            svg,
        } => with_plan(&file, |m, plan| {
            let Some(sweep) = sweep_args.of(m) else {
                return Ok(ExitCode::FAILURE);
            };
            if solver == SolverArg::Newton && !m.gears.is_empty() {
                eprintln!(
                    "error: {}: `--solver newton` does not model gear pairs yet (gear pair {}); the plan does: leave `--solver` out",
                    m.source.name,
                    m.gear_names()
                );
                return Ok(ExitCode::FAILURE);
            }
            let options = sweep_options(policy, branch);
            let form = Form::of(json, csv);
            let mut bar = progress::Frames::default();
            outcome(frames::simulate(
                m,
                plan,
                &sweep,
                options,
                solver.into(),
                form,
                svg.as_deref(),
                &mut bar,
                out,
            ))
        }),
        command @ Command::Analyze { .. } => analyze_planar(command, out),
        Command::Assemble { file, write } => assemble(&file, write, out),
        Command::Edit { file, port, open } => edit::run(file.as_deref(), port, open, out),
        Command::Synth(args) => synth::run(*args, out),
        Command::Import(args) => import::run(args, out),
    }
}

/// The spatial mechanism a command's file holds, if it is one (loaded and
/// validated; a 3D file that fails validation is reported here).
fn spatial_file(command: &Command) -> Option<Result<dofplan::model::spatial::Mechanism, ()>> {
    let file = match command {
        Command::Check { file, .. }
        | Command::Plan { file }
        | Command::Emit { file }
        | Command::Simulate { file, .. }
        | Command::Analyze { file, .. }
        | Command::Drag { file, .. } => file,
        // A spatial drawing with open joints is what it assembles: it
        // loads the file itself (`assemble`).
        Command::Fragments
        | Command::Edit { .. }
        | Command::Assemble { .. }
        | Command::Synth(_)
        | Command::Import(_) => return None,
    };
    if !dofplan::model::is_spatial_file(file) {
        return None;
    }
    Some(match dofplan::load_any(file) {
        Ok(Model::Spatial(m)) => Ok(m),
        Ok(Model::Planar(_)) => return None,
        Err(e) => {
            report(&e.render(colour()));
            Err(())
        }
    })
}

/// Runs a command on a spatial file.
fn spatial_command(
    command: Command,
    m: &Result<dofplan::model::spatial::Mechanism, ()>,
    out: &mut dyn Write,
) -> io::Result<ExitCode> {
    let Ok(m) = m else {
        return Ok(ExitCode::FAILURE);
    };
    match command {
        Command::Check { json, .. } => Ok(exit(dofplan::report::spatial::check(m, json, out)?)),
        Command::Plan { .. } => Ok(match spatial_plan(m) {
            Some(plan) => {
                write!(out, "{}", plan.explain_all())?;
                ExitCode::SUCCESS
            }
            None => ExitCode::FAILURE,
        }),
        Command::Simulate { .. } => simulate_spatial(m, command, out),
        Command::Drag { .. } => drag_spatial(m, command, out),
        Command::Analyze {
            sensitivity: true,
            sweep: sweep_args,
            json,
            csv,
            tolerance,
            monte_carlo,
            seed,
            ..
        } => {
            let Some(sweep) = sweep_args.of(m) else {
                return Ok(ExitCode::FAILURE);
            };
            let study = Study {
                tolerance,
                monte_carlo,
                seed,
            };
            outcome(dofplan::report::spatial::sensitivity::run(
                m,
                &sweep,
                study,
                Form::of(json, csv),
                out,
            ))
        }
        Command::Analyze { .. } => analyze_spatial(m, command, out),
        Command::Emit { .. } => Ok(match spatial_plan(m) {
            Some(plan) => {
                write!(out, "{}", dofplan::emit::emit_spatial(&plan))?;
                ExitCode::SUCCESS
            }
            None => ExitCode::FAILURE,
        }),
        // Never a spatial file here (`spatial_file` leaves it to `assemble`).
        Command::Assemble { file, write } => assemble(&file, write, out),
        Command::Fragments => fragments(out),
        // Never a spatial file here (`spatial_file` leaves them to the
        // editor and synth).
        Command::Edit { file, port, open } => edit::run(file.as_deref(), port, open, out),
        Command::Synth(args) => synth::run(*args, out),
        Command::Import(args) => import::run(args, out),
    }
}

/// `dofplan simulate` on a spatial file.
fn simulate_spatial(
    m: &dofplan::model::spatial::Mechanism,
    command: Command,
    out: &mut dyn Write,
) -> io::Result<ExitCode> {
    let Command::Simulate {
        sweep: sweep_args,
        policy,
        branch,
        json,
        csv,
        svg,
        ..
    } = command
    else {
        unreachable!("simulate_spatial is given a Simulate")
    };
    let Some(sweep) = sweep_args.of(m) else {
        return Ok(ExitCode::FAILURE);
    };
    let Some(plan) = spatial_plan(m) else {
        return Ok(ExitCode::FAILURE);
    };
    let options = sweep_options(policy, branch);
    let form = Form::of(json, csv);
    let mut bar = progress::Frames::default();
    outcome(spatial_report::simulate(
        m,
        &plan,
        &sweep,
        options,
        form,
        svg.as_deref(),
        &mut bar,
        out,
    ))
}

/// `dofplan drag` on a spatial file.
fn drag_spatial(
    m: &dofplan::model::spatial::Mechanism,
    command: Command,
    out: &mut dyn Write,
) -> io::Result<ExitCode> {
    let Command::Drag {
        marker,
        to,
        from,
        steps,
        policy,
        json,
        csv,
        svg,
        ..
    } = command
    else {
        unreachable!("drag_spatial is given a Drag")
    };
    let place = m.source.name.clone();
    let (Ok(to), Ok(from)) = (to.of(3, &place), from.map(|f| f.of(3, &place)).transpose()) else {
        return Ok(ExitCode::FAILURE);
    };
    let options = Options {
        breaking: policy.into(),
        ..Options::default()
    };
    let form = Form::of(json, csv);
    let mut bar = progress::Frames::default();
    outcome(spatial_report::drag(
        m,
        &marker,
        from,
        to,
        steps as usize,
        options,
        form,
        svg.as_deref(),
        &mut bar,
        out,
    ))
}

/// `dofplan analyze` on a planar file: rates, `--sensitivity` or `--forces`.
fn analyze_planar(command: Command, out: &mut dyn Write) -> io::Result<ExitCode> {
    let Command::Analyze {
        file,
        sweep: sweep_args,
        rate,
        json,
        csv,
        svg,
        sensitivity,
        tolerance,
        monte_carlo,
        seed,
        forces,
        polar,
        acceleration,
    } = command
    else {
        unreachable!("analyze_planar is given an Analyze")
    };
    with_plan(&file, |m, plan| {
        let Some(sweep) = sweep_args.of(m) else {
            return Ok(ExitCode::FAILURE);
        };
        let form = Form::of(json, csv);
        if forces {
            let plots = svg.as_deref().map(|svg| Plots {
                svg,
                polar: polar.as_deref(),
            });
            return outcome(dofplan::report::planar::forces::run(
                m,
                plan,
                &sweep,
                running(rate, acceleration),
                form,
                plots,
                out,
            ));
        }
        let rate = rate.unwrap_or(1.0);
        if sensitivity {
            let study = Study {
                tolerance,
                monte_carlo,
                seed,
            };
            return outcome(sensitivity::run(m, &sweep, study, form, out));
        }
        let mut bar = progress::Frames::default();
        outcome(analyze::analyze(
            m,
            plan,
            &sweep,
            rate,
            form,
            svg.as_deref(),
            &mut bar,
            out,
        ))
    })
}

/// `--forces`' motion: none without `--rate` (statics); `--acceleration`
/// needs `--rate` (clap says so).
fn running(rate: Option<f64>, acceleration: Option<f64>) -> Option<Running> {
    rate.map(|rate| Running {
        rate,
        acceleration: acceleration.unwrap_or(0.0),
    })
}

/// `dofplan analyze` on a spatial file.
fn analyze_spatial(
    m: &dofplan::model::spatial::Mechanism,
    command: Command,
    out: &mut dyn Write,
) -> io::Result<ExitCode> {
    let Command::Analyze {
        sweep: sweep_args,
        rate,
        json,
        csv,
        svg,
        forces,
        polar,
        acceleration,
        ..
    } = command
    else {
        unreachable!("analyze_spatial is given an Analyze")
    };
    let Some(sweep) = sweep_args.of(m) else {
        return Ok(ExitCode::FAILURE);
    };
    let Some(plan) = spatial_plan(m) else {
        return Ok(ExitCode::FAILURE);
    };
    let form = Form::of(json, csv);
    if forces {
        let plots = svg.as_deref().map(|svg| Plots {
            svg,
            polar: polar.as_deref(),
        });
        return outcome(dofplan::report::spatial::forces::run(
            m,
            &plan,
            &sweep,
            running(rate, acceleration),
            form,
            plots,
            out,
        ));
    }
    let rate = rate.unwrap_or(1.0);
    let mut bar = progress::Frames::default();
    outcome(spatial_analyze::analyze(
        m,
        &plan,
        &sweep,
        rate,
        form,
        svg.as_deref(),
        &mut bar,
        out,
    ))
}

/// The options of a sweep's frames: one that starts out of reach has no
/// pose to hold until the input enters the range.
fn sweep_options(policy: PolicyArg, branch: BranchArg) -> Options {
    Options {
        breaking: policy.into(),
        branch: match branch {
            BranchArg::Keep => BranchPolicy::Keep,
            BranchArg::Nearest => BranchPolicy::Nearest,
        },
        start: StartPolicy::Sweep,
        ..Options::default()
    }
}

/// The plan of a spatial file, or `None` when the analysis failed (said on
/// standard error).
fn spatial_plan(m: &dofplan::model::spatial::Mechanism) -> Option<dofplan::plan::spatial::Plan> {
    dofplan::analysis::spatial::analyse(m)
        .map_err(|e| report(&format!("{}: error: {e}", m.source.name)))
        .ok()
}

/// `dofplan fragments`: the spatial plan-fragment table.
fn fragments(out: &mut dyn Write) -> io::Result<ExitCode> {
    write!(out, "{}", dofplan::analysis::spatial::fragments::table())?;
    Ok(ExitCode::SUCCESS)
}

/// `dofplan assemble`: the table of moves goes to standard error when the
/// file goes to standard output, so the output can be redirected to a file.
fn assemble(file: &Path, write: bool, out: &mut dyn Write) -> io::Result<ExitCode> {
    // (the table of moves, the text, whether nothing moved)
    let done = if dofplan::model::is_spatial_file(file) {
        dofplan::assemble::spatial::assemble_file(file).map(|d| (d.report(), d.unchanged(), d.text))
    } else {
        assemble_file(file).map(|d| (d.report(), d.unchanged(), d.text))
    };
    let (table, unchanged, text) = match done {
        Ok(done) => done,
        Err(e) => {
            report(&e.render(colour()));
            return Ok(ExitCode::FAILURE);
        }
    };
    if !write {
        report(&table);
        write!(out, "{text}")?;
        return Ok(ExitCode::SUCCESS);
    }
    write!(out, "{table}")?;
    if unchanged {
        return Ok(ExitCode::SUCCESS);
    }
    if let Err(e) = std::fs::write(file, &text) {
        report(&format!("{}: error: cannot write the file: {e}", file.display()));
        return Ok(ExitCode::FAILURE);
    }
    writeln!(out, "wrote {}", file.display())?;
    Ok(ExitCode::SUCCESS)
}

/// Writes to standard error. A closed standard error is no reason to panic:
/// there is nobody left to tell.
fn report(text: &str) {
    let mut err = io::stderr().lock();
    let _ = err.write_all(text.as_bytes());
    if !text.ends_with('\n') {
        let _ = err.write_all(b"\n");
    }
}

/// Whether errors are coloured: only on a terminal, and not when NO_COLOR
/// is set to anything (<https://no-color.org>).
fn colour() -> bool {
    wants_colour(io::stderr().is_terminal(), std::env::var_os("NO_COLOR"))
}

/// The rule of [`colour`], given what it looks at.
fn wants_colour(terminal: bool, no_color: Option<std::ffi::OsString>) -> bool {
    terminal && no_color.is_none_or(|v| v.is_empty())
}

/// Reports an error about `place` (a file) that has no position in it, and
/// what to do.
fn error(place: &str, message: &str, help: &str) {
    report(&dofplan::report::error(place, message, help));
}

/// Loads a file, showing progress on a terminal for a large one, or
/// reports why not (once, with the source snippet).
fn load(bar: &progress::Bar, file: &Path) -> Option<Mechanism> {
    bar.load(file).map_err(|e| report(&e.render(colour()))).ok()
}

/// Writes a command's whole output.
fn print(out: &mut dyn Write, text: &str) -> io::Result<ExitCode> {
    write!(out, "{text}")?;
    Ok(ExitCode::SUCCESS)
}

fn with_plan(file: &Path, f: impl FnOnce(&Mechanism, &Plan) -> io::Result<ExitCode>) -> io::Result<ExitCode> {
    let bar = progress::Bar::for_file(file);
    let Some(m) = load(&bar, file) else {
        return Ok(ExitCode::FAILURE);
    };
    let analysis = analyse_with(&m, &mut |p| bar.report(p));
    match &analysis.plan {
        Ok(plan) => bar.around_output("output", || f(&m, plan)),
        Err(e) => {
            bar.finish();
            report(&format!("{}: error: {e}", file.display()));
            Ok(ExitCode::FAILURE)
        }
    }
}

fn check(file: &Path, json_out: bool, out: &mut dyn Write) -> io::Result<ExitCode> {
    let bar = progress::Bar::for_file(file);
    let Some(m) = load(&bar, file) else {
        return Ok(ExitCode::FAILURE);
    };
    let check = Check::of(&m, &mut |p| bar.report(p));
    bar.finish();
    Ok(exit(check.write(
        &m,
        &file.display().to_string(),
        json_out,
        out,
    )?))
}

/// The exit code of a command that succeeded or not.
fn exit(success: bool) -> ExitCode {
    if success {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    }
}

/// Parses "X,Y" into a finite point.
fn parse_point(text: &str) -> Result<Target, String> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    if !(2..=3).contains(&parts.len()) {
        return Err(format!(
            "expected X,Y (two numbers; X,Y,Z for a spatial file), got `{text}`"
        ));
    }
    let mut c = [0.0_f64; 3];
    for (k, part) in parts.iter().enumerate() {
        c[k] = part.parse().map_err(|_| format!("`{part}` is not a number"))?;
    }
    if c.iter().any(|v| !v.is_finite()) {
        return Err(format!("`{text}` is not a finite point"));
    }
    Ok(Target { c, n: parts.len() })
}

/// A drag target as written: 2 coordinates (planar) or 3 (spatial).
#[derive(Clone, Copy, Debug)]
struct Target {
    c: [f64; 3],
    n: usize,
}

impl Target {
    /// The target in `dimension` coordinates, or what to say.
    fn of(self, dimension: usize, file: &str) -> Result<[f64; 3], ()> {
        if self.n == dimension {
            return Ok(self.c);
        }
        let want = if dimension == 2 { "X,Y" } else { "X,Y,Z" };
        error(
            file,
            &format!(
                "a drag target of this file has {dimension} coordinates ({want}), not {}",
                self.n
            ),
            &format!("write --to {want}"),
        );
        Err(())
    }
}

/// Parses a finite number.
fn parse_positive(text: &str) -> Result<f64, String> {
    match parse_finite(text)? {
        x if x > 0.0 => Ok(x),
        _ => Err(format!("`{text}` is not a positive number")),
    }
}

fn parse_finite(text: &str) -> Result<f64, String> {
    let x: f64 = text
        .trim()
        .parse()
        .map_err(|_| format!("`{text}` is not a number"))?;
    if x.is_finite() {
        Ok(x)
    } else {
        Err(format!("`{text}` is not a finite number"))
    }
}

/// Shows a command's report, or the error it came to.
fn outcome(written: Outcome) -> io::Result<ExitCode> {
    Ok(match written? {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            report(&message);
            ExitCode::FAILURE
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn colour_only_on_a_terminal_without_no_color() {
        assert!(wants_colour(true, None));
        assert!(wants_colour(true, Some("".into())), "an empty NO_COLOR is unset");
        assert!(!wants_colour(true, Some("1".into())));
        assert!(!wants_colour(true, Some("false".into())), "any value disables");
        assert!(!wants_colour(false, None));
    }
}
