//! Design synthesis on plans: a mechanism's drawing as **design
//! parameters**, candidates prepared from them, and the exact derivatives
//! of every pose with respect to them.
//!
//! The parameters are the drawn positions of the joints and of the markers
//! in no joint, per coordinate: `D.x`, `D.y` for joint D, `coupler.P.x`
//! for a free marker. A candidate is a new drawing — assembled at input 0
//! by construction (the nodal-coordinate formulation of García-Marina et
//! al. 2018) — planned as a file is: its constants computed and its
//! branches chosen so the plan reproduces the candidate's drawing. Its
//! topology and plan order are the original's; a candidate whose drawing
//! would change them (two joints of a body moved onto one point) is
//! refused, not silently planned otherwise.
//!
//! On top of them, synthesis: a [`planar::Problem`] (path, function or
//! motion generation) searched by [`search::run`] — differential evolution
//! polished by Levenberg–Marquardt with the exact Jacobian — and
//! [`planar::synthesize`], which writes every solution into the file and
//! verifies it from there (`dofplan synth` is a thin layer over it).
//!
//! `planar/` has `params.rs` (the parameters and candidates),
//! `gradient.rs` (the derivatives), `tolerance.rs`, `problem.rs` and
//! `solve.rs`; `spatial/` has `params.rs`, `gradient.rs`, `problem.rs`
//! (path, function and motion generation) and `solve.rs`;
//! `nodes.rs`, `request.rs` (names, inputs and boxes resolved),
//! `search.rs`, `solution.rs` (what a synthesis returns), `target.rs` and
//! `timing.rs` (free timing's nearest points) serve both dimensions.
//!
//! A design loop of your own — candidates, their frames and the
//! derivatives of a marker with respect to every parameter:
//!
//! ```
//! use dofplan::synth::planar::{sensitivity, Design};
//! use dofplan_runtime::{Driver, Options};
//!
//! let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../mechanisms/fourbar.toml");
//! let m = dofplan::load_file(std::path::Path::new(path))?;
//! let design = Design::new(&m)?;
//! assert_eq!(design.names()[..4], ["A.x", "A.y", "B.x", "B.y"]);
//! let p = m.find_marker("coupler.P").unwrap();
//! let mut values = design.drawn();
//! values[design.index("B.x")?] += 0.1; // a longer crank
//! let candidate = design.prepare(&values)?;
//! let mut driver = Driver::new(candidate.interpreter.clone(), Options::default());
//! for theta in [0.0, 30.0, 60.0, 90.0] {
//!     assert!(driver.frame(&[theta]).is_solved());
//! }
//! let s = sensitivity(&design, &candidate, driver.poses(), &[90.0])?;
//! let d = s.marker(p); // d(coupler.P)/d(parameter), one [dx, dy] each
//! assert_eq!(d.len(), design.names().len());
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! A synthesis, cancellable from another thread through
//! [`search::Options::cancel`]:
//!
//! ```
//! use std::sync::{atomic::AtomicBool, Arc};
//! use dofplan::synth::planar::{problem, synthesize, Constraints, Kind, Request};
//! use dofplan::synth::search::Options;
//!
//! let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../mechanisms/fourbar.toml");
//! let text = std::fs::read_to_string(path)?;
//! let m = dofplan::load_str(path, &text, dofplan::model::Format::Toml)?;
//! // Given timing: the coupler point at three crank angles.
//! let targets = "input,x,y\n0,3,3.5\n90,1.2,4.1\n180,0.5,2.2\n".to_string();
//! let request = Request {
//!     kind: Kind::Path { marker: "coupler.P".into(), given: None },
//!     targets: ("targets.csv".into(), targets),
//!     input: None,
//!     vary: Some(vec!["B".into(), "coupler.P".into()]),
//!     bounds: None,
//!     point_bounds: Vec::new(),
//!     constraints: Constraints::default(),
//! };
//! let problem = problem(&m, &request)?;
//! let cancel = Arc::new(AtomicBool::new(false));
//! let options = Options {
//!     cancel: Some(cancel.clone()),
//!     time_limit: std::time::Duration::from_secs(1),
//!     ..Options::default()
//! };
//! let found = synthesize(&m, &text, dofplan::model::Format::Toml, &problem, &options, &mut |_| {})?;
//! let best = &found.solutions[0];
//! // The error reported is the written file's, the search's own to rounding.
//! assert!((best.error.sum_sq - best.searched.sum_sq).abs() < 1e-9);
//! assert!(best.text.contains("[bodies.coupler]")); // the file, rewritten
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod nodes;
pub mod planar;
pub mod reach;
mod request;
pub mod search;
pub mod solution;
pub mod spatial;
pub mod target;
mod timing;
pub mod tolerance;

use std::fmt;

/// Why a candidate cannot be prepared or differentiated.
#[derive(Clone, Debug, PartialEq)]
pub enum SynthError {
    /// A parameter name that the mechanism does not have.
    UnknownParameter {
        /// The name asked for.
        name: String,
        /// Some names it has, for the message.
        known: Vec<String>,
    },
    /// A parameter vector of the wrong length.
    WrongLength {
        /// Values given.
        given: usize,
        /// Parameters the design has.
        expected: usize,
    },
    /// A value that is not a finite number.
    NotFinite {
        /// The parameter.
        name: String,
    },
    /// The candidate's drawing has no plan (or not the original's).
    Plan {
        /// What the planner said.
        reason: String,
    },
    /// The candidate's drawing is planned in another order than the
    /// original's: the parameters moved two markers onto one point, or
    /// apart where the original drawing had them together.
    PlanChanged {
        /// The first step that differs, as the original plan explains it.
        step: String,
    },
    /// The inputs leave the mechanism freedoms: its poses depend on the
    /// path taken to them, not only on the dimensions, so they have no
    /// derivatives with respect to the dimensions.
    Underconstrained {
        /// Unknowns of the mobile bodies.
        unknowns: usize,
        /// Equations among them.
        equations: usize,
    },
    /// A varied parameter's box does not hold its drawn value: the search
    /// starts from the drawing, which must be a candidate.
    Bounds {
        /// The parameter.
        name: String,
        /// Its drawn value.
        value: f64,
        /// The box asked for.
        bounds: [f64; 2],
    },
    /// The goal cannot be set up on this mechanism.
    Goal {
        /// Why.
        reason: String,
    },
    /// The derivatives do not exist at this frame: the mechanism is at a
    /// dead point (or has a freedom the equations leave open), where a
    /// change of dimensions moves it by an unbounded amount.
    Singular {
        /// Smallest over largest singular value of the equations' Jacobian.
        ratio: f64,
    },
}

impl fmt::Display for SynthError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SynthError::UnknownParameter { name, known } => write!(
                f,
                "no design parameter '{name}': parameters are a joint's drawn position (JOINT.x, JOINT.y) or a free marker's (body.marker.x); this mechanism has {}",
                known.join(", ")
            ),
            SynthError::WrongLength { given, expected } => {
                write!(f, "{given} parameter values given, the design has {expected}")
            }
            SynthError::NotFinite { name } => write!(f, "parameter {name} is not a finite number"),
            SynthError::Plan { reason } => write!(f, "the candidate drawing cannot be planned: {reason}"),
            SynthError::PlanChanged { step } => write!(
                f,
                "the candidate drawing is planned differently from the original from step {step} on (markers moved onto one point, or apart): keep distinct joints of a body apart"
            ),
            SynthError::Underconstrained { unknowns, equations } => write!(
                f,
                "the inputs leave {} freedom(s) open ({unknowns} unknowns, {equations} equations): the poses depend on the path taken (or, for an idle spin such as a spherical–spherical link's about its own axis, on nothing), not only on the dimensions, so they have no derivatives with respect to them; drive the freedoms no input drives",
                unknowns - equations
            ),
            SynthError::Bounds { name, value, bounds } => write!(
                f,
                "the bounds of {name}, [{}, {}], exclude its drawn value {}: widen them, or move the drawing inside",
                bounds[0], bounds[1], value
            ),
            SynthError::Goal { reason } => write!(f, "{reason}"),
            SynthError::Singular { ratio } => write!(
                f,
                "the derivatives with respect to the dimensions do not exist here: the equations are singular (smallest/largest singular value {ratio:.2e}), a dead point or a freedom left open"
            ),
        }
    }
}

impl std::error::Error for SynthError {}
