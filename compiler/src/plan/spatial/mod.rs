//! The spatial plan IR: the contract between the spatial planner and both
//! back ends, as [`super::Plan`] is for planar plans.
//!
//! A spatial plan moves bodies by **actions** (Kramer's translate and
//! rotate, docs/design/spatial.md §2.2), each taking a body from the pose it has —
//! last frame's, at first — to one that meets one more constraint while
//! keeping those met before. Freedoms no constraint removes are therefore
//! kept at minimum motion (an RSSR coupler's spin stays where it was).
//! Loops are closed by intersecting the loci of partly placed markers into
//! **pseudo-markers** (temps). Every constant a step needs is here.

use dofplan_runtime::spatial::rows::RowKind;
use dofplan_runtime::spatial::Vec3;
use dofplan_runtime::Branch;

use crate::model::spatial::equations::Equation;
use crate::model::InputKind;

mod explain;

/// Index of a body in the mechanism's body order.
pub type BodyId = usize;

/// A world point a step reads, computed from poses already reached.
#[derive(Clone, Debug, PartialEq)]
pub enum PointRef {
    /// A constant (a marker of a fixed body).
    Fixed(Vec3),
    /// A point of a body, local (= drawn) coordinates.
    Body {
        /// The body.
        body: BodyId,
        /// Local coordinates.
        local: Vec3,
    },
    /// A point carried along a slide: `body.world(local + sign·s·dir)` for
    /// the slide input's value `s` (a rod's end seen from its barrel).
    Slid {
        /// The body whose frame it is fixed in, up to the slide.
        body: BodyId,
        /// Local coordinates at zero slide.
        local: Vec3,
        /// Unit slide direction, local.
        dir: Vec3,
        /// The slide input.
        input: usize,
        /// +1 or −1 (the slide seen from the other body).
        sign: f64,
    },
    /// A pseudo-marker computed by an earlier intersection.
    Temp(usize),
}

/// A world direction a step reads (unit length).
#[derive(Clone, Debug, PartialEq)]
pub enum DirRef {
    /// A constant.
    Fixed(Vec3),
    /// A direction of a body, local.
    Body {
        /// The body.
        body: BodyId,
        /// Unit direction, local.
        local: Vec3,
    },
    /// The unit direction from one point to another.
    Between(Box<PointRef>, Box<PointRef>),
    /// A pseudo-direction computed by an earlier intersection of cones.
    Temp(usize),
}

/// What an action does to its body (docs/design/spatial.md §2.2). Every rotation is
/// about the body's pivot, so it keeps the constraints met before.
#[derive(Clone, Debug, PartialEq)]
pub enum Action {
    /// Translate by `to − from` (`from` a point of the body).
    TranslateOnto {
        /// A point of the body.
        from: PointRef,
        /// Where it goes.
        to: PointRef,
    },
    /// Translate along `dir` by the component of `to − from` along it.
    TranslateAlong {
        /// A point of the body.
        from: PointRef,
        /// Its target.
        to: PointRef,
        /// The direction of motion.
        dir: DirRef,
    },
    /// Translate across `normal` by the component of `to − from` across it.
    TranslateInPlane {
        /// A point of the body.
        from: PointRef,
        /// Its target.
        to: PointRef,
        /// The plane's normal.
        normal: DirRef,
    },
    /// Translate `from` to its foot on the line (`through`, `dir`).
    TranslateToLine {
        /// A point of the body.
        from: PointRef,
        /// A point of the line.
        through: PointRef,
        /// The line's direction.
        dir: DirRef,
    },
    /// Translate `from` along `normal` onto the plane (`through`, `normal`).
    TranslateToPlane {
        /// A point of the body.
        from: PointRef,
        /// A point of the plane.
        through: PointRef,
        /// The plane's normal.
        normal: DirRef,
    },
    /// Translate along `dir` so that `(from − origin)·dir = axial0 + s` for
    /// the slide input's value `s`: by `sign·(axial0 + s − (from − origin)·dir)`
    /// (a slide input; `from` is the joint's second marker, `origin` its
    /// first).
    SlideTo {
        /// The slide's second marker, a point of the body.
        from: PointRef,
        /// The slide's first marker.
        origin: PointRef,
        /// The slide's direction.
        dir: DirRef,
        /// The axial distance as drawn.
        axial0: f64,
        /// The slide input.
        input: usize,
        /// +1 when the body carries the second marker, −1 the first.
        sign: f64,
    },
    /// The minimal rotation about `pivot` taking `from` (a point of the
    /// body) toward `to`.
    RotateOnto {
        /// The fixed point.
        pivot: PointRef,
        /// A point of the body.
        from: PointRef,
        /// Where it goes (up to its distance from the pivot).
        to: PointRef,
    },
    /// The minimal rotation about `pivot` taking the body's direction `from`
    /// to `to`.
    AlignDir {
        /// The fixed point.
        pivot: PointRef,
        /// A direction of the body.
        from: DirRef,
        /// Its target.
        to: DirRef,
    },
    /// The rotation about the line (`pivot`, `axis`) taking the point `from`
    /// of the body onto the half-plane of `to`.
    AxisOnto {
        /// A point of the axis.
        pivot: PointRef,
        /// The axis.
        axis: DirRef,
        /// A point of the body.
        from: PointRef,
        /// Its target.
        to: PointRef,
    },
    /// The rotation about (`pivot`, `axis`) taking the body's direction
    /// `from` to `to` (their components across the axis).
    AxisDir {
        /// A point of the axis.
        pivot: PointRef,
        /// The axis.
        axis: DirRef,
        /// A direction of the body.
        from: DirRef,
        /// Its target.
        to: DirRef,
    },
    /// The rotation about (`pivot`, `axis`) that sets the twist of the
    /// body's `x2` about `axis` from the other marker's `x1` to
    /// `angle` + the input (degrees), or `angle` alone (an angle input, or
    /// the x part of an offset-x).
    Twist {
        /// A point of the axis.
        pivot: PointRef,
        /// The axis (the first marker's z).
        axis: DirRef,
        /// The first marker's x.
        x1: DirRef,
        /// The body's marker's x.
        x2: DirRef,
        /// The twist as drawn or written (radians).
        angle: f64,
        /// The angle input added, if any.
        input: Option<usize>,
        /// +1 when the body carries the second marker, −1 the first.
        sign: f64,
    },
    /// The rotation about (`pivot`, `axis`) by the angle φ that makes
    /// `(Rot(axis, φ)·v)·w = cos` (≤ 2 roots: a branch).
    AxisCondition {
        /// A point of the axis.
        pivot: PointRef,
        /// The axis.
        axis: DirRef,
        /// A direction of the body.
        v: DirRef,
        /// The direction it keeps an angle to.
        w: DirRef,
        /// The cosine of that angle.
        cos: f64,
        /// The branch slot.
        branch: usize,
    },
    /// The pose of a body hinged on a fixed line, set outright: the turn
    /// about (`pivot`, `axis`), both constants, from the drawn pose by the
    /// angle `turn` gives. It replaces the steps that re-imposed the hinge
    /// every frame and the relative turn that followed them: the body never
    /// leaves its line, and its rotation, built afresh each frame, never
    /// drifts (see `analysis::spatial::hinge`).
    Hinge {
        /// A point of the line.
        pivot: Vec3,
        /// The line's unit direction.
        axis: Vec3,
        /// The angle.
        turn: HingeTurn,
    },
    /// The rotation about `pivot` and about `from × to` that sets the angle
    /// between the body's `from` and `to` to acos(`cos`): the body's
    /// direction then lies on a cone about `to`.
    Tilt {
        /// The fixed point.
        pivot: PointRef,
        /// A direction of the body.
        from: DirRef,
        /// The cone's axis.
        to: DirRef,
        /// cos of the cone's half-angle.
        cos: f64,
    },
}

/// The angle of an [`Action::Hinge`], from the drawn pose.
#[derive(Clone, Debug, PartialEq)]
pub enum HingeTurn {
    /// `sign·(offset + input)` degrees (an angle input, or an offset-x
    /// with no input).
    Degrees {
        /// Degrees added to the input: the twist wanted less the twist as
        /// drawn.
        offset: f64,
        /// The angle input, if any.
        input: Option<usize>,
        /// +1 when the body carries the joint's second marker, −1 the first.
        sign: f64,
    },
    /// The angle taking the body's point `from` (local = drawn) onto the
    /// half-plane of `to`.
    Onto {
        /// A point of the body, local.
        from: Vec3,
        /// Its target.
        to: PointRef,
    },
    /// The angle taking the body's direction `from` (local = drawn) to
    /// `to`, across the line.
    Dir {
        /// A direction of the body, local.
        from: Vec3,
        /// Its target.
        to: DirRef,
    },
}

/// A locus of a point: where a partly placed body's marker may go.
#[derive(Clone, Debug, PartialEq)]
pub enum Locus {
    /// A circle: the point `at` turning about the line (`pivot`, `axis`).
    Circle {
        /// A point of the axis.
        pivot: PointRef,
        /// The axis.
        axis: DirRef,
        /// The point, as its body now is.
        at: PointRef,
    },
    /// A sphere about `centre` of radius |a − b| (two points of one body).
    Sphere {
        /// The centre.
        centre: PointRef,
        /// One end of the radius.
        a: PointRef,
        /// The other end.
        b: PointRef,
    },
    /// A line through `at` along `dir`.
    Line {
        /// The point, as its body now is.
        at: PointRef,
        /// The line's direction.
        dir: DirRef,
    },
}

impl Locus {
    /// "circle", "sphere" or "line".
    pub fn name(&self) -> &'static str {
        match self {
            Locus::Circle { .. } => "circle",
            Locus::Sphere { .. } => "sphere",
            Locus::Line { .. } => "line",
        }
    }

    /// The locus's dimension (1 for curves, 2 for surfaces).
    pub fn dim(&self) -> usize {
        match self {
            Locus::Sphere { .. } => 2,
            Locus::Circle { .. } | Locus::Line { .. } => 1,
        }
    }
}

/// A redundant or consistency check: an equation's rows evaluated on two
/// frames of placed bodies.
#[derive(Clone, Debug, PartialEq)]
pub struct CheckRow {
    /// The rows.
    pub kind: RowKind,
    /// The two bodies.
    pub bodies: [BodyId; 2],
    /// The markers' local points.
    pub at: [Vec3; 2],
    /// The markers' local z axes.
    pub z: [Vec3; 2],
    /// The markers' local x axes.
    pub x: [Vec3; 2],
    /// How many of the rows are redundant (the others hold by construction).
    pub redundant: usize,
    /// The largest row that passes: a length tolerance or an angle's sine.
    pub tol: f64,
    /// "joint C parallel-z".
    pub name: String,
}

impl CheckRow {
    /// An equation as a plan's check or cluster row: `redundant` of its
    /// rows only checked, passing below 1e-9 of `size` (lengths) or 1e-9
    /// (sines).
    pub fn of(e: &Equation, redundant: usize, size: f64) -> CheckRow {
        CheckRow {
            kind: e.row_kind(),
            bodies: e.bodies,
            at: [e.frames[0].at, e.frames[1].at],
            z: [e.frames[0].axes.z, e.frames[1].axes.z],
            x: [e.frames[0].axes.x, e.frames[1].axes.x],
            redundant,
            tol: if e.linear() { 1e-9 * size } else { 1e-9 },
            name: format!("{} {}", e.origin, e.kind.name()),
        }
    }
}

/// What a step does.
#[derive(Clone, Debug, PartialEq)]
pub enum StepKind {
    /// One action on one body.
    Act {
        /// The body moved.
        body: BodyId,
        /// The action.
        action: Box<Action>,
    },
    /// A pseudo-marker: a point on both loci.
    Intersect {
        /// Index into [`Plan::temps`].
        temp: usize,
        /// The two loci.
        loci: Box<[Locus; 2]>,
        /// The branch slot, when two roots are valid.
        branch: Option<usize>,
        /// Candidates off a locus by more than this are not roots (the
        /// non-coplanar circles of a Bennett linkage).
        tol: f64,
    },
    /// Two pseudo-directions: a direction `d` on both cones (each the
    /// directions at a fixed angle to a body's rotation axis: `cos` of it),
    /// written to `temps[0]`, and `sign·d` to `temps[1]` — the world z of the
    /// two markers of a parallel-z between two bodies turning about their
    /// axes (directions-only loop closure: a spherical linkage drawn with
    /// every joint at the centre).
    IntersectDir {
        /// Indices into [`Plan::temps`].
        temps: [usize; 2],
        /// Each cone: the body's axis and the cosine of the angle kept to
        /// it.
        cones: Box<[(DirRef, f64); 2]>,
        /// +1 or −1: the second direction is `sign·d`.
        sign: f64,
        /// The branch slot.
        branch: usize,
    },
    /// Redundant rows: they must hold, or the frame breaks "inconsistent".
    Check {
        /// The rows.
        rows: Vec<CheckRow>,
    },
    /// Bodies no fragment places, solved together by Newton–Raphson.
    Cluster(Box<Cluster>),
}

/// A body of a numeric cluster and its unknowns.
#[derive(Clone, Debug, PartialEq)]
pub enum Param {
    /// Free: a rotation about its current origin and a translation (6).
    Free {
        /// The body.
        body: BodyId,
    },
    /// Rotation about a fixed pivot (3).
    Pivot {
        /// The body.
        body: BodyId,
        /// The pivot.
        pivot: PointRef,
    },
    /// Rotation about a fixed axis (1).
    Axis {
        /// The body.
        body: BodyId,
        /// A point of the axis.
        pivot: PointRef,
        /// The axis.
        axis: DirRef,
    },
}

impl Param {
    /// The body.
    pub fn body(&self) -> BodyId {
        match self {
            Param::Free { body } | Param::Pivot { body, .. } | Param::Axis { body, .. } => *body,
        }
    }

    /// Number of unknowns.
    pub fn count(&self) -> usize {
        match self {
            Param::Free { .. } => 6,
            Param::Pivot { .. } => 3,
            Param::Axis { .. } => 1,
        }
    }
}

/// A row of a cluster: an equation, or a distance kept by a contracted
/// chain (a leg of fixed length between two points).
#[derive(Clone, Debug, PartialEq)]
pub enum ClusterRow {
    /// An equation's rows.
    Equation(CheckRow),
    /// |a − b| = |c − d| (c, d points of a contracted chain: its length).
    Distance {
        /// One end.
        a: PointRef,
        /// The other end.
        b: PointRef,
        /// The chain's first point (its length's).
        c: PointRef,
        /// The chain's last point.
        d: PointRef,
        /// "leg1".
        name: String,
    },
    /// A dragged point: `body.world(local)` = (`inputs[0]`, `inputs[1]`,
    /// `inputs[2]`) — the drag's target, carried as the plan's three inputs.
    Pin {
        /// The dragged body.
        body: BodyId,
        /// The dragged marker, local.
        local: Vec3,
        /// "coupler.P".
        name: String,
    },
}

/// A numeric cluster.
#[derive(Clone, Debug, PartialEq)]
pub struct Cluster {
    /// Unknown bodies and their parametrisation.
    pub params: Vec<Param>,
    /// Residual rows.
    pub rows: Vec<ClusterRow>,
    /// The mechanism's size: Newton's tolerance and step bound scale with it.
    pub size: f64,
}

impl Cluster {
    /// Number of unknowns.
    pub fn unknowns(&self) -> usize {
        self.params.iter().map(Param::count).sum()
    }

    /// Number of scalar equations.
    pub fn equations(&self) -> usize {
        self.rows
            .iter()
            .map(|r| match r {
                ClusterRow::Equation(c) => c.kind.rows(),
                ClusterRow::Distance { .. } => 1,
                ClusterRow::Pin { .. } => 3,
            })
            .sum()
    }
}

/// One step and what it serves; its explanation is derived from it
/// ([`Plan::explain`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Step {
    /// What it does.
    pub kind: StepKind,
    /// The joints, constraints and inputs it serves ("joint B coincident").
    pub serves: Vec<String>,
}

/// A pseudo-marker: its drawn position (where the first frame starts).
#[derive(Clone, Debug, PartialEq)]
pub struct Temp {
    /// "coupler.C".
    pub name: String,
    /// Drawn world position.
    pub drawn: Vec3,
}

/// A branch slot's initial sign and what it is for.
#[derive(Clone, Debug, PartialEq)]
pub struct BranchSlot {
    /// The branch of the drawn pose.
    pub initial: Branch,
    /// The root's last record, as drawn: the sine of the angle (0) for a
    /// rotation to a condition, or unused.
    pub angle: f64,
}

/// A spatial plan.
#[derive(Clone, Debug, PartialEq)]
pub struct Plan {
    /// The mechanism's name.
    pub name: String,
    /// Body names in file order.
    pub bodies: Vec<String>,
    /// Which bodies are fixed.
    pub fixed: Vec<bool>,
    /// Input names.
    pub inputs: Vec<String>,
    /// Each input's kind, in [`Plan::inputs`] order: an angle (degrees) or
    /// a slide (length units). Generated modules list them (`INPUT_KINDS`);
    /// the steps already carry what they need of them.
    pub input_kinds: Vec<InputKind>,
    /// Each body's markers in file order: name and local (= drawn)
    /// coordinates. The generated module names them (`marker::CRANK_B`);
    /// no step reads them.
    pub markers: Vec<Vec<(String, Vec3)>>,
    /// Each marker's local z and x axes as its first joint's equations
    /// read them (none for a marker in no joint and without axes), as
    /// [`Plan::markers`] lists the markers: explanations name a body's
    /// direction by the marker axis it is ("rocker.D z").
    pub axes: Vec<Vec<Option<[Vec3; 2]>>>,
    /// The file's name without its folder (the generated module's header),
    /// so a plan does not depend on where its file was read from.
    pub source: String,
    /// Where each joint read from a file is written: its name as the
    /// steps' `serves` start with it ("joint B") and its line (the
    /// generated module's step comments cite `file:line`). Empty for a
    /// mechanism built in code.
    pub joint_lines: Vec<(String, usize)>,
    /// Steps in order.
    pub steps: Vec<Step>,
    /// Pseudo-markers.
    pub temps: Vec<Temp>,
    /// Branch slots.
    pub branches: Vec<BranchSlot>,
    /// Freedoms left at minimum motion, by body: (body, freedoms, why).
    pub idle: Vec<(BodyId, usize, String)>,
}

impl Plan {
    /// Rows the plan only checks (redundant), named.
    pub fn redundant(&self) -> Vec<(&str, usize)> {
        let mut out = Vec::new();
        for s in &self.steps {
            if let StepKind::Check { rows } = &s.kind {
                for r in rows {
                    if r.redundant > 0 {
                        out.push((r.name.as_str(), r.redundant));
                    }
                }
            }
        }
        out
    }

    /// Whether body `b`'s rotation is composed frame after frame (turned
    /// from last frame's pose), so the back ends correct it once a frame
    /// ([`Pose3::renormalize`](dofplan_runtime::spatial::Pose3::renormalize)):
    /// every moving body some step turns or a cluster solves, except those
    /// set outright by [`Action::Hinge`].
    pub fn composes(&self, b: BodyId) -> bool {
        !self.fixed[b]
            && self.steps.iter().any(|s| match &s.kind {
                StepKind::Act { body, action } => *body == b && !matches!(**action, Action::Hinge { .. }),
                StepKind::Cluster(c) => c.params.iter().any(|p| p.body() == b),
                _ => false,
            })
    }

    /// Unknowns and equations handed to Newton–Raphson.
    pub fn cluster_size(&self) -> (usize, usize) {
        self.steps.iter().fold((0, 0), |(u, e), s| match &s.kind {
            StepKind::Cluster(c) => (u + c.unknowns(), e + c.equations()),
            _ => (u, e),
        })
    }
}

/// The number `dofplan plan` shows for the spatial step whose runtime id is
/// `id` (a break's `step`, a stretch's step): the steps run with ids from
/// 1, and are listed and cited from 0, as planar steps are.
pub fn step_number(id: u32) -> usize {
    (id as usize).saturating_sub(1)
}
