//! `dofplan assemble` for spatial files (`dimension = 3`): the planar
//! assembler's rules in space. The assembly is the loader's own
//! ([`crate::conflict::spatial::assemble`]): every moving body
//! moves rigidly (a rotation and a translation, so its markers keep their
//! distances and its axes their angles), ground never moves, the inputs
//! stay at their drawn values unless the joints close only with them free,
//! and Newton's minimum-norm steps from the drawing keep the assembly mode
//! drawn. A moved marker's point is rewritten, and so are the `z` and `x`
//! it writes (turned with its body, each keeping the length it is written
//! with); nothing else in the file changes.

use std::path::Path;

use dofplan_runtime::spatial::{norm, sub, Pose3, Vec3};

use super::{conflicting, plain, rewrite_closed, short, undecided, Closing, Edit, Target};
use crate::conflict::load_any_str;
use crate::conflict::spatial::{self as conflict, Assembly};
use crate::model::spatial::{Mechanism, Primitive};
use crate::model::{Format, MarkerId, Model, ModelError, SourceFile};

/// Where one marker of a spatial file goes.
#[derive(Clone, Debug)]
pub struct Move {
    /// The marker.
    pub marker: MarkerId,
    /// Its position as drawn.
    pub from: Vec3,
    /// Its position in the assembly (as drawn when its body stays).
    pub to: Vec3,
    /// `|to − from|`.
    pub distance: f64,
    /// The angle its body turns, in degrees (about whatever axis).
    pub turn: f64,
    /// Whether the file's text for this marker changed (its point, or its
    /// axes turned with its body).
    pub changed: bool,
}

/// The result of assembling a spatial file.
#[derive(Clone, Debug)]
pub struct Assembled {
    /// The mechanism as drawn (joints open).
    pub mechanism: Mechanism,
    /// Every marker, body by body, in file order.
    pub moves: Vec<Move>,
    /// The file with the assembled coordinates (the text as given when
    /// nothing moved).
    pub text: String,
    /// How many joints and constraints did not hold as drawn.
    pub opened: usize,
    /// Whether the inputs stayed at their drawn values (false: the joints
    /// close only with them free, or the mechanism has none).
    pub inputs_held: bool,
}

impl Assembled {
    /// Whether the file was assembled already (every joint held as drawn).
    pub fn unchanged(&self) -> bool {
        self.moves.iter().all(|m| !m.changed)
    }

    /// The table of moves: one line per marker, `body.marker`, from, to and
    /// how far it moved ("unchanged" when its text is kept).
    pub fn report(&self) -> String {
        let m = &self.mechanism;
        if self.unchanged() {
            return format!("{}: already assembled, nothing moved\n", m.name);
        }
        let size = m.size();
        let inputs = match (m.inputs.is_empty(), self.inputs_held) {
            (true, _) => "",
            (false, true) => ", inputs at their drawn values",
            (false, false) => ", inputs free (held at their drawn values the joints do not close)",
        };
        let moved = self.moves.iter().filter(|mv| mv.changed).map(|mv| mv.distance);
        let mut out = super::headline(&m.name, self.opened, moved, self.moves.len(), inputs);
        let point = |p: Vec3| {
            format!(
                "[{}, {}, {}]",
                short(p[0], size),
                short(p[1], size),
                short(p[2], size)
            )
        };
        let rows: Vec<[String; 4]> = self
            .moves
            .iter()
            .map(|mv| {
                let name = m.marker_name(mv.marker);
                if !mv.changed {
                    return [name, point(mv.from), "unchanged".into(), String::new()];
                }
                // A marker on its body's axis of turn moves by rounding only.
                let mut distance = if mv.distance <= super::WRITTEN_PRECISION * size {
                    "0".to_string()
                } else {
                    crate::format::length(mv.distance)
                };
                if m.marker(mv.marker).axes.is_some() && mv.turn.abs() > 0.0 {
                    distance.push_str(&format!(", axes turned {:.3}°", mv.turn));
                }
                [name, point(mv.from), point(mv.to), distance]
            })
            .collect();
        super::table(&mut out, &rows);
        out
    }
}

/// Assembles a spatial mechanism file: see [`assemble_str`].
pub fn assemble_file(path: &Path) -> Result<Assembled, ModelError> {
    let text = std::fs::read_to_string(path).map_err(|e| ModelError {
        diagnostics: vec![plain(
            SourceFile {
                name: path.display().to_string(),
                text: "".into(),
            },
            format!("cannot read the file: {e}"),
        )],
    })?;
    assemble_str(&path.display().to_string(), &text, Format::of_path(path))
}

/// The angle of a rotation, in radians.
fn angle(p: &Pose3) -> f64 {
    let m = &p.rot.m;
    let axis = [m[2][1] - m[1][2], m[0][2] - m[2][0], m[1][0] - m[0][1]];
    norm(axis).atan2(m[0][0] + m[1][1] + m[2][2] - 1.0)
}

/// Assembles a spatial mechanism given as text: loads it (joints that do
/// not hold in the drawn pose are allowed, any other error is returned),
/// runs the least-squares assembly from the drawn pose, and rewrites the
/// text with every marker where the joints close.
///
/// Errors: the loader's (syntax, names...); the loader's errors naming the
/// joints in conflict when they cannot all close near the drawn pose; an
/// error when the assembly cannot tell.
pub fn assemble_str(file_name: &str, text: &str, format: Format) -> Result<Assembled, ModelError> {
    let drawn = crate::model::spatial::load_str_drawn(file_name, text, format)?;
    let m = &drawn.mechanism;
    let opened = drawn.open_count();
    if opened == 0 {
        let moves = m
            .all_markers()
            .map(|id| Move {
                marker: id,
                from: m.marker(id).at,
                to: m.marker(id).at,
                distance: 0.0,
                turn: 0.0,
                changed: false,
            })
            .collect();
        return Ok(Assembled {
            mechanism: m.clone(),
            moves,
            text: text.to_string(),
            opened,
            inputs_held: !m.inputs.is_empty(),
        });
    }
    let (poses, inputs_held) = match conflict::assemble(m) {
        Assembly::Closes {
            poses, inputs_held, ..
        } => (poses, inputs_held),
        // The loader's own diagnostics: each open joint with the joints in
        // conflict named.
        Assembly::Conflict { .. } => return Err(conflicting(m.source.clone(), conflict::assembled(drawn))),
        Assembly::Undecided => return Err(undecided(&drawn.open)),
    };
    let closed = Closed {
        m,
        poses: &poses,
        size: m.size(),
    };
    let loads_back = |rewritten: &str| -> Result<(), ModelError> {
        match load_any_str(file_name, rewritten, format)? {
            Model::Spatial(_) => Ok(()),
            Model::Planar(_) => unreachable!("a spatial file stays spatial: only numbers change"),
        }
    };
    let rewritten = rewrite_closed(&closed, text, format, &m.source, loads_back)?;
    let moves = rewritten.targets.iter().map(|t| closed.to_move(t)).collect();
    Ok(Assembled {
        mechanism: drawn.mechanism,
        moves,
        text: rewritten.text,
        opened,
        inputs_held,
    })
}

/// A spatial mechanism with the body poses at which its joints close.
struct Closed<'a> {
    m: &'a Mechanism,
    poses: &'a [Pose3],
    /// The mechanism's size, once.
    size: f64,
}

impl Closing for Closed<'_> {
    type Point = Vec3;

    fn size(&self) -> f64 {
        self.size
    }

    fn bodies(&self) -> usize {
        self.m.bodies.len()
    }

    fn fixed(&self, b: usize) -> bool {
        self.m.bodies[b].fixed
    }

    fn markers(&self) -> Vec<MarkerId> {
        self.m.all_markers().collect()
    }

    fn drawn(&self, id: MarkerId) -> Vec3 {
        self.m.marker(id).at
    }

    fn assembled(&self, id: MarkerId) -> Vec3 {
        self.poses[id.body].world(self.m.marker(id).at)
    }

    fn moved(&self, id: MarkerId) -> f64 {
        let at = self.drawn(id);
        norm(sub(self.poses[id.body].world(at), at))
    }

    fn turn(&self, b: usize) -> f64 {
        angle(&self.poses[b])
    }

    fn joined(&self) -> impl Iterator<Item = [MarkerId; 2]> + '_ {
        coincident_pairs(self.m)
    }

    /// A moved marker's point, and the `z` and `x` it writes turned with
    /// its body.
    fn edit(&self, id: MarkerId, to: Vec3, stays: bool) -> Edit {
        let (body, marker) = (&self.m.bodies[id.body], self.m.marker(id));
        let pose = self.poses[id.body];
        let dirs = match marker.axes.filter(|_| !stays) {
            Some(axes) => vec![("z", pose.dir(axes.z).to_vec()), ("x", pose.dir(axes.x).to_vec())],
            None => vec![],
        };
        Edit {
            body: body.name.clone(),
            marker: marker.name.clone(),
            at: (!stays).then(|| to.to_vec()),
            dirs,
            keep_length: true,
            size: self.size,
        }
    }
}

impl Closed<'_> {
    /// The report's move of a marker to its target.
    fn to_move(&self, target: &Target<Vec3>) -> Move {
        let (id, to) = (target.id, target.to);
        let marker = self.m.marker(id);
        Move {
            marker: id,
            from: marker.at,
            to,
            distance: if target.stays {
                self.moved(id)
            } else {
                norm(sub(to, marker.at))
            },
            turn: if target.stays {
                0.0
            } else {
                angle(&self.poses[id.body]).to_degrees()
            },
            changed: target.changed,
        }
    }
}

/// The marker pairs a coincident primitive joins (revolute, spherical,
/// universal and fixed joints; coincident constraints): written with the
/// very same numbers.
fn coincident_pairs(m: &Mechanism) -> impl Iterator<Item = [MarkerId; 2]> + '_ {
    let joints = (m.joints.iter())
        .filter(|j| j.kind.primitives().contains(&Primitive::Coincident))
        .map(|j| j.markers);
    let constraints = (m.constraints.iter())
        .filter(|c| c.kind == Primitive::Coincident)
        .map(|c| c.markers);
    joints.chain(constraints)
}
