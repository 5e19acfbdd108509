//! The on-circle rule: a pin in a circular slot. When one of its two
//! points is known (the centre or the pin), the other lies on the circle
//! of the slot's radius about it; a body that still turns about a known
//! pin, or slides along a known line, is placed where its own locus meets
//! that circle (Kramer's locus intersection, circle ∩ circle or
//! circle ∩ line, each with a branch).

use super::{dist, moving_marker, Know, Planner};
use crate::model::planar::equations::{End, Equation};
use crate::plan::{Line, PointRef, StepKind};

impl Planner<'_> {
    /// An on-circle equation with one point known: the other's body is
    /// placed on the circle, if its locus allows.
    pub(super) fn try_on_circle(&mut self, i: usize) -> bool {
        if self.used[i] {
            return false;
        }
        let Equation::OnCircle {
            centre,
            radius,
            point,
        } = &self.eqs[i].eq
        else {
            return false;
        };
        let (centre, radius, point) = (centre.clone(), *radius, point.clone());
        for (known, moving) in [(&centre, &point), (&point, &centre)] {
            let Some(q) = self.known_point(known.body, known.local, &known.name) else {
                continue;
            };
            if self.onto_circle(i, moving, q, radius) {
                return true;
            }
        }
        false
    }

    /// Places `moving`'s body so that its marker lies on the circle of
    /// `radius` about the known point `q`: where the circle it draws about
    /// its pin, or the line it slides on, crosses that circle.
    fn onto_circle(&mut self, i: usize, moving: &End, q: PointRef, radius: f64) -> bool {
        let body = moving.body;
        match self.know[body].clone() {
            Know::Pinned { local: l0, at: at0 } if dist(l0, moving.local) > self.tol => {
                let origin = self.consume(i);
                let out = self.temp(&moving.name);
                let branch = self.branch_slot(moving.local);
                self.push(
                    StepKind::CircleCircle {
                        out,
                        c1: at0.clone(),
                        r1: dist(l0, moving.local),
                        c2: q,
                        r2: radius,
                        branch,
                    },
                    vec![origin],
                );
                self.push(
                    StepKind::Align {
                        body,
                        p: l0,
                        p_at: at0,
                        q: moving.local,
                        q_at: PointRef::Temp { id: out },
                        redundant: false,
                    },
                    vec![],
                );
            }
            Know::Sliding { dir } => {
                let origin = self.consume(i);
                let out = self.temp(&moving.name);
                let branch = self.branch_slot(moving.local);
                self.push(
                    StepKind::CircleLine {
                        out,
                        c: q,
                        r: radius,
                        line: Line {
                            through: moving_marker(moving),
                            dir,
                        },
                        branch,
                    },
                    vec![origin],
                );
                self.push(
                    StepKind::Anchor {
                        body,
                        local: moving.local,
                        at: PointRef::Temp { id: out },
                    },
                    vec![],
                );
            }
            _ => return false,
        }
        self.set(body, Know::Placed);
        true
    }
}
