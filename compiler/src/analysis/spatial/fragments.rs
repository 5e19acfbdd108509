//! The spatial plan-fragment table (docs/design/spatial.md §2.3), as data.
//!
//! A row says: a body whose freedoms are (`t`, `r`), meeting a primitive
//! whose other side is known, in this `case`, takes this `action` and ends
//! in `then`, checking `checks` rows it cannot use (redundant ones). The
//! planner looks rows up by (state, primitive, case) and carries out the
//! action through the runtime's steps; `dofplan fragments` prints the table.

/// Translational freedom of a body (Kramer's TDOF, with its argument).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TDof {
    /// T3: free.
    Free,
    /// T2: a point of the body stays in a plane.
    Plane,
    /// T1: a point of the body stays on a line.
    Line,
    /// T0: a point of the body (the pivot) is fixed.
    Point,
}

/// Rotational freedom of a body (Kramer's RDOF, with its argument).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RDof {
    /// R3: free rotation about the pivot.
    Free,
    /// R2: a body direction stays on a cone about a world axis.
    Cone,
    /// R1: rotation about one axis through the pivot.
    Axis,
    /// R0: orientation known.
    Fixed,
}

impl TDof {
    /// "T3" … "T0".
    pub fn name(self) -> &'static str {
        match self {
            TDof::Free => "T3",
            TDof::Plane => "T2(plane)",
            TDof::Line => "T1(line)",
            TDof::Point => "T0(point)",
        }
    }
}

impl RDof {
    /// "R3" … "R0".
    pub fn name(self) -> &'static str {
        match self {
            RDof::Free => "R3",
            RDof::Cone => "R2(cone)",
            RDof::Axis => "R1(axis)",
            RDof::Fixed => "R0",
        }
    }
}

/// The primitive a fragment applies, seen from the moving body.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Prim {
    /// coincident: the body's marker onto a known point.
    Coincident,
    /// in-line: the body's marker onto a known line.
    InLine,
    /// in-line, the body owning the line through a known point (role swap).
    InLineOwner,
    /// in-plane: the body's marker onto a known plane.
    InPlane,
    /// in-plane, the body owning the plane through a known point.
    InPlaneOwner,
    /// parallel-z: the body's z onto a known direction.
    ParallelZ,
    /// offset-z / perpendicular-z: the body's z at an angle to a known one.
    OffsetZ,
    /// offset-x: the body's axes onto known ones (up to the offset).
    OffsetX,
    /// An angle input about the joint's axis.
    Angle,
    /// A slide input along the joint's line.
    Slide,
}

impl Prim {
    /// The name printed in the table.
    pub fn name(self) -> &'static str {
        match self {
            Prim::Coincident => "coincident",
            Prim::InLine => "in-line (point)",
            Prim::InLineOwner => "in-line (line owner)",
            Prim::InPlane => "in-plane (point)",
            Prim::InPlaneOwner => "in-plane (plane owner)",
            Prim::ParallelZ => "parallel-z",
            Prim::OffsetZ => "offset-z",
            Prim::OffsetX => "offset-x",
            Prim::Angle => "angle input",
            Prim::Slide => "slide input",
        }
    }
}

/// Which geometric case of a state and primitive a row covers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Case {
    /// Any.
    Any,
    /// The marker is the pivot.
    AtPivot,
    /// The marker is off the pivot.
    OffPivot,
    /// The marker (point) lies on the rotation axis.
    OnAxis,
    /// The marker (point) lies off the rotation axis.
    OffAxis,
    /// The marker's z is along the rotation axis (or the cone's direction).
    Along,
    /// The marker's z is across the rotation axis (or the cone's direction).
    Across,
}

impl Case {
    /// The text printed in the table.
    pub fn name(self) -> &'static str {
        match self {
            Case::Any => "",
            Case::AtPivot => "m = pivot",
            Case::OffPivot => "m ≠ pivot",
            Case::OnAxis => "m on the axis",
            Case::OffAxis => "m off the axis",
            Case::Along => "z_m along the axis",
            Case::Across => "z_m across the axis",
        }
    }
}

/// What a fragment does (each an action or a pair of runtime steps).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Do {
    /// Translate the marker onto the point.
    TranslateOnto,
    /// Translate along the body's line so the marker reaches the point.
    TranslateAlong,
    /// Translate in the body's plane so the marker reaches the point.
    TranslateInPlane,
    /// Translate the marker to its foot on the line.
    TranslateToLine,
    /// Translate the marker onto the plane.
    TranslateToPlane,
    /// Translate the body's line (its z known) through the point.
    OwnerLineThrough,
    /// Translate the body's plane (its z known) through the point.
    OwnerPlaneThrough,
    /// Minimal rotation about the pivot taking the marker toward the point.
    RotateOnto,
    /// Rotation about the axis taking the marker onto the point.
    AxisOnto,
    /// Rotate onto the point, then about the new axis onto the cone
    /// (a branch).
    RotateOntoCone,
    /// Pivot onto line ∩ sphere (a branch), then rotate onto the point.
    LineSphere,
    /// Marker onto circle ∩ line (a branch).
    CircleLine,
    /// Marker onto sphere ∩ line (a branch).
    SphereLine,
    /// Translate along the line, then rotate about it onto the point.
    SlideTurn,
    /// Minimal rotation taking z_m to the direction.
    AlignDir,
    /// Rotation about the axis taking z_m to the direction.
    AxisDir,
    /// Align z_m, then turn about it until the cone's direction is on its
    /// cone (a branch).
    AlignOntoCone,
    /// Rotation about the axis making the angle to the direction (a branch).
    AxisCondition,
    /// Tilt z_m to the angle: the cone state.
    Tilt,
    /// Align z, then twist x: orientation known.
    AlignTwist,
    /// Twist about the axis (the input's angle, or offset-x's).
    Twist,
    /// Slide along the line to the input's distance.
    SlideTo,
    /// Nothing to move: the rows are redundant.
    Check,
}

/// A row of the fragment table.
#[derive(Clone, Copy, Debug)]
pub struct Fragment {
    /// The body's translational state.
    pub t: TDof,
    /// Its rotational state (`None`: any).
    pub r: Option<RDof>,
    /// The primitive.
    pub prim: Prim,
    /// The case.
    pub case: Case,
    /// The action.
    pub action: Do,
    /// The state it ends in.
    pub then: &'static str,
    /// Rows it can only check (redundant), of the primitive's rows.
    pub checks: usize,
    /// Degenerate cases and notes.
    pub note: &'static str,
}

#[allow(clippy::too_many_arguments)]
const fn row(
    t: TDof,
    r: Option<RDof>,
    prim: Prim,
    case: Case,
    action: Do,
    then: &'static str,
    checks: usize,
    note: &'static str,
) -> Fragment {
    Fragment {
        t,
        r,
        prim,
        case,
        action,
        then,
        checks,
        note,
    }
}

use Case::*;
use Prim::*;
use RDof::{Axis, Cone, Fixed};
use TDof::{Line as TLine, Plane as TPlane, Point as TPoint};

/// The table, searched in order: the first matching row applies.
pub const FRAGMENTS: &[Fragment] = &[
    // coincident (3 rows)
    row(
        TDof::Free,
        None,
        Coincident,
        Any,
        Do::TranslateOnto,
        "T0 · R unchanged",
        0,
        "Kramer's (3,3,coincident)",
    ),
    row(TPoint, None, Coincident, AtPivot, Do::Check, "unchanged", 3, ""),
    row(
        TPoint,
        Some(Fixed),
        Coincident,
        Any,
        Do::Check,
        "unchanged",
        3,
        "",
    ),
    row(
        TPoint,
        Some(RDof::Free),
        Coincident,
        OffPivot,
        Do::RotateOnto,
        "T0 · R1(pivot→m)",
        1,
        "check |K−P| = r; antiparallel: 180° about a perpendicular; Kramer's brick step 2",
    ),
    row(
        TPoint,
        Some(Axis),
        Coincident,
        OnAxis,
        Do::Check,
        "unchanged",
        3,
        "",
    ),
    row(
        TPoint,
        Some(Axis),
        Coincident,
        OffAxis,
        Do::AxisOnto,
        "T0 · R0",
        2,
        "checks axial offset and radius; Kramer's brick step 3",
    ),
    row(
        TPoint,
        Some(Cone),
        Coincident,
        OffPivot,
        Do::RotateOntoCone,
        "T0 · R0",
        1,
        "branch; m−p along the cone's direction: deferred",
    ),
    row(
        TLine,
        Some(Fixed),
        Coincident,
        Any,
        Do::TranslateAlong,
        "T0 · R0",
        2,
        "",
    ),
    row(
        TLine,
        Some(Axis),
        Coincident,
        OnAxis,
        Do::TranslateAlong,
        "T0 · R1",
        2,
        "cylindrical state, m on its axis",
    ),
    row(
        TLine,
        Some(Axis),
        Coincident,
        OffAxis,
        Do::SlideTurn,
        "T0 · R0",
        1,
        "cylindrical state; checks the radius",
    ),
    row(
        TLine,
        Some(RDof::Free),
        Coincident,
        OffPivot,
        Do::LineSphere,
        "T0 · R1(pivot→m)",
        0,
        "branch; tangent: dead point",
    ),
    row(
        TPlane,
        Some(Axis),
        Coincident,
        Any,
        Do::TranslateInPlane,
        "T0 · R1",
        1,
        "planar state; checks the height over the plane",
    ),
    row(
        TPlane,
        Some(Fixed),
        Coincident,
        Any,
        Do::TranslateInPlane,
        "T0 · R0",
        1,
        "",
    ),
    // in-line: the body's point onto a known line (2 rows)
    row(
        TDof::Free,
        None,
        InLine,
        Any,
        Do::TranslateToLine,
        "T1(line) · R unchanged",
        0,
        "",
    ),
    row(TPoint, None, InLine, AtPivot, Do::Check, "unchanged", 2, ""),
    row(TPoint, Some(Fixed), InLine, Any, Do::Check, "unchanged", 2, ""),
    row(
        TPoint,
        Some(RDof::Free),
        InLine,
        OffPivot,
        Do::SphereLine,
        "T0 · R1(pivot→m)",
        0,
        "branch; the line misses the sphere: break",
    ),
    row(TPoint, Some(Axis), InLine, OnAxis, Do::Check, "unchanged", 2, ""),
    row(
        TPoint,
        Some(Axis),
        InLine,
        OffAxis,
        Do::CircleLine,
        "T0 · R0",
        1,
        "branch when the line lies in the circle's plane",
    ),
    // in-line with the body owning the line (role swap, docs/design/spatial.md §2.4 rule 1)
    row(
        TDof::Free,
        Some(Fixed),
        InLineOwner,
        Any,
        Do::OwnerLineThrough,
        "T1(line) · R0",
        0,
        "z of the line known",
    ),
    row(
        TDof::Free,
        Some(Axis),
        InLineOwner,
        Along,
        Do::OwnerLineThrough,
        "T1(line) · R1",
        0,
        "the line along the rotation axis",
    ),
    // in-plane (1 row)
    row(
        TDof::Free,
        None,
        InPlane,
        Any,
        Do::TranslateToPlane,
        "T2(plane) · R unchanged",
        0,
        "",
    ),
    row(TPoint, None, InPlane, AtPivot, Do::Check, "unchanged", 1, ""),
    row(TPoint, Some(Fixed), InPlane, Any, Do::Check, "unchanged", 1, ""),
    row(
        TDof::Free,
        Some(Fixed),
        InPlaneOwner,
        Any,
        Do::OwnerPlaneThrough,
        "T2(plane) · R0",
        0,
        "",
    ),
    row(
        TDof::Free,
        Some(Axis),
        InPlaneOwner,
        Along,
        Do::OwnerPlaneThrough,
        "T2(plane) · R1",
        0,
        "the plane across the rotation axis",
    ),
    // parallel-z (2 rows)
    row(
        TDof::Free,
        Some(RDof::Free),
        ParallelZ,
        Any,
        Do::AlignDir,
        "R1(z)",
        0,
        "antiparallel: 180° about a perpendicular",
    ),
    row(
        TPoint,
        Some(RDof::Free),
        ParallelZ,
        Any,
        Do::AlignDir,
        "T0 · R1(z)",
        0,
        "the revolute's second primitive",
    ),
    row(
        TLine,
        Some(RDof::Free),
        ParallelZ,
        Any,
        Do::AlignDir,
        "T1 · R1(z)",
        0,
        "",
    ),
    row(
        TPlane,
        Some(RDof::Free),
        ParallelZ,
        Any,
        Do::AlignDir,
        "T2 · R1(z)",
        0,
        "",
    ),
    row(
        TDof::Free,
        Some(Axis),
        ParallelZ,
        Along,
        Do::Check,
        "unchanged",
        2,
        "the axis already set",
    ),
    row(
        TPoint,
        Some(Axis),
        ParallelZ,
        Along,
        Do::Check,
        "unchanged",
        2,
        "the axis already set",
    ),
    row(TLine, Some(Axis), ParallelZ, Along, Do::Check, "unchanged", 2, ""),
    row(
        TPlane,
        Some(Axis),
        ParallelZ,
        Along,
        Do::Check,
        "unchanged",
        2,
        "",
    ),
    row(
        TDof::Free,
        Some(Axis),
        ParallelZ,
        Across,
        Do::AxisDir,
        "R0",
        1,
        "checks angle(z_m, axis) = angle(target, axis)",
    ),
    row(
        TPoint,
        Some(Axis),
        ParallelZ,
        Across,
        Do::AxisDir,
        "T0 · R0",
        1,
        "checks angle(z_m, axis) = angle(target, axis)",
    ),
    row(
        TLine,
        Some(Axis),
        ParallelZ,
        Across,
        Do::AxisDir,
        "T1 · R0",
        1,
        "",
    ),
    row(
        TPoint,
        Some(Cone),
        ParallelZ,
        Across,
        Do::AlignOntoCone,
        "T0 · R0",
        0,
        "branch",
    ),
    row(
        TDof::Free,
        Some(Fixed),
        ParallelZ,
        Any,
        Do::Check,
        "unchanged",
        2,
        "",
    ),
    row(TPoint, Some(Fixed), ParallelZ, Any, Do::Check, "unchanged", 2, ""),
    row(TLine, Some(Fixed), ParallelZ, Any, Do::Check, "unchanged", 2, ""),
    row(TPlane, Some(Fixed), ParallelZ, Any, Do::Check, "unchanged", 2, ""),
    // offset-z / perpendicular-z (1 row)
    row(
        TDof::Free,
        Some(RDof::Free),
        OffsetZ,
        Any,
        Do::Tilt,
        "R2(cone)",
        0,
        "z_m ∥ target: tilt about a perpendicular",
    ),
    row(
        TPoint,
        Some(RDof::Free),
        OffsetZ,
        Any,
        Do::Tilt,
        "T0 · R2(cone)",
        0,
        "the universal joint's second primitive",
    ),
    row(TPoint, Some(Axis), OffsetZ, Along, Do::Check, "unchanged", 1, ""),
    row(
        TPoint,
        Some(Axis),
        OffsetZ,
        Across,
        Do::AxisCondition,
        "T0 · R0",
        0,
        "branch; tangent: dead point (the Cardan joint)",
    ),
    row(
        TDof::Free,
        Some(Axis),
        OffsetZ,
        Across,
        Do::AxisCondition,
        "R0",
        0,
        "branch",
    ),
    row(
        TLine,
        Some(Axis),
        OffsetZ,
        Across,
        Do::AxisCondition,
        "T1 · R0",
        0,
        "branch",
    ),
    row(
        TDof::Free,
        Some(Fixed),
        OffsetZ,
        Any,
        Do::Check,
        "unchanged",
        1,
        "",
    ),
    row(TPoint, Some(Fixed), OffsetZ, Any, Do::Check, "unchanged", 1, ""),
    row(TLine, Some(Fixed), OffsetZ, Any, Do::Check, "unchanged", 1, ""),
    // offset-x (3 rows)
    row(
        TDof::Free,
        Some(RDof::Free),
        OffsetX,
        Any,
        Do::AlignTwist,
        "R0",
        0,
        "the fixed joint's, the prismatic joint's orientation",
    ),
    row(
        TPoint,
        Some(RDof::Free),
        OffsetX,
        Any,
        Do::AlignTwist,
        "T0 · R0",
        0,
        "",
    ),
    row(
        TLine,
        Some(RDof::Free),
        OffsetX,
        Any,
        Do::AlignTwist,
        "T1 · R0",
        0,
        "",
    ),
    row(TDof::Free, Some(Axis), OffsetX, Along, Do::Twist, "R0", 2, ""),
    row(TPoint, Some(Axis), OffsetX, Along, Do::Twist, "T0 · R0", 2, ""),
    row(TLine, Some(Axis), OffsetX, Along, Do::Twist, "T1 · R0", 2, ""),
    row(
        TDof::Free,
        Some(Fixed),
        OffsetX,
        Any,
        Do::Check,
        "unchanged",
        3,
        "",
    ),
    row(TPoint, Some(Fixed), OffsetX, Any, Do::Check, "unchanged", 3, ""),
    row(TLine, Some(Fixed), OffsetX, Any, Do::Check, "unchanged", 3, ""),
    // inputs (1 row)
    row(
        TDof::Free,
        Some(Axis),
        Angle,
        Along,
        Do::Twist,
        "R0",
        0,
        "rotation by the input about the joint axis",
    ),
    row(
        TPoint,
        Some(Axis),
        Angle,
        Along,
        Do::Twist,
        "T0 · R0",
        0,
        "rotation by the input about the joint axis",
    ),
    row(TLine, Some(Axis), Angle, Along, Do::Twist, "T1 · R0", 0, ""),
    row(
        TLine,
        None,
        Slide,
        Along,
        Do::SlideTo,
        "T0 · R unchanged",
        0,
        "translation by the input along the joint axis",
    ),
];

/// The first row for a state, primitive and case.
pub fn lookup(t: TDof, r: RDof, prim: Prim, case: Case) -> Option<&'static Fragment> {
    FRAGMENTS.iter().find(|f| {
        f.t == t && f.r.is_none_or(|fr| fr == r) && f.prim == prim && (f.case == case || f.case == Any)
    })
}

/// The table as `dofplan fragments` prints it.
pub fn table() -> String {
    let mut out = String::from(
        "state                  | primitive             | case                 | action            | new state               | checks | notes\n",
    );
    out.push_str(&format!("{}\n", "-".repeat(130)));
    for f in FRAGMENTS {
        let state = format!("{} · {}", f.t.name(), f.r.map_or("R*", RDof::name));
        out.push_str(&format!(
            "{:<22} | {:<21} | {:<20} | {:<17} | {:<23} | {:>6} | {}\n",
            state,
            f.prim.name(),
            f.case.name(),
            format!("{:?}", f.action),
            f.then,
            f.checks,
            f.note
        ));
    }
    out.push_str(
        "\nLoop closure (two partly placed bodies joined by coincident): intersect the markers' loci into a\n\
         pseudo-marker, then each body meets it by the rows above. Loci: T0·R1 circle, T0·R3 sphere, T1·R0 line;\n\
         pairs circle∩circle (coplanar, or on a common sphere, or one valid candidate), sphere∩circle,\n\
         line∩sphere, line∩circle. A parallel-z between two bodies turning about non-parallel axes\n\
         closes on directions: cone∩cone into a pseudo-direction each turns onto.\n\
         What no row closes becomes a numeric cluster.\n",
    );
    out
}
