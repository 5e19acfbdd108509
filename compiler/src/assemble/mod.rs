//! Authoring from approximate coordinates (`dofplan assemble`): a file whose
//! joints do not quite hold in the drawn pose is rewritten with every
//! marker moved to where the joints close.
//!
//! The assembly is the loader's own least-squares assembly from the drawn
//! pose ([`crate::conflict::assemble`]): each mobile body moves
//! **rigidly** (its markers keep their distances and angles to each other,
//! so the lengths a body is drawn with are the lengths it keeps), fixed
//! bodies never move, and Newton's minimum-norm steps from the drawn pose
//! end at a nearby assembly: the drawing decides the assembly mode. Only the
//! coordinate numbers of the file change (and the `dir` of a body that
//! turns, turned with it); comments, key order and layout are kept
//! (`toml_edit`). A JSON file is rewritten by `serde_json`: key order is
//! kept, formatting is not.
//!
//! Joints that cannot all close (an inconsistent redundant link) are the
//! loader's conflict error, naming them.
//!
//! Spatial files are assembled by [`spatial`] with the same rules, on the
//! spatial loader's assembly.

use crate::format::length;
use crate::model::{Diagnostic, Format, Location, MarkerId, ModelError, Note, SourceFile, DRAWN_TOLERANCE};

pub mod planar;
pub mod spatial;

pub use planar::{assemble_file, assemble_str, Assembled, Move};

/// Numbers are written with the fewest decimals that keep them within this
/// (relative to the mechanism's size, or to a direction's length) of the
/// assembled value: far below the loader's [`DRAWN_TOLERANCE`], so the
/// written file holds every joint.
const WRITTEN_PRECISION: f64 = 1e-12;

/// A body whose markers all move less than this share of the loader's
/// tolerance (and which turns less) is left as written. A quarter, so that
/// two markers of a joint both left as written still hold it: their gap is
/// then at most half the tolerance.
const UNCHANGED_SHARE: f64 = 0.25;

/// The report's first line, for either dimension: how many joints were
/// closed and how far the markers that changed (their `moved` distances, of
/// `total`) went; `note` ends the line (what happened to the inputs).
fn headline(name: &str, opened: usize, moved: impl Iterator<Item = f64>, total: usize, note: &str) -> String {
    let (count, most) = moved.fold((0, 0.0_f64), |(n, most), d| (n + 1, most.max(d)));
    format!(
        "{name}: {opened} open joint(s) closed; {count} of {total} markers moved (most {}), each body rigidly, \
         fixed bodies staying put{note}\n",
        length(most)
    )
}

/// Appends the table of moves (marker, from, to, moved), its columns
/// aligned.
fn table(out: &mut String, rows: &[[String; 4]]) {
    let header = ["marker", "from", "to", "moved"].map(String::from);
    let mut width = [0; 3];
    for row in std::iter::once(&header).chain(rows) {
        for k in 0..3 {
            width[k] = width[k].max(row[k].chars().count());
        }
    }
    for row in std::iter::once(&header).chain(rows) {
        let line = format!(
            "  {:w0$}  {:w1$}  {:w2$}  {}",
            row[0],
            row[1],
            row[2],
            row[3],
            w0 = width[0],
            w1 = width[1],
            w2 = width[2]
        );
        out.push_str(line.trim_end());
        out.push('\n');
    }
}

/// Markers that a revolute joint or a coincident constraint joins (in
/// space, every joint with a coincident primitive) are written with the very same numbers (each moved one takes the position
/// of one marker of its group: a marker left as written if there is one),
/// so the written file holds them exactly rather than to the assembly's
/// last digits. The move is within the assembly's residual.
fn same_where_joined<P: Copy>(
    pairs: impl Iterator<Item = [MarkerId; 2]>,
    ids: &[MarkerId],
    stays: &[bool],
    to: &mut [P],
) {
    let index = |id: MarkerId| ids.iter().position(|&x| x == id);
    let mut group: Vec<usize> = (0..ids.len()).collect();
    fn root(group: &mut [usize], mut i: usize) -> usize {
        while group[i] != i {
            group[i] = group[group[i]];
            i = group[i];
        }
        i
    }
    for [a, b] in pairs {
        let (Some(a), Some(b)) = (index(a), index(b)) else {
            continue;
        };
        let (ra, rb) = (root(&mut group, a), root(&mut group, b));
        // The root is a member left as written, if any, else the first.
        let (sa, sb) = (stays[ids[ra].body], stays[ids[rb].body]);
        let (keep, join) = if (sb && !sa) || (sa == sb && rb < ra) {
            (rb, ra)
        } else {
            (ra, rb)
        };
        group[join] = keep;
    }
    for i in 0..ids.len() {
        let r = root(&mut group, i);
        if !stays[ids[i].body] {
            to[i] = to[r];
        }
    }
}

/// A mechanism with the body poses at which its joints close: what the
/// steps both dimensions share ([`rewrite_closed`]) ask of either.
trait Closing {
    /// A point: `[x, y]` in the plane, `[x, y, z]` in space.
    type Point: Copy;
    /// The mechanism's size (what the tolerances scale with).
    fn size(&self) -> f64;
    /// How many bodies it has.
    fn bodies(&self) -> usize;
    /// Whether body `b` is fixed.
    fn fixed(&self, b: usize) -> bool;
    /// Every marker, body by body, in file order.
    fn markers(&self) -> Vec<MarkerId>;
    /// A marker's position as drawn.
    fn drawn(&self, id: MarkerId) -> Self::Point;
    /// A marker's position in the assembly (its body moved rigidly).
    fn assembled(&self, id: MarkerId) -> Self::Point;
    /// How far the assembly moves a marker from where it is drawn.
    fn moved(&self, id: MarkerId) -> f64;
    /// How far the assembly turns body `b`, in radians.
    fn turn(&self, b: usize) -> f64;
    /// The marker pairs a joint or constraint makes coincident.
    fn joined(&self) -> impl Iterator<Item = [MarkerId; 2]> + '_;
    /// The new numbers for marker `id`, written at `to` unless its body
    /// `stays` as written.
    fn edit(&self, id: MarkerId, to: Self::Point, stays: bool) -> Edit;
}

/// What [`rewrite_closed`] gives back: where each marker goes, and the text
/// written.
struct Rewritten<P> {
    /// Every marker's target, body by body, in file order.
    targets: Vec<Target<P>>,
    /// The rewritten file.
    text: String,
}

/// Where one marker goes, as [`rewrite_closed`] decided it.
struct Target<P> {
    /// The marker.
    id: MarkerId,
    /// Its position in the file written.
    to: P,
    /// Whether its body was left as written.
    stays: bool,
    /// Whether the file's text for it changed.
    changed: bool,
}

/// The steps of `dofplan assemble` both dimensions share once the poses at
/// which the joints close are found: where each marker goes, and the file
/// (`text`, from `source`) rewritten with it.
///
/// A body is left as written when the assembly moves it less than a
/// quarter of the loader's tolerance (fixed bodies always are); the others
/// move rigidly. The rewritten file must load back (`loads_back`): a safety
/// net, so a file is never written back worse than it was.
fn rewrite_closed<C: Closing>(
    closed: &C,
    text: &str,
    format: Format,
    source: &SourceFile,
    loads_back: impl FnOnce(&str) -> Result<(), ModelError>,
) -> Result<Rewritten<C::Point>, ModelError> {
    let size = closed.size();
    let kept = UNCHANGED_SHARE * DRAWN_TOLERANCE * size;
    let ids = closed.markers();
    let stays: Vec<bool> = (0..closed.bodies())
        .map(|b| {
            closed.fixed(b)
                || (ids
                    .iter()
                    .filter(|id| id.body == b)
                    .all(|&id| closed.moved(id) <= kept)
                    && closed.turn(b) * size <= kept)
        })
        .collect();
    let mut to: Vec<C::Point> = ids
        .iter()
        .map(|&id| {
            if stays[id.body] {
                closed.drawn(id)
            } else {
                closed.assembled(id)
            }
        })
        .collect();
    same_where_joined(closed.joined(), &ids, &stays, &mut to);
    let edits: Vec<Edit> = ids
        .iter()
        .zip(&to)
        .map(|(&id, &to)| closed.edit(id, to, stays[id.body]))
        .collect();
    let (rewritten, changed) = match format {
        Format::Toml => rewrite_toml(text, &edits),
        Format::Json => rewrite_json(text, &edits),
    }
    .map_err(|e| ModelError {
        diagnostics: vec![plain(source.clone(), format!("cannot rewrite the file: {e}"))],
    })?;
    if let Err(e) = loads_back(&rewritten) {
        let mut d = plain(
            source.clone(),
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
    let targets = ids
        .iter()
        .zip(to)
        .zip(changed)
        .map(|((&id, to), changed)| Target {
            id,
            to,
            stays: stays[id.body],
            changed,
        })
        .collect();
    Ok(Rewritten {
        targets,
        text: rewritten,
    })
}

/// A mechanism file's text with markers moved to new positions (`(body,
/// marker, position)`), nothing else changed: in TOML comments, key order
/// and layout are kept; JSON keeps its key order. Numbers are written with
/// the fewest decimals within 1e-12 of `size`. Synthesis
/// writes its solutions with it.
pub fn rewrite_positions(
    text: &str,
    format: Format,
    size: f64,
    moved: &[(String, String, Vec<f64>)],
) -> Result<String, String> {
    let edits: Vec<Edit> = (moved.iter())
        .map(|(body, marker, at)| Edit {
            body: body.clone(),
            marker: marker.clone(),
            at: Some(at.clone()),
            dirs: Vec::new(),
            keep_length: false,
            size,
        })
        .collect();
    let written = match format {
        Format::Toml => rewrite_toml(text, &edits),
        Format::Json => rewrite_json(text, &edits),
    };
    written.map(|(text, _)| text)
}

/// The error when the joints cannot all close near the drawn pose: the
/// loader's own diagnostics (`assembled`: the joints in conflict, named at
/// their positions), or a plain one should the loader find none.
fn conflicting<T>(file: SourceFile, assembled: Result<T, ModelError>) -> ModelError {
    assembled.err().unwrap_or_else(|| ModelError {
        diagnostics: vec![plain(
            file,
            "the joints cannot all close near the drawn pose".into(),
        )],
    })
}

/// The error when the assembly cannot tell whether the joints close.
fn undecided(open: &[Diagnostic]) -> ModelError {
    let first = &open[0];
    let mut d = Diagnostic {
        file: first.file.clone(),
        location: first.location.clone(),
        message: format!(
            "cannot tell whether the joints can all close: the least-squares assembly from the drawn pose did \
             not settle ({} joint(s) or constraint(s) open as drawn)",
            open.len()
        ),
        notes: open
            .iter()
            .map(|o| Note {
                location: o.location.clone(),
                message: o.message.clone(),
            })
            .collect(),
        help: Some(
            "draw the markers nearer to where the joints close (each body with its true shape, roughly in \
             place) and run `dofplan assemble` again"
                .into(),
        ),
    };
    d.notes.truncate(20);
    ModelError { diagnostics: vec![d] }
}

fn plain(file: SourceFile, message: String) -> Diagnostic {
    Diagnostic {
        file,
        location: Location::File,
        message,
        notes: vec![],
        help: None,
    }
}

/// New numbers for one marker: its position (`None`: leave as written) and
/// its directions by key (`dir` in the plane; `z` and `x` in space), each
/// rewritten only where the file writes that key.
struct Edit {
    body: String,
    marker: String,
    at: Option<Vec<f64>>,
    dirs: Vec<(&'static str, Vec<f64>)>,
    /// Whether a direction keeps the length it is written with (only its
    /// direction turns): spatial axes, which the file need not give as unit
    /// vectors.
    keep_length: bool,
    size: f64,
}

impl Edit {
    /// Whether it changes nothing.
    fn is_empty(&self) -> bool {
        self.at.is_none() && self.dirs.is_empty()
    }
}

/// The replacement texts of the numbers `old` (each with whether it is
/// written as a float) for the new values `new`: a point's within
/// [`WRITTEN_PRECISION`] of the size, a direction's of its length (scaled
/// to the length written first when `keep_length`). `None` for a number
/// that stays.
fn renumber(old: &[(f64, bool)], new: &[f64], dir: bool, edit: &Edit) -> Result<Vec<Option<String>>, String> {
    if old.len() != new.len() {
        return Err(format!("a point has {} numbers, not {}", old.len(), new.len()));
    }
    let length = |v: &mut dyn Iterator<Item = f64>| v.map(|c| c * c).sum::<f64>().sqrt();
    let scale = if dir && edit.keep_length {
        length(&mut old.iter().map(|o| o.0)) / length(&mut new.iter().copied())
    } else {
        1.0
    };
    let eps = if dir {
        WRITTEN_PRECISION * scale * length(&mut new.iter().copied())
    } else {
        WRITTEN_PRECISION * edit.size
    };
    Ok(old
        .iter()
        .zip(new)
        .map(|(&(o, float), &n)| replacement(o, float, n * scale, eps))
        .collect())
}

/// The number `v` with the fewest decimals within `eps` of it.
fn shortest(v: f64, eps: f64) -> String {
    for decimals in 0..=17 {
        let s = format!("{v:.decimals$}");
        if s.parse::<f64>().is_ok_and(|w| (w - v).abs() <= eps) {
            return if s.trim_start_matches('-').chars().all(|c| c == '0' || c == '.') {
                s.trim_start_matches('-').to_string()
            } else {
                s
            };
        }
    }
    format!("{v}")
}

/// A coordinate for the report: to the written precision.
fn short(v: f64, size: f64) -> String {
    shortest(v, WRITTEN_PRECISION * size)
}

/// The text of a number written in place of `old` (a float stays a float:
/// `2` becomes `2.0` if `old` was `1.5`), or `None` if `old` is within
/// `eps` of `new` already.
fn replacement(old: f64, old_is_float: bool, new: f64, eps: f64) -> Option<String> {
    if (old - new).abs() <= eps {
        return None;
    }
    let mut s = shortest(new, eps);
    if old_is_float && !s.contains(['.', 'e']) {
        s.push_str(".0");
    }
    Some(s)
}

/// Rewrites the numbers of a TOML file in place, keeping everything else.
/// Returns the text and, per edit, whether it changed anything.
fn rewrite_toml(text: &str, edits: &[Edit]) -> Result<(String, Vec<bool>), String> {
    use toml_edit::{DocumentMut, Item, Value};
    let mut doc: DocumentMut = text.parse().map_err(|e: toml_edit::TomlError| e.to_string())?;
    let mut changed = Vec::with_capacity(edits.len());
    /// Rewrites the numbers of an `[x, y]` or `[x, y, z]` item.
    fn numbers(item: &mut Item, new: &[f64], dir: bool, edit: &Edit) -> Result<bool, String> {
        let array = item.as_array_mut().ok_or("a point is not an array")?;
        let old = array
            .iter()
            .map(|v| match v {
                Value::Integer(i) => Ok((*i.value() as f64, false)),
                Value::Float(f) => Ok((*f.value(), true)),
                _ => Err("a coordinate is not a number".to_string()),
            })
            .collect::<Result<Vec<_>, _>>()?;
        let mut any = false;
        for (k, s) in renumber(&old, new, dir, edit)?.into_iter().enumerate() {
            let Some(s) = s else { continue };
            let v = array.get_mut(k).ok_or("a point lost a number")?;
            let mut written: Value = s.parse().map_err(|e: toml_edit::TomlError| e.to_string())?;
            *written.decor_mut() = v.decor().clone();
            *v = written;
            any = true;
        }
        Ok(any)
    }
    for edit in edits {
        if edit.is_empty() {
            changed.push(false);
            continue;
        }
        let missing = || format!("no marker `{}.{}` in the TOML document", edit.body, edit.marker);
        let item = doc
            .as_table_mut()
            .get_mut("bodies")
            .and_then(Item::as_table_like_mut)
            .and_then(|t| t.get_mut(&edit.body))
            .and_then(Item::as_table_like_mut)
            .and_then(|t| t.get_mut("markers"))
            .and_then(Item::as_table_like_mut)
            .and_then(|t| t.get_mut(&edit.marker))
            .ok_or_else(missing)?;
        let done = if item.is_array() {
            match &edit.at {
                Some(at) => numbers(item, at, false, edit)?,
                None => false,
            }
        } else {
            let fields = item.as_table_like_mut().ok_or_else(missing)?;
            let mut any = match &edit.at {
                Some(at) => numbers(fields.get_mut("at").ok_or_else(missing)?, at, false, edit)?,
                None => false,
            };
            for (key, v) in &edit.dirs {
                if let Some(d) = fields.get_mut(key) {
                    any |= numbers(d, v, true, edit)?;
                }
            }
            any
        };
        changed.push(done);
    }
    Ok((doc.to_string(), changed))
}

/// Rewrites the numbers of a JSON file; key order is kept (serde_json's
/// `preserve_order`), the layout becomes serde_json's pretty printing.
fn rewrite_json(text: &str, edits: &[Edit]) -> Result<(String, Vec<bool>), String> {
    use serde_json::Value;
    let mut doc: Value = serde_json::from_str(text).map_err(|e| e.to_string())?;
    let mut changed = Vec::with_capacity(edits.len());
    fn numbers(v: &mut Value, new: &[f64], dir: bool, edit: &Edit) -> Result<bool, String> {
        let array = v.as_array_mut().ok_or("a point is not an array")?;
        let old = array
            .iter()
            .map(|n| Ok((n.as_f64().ok_or("a coordinate is not a number")?, n.is_f64())))
            .collect::<Result<Vec<_>, String>>()?;
        let mut any = false;
        for (k, s) in renumber(&old, new, dir, edit)?.into_iter().enumerate() {
            let Some(s) = s else { continue };
            array[k] = serde_json::from_str(&s).map_err(|e| e.to_string())?;
            any = true;
        }
        Ok(any)
    }
    for edit in edits {
        if edit.is_empty() {
            changed.push(false);
            continue;
        }
        let missing = || format!("no marker `{}.{}` in the JSON document", edit.body, edit.marker);
        let item = doc
            .get_mut("bodies")
            .and_then(|b| b.get_mut(&edit.body))
            .and_then(|b| b.get_mut("markers"))
            .and_then(|ms| ms.get_mut(&edit.marker))
            .ok_or_else(missing)?;
        let done = if item.is_array() {
            match &edit.at {
                Some(at) => numbers(item, at, false, edit)?,
                None => false,
            }
        } else {
            let mut any = match &edit.at {
                Some(at) => numbers(item.get_mut("at").ok_or_else(missing)?, at, false, edit)?,
                None => false,
            };
            for (key, v) in &edit.dirs {
                if let Some(d) = item.get_mut(*key) {
                    any |= numbers(d, v, true, edit)?;
                }
            }
            any
        };
        changed.push(done);
    }
    let mut out = serde_json::to_string_pretty(&doc).map_err(|e| e.to_string())?;
    out.push('\n');
    Ok((out, changed))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_written_with_the_fewest_decimals_that_keep_them() {
        assert_eq!(shortest(1.0000000000001, 1e-11), "1");
        assert_eq!(shortest(-0.0000000000001, 1e-11), "0");
        assert_eq!(shortest(2.345678, 1e-3), "2.346");
        assert_eq!(shortest(-7.25, 1e-12), "-7.25");
        assert_eq!(replacement(1.5, true, 2.0, 1e-12).as_deref(), Some("2.0"));
        assert_eq!(replacement(1.0, false, 2.0, 1e-12).as_deref(), Some("2"));
        assert_eq!(replacement(2.0, false, 2.0 + 1e-14, 1e-12), None);
    }
}
