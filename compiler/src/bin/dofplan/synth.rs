//! `dofplan synth`: its options, and the run from the file to the report
//! (the search itself is the library's, `dofplan::synth`).

use std::io::{self, IsTerminal, Write};
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

use clap::{ArgGroup, Args, ValueEnum};
use dofplan::model::{Format, Model};
use dofplan::report;
use dofplan::synth::planar::{problem, synthesize, Constraints, Kind, Request};
use dofplan::synth::search::{Options, Progress};
use dofplan::synth::solution::Synthesis;
use dofplan::synth::spatial;
use indicatif::{ProgressBar, ProgressStyle};

/// Timing of a path's or a motion's targets.
#[derive(Clone, Copy, ValueEnum)]
pub enum Timing {
    /// Each target has its input value, the file's first column.
    Given,
    /// Each target gets an input value of its own, found with the
    /// dimensions.
    Free,
}

/// The options of `dofplan synth`.
#[derive(Args)]
#[command(group(ArgGroup::new("goal").required(true).args(["path", "function", "motion"])))]
pub struct SynthArgs {
    /// Mechanism file, planar or spatial: its topology, its drawing (the
    /// start, and what parameters stay), its input. A spatial file takes
    /// --path (given or free timing), --function and --motion (given
    /// timing), --full-turn, --max-ratio and --svg.
    pub file: PathBuf,
    /// Path generation: the marker that must pass the targets.
    #[arg(long, value_name = "BODY.M")]
    marker: Option<String>,
    /// Path generation: the target points, CSV of x,y (free timing) or
    /// input,x,y (given timing); spatial: x,y,z or input,x,y,z.
    #[arg(long, value_name = "TARGET.csv", requires = "marker")]
    path: Option<PathBuf>,
    /// Given or free timing (default: as the target file's columns say).
    #[arg(long, value_enum)]
    timing: Option<Timing>,
    /// Function generation: CSV of input,output pairs (the output joint's
    /// angle in degrees, or its slide, from the drawing).
    #[arg(long, value_name = "PAIRS.csv", requires = "output")]
    function: Option<PathBuf>,
    /// Function generation: the output joint.
    #[arg(long, value_name = "JOINT")]
    output: Option<String>,
    /// Motion generation: CSV of x,y,angle (free timing) or
    /// input,x,y,angle (given timing): where the body's marker (--marker,
    /// default its first) is and how far it has turned from the drawing
    /// (degrees). Spatial: input,x,y,z,rx,ry,rz, the turn a rotation
    /// vector (axis times angle, degrees).
    #[arg(long, value_name = "POSES.csv", requires = "body")]
    motion: Option<PathBuf>,
    /// Motion generation: the body.
    #[arg(long, value_name = "NAME")]
    body: Option<String>,
    /// The driving input (default: the sweep's, or the only one).
    #[arg(long, value_name = "NAME")]
    input: Option<String>,
    /// The parameters varied, comma-separated: JOINT.x, body.marker.y, or
    /// a point's name for both coordinates (default: all, ground pivots
    /// included).
    #[arg(long, value_delimiter = ',', value_name = "NAMES")]
    vary: Option<Vec<String>>,
    /// A box for every varied point, X0,Y0,X1,Y1 (spatial:
    /// X0,Y0,Z0,X1,Y1,Z1); NAME=X0,Y0,X1,Y1 for one point (repeat the
    /// option). Default: the box around the drawing and
    /// the targets, widened by half its larger side on each side.
    #[arg(long, value_name = "BOX", allow_hyphen_values = true)]
    bounds: Vec<String>,
    /// The input must turn through 360° without a break.
    #[arg(long)]
    full_turn: bool,
    /// Every four-bar loop's transmission angle stays within [DEG, 180 −
    /// DEG] over the input's range.
    #[arg(long, value_name = "DEG", value_parser = positive)]
    min_transmission: Option<f64>,
    /// Longest over shortest link at most R.
    #[arg(long, value_name = "R", value_parser = positive)]
    max_ratio: Option<f64>,
    /// The search's seed: the same seed gives the same search.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// The global search's population (default: ten per varied
    /// parameter, 40 to 200).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(5..=100_000))]
    population: Option<u32>,
    /// Stop after this many seconds.
    #[arg(long, value_name = "S", default_value_t = 10.0, value_parser = positive)]
    time_limit: f64,
    /// Stop after about N evaluations of candidates: unlike the time
    /// limit, the same result on any machine.
    #[arg(long, value_name = "N")]
    evaluations: Option<usize>,
    /// Stop once the sum of squares is at most E.
    #[arg(long, value_name = "E", value_parser = positive)]
    target: Option<f64>,
    /// Write the mechanism file with the best solution's coordinates
    /// (comments and key order kept).
    #[arg(long, value_name = "BEST.toml")]
    out: Option<PathBuf>,
    /// Draw the best solution into this SVG file: the mechanism over the
    /// input's range, the marker's path and the targets.
    #[arg(long, value_name = "OUT.svg")]
    svg: Option<PathBuf>,
    /// One JSON document: "error" (sum_sq, rms, max, from the written
    /// file), "parameters", "constraints" (name, value, margin),
    /// "inputs" (free timing), "evaluations", "seconds", "stopped" and
    /// "solutions" (the distinct solutions, best first, each with the same
    /// fields).
    #[arg(long)]
    json: bool,
}

fn positive(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(x) if x.is_finite() && x > 0.0 => Ok(x),
        _ => Err(format!("`{text}` is not a positive number")),
    }
}

/// Reads a `--bounds` value of a `D`-dimensional mechanism (`N` = 2`D`
/// numbers): `X0,Y0,X1,Y1` or `NAME=X0,Y0,X1,Y1` in the plane,
/// `X0,Y0,Z0,X1,Y1,Z1` in space.
fn parse_box<const N: usize>(text: &str) -> Result<(Option<String>, [f64; N]), String> {
    let form = if N == 4 {
        "X0,Y0,X1,Y1 (or NAME=X0,Y0,X1,Y1), four numbers"
    } else {
        "X0,Y0,Z0,X1,Y1,Z1 (or NAME=X0,Y0,Z0,X1,Y1,Z1), six numbers"
    };
    let (name, numbers) = match text.split_once('=') {
        Some((n, rest)) => (Some(n.trim().to_string()), rest),
        None => (None, text),
    };
    let v: Vec<f64> = numbers
        .split(',')
        .map(|t| t.trim().parse::<f64>().ok().filter(|x| x.is_finite()))
        .collect::<Option<_>>()
        .ok_or_else(|| format!("--bounds {text}: write {form}"))?;
    let v: [f64; N] = v
        .try_into()
        .map_err(|_| format!("--bounds {text}: write {form}"))?;
    let d = N / 2;
    if (0..d).any(|k| v[k] >= v[d + k]) {
        let order = if N == 4 {
            "X0 < X1 and Y0 < Y1"
        } else {
            "X0 < X1, Y0 < Y1 and Z0 < Z1"
        };
        return Err(format!("--bounds {text}: the box is empty ({order})"));
    }
    Ok((name, v))
}

/// The `--bounds` options: the common box and the points' own.
#[allow(clippy::type_complexity)]
fn all_boxes<const N: usize>(
    args: &SynthArgs,
) -> Result<(Option<[f64; N]>, Vec<(String, [f64; N])>), String> {
    let (mut bounds, mut point_bounds) = (None, Vec::new());
    for b in &args.bounds {
        match parse_box::<N>(b).map_err(|e| format!("error: {e}"))? {
            (None, v) => bounds = Some(v),
            (Some(n), v) => point_bounds.push((n, v)),
        }
    }
    Ok((bounds, point_bounds))
}

/// The target file's name and text.
fn read_targets(targets: &std::path::Path) -> Result<(String, String), String> {
    let name = targets.display().to_string();
    let text = std::fs::read_to_string(targets).map_err(|e| format!("{name}: error: cannot read it: {e}"))?;
    Ok((name, text))
}

/// The request the options make, the target file read.
fn request(args: &SynthArgs, targets: &std::path::Path, kind: Kind) -> Result<Request, String> {
    let (bounds, point_bounds) = all_boxes::<4>(args)?;
    Ok(Request {
        kind,
        targets: read_targets(targets)?,
        input: args.input.clone(),
        vary: args.vary.clone(),
        bounds,
        point_bounds,
        constraints: Constraints {
            full_turn: args.full_turn,
            min_transmission: args.min_transmission,
            max_ratio: args.max_ratio,
        },
    })
}

/// The spatial request the options make, or what they ask that spatial
/// synthesis does not do.
fn spatial_request(args: &SynthArgs) -> Result<spatial::Request, String> {
    if args.min_transmission.is_some() {
        return Err(format!(
            "{}: error: --min-transmission bounds the transmission angles of planar four-bar loops, and a spatial file has none; bound the links with --max-ratio, or keep the input turning with --full-turn",
            args.file.display()
        ));
    }
    if matches!(args.timing, Some(Timing::Free)) && args.path.is_none() {
        return Err(format!(
            "{}: error: --timing free (of a motion) works on planar files only for now; on a spatial file synth does path (--path, --marker; given or free timing), function (--function, --output) and motion generation (--motion, --body; given timing)",
            args.file.display()
        ));
    }
    let (targets, kind) = match (&args.path, &args.function, &args.motion) {
        (Some(p), _, _) => (
            p,
            spatial::Kind::Path {
                marker: args.marker.clone().unwrap_or_default(),
                given: args.timing.map(|t| matches!(t, Timing::Given)),
            },
        ),
        (_, Some(p), _) => (
            p,
            spatial::Kind::Function {
                output: args.output.clone().unwrap_or_default(),
            },
        ),
        (_, _, Some(p)) => (
            p,
            spatial::Kind::Motion {
                body: args.body.clone().unwrap_or_default(),
                marker: args.marker.clone(),
            },
        ),
        _ => unreachable!("clap requires one goal"),
    };
    let (bounds, point_bounds) = all_boxes::<6>(args)?;
    Ok(spatial::Request {
        kind,
        targets: read_targets(targets)?,
        input: args.input.clone(),
        vary: args.vary.clone(),
        bounds,
        point_bounds,
        constraints: spatial::Constraints {
            full_turn: args.full_turn,
            max_ratio: args.max_ratio,
        },
    })
}

/// `e` as a message about `name`, unless it already names where it is
/// (a target file's `file:line:column: error: …`).
fn about(name: &str, e: String) -> String {
    if e.contains(": error: ") {
        e
    } else {
        format!("{name}: error: {e}")
    }
}

/// The search's options.
fn options(args: &SynthArgs) -> Options {
    Options {
        seed: args.seed,
        time_limit: Duration::from_secs_f64(args.time_limit),
        target: args.target.unwrap_or(0.0),
        population: args.population.map(|n| n as usize),
        evaluations: args.evaluations,
        ..Options::default()
    }
}

/// Runs `search` with a progress bar on a terminal.
fn with_progress<T>(search: impl FnOnce(&mut (dyn FnMut(Progress) + Send)) -> T) -> T {
    let bar = std::io::stderr().is_terminal().then(|| {
        let bar = ProgressBar::new_spinner();
        bar.set_style(
            ProgressStyle::with_template("{spinner} synth: {msg} {elapsed}").expect("a valid template"),
        );
        bar.enable_steady_tick(Duration::from_millis(100));
        bar
    });
    let mut tick = |p: Progress| {
        if let Some(bar) = &bar {
            bar.set_message(format!(
                "generation {}, best sum of squares {:.4e}",
                p.generation, p.best
            ));
        }
    };
    let found = search(&mut tick);
    if let Some(bar) = &bar {
        bar.finish_and_clear();
    }
    found
}

/// The search's result, or the message for none found.
fn solved(name: &str, found: Result<Synthesis, String>) -> Result<Synthesis, String> {
    match found {
        Ok(s) if !s.solutions.is_empty() => Ok(s),
        Ok(_) => Err(format!(
            "{name}: error: no candidate in the box met the targets and the constraints; widen --bounds, relax the constraints or give more --time-limit"
        )),
        Err(e) => Err(format!("{name}: error: {e}")),
    }
}

/// Writes the best solution's file where `--out` says.
fn write_out(args: &SynthArgs, s: &Synthesis) -> Result<Option<String>, String> {
    match &args.out {
        Some(path) => match std::fs::write(path, &s.solutions[0].text) {
            Ok(()) => Ok(Some(path.display().to_string())),
            Err(e) => Err(format!("{}: error: cannot write it: {e}", path.display())),
        },
        None => Ok(None),
    }
}

/// `dofplan synth` on a spatial file.
fn run_spatial(
    args: &SynthArgs,
    name: &str,
    text: &str,
    format: Format,
    out: &mut dyn Write,
) -> Result<io::Result<()>, String> {
    let m = match dofplan::load_any_str(name, text, format) {
        Ok(Model::Spatial(m)) => m,
        Ok(Model::Planar(_)) => return Err(format!("{name}: error: the file is not spatial")),
        Err(e) => return Err(e.render(std::io::stderr().is_terminal())),
    };
    let request = spatial_request(args)?;
    let problem = spatial::problem(&m, &request).map_err(|e| about(name, e))?;
    let options = options(args);
    let found = with_progress(|tick| spatial::synthesize(&m, text, format, &problem, &options, tick));
    let s = solved(name, found)?;
    let written = write_out(args, &s)?;
    if let Some(path) = &args.svg {
        report::spatial::synth::picture(&m, &problem, &s.solutions[0], format)
            .and_then(|svg| std::fs::write(path, svg).map_err(|e| format!("cannot write it: {e}")))
            .map_err(|e| format!("{}: error: {e}", path.display()))?;
    }
    Ok(if args.json {
        report::spatial::synth::write_json(&m, &problem, &s, out)
    } else {
        report::spatial::synth::write_text(&m, &problem, &s, written.as_deref(), out)
    })
}

/// Runs `dofplan synth`.
pub fn run(args: SynthArgs, out: &mut dyn Write) -> io::Result<ExitCode> {
    let fail = |message: String| {
        eprintln!("{message}");
        Ok(ExitCode::FAILURE)
    };
    let name = args.file.display().to_string();
    let text = match std::fs::read_to_string(&args.file) {
        Ok(t) => t,
        Err(e) => return fail(format!("{name}: error: cannot read it: {e}")),
    };
    let format = Format::of_path(&args.file);
    if dofplan::model::is_spatial_file(&args.file) {
        return match run_spatial(&args, &name, &text, format, out) {
            Ok(written) => written.map(|()| ExitCode::SUCCESS),
            Err(e) => fail(e),
        };
    }
    let m = match dofplan::load_str(&name, &text, format) {
        Ok(m) => m,
        Err(e) => return fail(e.render(std::io::stderr().is_terminal())),
    };
    let (targets, kind) = match (&args.path, &args.function, &args.motion) {
        (Some(p), _, _) => (
            p,
            Kind::Path {
                marker: args.marker.clone().unwrap_or_default(),
                given: args.timing.map(|t| matches!(t, Timing::Given)),
            },
        ),
        (_, Some(p), _) => (
            p,
            Kind::Function {
                output: args.output.clone().unwrap_or_default(),
            },
        ),
        (_, _, Some(p)) => (
            p,
            Kind::Motion {
                body: args.body.clone().unwrap_or_default(),
                marker: args.marker.clone(),
                given: args.timing.map(|t| matches!(t, Timing::Given)),
            },
        ),
        _ => unreachable!("clap requires one goal"),
    };
    let request = match request(&args, targets, kind) {
        Ok(r) => r,
        Err(e) => return fail(e),
    };
    let problem = match problem(&m, &request) {
        Ok(p) => p,
        Err(e) => return fail(about(&name, e)),
    };
    let options = options(&args);
    let found = with_progress(|tick| synthesize(&m, &text, format, &problem, &options, tick));
    let s = match solved(&name, found) {
        Ok(s) => s,
        Err(e) => return fail(e),
    };
    let written = match write_out(&args, &s) {
        Ok(w) => w,
        Err(e) => return fail(e),
    };
    if let Some(path) = &args.svg {
        let drawn = report::planar::synth::picture(&m, &problem, &s.solutions[0], format)
            .and_then(|svg| std::fs::write(path, svg).map_err(|e| format!("cannot write it: {e}")));
        if let Err(e) = drawn {
            return fail(format!("{}: error: {e}", path.display()));
        }
    }
    if args.json {
        report::planar::synth::write_json(&m, &problem, &s, out)?;
    } else {
        report::planar::synth::write_text(&m, &problem, &s, written.as_deref(), out)?;
    }
    Ok(ExitCode::SUCCESS)
}
