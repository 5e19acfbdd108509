//! The mechanism model: bodies, markers, joints, primitive constraints,
//! inputs and a sweep, validated once when a file is loaded. Later stages
//! (analysis, back ends) never re-check user input.

pub mod equations;
mod error;
mod excerpt;
mod load;
mod shape;
pub mod source;
pub mod spatial;

use dofplan_runtime::Point;

pub use error::{Diagnostic, Location, ModelError, Note, SourceFile};
pub(crate) use load::Open;
pub use load::{
    is_spatial_file, load_any_drawn, load_any_str_drawn, load_file_drawn, load_str_drawn, load_str_drawn3,
    Drawn, Drawn3, DrawnModel, Format, Model, DRAWN_TOLERANCE, MAX_FILE_BYTES, MAX_STEPS,
};

/// A validated mechanism.
#[derive(Clone, Debug)]
pub struct Mechanism {
    /// Its name (also the generated module's name).
    pub name: String,
    /// 2: a planar mechanism ([`spatial::Mechanism3`] holds 3D ones).
    pub dimension: u8,
    /// Bodies in file order.
    pub bodies: Vec<Body>,
    /// Joints in file order.
    pub joints: Vec<Joint>,
    /// Primitive constraints written directly, in file order.
    pub constraints: Vec<Constraint>,
    /// Driving inputs in file order.
    pub inputs: Vec<Input>,
    /// The sweep to simulate, if the file has one.
    pub sweep: Option<Sweep>,
    /// The file it came from.
    pub source: SourceFile,
}

/// A rigid body: planar ([`Marker`]s) by default, spatial with
/// [`spatial::Marker3`]s.
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

impl MarkerLike for Marker {
    fn name(&self) -> &str {
        &self.name
    }
    fn coords(&self) -> &[f64] {
        &self.at
    }
}

/// A named point on a body, optionally with a direction.
#[derive(Clone, Debug)]
pub struct Marker {
    /// Name, unique on its body.
    pub name: String,
    /// World position in the pose as drawn.
    pub at: Point,
    /// Direction as written (not normalised), if any.
    pub dir: Option<Point>,
}

impl Marker {
    /// The direction scaled to unit length.
    pub fn unit_dir(&self) -> Option<Point> {
        self.dir.map(|d| {
            let n = (d[0] * d[0] + d[1] * d[1]).sqrt();
            [d[0] / n, d[1] / n]
        })
    }
}

/// A marker of a body.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct MarkerId {
    /// Index into [`Mechanism::bodies`].
    pub body: usize,
    /// Index into that body's markers.
    pub marker: usize,
}

/// A joint between markers of two bodies.
#[derive(Clone, Debug)]
pub struct Joint {
    /// Name, unique among joints and constraints.
    pub name: String,
    /// Kind.
    pub kind: JointKind,
    /// The two markers, in file order.
    pub markers: [MarkerId; 2],
    /// The line it is written on (1-based), for a joint read from a TOML
    /// file; `None` for JSON and for mechanisms built in code.
    pub line: Option<usize>,
}

/// The kinds of joint.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum JointKind {
    /// The two markers coincide (one relative rotation left).
    Revolute,
    /// The second marker slides along the first marker's direction and the
    /// bodies never turn relative to each other (one relative slide left).
    Prismatic,
}

impl JointKind {
    /// The name used in files.
    pub fn name(self) -> &'static str {
        match self {
            JointKind::Revolute => "revolute",
            JointKind::Prismatic => "prismatic",
        }
    }
}

/// A primitive constraint between two markers (Kramer's, as Brunkhart §5.1
/// uses them).
#[derive(Clone, Debug)]
pub struct Constraint {
    /// Name, unique among joints and constraints.
    pub name: String,
    /// Kind.
    pub kind: ConstraintKind,
    /// The two markers.
    pub markers: [MarkerId; 2],
}

/// Primitive constraint kinds in 2D.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ConstraintKind {
    /// The markers coincide (2 equations).
    Coincident,
    /// The second marker lies on the line of the first marker's direction
    /// (1 equation).
    InLine,
    /// The angle between the markers' directions stays as drawn (1 equation).
    Offset,
}

impl ConstraintKind {
    /// The name used in files.
    pub fn name(self) -> &'static str {
        match self {
            ConstraintKind::Coincident => "coincident",
            ConstraintKind::InLine => "in-line",
            ConstraintKind::Offset => "offset",
        }
    }
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

impl Mechanism {
    /// A marker by id.
    pub fn marker(&self, id: MarkerId) -> &Marker {
        &self.bodies[id.body].markers[id.marker]
    }

    /// "body.marker".
    pub fn marker_name(&self, id: MarkerId) -> String {
        format!(
            "{}.{}",
            self.bodies[id.body].name, self.bodies[id.body].markers[id.marker].name
        )
    }

    /// Looks a marker up by "body.marker".
    pub fn find_marker(&self, name: &str) -> Option<MarkerId> {
        find_marker(&self.bodies, name)
    }

    /// Every marker, body by body, in file order.
    pub fn all_markers(&self) -> impl Iterator<Item = MarkerId> + '_ {
        all_markers(&self.bodies)
    }

    /// The pairs of markers held on one point: those of every revolute
    /// joint and every coincident constraint, in file order.
    pub fn coincident_pairs(&self) -> impl Iterator<Item = [MarkerId; 2]> + '_ {
        let joints = self.joints.iter().filter(|j| j.kind == JointKind::Revolute);
        let constraints = (self.constraints.iter()).filter(|c| c.kind == ConstraintKind::Coincident);
        joints.map(|j| j.markers).chain(constraints.map(|c| c.markers))
    }

    /// The size of the mechanism: the diagonal of its markers' bounding box
    /// as drawn (1 if they all coincide). Tolerances are relative to it.
    pub fn size(&self) -> f64 {
        size_of(&self.bodies)
    }

    /// Number of links in Grübler's sense: every mobile body plus one for
    /// the ground (all fixed bodies together).
    pub fn links(&self) -> usize {
        self.bodies.iter().filter(|b| !b.fixed).count() + 1
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

/// [`Mechanism::size`] of a mechanism with these bodies.
pub(crate) fn size_of(bodies: &[Body]) -> f64 {
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for p in bodies.iter().flat_map(|b| &b.markers).map(|m| m.at) {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let d = ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2)).sqrt();
    if d.is_finite() && d > 0.0 {
        d
    } else {
        1.0
    }
}
