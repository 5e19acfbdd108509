//! A spatial frame's rates (markers' velocities and accelerations, bodies'
//! angular velocities and accelerations) from its bodies' jets.

use dofplan_runtime::real::Jet2;
use dofplan_runtime::spatial::{Pose3, Vec3};

use crate::model::spatial::Mechanism;

/// One spatial frame's rates.
#[derive(Clone, Debug, PartialEq)]
pub struct Motion {
    /// Every marker's velocity, in [`Mechanism::all_markers`] order.
    pub velocity: Vec<Vec3>,
    /// Every marker's acceleration, in the same order.
    pub acceleration: Vec<Vec3>,
    /// Every body's angular velocity ω (world frame, rad per unit of time).
    pub omega: Vec<Vec3>,
    /// Every body's angular acceleration α = ω̇.
    pub alpha: Vec<Vec3>,
}

/// The rates of `m`'s markers and bodies from the bodies' jets (as
/// [`Interpreter::rates`](crate::interp::spatial::Interpreter::rates)
/// gives them). With R the rotation, `Ṙ·Rᵀ = [ω]×` and `R̈·Rᵀ = [α]× + [ω]×²`,
/// whose antisymmetric part is `[α]×` (`[ω]×²` is symmetric).
pub fn motion(m: &Mechanism, jets: &[Pose3<Jet2>]) -> Motion {
    let (mut velocity, mut acceleration) = (Vec::new(), Vec::new());
    for id in m.all_markers() {
        let p = jets[id.body].world(m.marker(id).at);
        velocity.push(p.map(|x| x.d));
        acceleration.push(p.map(|x| x.dd));
    }
    let (mut omega, mut alpha) = (Vec::new(), Vec::new());
    for pose in jets {
        let r = &pose.rot.m;
        // a·Rᵀ for a = Ṙ or R̈, then its axial vector.
        let axial = |f: fn(&Jet2) -> f64| -> Vec3 {
            let at = |i: usize, j: usize| -> f64 { (0..3).map(|k| f(&r[i][k]) * r[j][k].v).sum() };
            [
                0.5 * (at(2, 1) - at(1, 2)),
                0.5 * (at(0, 2) - at(2, 0)),
                0.5 * (at(1, 0) - at(0, 1)),
            ]
        };
        omega.push(axial(|x| x.d));
        alpha.push(axial(|x| x.dd));
    }
    Motion {
        velocity,
        acceleration,
        omega,
        alpha,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use dofplan_runtime::spatial::Rot3;

    /// A body turning about z at ω(t) = 2 + 3t through t = 0, its origin at
    /// (1, 0, 0) drawn: angle φ = 2t + 1.5t², so at t = 0 the rotation's
    /// jets are R = I, Ṙ = 2·[z]×, R̈ = 3·[z]× + 4·[z]×²; ω = (0, 0, 2),
    /// α = (0, 0, 3), and the point (1, 0, 0) moves at (0, 2, 0) with
    /// acceleration (−4, 3, 0) (centripetal and tangential).
    #[test]
    fn a_body_turning_about_z_has_its_omega_alpha_and_point_rates() {
        let text = "name = \"spin\"\ndimension = 3\n[bodies.ground]\nfixed = true\nmarkers.A = { at = [0, 0, 0], z = [0, 0, 1] }\n\
                    [bodies.disc]\nmarkers.A = { at = [0, 0, 0], z = [0, 0, 1] }\nmarkers.P = [1, 0, 0]\n\
                    [joints.A]\nkind = \"revolute\"\nmarkers = [\"ground.A\", \"disc.A\"]\n";
        let crate::model::Model::Spatial(m) =
            crate::conflict::load_any_str("spin.toml", text, crate::model::Format::Toml).unwrap()
        else {
            panic!("a spatial file")
        };
        // [z]× = [[0, −1, 0], [1, 0, 0], [0, 0, 0]]; [z]×² = diag(−1, −1, 0).
        let k = [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0]];
        let k2 = [[-1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 0.0]];
        let id = |i: usize, j: usize| if i == j { 1.0 } else { 0.0 };
        let rot = Rot3 {
            m: std::array::from_fn(|i| {
                std::array::from_fn(|j| Jet2::new(id(i, j), 2.0 * k[i][j], 3.0 * k[i][j] + 4.0 * k2[i][j]))
            }),
        };
        let still = Pose3::<Jet2>::cst(Pose3::IDENTITY);
        let disc = Pose3 {
            rot,
            pos: [Jet2::new(0.0, 0.0, 0.0); 3],
        };
        let mo = motion(&m, &[still, disc]);
        assert_eq!(mo.omega, vec![[0.0; 3], [0.0, 0.0, 2.0]]);
        assert_eq!(mo.alpha, vec![[0.0; 3], [0.0, 0.0, 3.0]]);
        let p = m
            .all_markers()
            .position(|i| m.marker_name(i) == "disc.P")
            .unwrap();
        assert_eq!(mo.velocity[p], [0.0, 2.0, 0.0]);
        assert_eq!(mo.acceleration[p], [-4.0, 3.0, 0.0]);
    }
}
