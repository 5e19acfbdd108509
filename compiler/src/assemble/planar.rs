//! Assembling a planar file: the drawn coordinates moved to where every
//! joint holds, and the file rewritten with them.

use std::path::Path;

use dofplan_runtime::planar::Pose;
use dofplan_runtime::Point;

use crate::conflict::{self, Assembly};
use crate::conflict::{load_file, load_str};
use crate::format::length;
use crate::model::{load_str_drawn, Format, MarkerId, Mechanism, ModelError, SourceFile};

use super::{conflicting, headline, plain, rewrite_closed, short, table, undecided, Closing, Edit, Target};

/// Where one marker goes.
#[derive(Clone, Debug)]
pub struct Move {
    /// The marker.
    pub marker: MarkerId,
    /// Its position as drawn.
    pub from: Point,
    /// Its position in the assembly (as drawn when `changed` is false).
    pub to: Point,
    /// `|to − from|`.
    pub distance: f64,
    /// The angle its body turns, in degrees (counter-clockwise).
    pub turn: f64,
    /// Whether the file's text for this marker changed (its coordinates,
    /// or its direction turned with its body).
    pub changed: bool,
}

/// The result of assembling a file.
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
        let moved = self.moves.iter().filter(|mv| mv.changed).map(|mv| mv.distance);
        let mut out = headline(&m.name, self.opened, moved, self.moves.len(), "");
        let point = |p: Point| format!("[{}, {}]", short(p[0], size), short(p[1], size));
        let rows: Vec<[String; 4]> = self
            .moves
            .iter()
            .map(|mv| {
                let name = m.marker_name(mv.marker);
                if !mv.changed {
                    return [name, point(mv.from), "unchanged".into(), String::new()];
                }
                let mut distance = length(mv.distance);
                if m.marker(mv.marker).dir.is_some() && mv.turn.abs() > 0.0 {
                    distance.push_str(&format!(", dir turned {:.3}°", mv.turn));
                }
                [name, point(mv.from), point(mv.to), distance]
            })
            .collect();
        table(&mut out, &rows);
        out
    }
}

/// Assembles a mechanism file: see [`assemble_str`].
pub fn assemble_file(path: &Path) -> Result<Assembled, ModelError> {
    let text = match std::fs::read_to_string(path) {
        Ok(text) => text,
        // The loader words why a file cannot be read.
        Err(e) => {
            return Err(load_file(path).err().unwrap_or_else(|| {
                let file = SourceFile {
                    name: path.display().to_string(),
                    text: "".into(),
                };
                ModelError {
                    diagnostics: vec![plain(file, format!("cannot read the file: {e}"))],
                }
            }))
        }
    };
    assemble_str(&path.display().to_string(), &text, Format::of_path(path))
}

/// Assembles a mechanism given as text: loads it (joints that do not hold
/// in the drawn pose are allowed, any other error is returned), runs the
/// least-squares assembly from the drawn pose, and rewrites the text with
/// every marker where the joints close.
///
/// Errors: the loader's (syntax, names...); the loader's conflict error
/// when the joints cannot all close near the drawn pose; an error when the
/// assembly cannot tell.
pub fn assemble_str(file_name: &str, text: &str, format: Format) -> Result<Assembled, ModelError> {
    let drawn = load_str_drawn(file_name, text, format)?;
    let m = &drawn.mechanism;
    let opened = drawn.open.len();
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
            mechanism: drawn.mechanism,
            moves,
            text: text.to_string(),
            opened,
        });
    }
    let poses = match conflict::assemble(m) {
        Assembly::Closes { poses, .. } => poses,
        Assembly::Conflict { .. } => return Err(conflicting(m.source.clone(), conflict::assembled(drawn))),
        Assembly::Undecided => return Err(undecided(&drawn.open)),
    };
    let closed = Closed {
        m,
        poses: &poses,
        size: m.size(),
    };
    let loads_back = |rewritten: &str| load_str(file_name, rewritten, format).map(|_| ());
    let rewritten = rewrite_closed(&closed, text, format, &m.source, loads_back)?;
    let moves = rewritten.targets.iter().map(|t| closed.to_move(t)).collect();
    Ok(Assembled {
        mechanism: drawn.mechanism,
        moves,
        text: rewritten.text,
        opened,
    })
}

/// A planar mechanism with the body poses at which its joints close.
struct Closed<'a> {
    m: &'a Mechanism,
    poses: &'a [Pose],
    /// The mechanism's size, once.
    size: f64,
}

impl Closing for Closed<'_> {
    type Point = Point;

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

    fn drawn(&self, id: MarkerId) -> Point {
        self.m.marker(id).at
    }

    fn assembled(&self, id: MarkerId) -> Point {
        self.poses[id.body].world(self.m.marker(id).at)
    }

    fn moved(&self, id: MarkerId) -> f64 {
        let (from, to) = (self.drawn(id), self.assembled(id));
        (from[0] - to[0]).hypot(from[1] - to[1])
    }

    fn turn(&self, b: usize) -> f64 {
        self.poses[b].rot.degrees().to_radians().abs()
    }

    fn joined(&self) -> impl Iterator<Item = [MarkerId; 2]> + '_ {
        self.m.coincident_pairs()
    }

    /// A moved marker's point, and its `dir` turned with its body.
    fn edit(&self, id: MarkerId, to: Point, stays: bool) -> Edit {
        let (body, marker) = (&self.m.bodies[id.body], self.m.marker(id));
        let pose = self.poses[id.body];
        Edit {
            body: body.name.clone(),
            marker: marker.name.clone(),
            at: (!stays).then(|| to.to_vec()),
            dirs: (marker
                .dir
                .filter(|_| !stays)
                .map(|d| ("dir", pose.world_dir(d).to_vec())))
            .into_iter()
            .collect(),
            keep_length: false,
            size: self.size,
        }
    }
}

impl Closed<'_> {
    /// The report's move of a marker to its target.
    fn to_move(&self, target: &Target<Point>) -> Move {
        let (id, to) = (target.id, target.to);
        let marker = self.m.marker(id);
        Move {
            marker: id,
            from: marker.at,
            to,
            distance: if target.stays {
                self.moved(id)
            } else {
                (to[0] - marker.at[0]).hypot(to[1] - marker.at[1])
            },
            turn: if target.stays {
                0.0
            } else {
                self.poses[id.body].rot.degrees()
            },
            changed: target.changed,
        }
    }
}
