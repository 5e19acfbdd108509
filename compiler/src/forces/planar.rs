//! A planar frame's input forces by virtual work (see the module above).

use dofplan_runtime::planar::Pose;
use dofplan_runtime::scalar::Jet2;

use crate::interp::planar::InterpState;
use crate::interp::{Interpreter, RateError};
use crate::model::planar::loads::LoadKind;
use crate::model::{InputKind, MarkerId, Mechanism};

/// How the mechanism moves at the frame, for the loads that depend on it
/// (dampers) and the bodies' inertia: each input's rate and acceleration
/// in its own units per second (degrees for an angle, as
/// [`Interpreter::rates`] takes them).
#[derive(Clone, Copy, Debug)]
pub struct Moving<'a> {
    /// Each input's rate.
    pub rates: &'a [f64],
    /// Each input's acceleration.
    pub accelerations: &'a [f64],
}

/// The force (slide) or torque (angle, per radian) each input must supply
/// at the frame `state` was solved to, for the mechanism to hold there
/// (`moving` None: statics, no inertia, dampers idle) or to move as
/// `moving` says (kinetostatics: d'Alembert). Positive in the input's
/// positive direction. An error where the plan's rates are not defined (a
/// dead point).
pub fn input_forces(
    m: &Mechanism,
    interp: &Interpreter,
    state: &InterpState,
    inputs: &[f64],
    moving: Option<Moving>,
) -> Result<Vec<f64>, RateError> {
    let zero = vec![0.0; m.inputs.len()];
    let actual = match moving {
        Some(mv) => Some(interp.rates(state, inputs, mv.rates, mv.accelerations)?),
        None => None,
    };
    (0..m.inputs.len())
        .map(|i| {
            // A unit of the input per second: a radian (in degrees) for an
            // angle, so that the derivatives are per radian.
            let mut unit = zero.clone();
            unit[i] = match m.inputs[i].kind {
                InputKind::Angle => 1f64.to_degrees(),
                InputKind::Slide => 1.0,
            };
            let virtual_ = interp.rates(state, inputs, &unit, &zero)?;
            Ok(-power(m, &virtual_, actual.as_deref()))
        })
        .collect()
}

/// The power every load delivers (and with `actual` motion, the bodies'
/// d'Alembert inertia) at the virtual motion `v` (its first derivatives).
fn power(m: &Mechanism, v: &[Pose<Jet2>], actual: Option<&[Pose<Jet2>]>) -> f64 {
    let loads = &m.loads;
    let at = |id: MarkerId| v[id.body].world(m.marker(id).at);
    let mut p = 0.0;
    for load in &loads.applied {
        p += match &load.kind {
            LoadKind::Force {
                marker,
                force,
                body_axes,
            } => {
                let f = if *body_axes {
                    let r = &v[marker.body].rot;
                    [
                        r.c.v * force[0] - r.s.v * force[1],
                        r.s.v * force[0] + r.c.v * force[1],
                    ]
                } else {
                    *force
                };
                let x = at(*marker);
                f[0] * x[0].d + f[1] * x[1].d
            }
            LoadKind::Torque { body, torque } => torque * omega(&v[*body]),
            LoadKind::Spring {
                markers,
                stiffness,
                free_length,
            } => {
                let (length, rate) = stretch(at(markers[0]), at(markers[1]));
                -stiffness * (length - free_length) * rate
            }
            LoadKind::Damper { markers, damping } => {
                let speed = actual.map_or(0.0, |a| {
                    let w = |id: MarkerId| a[id.body].world(m.marker(id).at);
                    stretch(w(markers[0]), w(markers[1])).1
                });
                let (_, rate) = stretch(at(markers[0]), at(markers[1]));
                -damping * speed * rate
            }
            LoadKind::TorsionSpring {
                joint,
                stiffness,
                free_angle,
            } => {
                let [a, b] = m.joints[*joint].markers.map(|id| &v[id.body]);
                let turn = relative_turn(a, b);
                -stiffness * (turn - free_angle) * (omega(b) - omega(a))
            }
        };
    }
    for (b, pose) in v.iter().enumerate() {
        let Some(mass) = loads.mass(b) else { continue };
        let c = pose.world(mass.centre);
        let mut f = loads
            .gravity
            .map_or([0.0; 2], |g| [mass.mass * g[0], mass.mass * g[1]]);
        let mut torque = 0.0;
        if let Some(a) = actual {
            // d'Alembert: minus mass times the centre's acceleration, minus
            // the inertia times the angular acceleration.
            let ca = a[b].world(mass.centre);
            f[0] -= mass.mass * ca[0].dd;
            f[1] -= mass.mass * ca[1].dd;
            torque -= mass.inertia * alpha(&a[b]);
        }
        p += f[0] * c[0].d + f[1] * c[1].d + torque * omega(pose);
    }
    p
}

/// A body's angular rate from its pose's jet: for a unit (c, s), ω = c·ṡ −
/// s·ċ.
fn omega(p: &Pose<Jet2>) -> f64 {
    p.rot.c.v * p.rot.s.d - p.rot.s.v * p.rot.c.d
}

/// A body's angular acceleration: α = c·s̈ − s·c̈.
fn alpha(p: &Pose<Jet2>) -> f64 {
    p.rot.c.v * p.rot.s.dd - p.rot.s.v * p.rot.c.dd
}

/// The distance between two points and its rate.
fn stretch(a: [Jet2; 2], b: [Jet2; 2]) -> (f64, f64) {
    let d = [b[0].v - a[0].v, b[1].v - a[1].v];
    let length = d[0].hypot(d[1]);
    if length == 0.0 {
        return (0.0, 0.0);
    }
    let rate = (d[0] * (b[0].d - a[0].d) + d[1] * (b[1].d - a[1].d)) / length;
    (length, rate)
}

/// How far body `b` has turned relative to body `a` since the drawing,
/// in radians in (−π, π].
fn relative_turn(a: &Pose<Jet2>, b: &Pose<Jet2>) -> f64 {
    let (ca, sa, cb, sb) = (a.rot.c.v, a.rot.s.v, b.rot.c.v, b.rot.s.v);
    (sb * ca - cb * sa).atan2(cb * ca + sb * sa)
}
