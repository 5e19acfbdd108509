//! `dofplan synth`: its options, and the run from the file to the report
//! (the search itself is the library's, `dofplan::synth`).

use std::io::{self, IsTerminal, Write};
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

use clap::{ArgGroup, Args, ValueEnum};
use dofplan::model::Format;
use dofplan::report::planar::synth as report;
use dofplan::synth::planar::{problem, synthesize, Constraints, Kind, Request};
use dofplan::synth::search::Options;
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
    /// Mechanism file (planar): its topology, its drawing (the start, and
    /// what parameters stay), its input.
    pub file: PathBuf,
    /// Path generation: the marker that must pass the targets.
    #[arg(long, value_name = "BODY.M")]
    marker: Option<String>,
    /// Path generation: the target points, CSV of x,y (free timing) or
    /// input,x,y (given timing).
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
    /// (degrees).
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
    /// A box for every varied point, X0,Y0,X1,Y1; NAME=X0,Y0,X1,Y1 for one
    /// point (repeat the option). Default: the box around the drawing and
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

/// Reads a `--bounds` value: `X0,Y0,X1,Y1` or `NAME=X0,Y0,X1,Y1`.
fn parse_box(text: &str) -> Result<(Option<String>, [f64; 4]), String> {
    let (name, numbers) = match text.split_once('=') {
        Some((n, rest)) => (Some(n.trim().to_string()), rest),
        None => (None, text),
    };
    let v: Vec<f64> = numbers
        .split(',')
        .map(|t| t.trim().parse::<f64>().ok().filter(|x| x.is_finite()))
        .collect::<Option<_>>()
        .ok_or_else(|| format!("--bounds {text}: write X0,Y0,X1,Y1 (or NAME=X0,Y0,X1,Y1), four numbers"))?;
    match v[..] {
        [x0, y0, x1, y1] if x0 < x1 && y0 < y1 => Ok((name, [x0, y0, x1, y1])),
        [_, _, _, _] => Err(format!("--bounds {text}: the box is empty (X0 < X1 and Y0 < Y1)")),
        _ => Err(format!(
            "--bounds {text}: write X0,Y0,X1,Y1 (or NAME=X0,Y0,X1,Y1), four numbers"
        )),
    }
}

/// The request the options make, the target file read.
fn request(args: &SynthArgs, targets: &std::path::Path, kind: Kind) -> Result<Request, String> {
    let target_name = targets.display().to_string();
    let target_text =
        std::fs::read_to_string(targets).map_err(|e| format!("{target_name}: error: cannot read it: {e}"))?;
    let (mut bounds, mut point_bounds) = (None, Vec::new());
    for b in &args.bounds {
        match parse_box(b).map_err(|e| format!("error: {e}"))? {
            (None, v) => bounds = Some(v),
            (Some(n), v) => point_bounds.push((n, v)),
        }
    }
    Ok(Request {
        kind,
        targets: (target_name, target_text),
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

/// Runs `dofplan synth`.
pub fn run(args: SynthArgs, out: &mut dyn Write) -> io::Result<ExitCode> {
    let fail = |message: String| {
        eprintln!("{message}");
        Ok(ExitCode::FAILURE)
    };
    let name = args.file.display().to_string();
    if dofplan::model::is_spatial_file(&args.file) {
        return fail(format!(
            "{name}: error: synth works on planar files for now; spatial synthesis is not there yet"
        ));
    }
    let text = match std::fs::read_to_string(&args.file) {
        Ok(t) => t,
        Err(e) => return fail(format!("{name}: error: cannot read it: {e}")),
    };
    let format = Format::of_path(&args.file);
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
        Err(e) => return fail(format!("{name}: error: {e}")),
    };
    let options = Options {
        seed: args.seed,
        time_limit: Duration::from_secs_f64(args.time_limit),
        target: args.target.unwrap_or(0.0),
        population: args.population.map(|n| n as usize),
        evaluations: args.evaluations,
        ..Options::default()
    };
    let bar = std::io::stderr().is_terminal().then(|| {
        let bar = ProgressBar::new_spinner();
        bar.set_style(
            ProgressStyle::with_template("{spinner} synth: {msg} {elapsed}").expect("a valid template"),
        );
        bar.enable_steady_tick(Duration::from_millis(100));
        bar
    });
    let mut tick = |p: dofplan::synth::search::Progress| {
        if let Some(bar) = &bar {
            bar.set_message(format!(
                "generation {}, best sum of squares {:.4e}",
                p.generation, p.best
            ));
        }
    };
    let found = synthesize(&m, &text, format, &problem, &options, &mut tick);
    if let Some(bar) = &bar {
        bar.finish_and_clear();
    }
    let s = match found {
        Ok(s) if !s.solutions.is_empty() => s,
        Ok(_) => return fail(format!(
            "{name}: error: no candidate in the box met the targets and the constraints; widen --bounds, relax the constraints or give more --time-limit"
        )),
        Err(e) => return fail(format!("{name}: error: {e}")),
    };
    let written = match &args.out {
        Some(path) => match std::fs::write(path, &s.solutions[0].text) {
            Ok(()) => Some(path.display().to_string()),
            Err(e) => return fail(format!("{}: error: cannot write it: {e}", path.display())),
        },
        None => None,
    };
    if let Some(path) = &args.svg {
        let drawn = report::picture(&m, &problem, &s.solutions[0], format)
            .and_then(|svg| std::fs::write(path, svg).map_err(|e| format!("cannot write it: {e}")));
        if let Err(e) = drawn {
            return fail(format!("{}: error: {e}", path.display()));
        }
    }
    if args.json {
        report::write_json(&m, &problem, &s, out)?;
    } else {
        report::write_text(&m, &problem, &s, written.as_deref(), out)?;
    }
    Ok(ExitCode::SUCCESS)
}
