//! Reading and validating a mechanism file (TOML or JSON).
//!
//! Validation goes on past the first problem where it can, so a user sees
//! every error of a file at once; each error carries a position and the
//! names involved.

use foldhash::{HashMap, HashMapExt, HashSet, HashSetExt};
use std::path::Path;
use std::sync::Arc;

use dofplan_runtime::Point;

use super::error::{Diagnostic, Location, ModelError, Note, SourceFile};
use super::shape;
use super::source::{parse_json, parse_toml_by_serde, read_toml, At, Key, Node, NodeKind};
mod gears;
mod loads;
mod planar;
mod slots;
pub(crate) mod spatial;

use super::{
    Body, Constraint, ConstraintKind, Input, InputKind, Joint, JointKind, Marker, MarkerId, MarkerLike,
    Mechanism, Sweep, Swept,
};

/// Joints must hold in the drawn pose to this, relative to the mechanism's
/// size.
pub const DRAWN_TOLERANCE: f64 = 1e-9;

/// The largest mechanism file [`load_file_drawn`] and [`load_any_drawn`] read, in
/// bytes (256 MiB): about five times a chain of 90,000 four-bar loops
/// (53 MB). A larger file is refused before it is read; the `_str` loaders
/// set no limit.
pub const MAX_FILE_BYTES: u64 = 256 << 20;

/// A syntax error on a line longer than this (bytes) asks whether the
/// file is the right one.
const LONG_LINE: usize = 100_000;

/// The most values a sweep may have.
pub const MAX_STEPS: i64 = 1_000_000;

/// Marker coordinates and the mechanism's extent stay within these bounds:
/// the steps square lengths and multiply squares (a circle intersection's
/// half-chord is a fourth power), which overflow or underflow double
/// precision far beyond them.
pub const MAX_COORDINATE: f64 = 1e50;
/// See [`MAX_COORDINATE`].
pub const MIN_EXTENT: f64 = 1e-50;

/// The syntax of a mechanism file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// TOML (the usual form).
    Toml,
    /// The same structure as JSON.
    Json,
}

impl Format {
    /// By file extension: `.json` is JSON, anything else TOML.
    pub fn of_path(path: &Path) -> Format {
        match path.extension().and_then(|e| e.to_str()) {
            Some(e) if e.eq_ignore_ascii_case("json") => Format::Json,
            _ => Format::Toml,
        }
    }
}

/// Reads and validates a (planar) mechanism file like
/// [`load_str_drawn`]: joints open in the drawn pose are returned with
/// the mechanism, for the caller to diagnose (`conflict::assembled`).
pub fn load_file_drawn(path: &Path) -> Result<Drawn, ModelError> {
    let name = path.display().to_string();
    let file = read_file(path, name)?;
    let format = Format::of_path(path);
    let root = parse(&file, format)?;
    // The tree is dropped here, before the caller's diagnosis of open
    // joints (if any) allocates its own.
    drawn(file.clone(), &root, format)
}

/// Reads a file into the text errors quote, held once: the text read is
/// dropped as soon as it is shared (a 50 MB file is not held twice while
/// it is parsed).
fn read_file(path: &Path, name: String) -> Result<SourceFile, ModelError> {
    let text: Arc<str> = Arc::from(read_text(path, &name)?);
    Ok(SourceFile { name, text })
}

/// Reads a file as UTF-8 text, with an error that tells a wrong path from a
/// file that is not text.
fn read_text(path: &Path, name: &str) -> Result<String, ModelError> {
    let unread = |location: Location, message: String, help: &str| ModelError {
        diagnostics: vec![Diagnostic {
            file: SourceFile {
                name: name.to_string(),
                text: Arc::from(""),
            },
            location,
            message,
            notes: vec![],
            help: Some(help.into()),
        }],
    };
    let cannot_read = |e: std::io::Error| {
        unread(
            Location::File,
            format!("cannot read the file: {e}"),
            "check the path; mechanism files are TOML (or JSON with a .json extension)",
        )
    };
    // The size is checked before reading (and while reading, for what
    // tells no size: a pipe), so a file of gigabytes is refused at once.
    let too_big = |size: Option<u64>| {
        let limit = MAX_FILE_BYTES >> 20;
        unread(
            Location::File,
            match size {
                Some(size) => format!(
                    "the file is {size} bytes ({} MiB), more than the {limit} MiB a mechanism file may have",
                    size >> 20
                ),
                None => format!("the file is longer than the {limit} MiB a mechanism file may have"),
            },
            "is this the right file? Mechanisms are far smaller: a chain of 90,000 four-bar loops \
             (180,002 bodies) is 53 MB. To load a larger file anyway, read it yourself and pass its \
             text to `dofplan::load_any_str`, which sets no limit",
        )
    };
    let mut reader = std::fs::File::open(path).map_err(cannot_read)?;
    if let Ok(size) = reader.metadata().map(|m| m.len()) {
        if size > MAX_FILE_BYTES {
            return Err(too_big(Some(size)));
        }
    }
    let mut bytes = Vec::new();
    std::io::Read::read_to_end(
        &mut std::io::Read::take(&mut reader, MAX_FILE_BYTES + 1),
        &mut bytes,
    )
    .map_err(cannot_read)?;
    if bytes.len() as u64 > MAX_FILE_BYTES {
        return Err(too_big(None));
    }
    // Read as bytes first: a file that is there but is not text (a binary,
    // an image, UTF-16) is told apart from a wrong path. A NUL byte is
    // valid UTF-8 but text in neither TOML nor JSON: binaries are full of
    // them.
    let bad = match std::str::from_utf8(&bytes) {
        Ok(text) => text.find('\0'),
        Err(e) => Some(e.valid_up_to()),
    };
    if let Some(offset) = bad {
        // Where the bad byte is, counted in the text before it (valid).
        let before = std::str::from_utf8(&bytes[..offset]).unwrap_or_default();
        let line = before.matches('\n').count() + 1;
        let col = before[before.rfind('\n').map_or(0, |i| i + 1)..].chars().count() + 1;
        return Err(unread(
            Location::LineCol(line, col),
            format!(
                "the file is not UTF-8 text: byte 0x{:02x} at offset {offset} is not valid UTF-8{}",
                bytes[offset],
                if bytes[offset] == 0 { " text" } else { "" },
            ),
            "mechanism files are TOML or JSON text in UTF-8: is this the right file? (re-save it as UTF-8 if it is)",
        ));
    }
    Ok(String::from_utf8(bytes).expect("checked above"))
}

/// What every mechanism file needs, for errors about files with nothing in
/// them.
const WHAT_A_FILE_NEEDS: &str =
    "a mechanism file needs a `name`, `bodies` (one of them `fixed = true`) with \
     their `markers`, and `joints`; `inputs` and a `sweep` drive it (see mechanisms/fourbar.toml)";

/// A validated mechanism of either dimension.
#[derive(Clone, Debug)]
pub enum Model {
    /// A planar mechanism (`dimension` absent or 2).
    Planar(Mechanism),
    /// A spatial mechanism (`dimension = 3`).
    Spatial(super::spatial::Mechanism),
}

impl Model {
    /// The mechanism's name.
    pub fn name(&self) -> &str {
        match self {
            Model::Planar(m) => &m.name,
            Model::Spatial(m) => &m.name,
        }
    }

    /// 2 or 3.
    pub fn dimension(&self) -> u8 {
        match self {
            Model::Planar(_) => 2,
            Model::Spatial(_) => 3,
        }
    }
}

/// Whether a file says `dimension = 3` at its top level (read off its
/// tokens up to that key, not validated: a file that cannot be read is not
/// spatial; one that says so but is wrong elsewhere is, and loading it
/// reports what is wrong).
pub fn is_spatial_file(path: &Path) -> bool {
    // A file too large to load is not read here either: loading it says
    // why.
    if std::fs::metadata(path).is_ok_and(|m| m.len() > MAX_FILE_BYTES) {
        return false;
    }
    // Read off the tokens up to the key, not parsed: the loader that
    // follows parses the file (and reports what is wrong with it), so a
    // large file is parsed once, not twice.
    match Format::of_path(path) {
        Format::Toml => toml_file_says_spatial(path).unwrap_or(false),
        Format::Json => std::fs::read_to_string(path).is_ok_and(|text| shape::json_says_spatial(&text)),
    }
}

/// [`is_spatial_file`] for a TOML file: its start is read, then more of it
/// (twice as much each time) until its top-level keys are past. A 50 MB
/// file says so in its first lines, and is read once, by the loader.
fn toml_file_says_spatial(path: &Path) -> Option<bool> {
    let mut file = std::fs::File::open(path).ok()?;
    let mut bytes = Vec::new();
    let mut want: u64 = 1 << 16;
    loop {
        let had = bytes.len() as u64;
        std::io::Read::read_to_end(&mut std::io::Read::take(&mut file, want - had), &mut bytes).ok()?;
        let ended = (bytes.len() as u64) < want;
        // A start read so far is cut after its last new line: no key or
        // value of the top level is cut in two.
        let cut = match ended {
            true => bytes.len(),
            false => bytes.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1),
        };
        let (spatial, decided) = shape::toml_says_spatial_in(std::str::from_utf8(&bytes[..cut]).ok()?);
        if decided || ended {
            return Some(spatial);
        }
        want *= 2;
    }
}

/// A mechanism of either dimension as drawn: [`Drawn`] or [`spatial::Drawn`].
#[derive(Clone, Debug)]
pub enum DrawnModel {
    /// A planar mechanism (`dimension` absent or 2).
    Planar(Drawn),
    /// A spatial mechanism (`dimension = 3`).
    Spatial(spatial::Drawn),
}

/// Reads and validates a mechanism file of either dimension, open joints
/// returned with it (see [`DrawnModel`]).
pub fn load_any_drawn(path: &Path) -> Result<DrawnModel, ModelError> {
    let name = path.display().to_string();
    let file = read_file(path, name)?;
    load_any_file(file, Format::of_path(path))
}

/// Validates a mechanism of either dimension given as text, open joints
/// returned with it; `file_name` is used in errors.
pub fn load_any_str_drawn(file_name: &str, text: &str, format: Format) -> Result<DrawnModel, ModelError> {
    load_any_file(source_file(file_name, text), format)
}

/// [`load_any_str_drawn`] on a file's text: parsed once, validated as its
/// `dimension` says.
fn load_any_file(file: SourceFile, format: Format) -> Result<DrawnModel, ModelError> {
    let root = parse(&file, format)?;
    let spatial = match &root.kind {
        NodeKind::Table(top) => matches!(
            Validator::get(top, "dimension").map(|d| &d.kind),
            Some(NodeKind::Int(3))
        ),
        _ => false,
    };
    if !spatial {
        return drawn(file.clone(), &root, format).map(DrawnModel::Planar);
    }
    spatial::drawn(file.clone(), &root, format).map(DrawnModel::Spatial)
}

/// A text to parse, named `file_name` in errors.
fn source_file(file_name: &str, text: &str) -> SourceFile {
    SourceFile {
        name: file_name.to_string(),
        text: Arc::from(text),
    }
}

/// A mechanism whose only errors, if any, are joints and constraints that do
/// not hold in the drawn pose: what `dofplan assemble` starts from. With
/// open joints it is not a valid model: only the assembly
/// (`conflict::assemble`) may use it; everything else takes
/// `conflict::assembled`.
#[derive(Clone, Debug)]
pub struct Drawn {
    /// The mechanism, every joint and constraint included, open ones too.
    pub mechanism: Mechanism,
    /// The "does not hold in the drawn pose" errors, in file order; empty
    /// when every joint holds.
    pub open: Vec<Diagnostic>,
    /// Which joint or constraint each error is about.
    pub(crate) opened: Vec<Open>,
    /// Where each joint, then each constraint, of the mechanism is written.
    pub(crate) places: Vec<Location>,
}

/// A joint or constraint the loader found open in the drawn pose.
#[derive(Clone, Debug)]
pub(crate) struct Open {
    /// "joint B", "constraint c1".
    pub origin: String,
    /// Its "does not hold in the drawn pose" error, an index into the
    /// loader's diagnostics.
    pub diagnostic: usize,
}

/// Parses a file into its node tree, with the errors every file can have
/// (empty, syntax, nothing defined).
fn parse(file: &SourceFile, format: Format) -> Result<Node<'_>, ModelError> {
    let text: &str = &file.text;
    // Said plainly: the parsers' own words for nothing at all ("missing
    // `name`", "EOF while parsing a value") do not say the file is empty.
    if text.trim().is_empty() {
        return Err(ModelError {
            diagnostics: vec![Diagnostic {
                file: file.clone(),
                location: Location::File,
                message: if text.is_empty() {
                    "the file is empty".into()
                } else {
                    "the file is empty (only white space)".into()
                },
                notes: vec![],
                help: Some(WHAT_A_FILE_NEEDS.into()),
            }],
        });
    }
    // A well-formed TOML file is read in one pass (`source::read_toml`),
    // which takes no array longer than the format allows. Anything else is
    // scanned for those arrays, refused before a parser builds them (see
    // `shape`), then parsed by the `toml` crate or serde_json, which say
    // what is wrong.
    if let Some(root) = match format {
        Format::Toml => read_toml(text),
        Format::Json => None,
    } {
        return defines_something(file, format, root);
    }
    let too_long = match format {
        Format::Toml => shape::check_toml(text),
        Format::Json => shape::check_json(text),
    };
    if let Some(t) = too_long {
        return Err(ModelError {
            diagnostics: vec![Diagnostic {
                file: file.clone(),
                location: Location::Span(t.span),
                message: t.message,
                notes: vec![],
                help: Some(t.help),
            }],
        });
    }
    let parsed = match format {
        Format::Toml => parse_toml_by_serde(text),
        Format::Json => parse_json(text),
    };
    let root = parsed.map_err(|e| {
        let mut message = format!("{} syntax error: {}", format_name(format), e.message.trim());
        let mut help = None;
        // A TOML date reaches the span-keeping reader as serde's private
        // datetime marker; say what it is rather than leak the marker name.
        if e.message.contains("$__toml_private_datetime") {
            message = "a date or time is not a valid value in a mechanism file".into();
            help = Some("write a number, string, boolean, array or table".into());
        }
        // toml says only "duplicate key"; name the key (its span).
        if let Some(key) = e
            .span
            .as_ref()
            .and_then(|s| text.get(s.clone()))
            .filter(|k| !k.is_empty())
        {
            if e.message.trim() == "duplicate key" {
                message = format!("{message} `{key}`");
                help = Some("a name may be defined only once in a table: rename or merge the two".into());
            }
        }
        // On a line of megabytes, the error is likely the file itself: a
        // mechanism is written a few entries a line.
        if let Some(at) = e
            .span
            .as_ref()
            .map(|s| s.start.min(text.len()))
            .filter(|_| help.is_none())
        {
            let (before, after) = text.as_bytes().split_at(at);
            let start = before.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
            let end = after
                .iter()
                .position(|&b| b == b'\n')
                .map_or(text.len(), |i| at + i);
            if end - start > LONG_LINE {
                let line = before.iter().filter(|&&b| b == b'\n').count() + 1;
                help = Some(format!(
                    "line {line} is {} bytes long: is this the right file? \
                     A mechanism file is written a few entries a line (see mechanisms/fourbar.toml)",
                    end - start
                ));
            }
        }
        ModelError {
            diagnostics: vec![Diagnostic {
                file: file.clone(),
                location: e.span.map_or(Location::File, Location::Span),
                message,
                notes: vec![],
                help,
            }],
        }
    })?;
    defines_something(file, format, root)
}

/// The tree of a file, or the error for a file that defines nothing.
fn defines_something<'s>(file: &SourceFile, format: Format, root: Node<'s>) -> Result<Node<'s>, ModelError> {
    if matches!(&root.kind, NodeKind::Table(t) if t.is_empty()) {
        return Err(ModelError {
            diagnostics: vec![Diagnostic {
                file: file.clone(),
                location: Location::File,
                message: match format {
                    Format::Toml => "the file defines nothing (it has only comments)".into(),
                    Format::Json => "the file defines nothing (an empty object)".into(),
                },
                notes: vec![],
                help: Some(WHAT_A_FILE_NEEDS.into()),
            }],
        });
    }
    Ok(root)
}

/// Validates a mechanism given as text like `dofplan::load_str`, but returns it
/// even when joints or constraints do not hold in the drawn pose (with
/// those errors). Every other error (syntax, unknown names, kinds...) is
/// still an error.
pub fn load_str_drawn(file_name: &str, text: &str, format: Format) -> Result<Drawn, ModelError> {
    let file = source_file(file_name, text);
    let root = parse(&file, format)?;
    drawn(file.clone(), &root, format)
}

/// The planar validation of a parsed file, open joints allowed.
fn drawn(file: SourceFile, root: &Node, format: Format) -> Result<Drawn, ModelError> {
    let mut v = Validator::new(file, format);
    let mechanism = v.mechanism(root);
    match mechanism {
        // Only joints open in the drawn pose (or none): the assembly check
        // says whether the mechanism assembles at all, or which joints are
        // in conflict (`conflict::assembled`).
        Some(m) if v.diags.len() == v.open.len() => Ok(Drawn {
            mechanism: m,
            open: v.diags,
            opened: v.open,
            places: v.places,
        }),
        _ => Err(ModelError { diagnostics: v.diags }),
    }
}

fn format_name(format: Format) -> &'static str {
    match format {
        Format::Toml => "TOML",
        Format::Json => "JSON",
    }
}

/// A marker reference with where it was written, before resolution: its
/// path in the file is made only for an error.
struct Written<'a> {
    node: &'a Node<'a>,
    path: &'a dyn Fn() -> String,
}

/// A table's entries as parsed.
type Entries<'n> = &'n [(Key<'n>, Node<'n>)];

/// Bodies by name, and for each body with more than a few markers, its
/// markers by name (the others are searched).
type Names = (HashMap<String, usize>, Vec<Option<HashMap<String, usize>>>);

struct Validator {
    file: SourceFile,
    diags: Vec<Diagnostic>,
    /// "body" and "body.marker" names that are written but failed
    /// validation (with an error already): references to them get no second
    /// error.
    broken: HashSet<String>,
    /// Joints and constraints that do not hold in the drawn pose (each with
    /// an error already). They are kept in the mechanism, so the assembly
    /// check sees them; the file is rejected anyway.
    open: Vec<Open>,
    /// Where each joint, then each constraint, is written (as `Drawn`).
    places: Vec<Location>,
    /// The mechanism's size, computed once from the bodies (every joint's
    /// drawn-pose tolerance is relative to it).
    size: Option<f64>,
    /// Bodies by name, and markers by body and name (first of a name),
    /// indexed once the bodies are read: references look them up.
    names: Option<Names>,
    /// Whether a table may name a key twice: JSON allows it, TOML does
    /// not (its parse has refused the file already).
    repeats: bool,
}

impl Validator {
    fn new(file: SourceFile, format: Format) -> Validator {
        Validator {
            repeats: format == Format::Json,
            file,
            diags: Vec::new(),
            broken: HashSet::new(),
            open: Vec::new(),
            places: Vec::new(),
            size: None,
            names: None,
        }
    }

    /// Each of `items` with the line its node is written on given to it by
    /// `set`: one pass over the text, however many there are.
    fn with_lines<T>(&self, items: Vec<(T, &Node)>, set: impl Fn(&mut T, Option<usize>)) -> Vec<T> {
        let mut starts: Vec<(usize, usize)> = (items.iter().enumerate())
            .filter_map(|(i, (_, n))| n.span().map(|s| (s.start, i)))
            .collect();
        starts.sort_unstable();
        let mut lines = vec![None; items.len()];
        let (mut line, mut at) = (1, 0);
        let text = self.file.text.as_bytes();
        for (start, i) in starts {
            let start = start.min(text.len());
            line += text[at..start].iter().filter(|&&b| b == b'\n').count();
            at = start;
            lines[i] = Some(line);
        }
        (items.into_iter().zip(lines))
            .map(|((mut item, _), line)| {
                set(&mut item, line);
                item
            })
            .collect()
    }

    fn loc(&self, node: &Node, path: &str) -> Location {
        match node.span() {
            Some(s) => Location::Span(s),
            None => Location::Path(path.to_string()),
        }
    }

    fn key_loc(&self, key: &Key, path: &str) -> Location {
        match key.span() {
            Some(s) => Location::Span(s),
            None => Location::Path(path.to_string()),
        }
    }

    fn error(&mut self, location: Location, message: String, help: Option<String>) {
        self.diags.push(Diagnostic {
            file: self.file.clone(),
            location,
            message,
            notes: vec![],
            help,
        });
    }

    fn error_notes(&mut self, location: Location, message: String, notes: Vec<Note>, help: Option<String>) {
        self.diags.push(Diagnostic {
            file: self.file.clone(),
            location,
            message,
            notes,
            help,
        });
    }

    fn table<'n>(&mut self, node: &'n Node<'n>, path: &str) -> Option<&'n [(Key<'n>, Node<'n>)]> {
        match &node.kind {
            NodeKind::Table(t) => Some(t),
            other => {
                let loc = self.loc(node, path);
                self.error(
                    loc,
                    format!("`{path}` must be a table, found {}", other.type_name()),
                    None,
                );
                None
            }
        }
    }

    /// Rejects keys outside `allowed` (nothing the user wrote is ignored)
    /// and names within one table that repeat (JSON allows them).
    fn check_keys(&mut self, entries: &[(Key, Node)], allowed: &[&str], path: &str) {
        // A table of a few entries is searched; a larger one is looked up.
        let mut seen: Option<HashMap<&str, &Key>> = (entries.len() > 8).then(HashMap::new);
        for (i, (key, _)) in entries.iter().enumerate() {
            let first = match &mut seen {
                _ if !self.repeats => None,
                Some(seen) => match seen.entry(key.name.as_ref()) {
                    std::collections::hash_map::Entry::Occupied(e) => Some(*e.get()),
                    std::collections::hash_map::Entry::Vacant(e) => {
                        e.insert(key);
                        None
                    }
                },
                None => entries[..i].iter().map(|(k, _)| k).find(|k| k.name == key.name),
            };
            if let Some(first) = first {
                let kpath = join(path, &key.name);
                let first_loc = self.key_loc(first, &kpath);
                let loc = self.key_loc(key, &kpath);
                self.error_notes(
                    loc,
                    format!("duplicate name `{}` in {}", key.name, display_path(path)),
                    vec![Note {
                        location: first_loc,
                        message: "first defined here".into(),
                    }],
                    Some("rename one of them".into()),
                );
            }
            if !allowed.is_empty() && !allowed.contains(&key.name.as_ref()) {
                let loc = self.key_loc(key, &join(path, &key.name));
                self.error(
                    loc,
                    format!("unknown key `{}` in {}", key.name, display_path(path)),
                    Some(format!("expected one of: {}", allowed.join(", "))),
                );
            }
        }
    }

    fn get<'n>(entries: &'n [(Key<'n>, Node<'n>)], name: &str) -> Option<&'n Node<'n>> {
        entries.iter().find(|(k, _)| k.name == name).map(|(_, n)| n)
    }

    fn required<'n>(
        &mut self,
        entries: &'n [(Key<'n>, Node<'n>)],
        name: &str,
        parent: &Node,
        path: &str,
    ) -> Option<&'n Node<'n>> {
        let found = Self::get(entries, name);
        if found.is_none() {
            let loc = self.loc(parent, path);
            self.error(loc, format!("{} is missing `{name}`", display_path(path)), None);
        }
        found
    }

    fn string<'n>(&mut self, node: &'n Node<'n>, path: &str) -> Option<&'n str> {
        match &node.kind {
            NodeKind::Str(s) => Some(s),
            other => {
                let loc = self.loc(node, path);
                self.error(
                    loc,
                    format!("`{path}` must be a string, found {}", other.type_name()),
                    None,
                );
                None
            }
        }
    }

    fn number(&mut self, node: &Node, path: &str) -> Option<f64> {
        let value = match &node.kind {
            NodeKind::Int(i) => *i as f64,
            NodeKind::Float(f) => *f,
            other => {
                let loc = self.loc(node, path);
                self.error(
                    loc,
                    format!("`{path}` must be a number, found {}", other.type_name()),
                    None,
                );
                return None;
            }
        };
        if !value.is_finite() {
            let loc = self.loc(node, path);
            self.error(
                loc,
                format!("`{path}` is {value}, not a finite number"),
                Some("write a finite number".into()),
            );
            return None;
        }
        Some(value)
    }

    fn point(&mut self, node: &Node, path: &str) -> Option<Point> {
        self.coords(node, path)
    }

    /// `N` numbers `[x, y]` or `[x, y, z]`: a point of either dimension.
    fn coords<const N: usize>(&mut self, node: &Node, path: &str) -> Option<[f64; N]> {
        let form = || ["x", "y", "z"][..N].join(", ");
        match &node.kind {
            NodeKind::Array(items) if items.len() == N => {
                let mut out = [0.0; N];
                let mut ok = true;
                for (k, item) in items.iter().enumerate() {
                    // Every coordinate is read, so each bad one is reported
                    // (its path made only then).
                    let value = match item.kind {
                        NodeKind::Int(i) => Some(i as f64),
                        NodeKind::Float(f) if f.is_finite() => Some(f),
                        _ => self.number(item, &format!("{path}[{k}]")),
                    };
                    match value {
                        Some(v) => out[k] = v,
                        None => ok = false,
                    }
                }
                ok.then_some(out)
            }
            NodeKind::Array(items) => {
                let loc = self.loc(node, path);
                self.error(
                    loc,
                    format!(
                        "`{path}` must have {N} coordinates [{}], found {}",
                        form(),
                        items.len()
                    ),
                    Some(format!("dimension is {N}: write [{}]", form())),
                );
                None
            }
            other => {
                let loc = self.loc(node, path);
                self.error(
                    loc,
                    format!("`{path}` must be [{}], found {}", form(), other.type_name()),
                    None,
                );
                None
            }
        }
    }

    /// A marker's position: a point within [`MAX_COORDINATE`].
    fn position(&mut self, marker: &dyn Fn() -> String, node: &Node, path: &str) -> Option<Point> {
        let p = self.point(node, path)?;
        if let Some(c) = p.iter().find(|c| c.abs() > MAX_COORDINATE) {
            let loc = self.loc(node, path);
            self.error(
                loc,
                format!(
                    "marker `{}` has a coordinate {c:e}, too far from the origin to compute with",
                    marker()
                ),
                Some(format!(
                    "rescale the drawing (units are free): coordinates up to {MAX_COORDINATE:e} work"
                )),
            );
            return None;
        }
        Some(p)
    }

    /// The top-level table of a file of either dimension, its keys checked,
    /// and its `name`.
    fn top<'n>(&mut self, root: &'n Node<'n>) -> Option<(Entries<'n>, Option<String>)> {
        let top = self.table(root, "")?;
        self.check_keys(
            top,
            &[
                "name",
                "dimension",
                "bodies",
                "joints",
                "constraints",
                "inputs",
                "sweep",
                "gravity",
                "loads",
            ],
            "",
        );
        let name = self
            .required(top, "name", root, "")
            .and_then(|n| self.string(n, "name").map(str::to_string));
        if let Some(n) = &name {
            if n.is_empty() {
                let loc = self.loc(Self::get(top, "name").unwrap(), "name");
                self.error(loc, "`name` must not be empty".into(), None);
            }
        }
        Some((top, name))
    }

    /// Reads `[bodies]`, each marker by `read` (the dimension's form).
    fn bodies<M: MarkerLike>(
        &mut self,
        node: &Node,
        read: fn(&mut Self, &str, &str, &Node, &str) -> Option<M>,
    ) -> Vec<Body<M>> {
        let Some(entries) = self.table(node, "bodies") else {
            return Vec::new();
        };
        self.check_keys(entries, &[], "bodies");
        let mut bodies = Vec::with_capacity(entries.len());
        // Paths are written into buffers, not allocated for every entry.
        let mut path = String::from("bodies.");
        let mut mpath = String::new();
        let mut p = String::new();
        for (key, bnode) in entries {
            path.truncate("bodies.".len());
            path.push_str(&key.name);
            let path = &path;
            self.check_name(key, path, "body");
            let Some(fields) = self.table(bnode, path) else {
                self.broken.insert(key.name.to_string());
                continue;
            };
            // Mass properties are read by each dimension (`loads.rs`).
            self.check_keys(fields, &["fixed", "markers", "mass", "centre", "inertia"], path);
            let fixed = match Self::get(fields, "fixed") {
                None => false,
                Some(f) => match f.kind {
                    NodeKind::Bool(b) => b,
                    ref other => {
                        let loc = self.loc(f, &join(path, "fixed"));
                        self.error(
                            loc,
                            format!(
                                "`{path}.fixed` must be true or false, found {}",
                                other.type_name()
                            ),
                            None,
                        );
                        false
                    }
                },
            };
            let mut markers = Vec::new();
            mpath.clear();
            mpath.push_str(path);
            mpath.push_str(".markers");
            let mentries = self
                .required(fields, "markers", bnode, path)
                .and_then(|mnode| self.table(mnode, &mpath));
            match mentries {
                None => {
                    self.broken.insert(key.name.to_string());
                }
                Some(mentries) => {
                    self.check_keys(mentries, &[], &mpath);
                    markers.reserve_exact(mentries.len());
                    for (mkey, m) in mentries {
                        p.clear();
                        p.push_str(&mpath);
                        p.push('.');
                        p.push_str(&mkey.name);
                        self.check_name(mkey, &p, "marker");
                        match read(self, &key.name, &mkey.name, m, &p) {
                            Some(marker) => markers.push(marker),
                            None => {
                                self.broken.insert(format!("{}.{}", key.name, mkey.name));
                            }
                        }
                    }
                }
            }
            bodies.push(Body {
                name: key.name.to_string(),
                fixed,
                markers,
            });
        }
        // The bounding box's diagonal by `hypot`, which cannot underflow
        // (squares of 1e-300 are 0). Markers that all coincide (extent 0)
        // are a degenerate drawing, not a scale.
        let extent = crate::model::extent(bodies.iter().flat_map(|b| &b.markers).map(|m| m.coords()));
        if extent > 0.0 && extent < MIN_EXTENT {
            let loc = self.loc(node, "bodies");
            self.error(
                loc,
                format!("the markers span only {extent:e}, too small to compute with"),
                Some(format!(
                    "rescale the drawing (units are free): spans from {MIN_EXTENT:e} to {MAX_COORDINATE:e} work"
                )),
            );
        }
        if !bodies.is_empty() && !bodies.iter().any(|b| b.fixed) {
            let loc = self.loc(node, "bodies");
            self.error(
                loc,
                "no fixed body: a mechanism needs a ground".into(),
                Some(format!(
                    "add `fixed = true` to the ground body (e.g. [bodies.{}])",
                    bodies[0].name
                )),
            );
        }
        bodies
    }

    /// Names are used as "body.marker" and as Rust identifiers in generated
    /// code: no dots, not empty.
    fn check_name(&mut self, key: &Key, path: &str, what: &str) {
        if key.name.is_empty() || key.name.contains('.') || key.name.chars().any(char::is_whitespace) {
            let loc = self.key_loc(key, path);
            self.error(
                loc,
                format!(
                    "{what} name `{}` must be non-empty, without dots or spaces",
                    key.name
                ),
                None,
            );
        }
    }

    /// Resolves "body.marker".
    fn marker_ref<M: MarkerLike>(
        &mut self,
        w: &Written,
        bodies: &[Body<M>],
        owner: &str,
    ) -> Option<MarkerId> {
        let text = match &w.node.kind {
            NodeKind::Str(s) => s.as_ref(),
            _ => {
                // Not a string: `string` says so.
                self.string(w.node, &(w.path)());
                return None;
            }
        };
        let Some((b, m)) = text.split_once('.') else {
            let loc = self.loc(w.node, &(w.path)());
            self.error(
                loc,
                format!("{owner}: `{text}` is not of the form \"body.marker\""),
                None,
            );
            return None;
        };
        let (body_index, marker_index) = self.names.get_or_insert_with(|| {
            let mut by_name = HashMap::new();
            for (bi, body) in bodies.iter().enumerate() {
                by_name.entry(body.name.clone()).or_insert(bi);
            }
            let markers = bodies
                .iter()
                .map(|body| {
                    (body.markers.len() > 8).then(|| {
                        let mut index = HashMap::new();
                        for (mi, marker) in body.markers.iter().enumerate() {
                            index.entry(marker.name().to_string()).or_insert(mi);
                        }
                        index
                    })
                })
                .collect();
            (by_name, markers)
        });
        // The first marker of the name, as the index keeps it.
        let bi = body_index.get(b).copied();
        let mi = bi.and_then(|bi| match &marker_index[bi] {
            Some(index) => index.get(m).copied(),
            None => bodies[bi].markers.iter().position(|k| k.name() == m),
        });
        let Some(bi) = bi else {
            if self.broken.contains(b) {
                return None;
            }
            let names: Vec<_> = bodies.iter().map(|b| b.name.as_str()).collect();
            let loc = self.loc(w.node, &(w.path)());
            self.error(
                loc,
                format!("{owner}: unknown body `{b}` in `{text}`"),
                Some(format!("bodies are: {}", names.join(", "))),
            );
            return None;
        };
        let Some(mi) = mi else {
            if self.broken.contains(b) || self.broken.contains(text) {
                return None;
            }
            let names: Vec<_> = bodies[bi].markers.iter().map(|m| m.name()).collect();
            let loc = self.loc(w.node, &(w.path)());
            self.error(
                loc,
                format!("{owner}: body `{b}` has no marker `{m}`"),
                Some(format!("markers of `{b}` are: {}", names.join(", "))),
            );
            return None;
        };
        Some(MarkerId { body: bi, marker: mi })
    }

    /// The two markers of a joint or constraint (or a spring or damper:
    /// `between` is the help for two markers on one body).
    fn pair<M: MarkerLike>(
        &mut self,
        fields: &[(Key, Node)],
        node: &Node,
        path: &str,
        bodies: &[Body<M>],
        (owner, between): (&str, &str),
    ) -> Option<[MarkerId; 2]> {
        let mnode = self.required(fields, "markers", node, path)?;
        // The path, for errors only.
        let mpath = || join(path, "markers");
        let items = match &mnode.kind {
            NodeKind::Array(items) if items.len() == 2 => items,
            _ => {
                let loc = self.loc(mnode, &mpath());
                self.error(
                    loc,
                    format!("{owner}: `markers` must be two markers [\"body.A\", \"other.B\"]"),
                    None,
                );
                return None;
            }
        };
        let a = self.marker_ref(
            &Written {
                node: &items[0],
                path: &|| format!("{}[0]", mpath()),
            },
            bodies,
            owner,
        );
        let b = self.marker_ref(
            &Written {
                node: &items[1],
                path: &|| format!("{}[1]", mpath()),
            },
            bodies,
            owner,
        );
        let (a, b) = (a?, b?);
        if a.body == b.body {
            let loc = self.loc(mnode, &mpath());
            self.error(
                loc,
                format!(
                    "{owner} joins two markers of the same body `{}`",
                    bodies[a.body].name
                ),
                Some(between.into()),
            );
            return None;
        }
        Some([a, b])
    }

    fn kind<'n>(
        &mut self,
        fields: &'n [(Key<'n>, Node<'n>)],
        node: &Node,
        path: &str,
        allowed: &[&str],
        owner: &str,
    ) -> Option<(&'n str, &'n Node<'n>)> {
        let knode = self.required(fields, "kind", node, path)?;
        let kind = match &knode.kind {
            NodeKind::Str(s) => s.as_ref(),
            // Not a string: `string` says so.
            _ => return self.string(knode, &join(path, "kind")).and(None),
        };
        if !allowed.contains(&kind) {
            let loc = self.loc(knode, &join(path, "kind"));
            self.error(
                loc,
                format!("{owner}: unknown kind `{kind}`"),
                Some(format!("expected one of: {}", allowed.join(", "))),
            );
            return None;
        }
        Some((kind, knode))
    }

    /// Walks `[joints]` or `[constraints]`: every entry is a table with a
    /// `kind` among `kinds` and two `markers` (entries of a kind in `skip`
    /// are another reader's). Calls `check` with the kind
    /// and the resolved markers; entries it accepts are returned.
    #[allow(clippy::too_many_arguments)]
    fn connections<'n, T, M: MarkerLike>(
        &mut self,
        node: &'n Node<'n>,
        bodies: &[Body<M>],
        section: &str,
        what: &str,
        (kinds, extra, skip): (&[&str], &[&str], &[&str]),
        mut check: impl FnMut(&mut Self, &str, [MarkerId; 2], &Node, &str, &str) -> Option<T>,
    ) -> Vec<(String, T, [MarkerId; 2], &'n Node<'n>)> {
        let Some(entries) = self.table(node, section) else {
            return Vec::new();
        };
        self.check_keys(entries, &[], section);
        let mut out = Vec::with_capacity(entries.len());
        let allowed: Vec<&str> = ["kind", "markers"].iter().chain(extra).copied().collect();
        // The path and the name in errors are written into buffers, not
        // allocated for every entry.
        let (mut path, mut owner) = (String::new(), String::new());
        for (key, entry) in entries {
            // Entries of the kinds read elsewhere (gear pairs, slots).
            if let NodeKind::Table(fields) = &entry.kind {
                if let Some(NodeKind::Str(k)) = Self::get(fields, "kind").map(|n| &n.kind) {
                    if skip.contains(&k.as_ref()) {
                        continue;
                    }
                }
            }
            path.clear();
            path.push_str(section);
            path.push('.');
            path.push_str(&key.name);
            owner.clear();
            owner.push_str(what);
            owner.push_str(" `");
            owner.push_str(&key.name);
            owner.push('`');
            let (path, owner) = (&path, &owner);
            self.check_name(key, path, what);
            let Some(fields) = self.table(entry, path) else {
                continue;
            };
            self.check_keys(fields, &allowed, path);
            let kind = self.kind(fields, entry, path, kinds, owner);
            let pair = self.pair(
                fields,
                entry,
                path,
                bodies,
                (
                    owner,
                    "a joint or constraint connects markers of two different bodies",
                ),
            );
            let (Some((kind, _)), Some(markers)) = (kind, pair) else {
                continue;
            };
            if let Some(value) = check(self, kind, markers, entry, path, owner) {
                out.push((key.name.to_string(), value, markers, entry));
            }
        }
        out
    }

    fn cross_duplicates(&mut self, joints: &Node, constraints: &Node) {
        let (NodeKind::Table(j), NodeKind::Table(c)) = (&joints.kind, &constraints.kind) else {
            return;
        };
        for (ck, _) in c {
            if let Some((jk, _)) = j.iter().find(|(jk, _)| jk.name == ck.name) {
                let loc = self.key_loc(ck, &join("constraints", &ck.name));
                let first = self.key_loc(jk, &join("joints", &jk.name));
                self.error_notes(
                    loc,
                    format!("duplicate name `{}`: a joint already has it", ck.name),
                    vec![Note {
                        location: first,
                        message: "the joint is defined here".into(),
                    }],
                    Some("joints and constraints share one namespace; rename one".into()),
                );
            }
        }
    }

    /// Records that the joint or constraint `owner` ("joint `B`") does not
    /// hold in the drawn pose; its error is the last one.
    fn opened(&mut self, owner: &str) {
        self.open.push(Open {
            origin: owner.replace('`', ""),
            diagnostic: self.diags.len() - 1,
        });
    }

    /// Reads `[inputs]`: each names a joint of `joints` that takes its kind
    /// and is not driven already (the rules of either dimension come from
    /// [`JointLike`]).
    fn inputs<J: JointLike, M: MarkerLike>(
        &mut self,
        node: &Node,
        joints_node: &Node,
        joints: &[(J, &Node)],
        bodies: &[Body<M>],
    ) -> Vec<Input> {
        let Some(entries) = self.table(node, "inputs") else {
            return Vec::new();
        };
        self.check_keys(entries, &[], "inputs");
        let written_joints: Vec<&str> = match &joints_node.kind {
            NodeKind::Table(t) => t.iter().map(|(k, _)| k.name.as_ref()).collect(),
            _ => vec![],
        };
        let mut inputs: Vec<Input> = Vec::new();
        for (key, inode) in entries {
            let path = join("inputs", &key.name);
            let owner = format!("input `{}`", key.name);
            self.check_name(key, &path, "input");
            let Some(fields) = self.table(inode, &path) else {
                continue;
            };
            self.check_keys(fields, &["kind", "joint"], &path);
            let kind = self.kind(fields, inode, &path, &["angle", "slide"], &owner);
            let jnode = self.required(fields, "joint", inode, &path);
            let jname = jnode.and_then(|n| self.string(n, &join(&path, "joint")));
            let (Some((kind, knode)), Some(jname), Some(jnode)) = (kind, jname, jnode) else {
                continue;
            };
            let kind = if kind == "angle" {
                InputKind::Angle
            } else {
                InputKind::Slide
            };
            let Some(ji) = joints.iter().position(|(j, _)| j.name() == jname) else {
                // A joint that was written but failed validation has its own
                // error already.
                if !written_joints.contains(&jname) {
                    let loc = self.loc(jnode, &join(&path, "joint"));
                    self.error(
                        loc,
                        format!("{owner} drives joint `{jname}`, which does not exist"),
                        Some(format!(
                            "joints are: {}",
                            joints
                                .iter()
                                .map(|(j, _)| j.name())
                                .collect::<Vec<_>>()
                                .join(", ")
                        )),
                    );
                }
                continue;
            };
            let joint = &joints[ji].0;
            if let Some(help) = joint.refuses(kind) {
                let loc = self.loc(knode, &join(&path, "kind"));
                self.error_notes(
                    loc,
                    format!(
                        "{owner} is of kind `{}` but joint `{jname}` is {}",
                        kind.name(),
                        joint.kind_name()
                    ),
                    vec![Note {
                        location: self.loc(joints[ji].1, &join("joints", jname)),
                        message: format!("joint `{jname}` is defined here"),
                    }],
                    Some(help),
                );
                continue;
            }
            if joint.markers().iter().all(|m| bodies[m.body].fixed) {
                let loc = self.loc(jnode, &join(&path, "joint"));
                self.error(
                    loc,
                    format!("{owner} drives joint `{jname}`, which joins two fixed bodies"),
                    Some("drive a joint of a mobile body".into()),
                );
                continue;
            }
            // A cylindrical joint takes an angle and a slide; every other
            // joint one input.
            if let Some(other) = inputs
                .iter()
                .find(|i| i.joint == ji && (i.kind == kind || !joint.takes_both()))
            {
                let loc = self.loc(jnode, &join(&path, "joint"));
                self.error(
                    loc,
                    format!(
                        "{owner} drives joint `{jname}`, already driven by input `{}`",
                        other.name
                    ),
                    None,
                );
                continue;
            }
            inputs.push(Input {
                name: key.name.to_string(),
                kind,
                joint: ji,
            });
        }
        inputs
    }

    fn sweep(
        &mut self,
        node: &Node,
        inputs: &[Input],
        written_inputs: &[&str],
        bodies: &[Body<impl MarkerLike>],
    ) -> Option<Sweep> {
        let fields = self.table(node, "sweep")?;
        self.check_keys(
            fields,
            &["input", "from", "to", "inputs", "steps", "trace"],
            "sweep",
        );
        let steps = match self.required(fields, "steps", node, "sweep") {
            Some(n) => match n.kind {
                NodeKind::Int(i) if (1..=MAX_STEPS).contains(&i) => Some(i as usize),
                _ => {
                    let loc = self.loc(n, "sweep.steps");
                    // An unbounded count would make the sweep's frames an
                    // allocation that cannot succeed.
                    self.error(
                        loc,
                        format!("`sweep.steps` must be a whole number from 1 to {MAX_STEPS}"),
                        None,
                    );
                    None
                }
            },
            None => None,
        };
        let mut trace = Vec::new();
        if let Some(t) = Self::get(fields, "trace") {
            match &t.kind {
                NodeKind::Array(items) => {
                    for (i, item) in items.iter().enumerate() {
                        let w = Written {
                            node: item,
                            path: &|| format!("sweep.trace[{i}]"),
                        };
                        if let Some(id) = self.marker_ref(&w, bodies, "sweep trace") {
                            trace.push(id);
                        }
                    }
                }
                other => {
                    let loc = self.loc(t, "sweep.trace");
                    self.error(
                        loc,
                        format!(
                            "`sweep.trace` must be an array of \"body.marker\", found {}",
                            other.type_name()
                        ),
                        None,
                    );
                }
            }
        }
        let swept = match Self::get(fields, "inputs") {
            Some(many) => {
                // Both forms at once would leave it unclear which range wins.
                if let Some((k, _)) = fields
                    .iter()
                    .find(|(k, _)| ["input", "from", "to"].contains(&k.name.as_ref()))
                {
                    let loc = self.key_loc(k, &join("sweep", &k.name));
                    self.error(
                        loc,
                        format!("`sweep.{}` cannot stand beside `sweep.inputs`", k.name),
                        Some(
                            "sweep one input with input/from/to, or several with inputs = { name = [from, to], ... }"
                                .into(),
                        ),
                    );
                    return None;
                }
                self.swept_many(many, inputs, written_inputs)?
            }
            None => {
                let inode = self.required(fields, "input", node, "sweep");
                let input = inode.and_then(|n| self.string(n, "sweep.input").map(|s| (s, n)));
                let from = self
                    .required(fields, "from", node, "sweep")
                    .and_then(|n| self.number(n, "sweep.from"));
                let to = self
                    .required(fields, "to", node, "sweep")
                    .and_then(|n| self.number(n, "sweep.to"));
                let (name, inode) = input?;
                let index = self.swept_input(name, inode, "sweep.input", inputs, written_inputs)?;
                vec![Swept {
                    input: index,
                    from: from?,
                    to: to?,
                }]
            }
        };
        Some(Sweep {
            inputs: swept,
            steps: steps?,
            trace,
        })
    }

    /// `sweep.inputs = { name = [from, to], ... }`: several inputs moved
    /// together.
    fn swept_many(&mut self, node: &Node, inputs: &[Input], written_inputs: &[&str]) -> Option<Vec<Swept>> {
        let entries = self.table(node, "sweep.inputs")?;
        self.check_keys(entries, &[], "sweep.inputs");
        if entries.is_empty() {
            let loc = self.loc(node, "sweep.inputs");
            self.error(
                loc,
                "`sweep.inputs` names no input".into(),
                Some("write inputs = { name = [from, to], ... }".into()),
            );
            return None;
        }
        let mut out = Vec::new();
        let mut ok = true;
        for (key, range) in entries {
            let path = join("sweep.inputs", &key.name);
            let key_node = Node {
                at: key.at,
                kind: NodeKind::Str(key.name.clone()),
            };
            let index = self.swept_input(&key.name, &key_node, &path, inputs, written_inputs);
            let ends = match &range.kind {
                NodeKind::Array(items) if items.len() == 2 => {
                    let from = self.number(&items[0], &format!("{path}[0]"));
                    let to = self.number(&items[1], &format!("{path}[1]"));
                    from.zip(to)
                }
                other => {
                    let loc = self.loc(range, &path);
                    self.error(
                        loc,
                        format!("`{path}` must be [from, to], found {}", other.type_name()),
                        None,
                    );
                    None
                }
            };
            match (index, ends) {
                (Some(input), Some((from, to))) => out.push(Swept { input, from, to }),
                _ => ok = false,
            }
        }
        ok.then_some(out)
    }

    /// The index of the input a sweep names.
    fn swept_input(
        &mut self,
        name: &str,
        node: &Node,
        path: &str,
        inputs: &[Input],
        written_inputs: &[&str],
    ) -> Option<usize> {
        if let Some(index) = inputs.iter().position(|i| i.name == name) {
            return Some(index);
        }
        // An input that was written but failed validation has its own
        // error already.
        if written_inputs.contains(&name) {
            return None;
        }
        let loc = self.loc(node, path);
        let names: Vec<_> = inputs.iter().map(|i| i.name.as_str()).collect();
        self.error(
            loc,
            format!("the sweep drives input `{name}`, which does not exist"),
            Some(if names.is_empty() {
                "declare it under [inputs]".into()
            } else {
                format!("inputs are: {}", names.join(", "))
            }),
        );
        None
    }
}

/// What the input rules need of a joint of either dimension.
pub(super) trait JointLike {
    /// Its name.
    fn name(&self) -> &str;
    /// Its kind's name in files.
    fn kind_name(&self) -> &'static str;
    /// Its two markers.
    fn markers(&self) -> [MarkerId; 2];
    /// `None` when an input of `kind` can drive it, else what to do.
    fn refuses(&self, kind: InputKind) -> Option<String>;
    /// Whether an angle and a slide input may drive it together.
    fn takes_both(&self) -> bool {
        false
    }
}

fn join(path: &str, key: &str) -> String {
    if path.is_empty() {
        key.to_string()
    } else {
        format!("{path}.{key}")
    }
}

/// A table's path as errors name it: `` `joints.A` ``, or "the file" for
/// the top level.
fn display_path(path: &str) -> String {
    if path.is_empty() {
        "the file".into()
    } else {
        format!("`{path}`")
    }
}
