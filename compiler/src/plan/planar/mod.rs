//! The planar plan IR. A [`Plan`] is straight-line: its [`Step`]s run in
//! order, each one call to a runtime function, each reading what earlier
//! steps placed.

mod explain;

use dofplan_runtime::{Branch, Point};

/// A primitive equation of a numeric cluster, as the runtime evaluates it.
pub use dofplan_runtime::planar::cluster::Row as ClusterRow;

use crate::model::InputKind;

/// Index of a body in [`Plan::bodies`] (the mechanism's body order).
pub type BodyId = usize;

/// A world point a step reads.
#[derive(Clone, Debug, PartialEq)]
pub enum PointRef {
    /// A marker of a fixed body: a constant.
    Fixed {
        /// World position (= drawn position).
        at: Point,
        /// "body.marker".
        name: String,
    },
    /// A marker of a body placed by an earlier step.
    Marker {
        /// The body.
        body: BodyId,
        /// Local (= drawn) coordinates.
        local: Point,
        /// "body.marker".
        name: String,
    },
    /// A marker carried along a slide input: `body.world(local + sign·u·dir)`
    /// where `u` is the slide input's value.
    Slid {
        /// The body whose frame the point is fixed in, up to the slide.
        body: BodyId,
        /// Local coordinates at zero slide.
        local: Point,
        /// Unit slide direction in the body's frame.
        dir: Point,
        /// The slide input.
        input: usize,
        /// +1 or −1 (the slide seen from the other body).
        sign: f64,
        /// "body.marker".
        name: String,
    },
    /// A point computed by an earlier intersection step.
    Temp {
        /// Index into [`Plan::temps`].
        id: usize,
    },
}

/// A world direction a step reads (unit length).
#[derive(Clone, Debug, PartialEq)]
pub enum DirRef {
    /// The direction of a marker on a fixed body: a constant.
    Fixed(Point),
    /// The direction of a marker of a body whose rotation is known.
    Body {
        /// The body.
        body: BodyId,
        /// Unit direction in the body's frame.
        local: Point,
    },
}

/// A straight-line locus.
#[derive(Clone, Debug, PartialEq)]
pub struct Line {
    /// A point on it.
    pub through: PointRef,
    /// Its direction.
    pub dir: DirRef,
}

/// A relative rotation carried by a joint.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Rel {
    /// No relative rotation (prismatic joint, offset constraint).
    Identity,
    /// The angle input, or its inverse when the driven body is the joint's
    /// first.
    Input {
        /// The angle input.
        input: usize,
        /// Apply the inverse rotation.
        inverse: bool,
    },
}

/// A number affine in the inputs, `constant + Σ coefficient · input`: a
/// body's rotation in degrees, or a rack's slide, when every step that
/// sets it is a rotation by an input or a gear pair (rotations then add
/// up and gears scale them, so the angle is known unwrapped, past a full
/// turn, and a ratio that is not a whole number needs no memory of the
/// previous frame).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Affine {
    /// The value at zero inputs.
    pub constant: f64,
    /// (input, coefficient), by input, no zero coefficient.
    pub terms: Vec<(usize, f64)>,
}

impl Affine {
    /// `±input`.
    pub fn input(input: usize, sign: f64) -> Affine {
        Affine {
            constant: 0.0,
            terms: vec![(input, sign)],
        }
    }

    /// `a·self + b·other`.
    pub fn combine(&self, a: f64, other: &Affine, b: f64) -> Affine {
        let mut terms: Vec<(usize, f64)> = Vec::new();
        for &(i, c) in &self.terms {
            terms.push((i, a * c));
        }
        for &(i, c) in &other.terms {
            match terms.iter_mut().find(|t| t.0 == i) {
                Some(t) => t.1 += b * c,
                None => terms.push((i, b * c)),
            }
        }
        terms.retain(|t| t.1 != 0.0);
        terms.sort_by_key(|t| t.0);
        Affine {
            constant: a * self.constant + b * other.constant,
            terms,
        }
    }

    /// Its value at `inputs`, on any scalar (frames, jets, lanes).
    pub fn eval<T: dofplan_runtime::scalar::Real>(&self, inputs: &[T]) -> T {
        let mut v = T::cst(self.constant);
        for &(i, c) in &self.terms {
            v = v + T::cst(c) * inputs[i];
        }
        v
    }
}

/// How a cluster body is parametrised, with the points and directions it
/// depends on still to be evaluated each frame.
#[derive(Clone, Debug, PartialEq)]
pub enum ClusterParam {
    /// Translation and angle (3 unknowns).
    Free {
        /// The body.
        body: BodyId,
    },
    /// Pinned at a placed point: its angle (1 unknown).
    Angle {
        /// The body.
        body: BodyId,
        /// The pinned marker, local.
        pin: Point,
        /// Where it is pinned.
        at: PointRef,
    },
    /// Pinned by a revolute joint to a marker of an earlier cluster body
    /// (joint coordinates): its angle (1 unknown); the joint holds by
    /// construction and is no equation of the cluster.
    Hinge {
        /// The body.
        body: BodyId,
        /// The pinned marker, local.
        pin: Point,
        /// The parent: an earlier param's body.
        parent: BodyId,
        /// The parent's marker, local to the parent.
        at: Point,
        /// "parent.marker".
        name: String,
    },
    /// Rotation known, on a line: the displacement along it (1 unknown).
    Slide {
        /// The body.
        body: BodyId,
        /// The line's direction.
        dir: DirRef,
    },
    /// Rotation known: translation (2 unknowns).
    Translate {
        /// The body.
        body: BodyId,
    },
}

impl ClusterParam {
    /// The body.
    pub fn body(&self) -> BodyId {
        match self {
            ClusterParam::Free { body }
            | ClusterParam::Angle { body, .. }
            | ClusterParam::Hinge { body, .. }
            | ClusterParam::Slide { body, .. }
            | ClusterParam::Translate { body } => *body,
        }
    }

    /// Number of unknowns.
    pub fn count(&self) -> usize {
        match self {
            ClusterParam::Free { .. } => 3,
            ClusterParam::Translate { .. } => 2,
            ClusterParam::Angle { .. } | ClusterParam::Hinge { .. } | ClusterParam::Slide { .. } => 1,
        }
    }
}

/// What a step does.
#[derive(Clone, Debug, PartialEq)]
pub enum StepKind {
    /// Sets `body`'s rotation to `from`'s followed by `rel`.
    Orient {
        /// The body turned.
        body: BodyId,
        /// The body whose rotation is known; `None` for the ground, whose
        /// rotation is the identity, so `rel` is the rotation itself.
        from: Option<BodyId>,
        /// The relative rotation.
        rel: Rel,
    },
    /// Sets `body`'s rotation to `angle` degrees (a gear pair's driven
    /// body, or the carrier of one).
    Turn {
        /// The body turned.
        body: BodyId,
        /// Its rotation in degrees, affine in the inputs.
        angle: Affine,
    },
    /// Translates `body` (rotation known) so its marker `local` lands on
    /// `carrier.world(at + slide · dir)`: a rack moved by its pinion
    /// along the prismatic joint it slides in.
    Shift {
        /// The rack.
        body: BodyId,
        /// Its marker on the prismatic joint, local.
        local: Point,
        /// The body it slides on (a fixed one: the frame, at its drawn
        /// pose).
        carrier: BodyId,
        /// Where the marker is at zero slide, in the carrier's frame.
        at: Point,
        /// The unit slide direction in the carrier's frame.
        dir: Point,
        /// The slide, affine in the inputs.
        slide: Affine,
        /// "body.marker" of the rack's marker.
        name: String,
    },
    /// Translates `body` (rotation known) so its marker `local` lands on `at`.
    Anchor {
        /// The body moved.
        body: BodyId,
        /// Its marker, local coordinates.
        local: Point,
        /// Where it goes.
        at: PointRef,
    },
    /// Places `body` by two markers: `p` onto `p_at`, `q` toward `q_at`.
    Align {
        /// The body placed.
        body: BodyId,
        /// First marker (local).
        p: Point,
        /// Where it goes.
        p_at: PointRef,
        /// Second marker (local).
        q: Point,
        /// Where it goes.
        q_at: PointRef,
        /// The distance between the two targets is not guaranteed by an
        /// earlier step (a body pinned twice: a redundant equation), so it
        /// is checked — the consistency check after contraction
        /// (Brunkhart §3.3.6) — and a mismatch is a break.
        redundant: bool,
    },
    /// Intersects two circles into temp `out`.
    CircleCircle {
        /// The temp written.
        out: usize,
        /// First centre.
        c1: PointRef,
        /// First radius.
        r1: f64,
        /// Second centre.
        c2: PointRef,
        /// Second radius.
        r2: f64,
        /// Index into [`Plan::branches`].
        branch: usize,
    },
    /// Intersects a circle and a line into temp `out`.
    CircleLine {
        /// The temp written.
        out: usize,
        /// Centre.
        c: PointRef,
        /// Radius.
        r: f64,
        /// The line.
        line: Line,
        /// Index into [`Plan::branches`].
        branch: usize,
    },
    /// Intersects two lines into temp `out`.
    LineLine {
        /// The temp written.
        out: usize,
        /// First line.
        a: Line,
        /// Second line.
        b: Line,
    },
    /// Turns `body` about `pivot` until its line (local unit `dir`) passes at
    /// signed distance `kappa` from `target` (sets the rotation only).
    TurnLine {
        /// The body turned.
        body: BodyId,
        /// The pivot's world position.
        pivot: PointRef,
        /// The point the line must pass.
        target: PointRef,
        /// The line's unit direction in the body's frame.
        dir: Point,
        /// `cross(target − pivot, R·dir)` required.
        kappa: f64,
        /// Index into [`Plan::branches`].
        branch: usize,
    },
    /// Checks that a pin lies between the ends of its slot (the line
    /// through `at` along `dir`, or the circle about `at`): past an end
    /// the frame breaks, an assembly limit like the circles' reach.
    Within {
        /// The slot's marker (an arc's centre).
        at: PointRef,
        /// The slot's direction (where an arc's angles count from).
        dir: DirRef,
        /// The pin.
        pin: PointRef,
        /// The ends: along `dir` from `at`, or for an arc angles in
        /// degrees about `at` from `dir`.
        ends: [f64; 2],
        /// Whether the slot is a circular arc about `at`.
        arc: bool,
    },
    /// Places the bodies the closed form could not, by Newton–Raphson on
    /// the fewest unknowns their loci allow (a mixed plan's numeric part).
    Cluster {
        /// Index of this cluster among the plan's clusters (its work slot).
        index: usize,
        /// The cluster bodies and their unknowns.
        params: Vec<ClusterParam>,
        /// The equations among them and the placed bodies.
        rows: Vec<ClusterRow>,
    },
}

impl StepKind {
    /// Unknowns and scalar equations of a cluster step ((0, 0) otherwise).
    pub fn cluster_size(&self) -> (usize, usize) {
        match self {
            StepKind::Cluster { params, rows, .. } => (
                params.iter().map(ClusterParam::count).sum(),
                rows.iter().map(ClusterRow::count).sum(),
            ),
            _ => (0, 0),
        }
    }
}

/// One step of a plan.
#[derive(Clone, Debug, PartialEq)]
pub struct Step {
    /// What it does.
    pub kind: StepKind,
    /// The joints, constraints and inputs it satisfies (by name).
    pub serves: Vec<String>,
}

/// A branching step's slot: its root choice and the point (or rotation, as
/// cos/sin) of the drawn pose, which is also the first "previous frame"
/// value of the nearest-root policy.
#[derive(Clone, Debug, PartialEq)]
pub struct BranchSlot {
    /// The step that owns the slot.
    pub step: usize,
    /// The branch that reproduces the drawn pose.
    pub initial: Branch,
    /// The drawn value.
    pub drawn: Point,
}

/// An input as the plan sees it.
#[derive(Clone, Debug, PartialEq)]
pub struct PlanInput {
    /// Name.
    pub name: String,
    /// Angle or slide.
    pub kind: InputKind,
}

/// A body as the plan sees it.
#[derive(Clone, Debug, PartialEq)]
pub struct PlanBody {
    /// Name.
    pub name: String,
    /// Part of the ground (never moved).
    pub fixed: bool,
    /// Its markers' names and local coordinates (for explanations).
    pub markers: Vec<(String, Point)>,
}

/// A computed point.
#[derive(Clone, Debug, PartialEq)]
pub struct Temp {
    /// The markers that meet there, e.g. "coupler.C".
    pub name: String,
}

/// A complete plan for one mechanism and choice of inputs.
#[derive(Clone, Debug, PartialEq)]
pub struct Plan {
    /// The mechanism's name.
    pub mechanism: String,
    /// The source file name (for the generated header).
    pub source: String,
    /// Where each joint read from a file is written: its name as the
    /// steps' `serves` start with it ("joint B") and its line (the
    /// generated module's step comments cite `file:line`). Empty for a
    /// mechanism built in code.
    pub joint_lines: Vec<(String, usize)>,
    /// Bodies in mechanism order.
    pub bodies: Vec<PlanBody>,
    /// Inputs in mechanism order.
    pub inputs: Vec<PlanInput>,
    /// Points computed per frame.
    pub temps: Vec<Temp>,
    /// Branch slots of the branching steps.
    pub branches: Vec<BranchSlot>,
    /// The steps, in execution order.
    pub steps: Vec<Step>,
    /// The mechanism's size (tolerances and the scaling of angles in
    /// numeric clusters are relative to it).
    pub size: f64,
}

impl Plan {
    /// Unknowns and equations handed to Newton–Raphson, over all clusters
    /// (Figure 30's "Mixed" column; (0, 0) for a closed-form plan).
    pub fn numeric_size(&self) -> (usize, usize) {
        self.steps
            .iter()
            .map(|s| s.kind.cluster_size())
            .fold((0, 0), |a, b| (a.0 + b.0, a.1 + b.1))
    }

    /// Number of cluster steps.
    pub fn clusters(&self) -> usize {
        self.steps
            .iter()
            .filter(|s| matches!(s.kind, StepKind::Cluster { .. }))
            .count()
    }
}

impl StepKind {
    /// The bodies whose poses this step writes.
    pub fn writes(&self) -> Vec<BodyId> {
        match self {
            StepKind::Orient { body, .. }
            | StepKind::Turn { body, .. }
            | StepKind::Shift { body, .. }
            | StepKind::Anchor { body, .. }
            | StepKind::Align { body, .. }
            | StepKind::TurnLine { body, .. } => vec![*body],
            StepKind::Cluster { params, .. } => params.iter().map(ClusterParam::body).collect(),
            StepKind::CircleCircle { .. }
            | StepKind::CircleLine { .. }
            | StepKind::LineLine { .. }
            | StepKind::Within { .. } => vec![],
        }
    }

    /// Whether the step can only check an equation an earlier step already
    /// decided (a body pinned twice): the redundancy the DOF analysis
    /// itself finds, which move time checks rather than solves.
    pub fn only_checks(&self) -> bool {
        matches!(self, StepKind::Align { redundant: true, .. })
    }

    /// Whether this step writes body `b`'s pose (one of [`StepKind::writes`],
    /// without collecting them).
    pub fn writes_body(&self, b: BodyId) -> bool {
        match self {
            StepKind::Orient { body, .. }
            | StepKind::Turn { body, .. }
            | StepKind::Shift { body, .. }
            | StepKind::Anchor { body, .. }
            | StepKind::Align { body, .. }
            | StepKind::TurnLine { body, .. } => *body == b,
            StepKind::Cluster { params, .. } => params.iter().any(|p| p.body() == b),
            StepKind::CircleCircle { .. }
            | StepKind::CircleLine { .. }
            | StepKind::LineLine { .. }
            | StepKind::Within { .. } => false,
        }
    }

    /// The temp this step computes, if it is an intersection.
    pub fn computes(&self) -> Option<usize> {
        match self {
            StepKind::CircleCircle { out, .. }
            | StepKind::CircleLine { out, .. }
            | StepKind::LineLine { out, .. } => Some(*out),
            _ => None,
        }
    }

    /// The branch slot this step owns, if it has two roots.
    pub fn branch(&self) -> Option<usize> {
        match self {
            StepKind::CircleCircle { branch, .. }
            | StepKind::CircleLine { branch, .. }
            | StepKind::TurnLine { branch, .. } => Some(*branch),
            _ => None,
        }
    }
}
