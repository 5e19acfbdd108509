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
//! Each dimension has its own folder with the same file names:
//! `params.rs` (the parameters and candidates), `gradient.rs` (the
//! derivatives).

pub mod planar;
pub mod search;
pub mod target;

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
        /// Independent equations among them.
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
                "the inputs leave {} freedom(s) open ({unknowns} unknowns, {equations} independent equations): the poses depend on the path taken, not only on the dimensions, so they have no derivatives with respect to them; add inputs for the idle freedoms",
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
