//! Joints, primitive constraints and inputs as primitive equations on body
//! poses (Kramer's constraints in their 2D form, Brunkhart §5.1).
//!
//! - revolute = coincident (2 equations);
//! - prismatic = in-line (1) + parallel (1, no relative rotation);
//! - an angle input adds a parallel equation with the input as the relative
//!   rotation; a slide input turns the prismatic's in-line into a coincident
//!   displaced by the slide (it implies the in-line).

use dofplan_runtime::planar::cluster::Row as ClusterRow;
use dofplan_runtime::Point;

use crate::model::planar::slots::Shape;
use crate::model::{ConstraintKind, InputKind, JointKind, MarkerId, Mechanism};

/// One end of an equation: a marker of a body.
#[derive(Clone, Debug)]
pub struct End {
    /// The body.
    pub body: usize,
    /// The marker's local (= drawn) coordinates.
    pub local: Point,
    /// "body.marker".
    pub name: String,
}

/// A primitive equation.
#[derive(Clone, Debug)]
pub enum Equation {
    /// `a.body.world(a.local + u·dir) = b.body.world(b.local)`, with `u` the
    /// slide input's value (0 without one).
    Coincident {
        /// First end.
        a: End,
        /// Second end.
        b: End,
        /// A slide input and its unit direction (in `a.body`'s frame).
        slide: Option<(usize, Point)>,
    },
    /// `point` lies on the line through `line` along `dir`.
    InLine {
        /// The marker carrying the line.
        line: End,
        /// Unit direction of the line in `line.body`'s frame.
        dir: Point,
        /// The marker on the line.
        point: End,
    },
    /// `point` lies on the circle of `radius` about `centre` (a pin in a
    /// circular slot).
    OnCircle {
        /// The circle's centre, a marker of the slot's body.
        centre: End,
        /// The radius.
        radius: f64,
        /// The marker on the circle.
        point: End,
    },
    /// `rot(b) = rot(a) · rel`, `rel` = the angle input or the identity.
    Parallel {
        /// First body.
        a: usize,
        /// Second body.
        b: usize,
        /// The angle input, if any.
        input: Option<usize>,
    },
}

impl Equation {
    /// The primitive's name, as `check --json` lists redundant rows.
    pub fn kind_name(&self) -> &'static str {
        match self {
            Equation::Coincident { .. } => "coincident",
            Equation::InLine { .. } => "in-line",
            Equation::OnCircle { .. } => "on-circle",
            Equation::Parallel { .. } => "offset",
        }
    }

    /// How many scalar equations it stands for.
    pub fn count(&self) -> usize {
        match self {
            Equation::Coincident { .. } => 2,
            Equation::InLine { .. } | Equation::OnCircle { .. } | Equation::Parallel { .. } => 1,
        }
    }

    /// The equation as a numeric cluster's row (the runtime's residual
    /// form of it).
    pub fn row(&self) -> ClusterRow {
        match self {
            Equation::Coincident { a, b, slide } => ClusterRow::Coincident {
                a: a.body,
                la: a.local,
                slide: *slide,
                b: b.body,
                lb: b.local,
            },
            Equation::InLine { line, dir, point } => ClusterRow::InLine {
                a: line.body,
                la: line.local,
                dir: *dir,
                b: point.body,
                lb: point.local,
            },
            Equation::OnCircle {
                centre,
                radius,
                point,
            } => ClusterRow::OnCircle {
                a: centre.body,
                la: centre.local,
                r: *radius,
                b: point.body,
                lb: point.local,
            },
            Equation::Parallel { a, b, input } => ClusterRow::Parallel {
                a: *a,
                b: *b,
                input: *input,
            },
        }
    }

    /// The two bodies it relates.
    pub fn bodies(&self) -> [usize; 2] {
        match self {
            Equation::Coincident { a, b, .. } => [a.body, b.body],
            Equation::InLine { line, point, .. } => [line.body, point.body],
            Equation::OnCircle { centre, point, .. } => [centre.body, point.body],
            Equation::Parallel { a, b, .. } => [*a, *b],
        }
    }
}

/// An equation and the joint, constraint or input it comes from.
#[derive(Clone, Debug)]
pub struct Sourced {
    /// The equation.
    pub eq: Equation,
    /// "joint A", "constraint c1", "input theta".
    pub origin: String,
}

fn end(m: &Mechanism, id: MarkerId) -> End {
    End {
        body: id.body,
        local: m.marker(id).at,
        name: m.marker_name(id),
    }
}

/// Every primitive equation of a mechanism, joints first (slots after the
/// others), then constraints, in file order.
pub fn equations(m: &Mechanism) -> Vec<Sourced> {
    let mut out = Vec::new();
    for (ji, joint) in m.joints.iter().enumerate() {
        let origin = format!("joint {}", joint.name);
        let input = m.inputs.iter().position(|i| i.joint == ji);
        let [a, b] = joint.markers;
        match joint.kind {
            JointKind::Revolute => {
                out.push(Sourced {
                    eq: Equation::Coincident {
                        a: end(m, a),
                        b: end(m, b),
                        slide: None,
                    },
                    origin: origin.clone(),
                });
                if let Some(i) = input {
                    debug_assert_eq!(m.inputs[i].kind, InputKind::Angle);
                    out.push(Sourced {
                        eq: Equation::Parallel {
                            a: a.body,
                            b: b.body,
                            input: Some(i),
                        },
                        origin: format!("input {}", m.inputs[i].name),
                    });
                }
            }
            JointKind::Prismatic => {
                let dir = m
                    .marker(a)
                    .unit_dir()
                    .expect("validated: prismatic markers carry a dir");
                out.push(Sourced {
                    eq: Equation::Parallel {
                        a: a.body,
                        b: b.body,
                        input: None,
                    },
                    origin: origin.clone(),
                });
                match input {
                    Some(i) => out.push(Sourced {
                        // The slide fixes where the second marker is on the
                        // line, so the in-line becomes a coincidence with
                        // the point displaced along the line.
                        eq: Equation::Coincident {
                            a: End {
                                body: a.body,
                                local: m.marker(b).at,
                                name: m.marker_name(a),
                            },
                            b: end(m, b),
                            slide: Some((i, dir)),
                        },
                        origin: format!("input {}", m.inputs[i].name),
                    }),
                    None => out.push(Sourced {
                        eq: Equation::InLine {
                            line: end(m, a),
                            dir,
                            point: end(m, b),
                        },
                        origin,
                    }),
                }
            }
        }
    }
    // A pin in a slot: on the slot's line or circle (its ends are checked
    // by the plan's last steps, not equations).
    for slot in &m.slots {
        let [a, b] = slot.markers;
        let eq = match slot.shape {
            Shape::Straight => Equation::InLine {
                line: end(m, a),
                dir: m
                    .marker(a)
                    .unit_dir()
                    .expect("validated: a slot's marker carries a dir"),
                point: end(m, b),
            },
            Shape::Arc { radius } => Equation::OnCircle {
                centre: end(m, a),
                radius,
                point: end(m, b),
            },
        };
        out.push(Sourced {
            eq,
            origin: format!("joint {}", slot.name),
        });
    }
    for c in &m.constraints {
        let origin = format!("constraint {}", c.name);
        let [a, b] = c.markers;
        let eq = match c.kind {
            ConstraintKind::Coincident => Equation::Coincident {
                a: end(m, a),
                b: end(m, b),
                slide: None,
            },
            ConstraintKind::InLine => Equation::InLine {
                line: end(m, a),
                dir: m
                    .marker(a)
                    .unit_dir()
                    .expect("validated: in-line markers carry a dir"),
                point: end(m, b),
            },
            ConstraintKind::Offset => Equation::Parallel {
                a: a.body,
                b: b.body,
                input: None,
            },
        };
        out.push(Sourced { eq, origin });
    }
    out
}
