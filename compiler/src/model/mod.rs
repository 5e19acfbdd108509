//! The mechanism model: bodies, markers, joints, primitive constraints,
//! inputs and a sweep, validated once when a file is loaded. Later stages
//! (analysis, back ends) never re-check user input.
//!
//! One folder per dimension with the same files: `mod.rs` (the mechanism,
//! its markers, joints and constraints) and `equations.rs` (their primitive
//! equations). What both share is here: bodies, marker ids, inputs and the
//! sweep, and the loader of files of either dimension (`load`).

mod error;
mod excerpt;
mod load;
pub mod loads;
pub mod planar;
mod shape;
pub mod source;
pub mod spatial;

pub use error::{Diagnostic, Location, ModelError, Note, SourceFile};
pub(crate) use load::Open;
pub use load::{
    is_spatial_file, load_any_drawn, load_any_str_drawn, load_file_drawn, load_str_drawn, Drawn, DrawnModel,
    Format, Model, DRAWN_TOLERANCE, MAX_FILE_BYTES, MAX_STEPS,
};
pub use planar::{equations, Constraint, ConstraintKind, Joint, JointKind, Marker, Mechanism};

/// A rigid body: planar ([`Marker`]s) by default, spatial with
/// [`spatial::Marker`]s.
#[derive(Clone, Debug)]
pub struct Body<M = Marker> {
    /// Name, unique in the mechanism.
    pub name: String,
    /// Part of the ground.
    pub fixed: bool,
    /// Markers in file order.
    pub markers: Vec<M>,
}

/// Looks a marker up by "body.marker" among `bodies` (either dimension).
pub(crate) fn find_marker<M: MarkerLike>(bodies: &[Body<M>], name: &str) -> Option<MarkerId> {
    let (body, marker) = name.split_once('.')?;
    let b = bodies.iter().position(|b| b.name == body)?;
    let m = bodies[b].markers.iter().position(|m| m.name() == marker)?;
    Some(MarkerId { body: b, marker: m })
}

/// Every marker of `bodies`, body by body, in file order.
pub(crate) fn all_markers<M>(bodies: &[Body<M>]) -> impl Iterator<Item = MarkerId> + '_ {
    bodies
        .iter()
        .enumerate()
        .flat_map(|(b, body)| (0..body.markers.len()).map(move |m| MarkerId { body: b, marker: m }))
}

/// What the loader and the reports need of a marker of either dimension.
pub trait MarkerLike: Clone {
    /// Its name, unique on its body.
    fn name(&self) -> &str;
    /// Its drawn world coordinates (2 or 3 of them).
    fn coords(&self) -> &[f64];
}

/// A marker of a body.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct MarkerId {
    /// Index into [`Mechanism::bodies`].
    pub body: usize,
    /// Index into that body's markers.
    pub marker: usize,
}

/// A driving input.
#[derive(Clone, Debug)]
pub struct Input {
    /// Name.
    pub name: String,
    /// Kind.
    pub kind: InputKind,
    /// Index into [`Mechanism::joints`].
    pub joint: usize,
}

pub use dofplan_runtime::planar::InputKind;

/// One input of a sweep and the range it moves over.
#[derive(Clone, Debug, PartialEq)]
pub struct Swept {
    /// Index into the mechanism's inputs.
    pub input: usize,
    /// First value.
    pub from: f64,
    /// Last value.
    pub to: f64,
}

/// A sweep: one input (`input`, `from`, `to` in the file) or several moved
/// together linearly (`inputs = { name = [from, to], ... }`); the inputs it
/// does not list stay at 0.
#[derive(Clone, Debug)]
pub struct Sweep {
    /// The swept inputs, in file order (at least one).
    pub inputs: Vec<Swept>,
    /// Number of frames, both ends included.
    pub steps: usize,
    /// Markers whose paths are drawn.
    pub trace: Vec<MarkerId>,
}

impl Sweep {
    /// A sweep of one input.
    pub fn single(input: usize, from: f64, to: f64, steps: usize, trace: Vec<MarkerId>) -> Sweep {
        Sweep {
            inputs: vec![Swept { input, from, to }],
            steps,
            trace,
        }
    }

    /// The first swept input (the only one of a single-input sweep): what a
    /// plot's horizontal axis shows.
    pub fn primary(&self) -> &Swept {
        &self.inputs[0]
    }

    /// The primary input's values: `steps` evenly spaced values from `from`
    /// to `to`, both included.
    pub fn values(&self) -> Vec<f64> {
        (0..self.steps).map(|i| self.value(i)).collect()
    }

    /// The `i`-th of the primary input's [`values`](Sweep::values).
    pub fn value(&self, i: usize) -> f64 {
        let s = self.primary();
        self.value_of(s, i)
    }

    /// Writes frame `i`'s value of every swept input into `inputs` (one
    /// slot per input of the mechanism; the others are left as they are).
    pub fn set(&self, i: usize, inputs: &mut [f64]) {
        for s in &self.inputs {
            inputs[s.input] = self.value_of(s, i);
        }
    }

    /// The `i`-th value of one swept input, computed alone so a long sweep
    /// can be run without holding all of them.
    pub fn value_of(&self, s: &Swept, i: usize) -> f64 {
        if self.steps <= 1 || i == 0 {
            s.from
        } else if i + 1 >= self.steps {
            // Exactly `to`, not `from` plus a rounded difference.
            s.to
        } else {
            let n = (self.steps - 1) as f64;
            // Ends far apart (0 to 1e308, or −1e308 to 1e308) overflow
            // `(to − from)·i`: interpolate without it then.
            let along = (s.to - s.from) * (i as f64);
            if along.is_finite() {
                s.from + along / n
            } else {
                let t = i as f64 / n;
                s.from * (1.0 - t) + s.to * t
            }
        }
    }
}

/// The diagonal of the bounding box of `points` (of any dimension), by
/// `hypot`, which cannot underflow (squares of 1e-300 are 0); 0 for no
/// points.
pub(crate) fn extent<'p>(points: impl Iterator<Item = &'p [f64]>) -> f64 {
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    let mut any = false;
    for p in points {
        any = true;
        for (k, c) in p.iter().enumerate() {
            lo[k] = lo[k].min(*c);
            hi[k] = hi[k].max(*c);
        }
    }
    if !any {
        return 0.0;
    }
    let span = |k: usize| if hi[k] >= lo[k] { hi[k] - lo[k] } else { 0.0 };
    span(0).hypot(span(1)).hypot(span(2))
}
