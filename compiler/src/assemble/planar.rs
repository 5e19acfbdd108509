//! Assembling a planar file: the drawn coordinates moved to where every
//! joint holds, and the file rewritten with them.

use std::path::Path;

use dofplan_runtime::Point;

use crate::conflict::{self, Assembly};
use crate::conflict::{load_file, load_str};
use crate::format::length;
use crate::model::{
    load_str_drawn, Format, Location, MarkerId, Mechanism, ModelError, Note, SourceFile, DRAWN_TOLERANCE,
};

use super::{
    headline, plain, rewrite_json, rewrite_toml, same_where_joined, short, table, undecided, Edit,
    UNCHANGED_SHARE,
};

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
        Assembly::Conflict { .. } => {
            // The loader's own diagnostics: the joints in conflict, named at
            // their positions.
            let file = m.source.clone();
            return Err(conflict::assembled(drawn).err().unwrap_or_else(|| ModelError {
                diagnostics: vec![plain(
                    file,
                    "the joints cannot all close near the drawn pose".into(),
                )],
            }));
        }
        Assembly::Undecided => return Err(undecided(&drawn.open)),
    };
    let size = m.size();
    let kept = UNCHANGED_SHARE * DRAWN_TOLERANCE * size;
    let ids: Vec<MarkerId> = m.all_markers().collect();
    let moved = |id: MarkerId| {
        let (from, to) = (m.marker(id).at, poses[id.body].world(m.marker(id).at));
        (from[0] - to[0]).hypot(from[1] - to[1])
    };
    // A body is left as written when the assembly moves it less than
    // `kept` (fixed bodies always are); the others move rigidly.
    let stays: Vec<bool> = m
        .bodies
        .iter()
        .enumerate()
        .map(|(b, body)| {
            body.fixed
                || (ids.iter().filter(|id| id.body == b).all(|&id| moved(id) <= kept)
                    && poses[b].rot.degrees().to_radians().abs() * size <= kept)
        })
        .collect();
    let mut to: Vec<Point> = ids
        .iter()
        .map(|&id| {
            let at = m.marker(id).at;
            if stays[id.body] {
                at
            } else {
                poses[id.body].world(at)
            }
        })
        .collect();
    same_where_joined(m.coincident_pairs(), &ids, &stays, &mut to);
    let mut moves = Vec::new();
    let mut edits = Vec::new();
    for (&id, &to) in ids.iter().zip(&to) {
        let (body, marker) = (&m.bodies[id.body], m.marker(id));
        let pose = poses[id.body];
        let stays = stays[id.body];
        edits.push(Edit {
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
            size,
        });
        moves.push(Move {
            marker: id,
            from: marker.at,
            to,
            distance: if stays {
                moved(id)
            } else {
                (to[0] - marker.at[0]).hypot(to[1] - marker.at[1])
            },
            turn: if stays { 0.0 } else { pose.rot.degrees() },
            changed: false,
        });
    }
    let (rewritten, changed) = match format {
        Format::Toml => rewrite_toml(text, &edits),
        Format::Json => rewrite_json(text, &edits),
    }
    .map_err(|e| ModelError {
        diagnostics: vec![plain(m.source.clone(), format!("cannot rewrite the file: {e}"))],
    })?;
    for (mv, c) in moves.iter_mut().zip(changed) {
        mv.changed = c;
    }
    // The rewritten file must hold every joint: a safety net, so a file is
    // never written back worse than it was.
    if let Err(e) = load_str(file_name, &rewritten, format) {
        let mut d = plain(
            m.source.clone(),
            "the assembled coordinates do not load back (a bug in `dofplan assemble`): the file is left as it is"
                .into(),
        );
        d.notes = e
            .diagnostics
            .iter()
            .map(|d| Note {
                location: Location::File,
                message: d.message.clone(),
            })
            .collect();
        return Err(ModelError { diagnostics: vec![d] });
    }
    Ok(Assembled {
        mechanism: drawn.mechanism,
        moves,
        text: rewritten,
        opened,
    })
}
