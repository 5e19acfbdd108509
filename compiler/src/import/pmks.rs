//! Pyslvs's PMKS mechanism expressions, imported as dofplan mechanism files.
//!
//! Pyslvs (a planar linkage tool) stores a mechanism as one expression:
//!
//! ```text
//! M[J[R, color[Green], P[0, 0], L[ground, L1]], J[R, P[10, 30], L[L1, L2]], …]
//! ```
//!
//! Each `J[...]` is a point, named `P0`, `P1`, … in order as Pyslvs names
//! them: its type, `R` (revolute), `P` (prismatic) or `RP` (a pin in a
//! slot); for `P` and `RP` the slot's direction `A[degrees]`; an optional
//! `color[...]` (ignored); its drawn position `P[x, y]`; and the links
//! `L[...]` it is on. `ground` is the fixed frame. For a `P` or `RP` point
//! the first link carries the slot and the others are pinned in it (`P`:
//! they slide without turning relative to the slot's link; `RP`: they may
//! also turn). Input pairs `(base, drive)` go beside the expression:
//! `(b, d)` turns the link that carries both points about point `b`, and
//! `(b, b)` slides the `P` or `RP` point `b` along its slot.
//!
//! [`import_pmks`] writes the dofplan mechanism (see
//! `docs/guide/import.md`):
//!
//! - `ground` is a fixed body; every other link a body of the same name.
//! - Every point is a marker named after it (`P3`) on every link it lists,
//!   at its drawn position.
//! - An `R` point on k links is k − 1 revolute joints, each between the
//!   point's hub (`ground` if it lists it, else its first link) and one of
//!   the others: `P3` for a point on two links, `P3_L2`, `P3_L4` (named
//!   after the other link) for more.
//! - A `P` point is a prismatic joint `P3` from the slot link's marker
//!   (with `dir` at `A` degrees) to the pinned link. Several pinned links
//!   slide as one: the first has the prismatic joint `P3_L2`, each other
//!   one a revolute joint `P3_L4` to it and an `offset` constraint
//!   `P3_L4_angle` that keeps it from turning.
//! - An `RP` point becomes a slider block, a body `P3_block` added because
//!   dofplan has no pin-in-slot joint: a prismatic joint `P3` from the
//!   slot link to the block and a revolute joint `P3_L2` from the block to
//!   each pinned link.
//! - A point on one link is a point of that link; if it is not on ground it
//!   is traced (`sweep.trace`).
//! - An input pair `(b, d)` is an `angle` input `Pb_Pd` on the revolute
//!   joint at `b` that turns the link both points are on, written with the
//!   other link first, so that a positive value turns the link
//!   counter-clockwise as Pyslvs's angle does. `(b, b)` is a `slide` input
//!   `Pb_slide` on the point's prismatic joint. dofplan counts inputs from
//!   the drawn pose: Pyslvs's absolute angle of `b→d` is the drawn angle
//!   (written in the file's header) plus the input.
//! - The sweep runs the first input over a full turn, or over its assembly
//!   range when it cannot turn fully (a slide: its assembly range).
//!
//! Names and numbers in errors point into the expression (`file:line:col`).
//! The text written is loaded before it is returned, so it always loads.

mod layout;
mod write;

use crate::model::source::Span;
use crate::model::{Diagnostic, Format, Location, Mechanism, ModelError, Note, SourceFile};

/// The type of a point (Pyslvs calls points joints).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum JointType {
    /// `R`: a revolute joint, every link it lists turns about it.
    R,
    /// `P`: a prismatic joint, the links after the first slide along the
    /// first one's slot without turning relative to it.
    P,
    /// `RP`: a pin in a slot, the links after the first slide along the
    /// first one's slot and may turn.
    RP,
}

impl JointType {
    /// As written in an expression.
    pub fn name(self) -> &'static str {
        match self {
            JointType::R => "R",
            JointType::P => "P",
            JointType::RP => "RP",
        }
    }
}

/// One `J[...]` of an expression.
#[derive(Clone, Debug)]
pub struct Point {
    /// Its index: Pyslvs names it `P{index}`.
    pub index: usize,
    /// Its type.
    pub kind: JointType,
    /// The slot's direction in degrees from the x axis (`A[...]`), for `P`
    /// and `RP` points.
    pub angle: Option<f64>,
    /// The drawn position (`P[x, y]`).
    pub at: [f64; 2],
    /// The links it is on, as written, with where each is written; for a
    /// `P` or `RP` point the first carries the slot.
    pub links: Vec<(String, Span)>,
    /// Where the whole `J[...]` is written.
    pub span: Span,
}

impl Point {
    /// Pyslvs's name of the point, which the imported marker keeps.
    pub fn name(&self) -> String {
        format!("P{}", self.index)
    }

    /// Whether it lists link `name`.
    pub fn on(&self, name: &str) -> bool {
        self.links.iter().any(|(n, _)| n == name)
    }
}

/// An input pair `(base, drive)`: turn the link that carries both points
/// about `base`, or slide point `base` when `drive == base`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct InputPair {
    /// The point the link turns about (or the slider).
    pub base: usize,
    /// Another point of the turned link (or `base` again).
    pub drive: usize,
    /// Where it is written, if it was read from the expression's text.
    pub span: Option<Span>,
}

/// A parsed expression.
#[derive(Clone, Debug)]
pub struct Expression {
    /// The text it was read from (errors point into it).
    pub file: SourceFile,
    /// The points, in order.
    pub points: Vec<Point>,
    /// Where the `M[...]` is written.
    pub span: Span,
    /// The input pairs written after the expression, if any were.
    pub inputs: Option<Vec<InputPair>>,
}

/// What [`import_pmks`] made of an expression.
#[derive(Clone, Debug)]
pub struct Imported {
    /// The mechanism file (TOML), with a header saying where it came from
    /// and how the names map.
    pub toml: String,
    /// The same file, loaded.
    pub mechanism: Mechanism,
    /// What the user should know that is not an error (no inputs, no plan
    /// yet), one sentence each; also written in the file's header.
    pub notes: Vec<String>,
}

/// Parses an expression, `M[...]`, optionally followed by its input pairs
/// in Pyslvs's tuple form: `((0, 1),)`, `((0, 1), (0, 2))`, `[(0, 1)]` or
/// one pair `(0, 1)`, with or without a comma between the two. White space
/// and Pyslvs's comments (`# …` to the end of the line, `#[ … #]`) may be
/// anywhere between items. `file_name` is used in errors.
pub fn parse(file_name: &str, text: &str) -> Result<Expression, ModelError> {
    let mut p = Parser {
        text,
        pos: 0,
        file: SourceFile {
            name: file_name.to_string(),
            text: text.into(),
        },
    };
    let (points, span) = p.expression()?;
    p.eat(',')?;
    p.blank()?;
    let inputs = if p.at_end() { None } else { Some(p.pairs()?) };
    p.blank()?;
    if !p.at_end() {
        return Err(p.unexpected(
            "expected the end of the text after the input pairs".into(),
            Some("the file holds one expression `M[...]`, optionally followed by its input pairs".into()),
        ));
    }
    Ok(Expression {
        file: p.file,
        points,
        span,
        inputs,
    })
}

/// Imports an expression: parses `text` (see [`parse`]), lays the points
/// out as bodies, markers and joints, and writes and loads the dofplan
/// mechanism named `name`. `inputs`, when given, replace the input pairs
/// written after the expression. Errors point into `text` (named
/// `file_name`): malformed syntax, an unknown joint type, a point with no
/// links, no `ground`, a link joined to nothing, an input pair that does
/// not exist or that drives nothing dofplan can express.
pub fn import_pmks(
    file_name: &str,
    text: &str,
    inputs: Option<&[(usize, usize)]>,
    name: &str,
) -> Result<Imported, ModelError> {
    let expr = parse(file_name, text)?;
    let pairs: Vec<InputPair> = match inputs {
        Some(given) => (given.iter())
            .map(|&(base, drive)| InputPair {
                base,
                drive,
                span: None,
            })
            .collect(),
        None => expr.inputs.clone().unwrap_or_default(),
    };
    let layout = layout::build(&expr, &pairs)?;
    let name = if name.trim().is_empty() { "imported" } else { name };
    // The sweep's range comes from the mechanism's own assembly ranges, so
    // the file is written once without a sweep, loaded and planned.
    let draft = write::toml(&expr, &layout, name, None, &[]);
    let (sweep, notes) = write::sweep(&load(&expr, name, &draft)?, &layout);
    let toml = write::toml(&expr, &layout, name, sweep.as_ref(), &notes);
    let mechanism = load(&expr, name, &toml)?;
    Ok(Imported {
        toml,
        mechanism,
        notes,
    })
}

/// [`import_pmks`]'s mechanism file only.
pub fn pmks_to_toml(
    file_name: &str,
    text: &str,
    inputs: Option<&[(usize, usize)]>,
    name: &str,
) -> Result<String, ModelError> {
    import_pmks(file_name, text, inputs, name).map(|i| i.toml)
}

/// Loads the file written. The layout checks everything a file of its
/// making could fail on, so an error here is the importer's bug: it is
/// still an error, never a panic, pointing at the expression.
fn load(expr: &Expression, name: &str, toml: &str) -> Result<Mechanism, ModelError> {
    crate::load_str(&format!("{name}.toml"), toml, Format::Toml).map_err(|e| {
        error(
            &expr.file,
            expr.span.clone(),
            format!("the mechanism imported from this expression does not load: {e}"),
            Some("this is a bug of `dofplan import`: please report it with the expression".into()),
        )
    })
}

/// One error at `span` of `file`.
fn error(file: &SourceFile, span: Span, message: String, help: Option<String>) -> ModelError {
    error_with(file, span, message, Vec::new(), help)
}

/// One error at `span` of `file`, with other places involved.
fn error_with(
    file: &SourceFile,
    span: Span,
    message: String,
    notes: Vec<(Span, String)>,
    help: Option<String>,
) -> ModelError {
    ModelError {
        diagnostics: vec![Diagnostic {
            file: file.clone(),
            location: Location::Span(span),
            message,
            notes: (notes.into_iter())
                .map(|(s, message)| Note {
                    location: Location::Span(s),
                    message,
                })
                .collect(),
            help,
        }],
    }
}

/// The help of a syntax error.
const SYNTAX: &str = "an expression is `M[J[TYPE, A[degrees], color[...], P[x, y], L[link, ...]], ...]` (`A[...]` for `P` and `RP` points only, `color[...]` optional), then optionally its input pairs, `((0, 1),)`";

/// A recursive-descent reader of the expression's text, by byte offset.
struct Parser<'t> {
    text: &'t str,
    pos: usize,
    file: SourceFile,
}

/// The items of one `J[...]` after its type, as they are read.
#[derive(Default)]
struct Items {
    angle: Option<(f64, Span)>,
    at: Option<([f64; 2], Span)>,
    links: Option<(Vec<(String, Span)>, Span)>,
    color: Option<Span>,
}

impl<'t> Parser<'t> {
    fn rest(&self) -> &'t str {
        &self.text[self.pos..]
    }

    fn peek(&self) -> Option<char> {
        self.rest().chars().next()
    }

    fn at_end(&self) -> bool {
        self.pos >= self.text.len()
    }

    /// Skips white space and comments, as Pyslvs's grammar ignores them.
    fn blank(&mut self) -> Result<(), ModelError> {
        loop {
            let rest = self.rest();
            self.pos += rest.len() - rest.trim_start().len();
            let rest = self.rest();
            if let Some(body) = rest.strip_prefix("#[") {
                let Some(end) = body.find("#]") else {
                    return Err(error(
                        &self.file,
                        self.pos..self.pos + 2,
                        "this comment `#[` is never closed with `#]`".into(),
                        Some(
                            "end the comment with `#]`, or write `# ` comments, which end with their line"
                                .into(),
                        ),
                    ));
                };
                self.pos += 2 + end + 2;
            } else if rest.starts_with('#') {
                self.pos += rest.find('\n').unwrap_or(rest.len());
            } else {
                return Ok(());
            }
        }
    }

    /// Takes `c` if it comes next (after blanks).
    fn eat(&mut self, c: char) -> Result<bool, ModelError> {
        self.blank()?;
        let here = self.peek() == Some(c);
        if here {
            self.pos += c.len_utf8();
        }
        Ok(here)
    }

    /// Takes `c`, or says what was `expected` instead.
    fn expect(&mut self, c: char, expected: &str) -> Result<(), ModelError> {
        if self.eat(c)? {
            Ok(())
        } else {
            Err(self.unexpected(format!("expected {expected}"), None))
        }
    }

    /// What comes next, for an error: its span and how to quote it.
    fn found(&self) -> (Span, String) {
        let rest = self.rest();
        let Some(c) = rest.chars().next() else {
            return (self.pos..self.pos, "the end of the text".into());
        };
        let word = |c: char| c.is_alphanumeric() || c == '_';
        let len = if word(c) {
            // A word is quoted whole, up to a screenful.
            let mut end = 0;
            for (n, (i, ch)) in rest.char_indices().enumerate() {
                if !word(ch) || n == 24 {
                    break;
                }
                end = i + ch.len_utf8();
            }
            end
        } else {
            c.len_utf8()
        };
        (self.pos..self.pos + len, format!("`{}`", &rest[..len]))
    }

    /// "expected …, found …" at what comes next; the help is the syntax
    /// unless a more precise one is given.
    fn unexpected(&self, expected: String, help: Option<String>) -> ModelError {
        let (span, found) = self.found();
        let help = help.unwrap_or_else(|| SYNTAX.into());
        error(&self.file, span, format!("{expected}, found {found}"), Some(help))
    }

    /// A name: letters, digits and `_`, not starting with a digit (Pyslvs's
    /// CNAME), or `None` (nothing taken) if none comes next.
    fn word(&mut self) -> Result<Option<(Span, &'t str)>, ModelError> {
        self.blank()?;
        let rest = self.rest();
        let len = rest
            .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
            .unwrap_or(rest.len());
        if len == 0 || rest.as_bytes()[0].is_ascii_digit() {
            return Ok(None);
        }
        let span = self.pos..self.pos + len;
        self.pos += len;
        Ok(Some((span, &rest[..len])))
    }

    /// A number as Pyslvs writes them: `12`, `-3.5`, `.5`, `1e-3`.
    fn number(&mut self, what: &str) -> Result<(f64, Span), ModelError> {
        self.blank()?;
        let b = self.rest().as_bytes();
        let digits = |mut i: usize| {
            while b.get(i).is_some_and(u8::is_ascii_digit) {
                i += 1;
            }
            i
        };
        let start = usize::from(matches!(b.first(), Some(b'+' | b'-')));
        let mut end = digits(start);
        let mut mantissa = end > start;
        if b.get(end) == Some(&b'.') {
            let after = digits(end + 1);
            mantissa |= after > end + 1;
            end = after;
        }
        if !mantissa {
            return Err(self.unexpected(format!("expected {what} (a number)"), None));
        }
        if matches!(b.get(end), Some(b'e' | b'E')) {
            let sign = end + 1 + usize::from(matches!(b.get(end + 1), Some(b'+' | b'-')));
            let exponent = digits(sign);
            if exponent > sign {
                end = exponent;
            }
        }
        let span = self.pos..self.pos + end;
        let text = &self.rest()[..end];
        self.pos += end;
        match text.parse::<f64>() {
            Ok(x) if x.is_finite() => Ok((x, span)),
            _ => Err(error(
                &self.file,
                span,
                format!("{what} `{text}` is not a finite number"),
                Some("coordinates and angles are finite numbers, e.g. `12.5` or `-3e2`".into()),
            )),
        }
    }

    /// A point's index in an input pair.
    fn index(&mut self, what: &str) -> Result<usize, ModelError> {
        self.blank()?;
        let len = self.rest().bytes().take_while(u8::is_ascii_digit).count();
        if len == 0 {
            return Err(self.unexpected(format!("expected {what} (a point's index)"), None));
        }
        let span = self.pos..self.pos + len;
        let text = &self.rest()[..len];
        self.pos += len;
        text.parse().map_err(|_| {
            error(
                &self.file,
                span,
                format!("{what} `{text}` is not a point's index: it is far too large"),
                Some("points are numbered from 0 in the order they are written".into()),
            )
        })
    }

    /// `M[ point, point, … ]`.
    fn expression(&mut self) -> Result<(Vec<Point>, Span), ModelError> {
        self.blank()?;
        let start = self.pos;
        if !matches!(self.word()?, Some((_, "M"))) {
            self.pos = start;
            return Err(self.unexpected(
                "expected a Pyslvs mechanism expression `M[...]`".into(),
                Some("the expression is `M[` then its points `J[...]` separated by commas, then `]`, e.g. `M[J[R, P[0, 0], L[ground, L1]], J[R, P[10, 30], L[L1]]]`".into()),
            ));
        }
        self.expect('[', "`[` after `M`")?;
        let mut points = Vec::new();
        loop {
            if self.eat(']')? {
                break;
            }
            self.blank()?;
            if self.at_end() {
                return Err(error_with(
                    &self.file,
                    self.pos..self.pos,
                    "the expression ends before its closing `]`".into(),
                    vec![(start..start + 1, "the expression starts here".into())],
                    Some("close the `M[` with `]` after its last point".into()),
                ));
            }
            points.push(self.point(points.len())?);
            if self.eat(',')? {
                continue;
            }
            if self.eat(']')? {
                break;
            }
            return Err(self.unexpected(
                format!("expected `,` or `]` after point P{}", points.len() - 1),
                None,
            ));
        }
        Ok((points, start..self.pos))
    }

    /// `J[TYPE, item, …]`: point `index`.
    fn point(&mut self, index: usize) -> Result<Point, ModelError> {
        let start = self.pos;
        if !matches!(self.word()?, Some((_, "J"))) {
            self.pos = start;
            return Err(self.unexpected(
                format!("expected point P{index}, `J[...]`"),
                Some("a point is `J[type, P[x, y], L[links]]`, e.g. `J[R, P[0, 0], L[ground, L1]]`".into()),
            ));
        }
        self.expect('[', &format!("`[` after `J` (point P{index})"))?;
        let kind = self.joint_type(index)?;
        let mut items = Items::default();
        loop {
            if self.eat(']')? {
                break;
            }
            if !self.eat(',')? {
                return Err(self.unexpected(format!("expected `,` or `]` in point P{index}"), None));
            }
            if self.eat(']')? {
                break;
            }
            self.item(index, &mut items)?;
        }
        self.finish(index, kind, items, start..self.pos)
    }

    /// `R`, `P` or `RP`.
    fn joint_type(&mut self, index: usize) -> Result<JointType, ModelError> {
        let help = Some("a point's type is `R` (revolute), `P` (prismatic) or `RP` (a pin in a slot), e.g. `J[R, P[0, 0], L[ground, L1]]`".to_string());
        let Some((span, word)) = self.word()? else {
            return Err(self.unexpected(format!("expected the joint type of point P{index}"), help));
        };
        match word {
            "R" => Ok(JointType::R),
            "P" => Ok(JointType::P),
            "RP" => Ok(JointType::RP),
            _ => Err(error(
                &self.file,
                span,
                format!("unknown joint type `{word}` of point P{index}"),
                help,
            )),
        }
    }

    /// One item of point `index`: `A[...]`, `color[...]`, `P[...]` or `L[...]`.
    fn item(&mut self, index: usize, items: &mut Items) -> Result<(), ModelError> {
        let what = format!("an item of point P{index}: `A[angle]`, `color[...]`, `P[x, y]` or `L[links]`");
        let Some((name_span, name)) = self.word()? else {
            return Err(self.unexpected(format!("expected {what}"), None));
        };
        let first = match name {
            "A" => items.angle.as_ref().map(|a| a.1.clone()),
            "color" => items.color.clone(),
            "P" => items.at.as_ref().map(|a| a.1.clone()),
            "L" => items.links.as_ref().map(|l| l.1.clone()),
            _ => {
                return Err(error(
                    &self.file,
                    name_span,
                    format!("unknown item `{name}[...]` in point P{index}"),
                    Some(format!("{what} (a point's type comes first)")),
                ))
            }
        };
        if let Some(first) = first {
            return Err(error_with(
                &self.file,
                name_span,
                format!("point P{index} has a second `{name}[...]`"),
                vec![(first, "the first one".into())],
                Some(format!("keep one `{name}[...]`")),
            ));
        }
        let start = name_span.start;
        self.expect('[', &format!("`[` after `{name}`"))?;
        match name {
            "A" => {
                let (a, _) = self.number("the slide direction in degrees")?;
                self.expect(']', "`]` after the slide direction")?;
                items.angle = Some((a, start..self.pos));
            }
            "color" => {
                self.skip_color()?;
                items.color = Some(start..self.pos);
            }
            "P" => {
                let (x, _) = self.number("the x coordinate")?;
                self.expect(',', "`,` between the x and y coordinates")?;
                let (y, _) = self.number("the y coordinate")?;
                self.expect(']', "`]` after the y coordinate")?;
                items.at = Some(([x, y], start..self.pos));
            }
            _ => {
                let links = self.links(index)?;
                items.links = Some((links, start..self.pos));
            }
        }
        Ok(())
    }

    /// The rest of `color[...]`: a name (`Green`, `Dark-Red`) or an RGB
    /// triple `(255, 0, 0)`, and its `]`. The colour is not imported.
    fn skip_color(&mut self) -> Result<(), ModelError> {
        let help =
            Some("a colour is a name or an RGB triple: `color[Green]`, `color[(255, 0, 0)]`".to_string());
        self.blank()?;
        if self.eat('(')? {
            for k in 0..3 {
                if k > 0 {
                    self.expect(',', "`,` between the colour's red, green and blue")?;
                }
                self.index("the colour's red, green or blue")?;
            }
            self.expect(')', "`)` after the colour's blue")?;
        } else {
            let rest = self.rest();
            let len = rest
                .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == '-'))
                .unwrap_or(rest.len());
            if len == 0 {
                return Err(self.unexpected("expected a colour in `color[...]`".into(), help));
            }
            self.pos += len;
        }
        if self.eat(']')? {
            Ok(())
        } else {
            Err(self.unexpected("expected `]` after the colour".into(), help))
        }
    }

    /// The names of `L[...]` up to its `]`.
    fn links(&mut self, index: usize) -> Result<Vec<(String, Span)>, ModelError> {
        let mut links: Vec<(String, Span)> = Vec::new();
        loop {
            if self.eat(']')? {
                return Ok(links);
            }
            let Some((span, name)) = self.word()? else {
                return Err(self.unexpected(
                    format!("expected a link name or `]` in the links of point P{index}"),
                    Some("a link's name is letters, digits and `_`, not starting with a digit; `ground` is the fixed frame".into()),
                ));
            };
            if let Some((_, first)) = links.iter().find(|(n, _)| n == name) {
                return Err(error_with(
                    &self.file,
                    span,
                    format!("point P{index} lists link {name} twice"),
                    vec![(first.clone(), "first listed here".into())],
                    Some(format!("list {name} once")),
                ));
            }
            links.push((name.to_string(), span));
            if !self.eat(',')? && self.peek() != Some(']') {
                return Err(self.unexpected(
                    format!("expected `,` or `]` in the links of point P{index}"),
                    None,
                ));
            }
        }
    }

    /// Point `index` from its items, or what it lacks.
    fn finish(&self, index: usize, kind: JointType, items: Items, span: Span) -> Result<Point, ModelError> {
        let lacks = |message: String, help: &str| error(&self.file, span.clone(), message, Some(help.into()));
        let Some((at, _)) = items.at else {
            return Err(lacks(
                format!("point P{index} has no position `P[x, y]`"),
                "write where the point is drawn, e.g. `J[R, P[0, 0], L[ground, L1]]`",
            ));
        };
        let Some((links, links_span)) = items.links else {
            return Err(lacks(
                format!("point P{index} has no links `L[...]`"),
                "list the links the point is on, e.g. `L[ground, L1]`",
            ));
        };
        if links.is_empty() {
            return Err(error(
                &self.file,
                links_span,
                format!("point P{index} is on no link"),
                Some("a point belongs to one link or more (`ground` is the fixed frame): list them in `L[...]`, or remove the point".into()),
            ));
        }
        match (kind, &items.angle) {
            (JointType::R, Some((_, a))) => Err(error(
                &self.file,
                a.clone(),
                format!("point P{index} is revolute (R) and has a slide direction `A[...]`"),
                Some("remove `A[...]`, or make the point `P` (prismatic) or `RP` (a pin in a slot)".into()),
            )),
            (JointType::P | JointType::RP, None) => Err(lacks(
                format!(
                    "point P{index} is a {} joint without its slide direction `A[degrees]`",
                    kind.name()
                ),
                "write the slot's direction after the type, e.g. `J[P, A[0], P[10, 0], L[ground, L2]]` (the first link carries the slot)",
            )),
            _ => Ok(Point {
                index,
                kind,
                angle: items.angle.map(|a| a.0),
                at,
                links,
                span,
            }),
        }
    }

    /// The input pairs: `((0, 1), (0, 2))`, `((0, 1),)`, `[(0, 1)]`, `()`
    /// or one pair `(0, 1)`.
    fn pairs(&mut self) -> Result<Vec<InputPair>, ModelError> {
        let expected = "expected the input pairs, e.g. `((0, 1),)`";
        let close = match self.peek() {
            Some('(') => ')',
            Some('[') => ']',
            _ => return Err(self.unexpected(
                expected.into(),
                Some(
                    "after the expression may come its input pairs `(base, drive)` in Pyslvs's tuple form"
                        .into(),
                ),
            )),
        };
        // One pair alone, `(0, 1)`, has a number after its bracket.
        let open = self.pos;
        self.pos += 1;
        self.blank()?;
        let single = self.peek().is_some_and(|c| c.is_ascii_digit());
        if single {
            self.pos = open;
            return Ok(vec![self.pair()?]);
        }
        let mut pairs = Vec::new();
        loop {
            if self.eat(close)? {
                return Ok(pairs);
            }
            pairs.push(self.pair()?);
            if !self.eat(',')? && self.peek() != Some(close) {
                return Err(self.unexpected(format!("expected `,` or `{close}` after an input pair"), None));
            }
        }
    }

    /// `(base, drive)`.
    fn pair(&mut self) -> Result<InputPair, ModelError> {
        self.blank()?;
        let start = self.pos;
        let close = match self.peek() {
            Some('(') => ')',
            Some('[') => ']',
            _ => return Err(self.unexpected("expected an input pair `(base, drive)`".into(), None)),
        };
        self.pos += 1;
        let base = self.index("the base point")?;
        self.expect(',', "`,` between the base point and the driving point")?;
        let drive = self.index("the driving point")?;
        self.eat(',')?;
        self.expect(close, &format!("`{close}` after an input pair's two points"))?;
        Ok(InputPair {
            base,
            drive,
            span: Some(start..self.pos),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `file:line:col` of the first `needle` in `text` (of its end for an
    /// empty needle), as errors print it.
    fn at(text: &str, needle: &str) -> String {
        let offset = if needle.is_empty() {
            text.len()
        } else {
            text.find(needle)
                .unwrap_or_else(|| panic!("`{needle}` is in the text"))
        };
        let (line, col) = SourceFile {
            name: "t.pmks".into(),
            text: text.into(),
        }
        .line_col(offset);
        format!("t.pmks:{line}:{col}")
    }

    /// The error of importing `text`, checked: its first line is `message`
    /// at the first `needle`, and it says what to do.
    fn fails(text: &str, needle: &str, message: &str) -> String {
        let e = import_pmks("t.pmks", text, None, "t")
            .expect_err(text)
            .to_string();
        assert_eq!(
            e.lines().next(),
            Some(format!("{}: error: {message}", at(text, needle)).as_str()),
            "{text}"
        );
        assert!(e.contains("\n  help: "), "{e}");
        e
    }

    fn toml(text: &str) -> String {
        pmks_to_toml("t.pmks", text, None, "t").unwrap_or_else(|e| panic!("{e}"))
    }

    const FOUR_BAR: &str = "M[J[R, P[0, 0], L[ground, a]], J[R, P[1, 2], L[a, b]], J[R, P[6, 5], L[b, c]], J[R, P[8, 0], L[ground, c]], J[R, P[3, 6], L[b]]]";

    #[test]
    fn reads_every_form_pyslvs_writes() {
        let text = "# a comment\nM[\n  J[R, color[Green], P[0.0, 0.0], L[ground, L1]], #[ a comment\n over lines #]\n  J[RP, A[30.0], color[(255, 0, 0)], P[.5, 1.], L[L1, L2,]],\n  J[P,A[-3e1],P[+4,-2.5E-1],L[ground,L2]],\n]\n, ((0, 1), (1, 1),)";
        let e = parse("t.pmks", text).unwrap();
        assert_eq!(e.points.len(), 3);
        let p = &e.points[1];
        assert_eq!(
            (p.index, p.kind, p.angle, p.at),
            (1, JointType::RP, Some(30.0), [0.5, 1.0])
        );
        let links: Vec<&str> = p.links.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(links, ["L1", "L2"]);
        assert_eq!(
            &text[p.span.clone()],
            "J[RP, A[30.0], color[(255, 0, 0)], P[.5, 1.], L[L1, L2,]]"
        );
        assert_eq!(
            (e.points[2].kind, e.points[2].angle, e.points[2].at),
            (JointType::P, Some(-30.0), [4.0, -0.25])
        );
        let pairs: Vec<(usize, usize)> = e.inputs.unwrap().iter().map(|p| (p.base, p.drive)).collect();
        assert_eq!(pairs, [(0, 1), (1, 1)]);
        assert!(text[e.span].starts_with("M[") && text.contains("]\n,"));
    }

    #[test]
    fn input_pairs_in_every_tuple_form() {
        let expr = "M[J[R, P[0, 0], L[ground, a]]]";
        for (after, want) in [
            ("", None),
            (" ((0, 1),)", Some(vec![(0, 1)])),
            ("\n((0, 1), (0, 2))", Some(vec![(0, 1), (0, 2)])),
            (", ((0, 1),)", Some(vec![(0, 1)])),
            (" [(0, 1), [2, 3]]", Some(vec![(0, 1), (2, 3)])),
            (" (4, 5)", Some(vec![(4, 5)])),
            (" (4, 5,)", Some(vec![(4, 5)])),
            (" ()", Some(vec![])),
            (" # none\n", None),
        ] {
            let e = parse("t.pmks", &format!("{expr}{after}")).unwrap_or_else(|e| panic!("{after}: {e}"));
            let got = e
                .inputs
                .map(|v| v.iter().map(|p| (p.base, p.drive)).collect::<Vec<_>>());
            assert_eq!(got, want, "{after}");
        }
    }

    #[test]
    fn malformed_text_is_an_error_at_its_line_and_column() {
        let cases = [
            (
                "x",
                "x",
                "expected a Pyslvs mechanism expression `M[...]`, found `x`",
            ),
            (
                "",
                "",
                "expected a Pyslvs mechanism expression `M[...]`, found the end of the text",
            ),
            ("M(", "(", "expected `[` after `M`, found `(`"),
            (
                "M[\n  J[R, P[0, 0], L[ground, a]],\n",
                "",
                "the expression ends before its closing `]`",
            ),
            ("M[K[R]]", "K", "expected point P0, `J[...]`, found `K`"),
            (
                "M[J[R P[0, 0]]]",
                "P[",
                "expected `,` or `]` in point P0, found `P`",
            ),
            (
                "M[J[Q, P[0, 0], L[ground]]]",
                "Q",
                "unknown joint type `Q` of point P0",
            ),
            (
                "M[J[, P[0, 0]]]",
                ",",
                "expected the joint type of point P0, found `,`",
            ),
            (
                "M[J[R, B[1], P[0, 0], L[ground]]]",
                "B",
                "unknown item `B[...]` in point P0",
            ),
            (
                "M[J[R, P[x, 0], L[ground]]]",
                "x,",
                "expected the x coordinate (a number), found `x`",
            ),
            (
                "M[J[R, P[1e999, 0], L[ground]]]",
                "1e999",
                "the x coordinate `1e999` is not a finite number",
            ),
            (
                "M[J[R, P[0; 0], L[ground]]]",
                ";",
                "expected `,` between the x and y coordinates, found `;`",
            ),
            (
                "M[J[R, P[0, 0], L[ground, 2a]]]",
                "2a",
                "expected a link name or `]` in the links of point P0, found `2a`",
            ),
            (
                "M[J[R, P[0, 0], L[ground a]]]",
                "a]]]",
                "expected `,` or `]` in the links of point P0, found `a`",
            ),
            (
                "M[J[R, color[Green, P[0, 0], L[ground]]]",
                ", P",
                "expected `]` after the colour, found `,`",
            ),
            (
                "M[J[R, color[(1, 2), P[0, 0], L[ground]]]",
                "), P",
                "expected `,` between the colour's red, green and blue, found `)`",
            ),
            (
                "M[J[R, color[], P[0, 0], L[ground]]]",
                "], P",
                "expected a colour in `color[...]`, found `]`",
            ),
            (
                "#[ open\nM[]",
                "#[",
                "this comment `#[` is never closed with `#]`",
            ),
            (
                "M[J[R, P[0, 0], L[ground]]] X",
                "X",
                "expected the input pairs, e.g. `((0, 1),)`, found `X`",
            ),
            (
                "M[J[R, P[0, 0], L[ground]]] ((0 1),)",
                "1)",
                "expected `,` between the base point and the driving point, found `1`",
            ),
            (
                "M[J[R, P[0, 0], L[ground]]] ((0, -1),)",
                "-1",
                "expected the driving point (a point's index), found `-`",
            ),
            (
                "M[J[R, P[0, 0], L[ground]]] ((0, 99999999999999999999999),)",
                "999",
                "the driving point `99999999999999999999999` is not a point's index: it is far too large",
            ),
            (
                "M[J[R, P[0, 0], L[ground]]] ((0, 1)) x",
                "x",
                "expected the end of the text after the input pairs, found `x`",
            ),
            (
                "M[J[R, P[0, 0], L[ground]]] ((0, 1) (0, 2))",
                "(0, 2",
                "expected `,` or `)` after an input pair, found `(`",
            ),
        ];
        for (text, needle, message) in cases {
            fails(text, needle, message);
        }
    }

    #[test]
    fn a_point_that_lacks_or_repeats_an_item_is_an_error() {
        let cases = [
            ("M[J[R, L[ground]]]", "J[", "point P0 has no position `P[x, y]`"),
            ("M[J[R, P[0, 0]]]", "J[", "point P0 has no links `L[...]`"),
            (
                "M[J[R, P[0, 0], L[ground, a]], J[R, P[1, 1], L[]]]",
                "L[]",
                "point P1 is on no link",
            ),
            (
                "M[J[R, P[0, 0], L[ground, a, ground]]]",
                "ground]",
                "point P0 lists link ground twice",
            ),
            (
                "M[J[R, P[0, 0], P[1, 1], L[ground]]]",
                "P[1",
                "point P0 has a second `P[...]`",
            ),
            (
                "M[J[P, P[0, 0], L[ground, a]]]",
                "J[",
                "point P0 is a P joint without its slide direction `A[degrees]`",
            ),
            (
                "M[J[RP, P[0, 0], L[ground, a]]]",
                "J[",
                "point P0 is a RP joint without its slide direction `A[degrees]`",
            ),
            (
                "M[J[R, A[30], P[0, 0], L[ground, a]]]",
                "A[",
                "point P0 is revolute (R) and has a slide direction `A[...]`",
            ),
        ];
        for (text, needle, message) in cases {
            fails(text, needle, message);
        }
        // A second item is shown beside the first.
        let e = fails(
            "M[J[R, L[a], P[0, 0], L[ground]]]",
            "L[ground",
            "point P0 has a second `L[...]`",
        );
        assert!(
            e.contains(&format!(
                "{}: note: the first one",
                at("M[J[R, L[a], P[0, 0], L[ground]]]", "L[a]")
            )),
            "{e}"
        );
    }

    #[test]
    fn what_dofplan_cannot_stand_or_drive_is_an_error_naming_it() {
        let four = |pairs: &str| format!("{FOUR_BAR}\n{pairs}");
        let cases = [
            ("M[J[R, P[0, 0], L[a, b]]]".to_string(), "M[", "no point is on `ground`: the mechanism has no fixed frame"),
            (
                "M[J[R, P[0, 0], L[ground, a]], J[R, P[1, 1], L[a, b]], J[R, P[2, 2], L[z]]]".into(),
                "z]",
                "link z is joined to nothing: it is only on P2, with no other link",
            ),
            (four("((0, 9),)"), "(0, 9)", "input pair (0, 9): there is no point P9 (the expression has 5 points, P0 to P4)"),
            (four("((0, 2),)"), "(0, 2)", "input pair (0, 2): P0 (on ground, a) and P2 (on b, c) share no link, so the pair turns nothing"),
            (four("((0, 3),)"), "(0, 3)", "input pair (0, 3): P0 and P3 are both on ground, which never turns"),
            (four("((1, 1),)"), "(1, 1)", "input pair (1, 1) slides point P1 along its slot, but P1 is revolute (R)"),
            (four("((4, 1),)"), "(4, 1)", "input pair (4, 1) turns b about P4, but P4 joins b to no other link, so nothing turns it there"),
            (four("((0, 1), (0, 1))"), "(0, 1))", "input pairs (0, 1) and (0, 1) both drive joint P0"),
            (
                "M[J[R, P[0, 0], L[ground, a]], J[R, P[1, 0], L[a, b]], J[R, P[2, 0], L[a, b, c]], J[R, P[5, 0], L[ground, c]]]\n((1, 2),)".into(),
                "(1, 2)",
                "input pair (1, 2): P1 and P2 are both on links a and b, so which one turns is ambiguous",
            ),
            (
                "M[J[R, P[0, 0], L[ground, a]], J[P, A[0], P[3, 0], L[ground, a]], J[R, P[0, 1], L[a]]]\n((1, 2),)".into(),
                "(1, 2)",
                "input pair (1, 2) turns a about P1, but P1 is a prismatic (P) joint, where no link turns",
            ),
            (
                "M[J[R, P[0, 0], L[ground, a]], J[RP, A[0], P[3, 0], L[a]]]\n((1, 1),)".into(),
                "(1, 1)",
                "input pair (1, 1): nothing slides in the slot of P1, which is on a only",
            ),
        ];
        for (text, needle, message) in &cases {
            fails(text, needle, message);
        }
        // Pairs given to the function have no place in the text: the error
        // is at the base point, or at the expression when there is none.
        for (pair, needle, message) in [
            (
                (1, 3),
                "J[R, P[1, 2]",
                "input pair (1, 3): P1 (on a, b) and P3 (on ground, c) share no link",
            ),
            ((7, 0), "M[", "input pair (7, 0): there is no point P7"),
        ] {
            let e = import_pmks("t.pmks", FOUR_BAR, Some(&[pair]), "t")
                .unwrap_err()
                .to_string();
            assert!(
                e.starts_with(&format!("{}: error: {message}", at(FOUR_BAR, needle))),
                "{e}"
            );
        }
    }

    #[test]
    fn points_become_markers_and_named_joints() {
        // A point on three links, a P point with two pinned links, an RP
        // point with two, and a link whose name a block would take.
        let text = "M[J[R, P[0, 0], L[L1, ground, L2]], J[R, P[1, 1], L[L1, L3]], J[P, A[90], P[5, 0], L[ground, L3, L4]], J[RP, A[0], P[0, 4], L[L2, L5, P3_block]], J[R, P[2, 2], L[L4, L5]], J[R, P[3, 3], L[P3_block, L4]]]";
        let t = toml(text);
        for piece in [
            "[bodies.ground]\nfixed = true\nmarkers = { P0 = [0.0, 0.0], P2 = { at = [5.0, 0.0], dir = [0.0, 1.0] } }",
            "[bodies.L3]\nmarkers = { P1 = [1.0, 1.0], P2 = { at = [5.0, 0.0], dir = [0.0, 1.0] } }",
            "[bodies.P3_block_2]\nmarkers = { P3 = [0.0, 4.0] }",
            // Ground is the hub of P0, though listed second.
            "[joints.P0_L1]\nkind = \"revolute\"\nmarkers = [\"ground.P0\", \"L1.P0\"]",
            "[joints.P0_L2]\nkind = \"revolute\"\nmarkers = [\"ground.P0\", \"L2.P0\"]",
            "[joints.P2_L3]\nkind = \"prismatic\"\nmarkers = [\"ground.P2\", \"L3.P2\"]",
            "[joints.P2_L4]\nkind = \"revolute\"\nmarkers = [\"L3.P2\", \"L4.P2\"]",
            "[constraints.P2_L4_angle]\nkind = \"offset\"\nmarkers = [\"L3.P2\", \"L4.P2\"]",
            "[joints.P3]\nkind = \"prismatic\"\nmarkers = [\"L2.P3\", \"P3_block_2.P3\"]",
            "[joints.P3_L5]\nkind = \"revolute\"\nmarkers = [\"P3_block_2.P3\", \"L5.P3\"]",
            "[joints.P3_P3_block]\nkind = \"revolute\"\nmarkers = [\"P3_block_2.P3\", \"P3_block.P3\"]",
            "# P3 RP A[0] at (0.0, 4.0) on L2, L5, P3_block: slider block P3_block_2 slides in L2's slot (prismatic joint P3); on it turns L5 (revolute joint P3_L5), P3_block (revolute joint P3_P3_block)",
            "# Note: the expression has no input pairs",
        ] {
            assert!(t.contains(piece), "{piece}\n---\n{t}");
        }
        assert!(!t.contains("[sweep]"), "no input, no sweep");
    }

    #[test]
    fn an_input_turns_its_link_counter_clockwise_relative_to_the_other() {
        // (1, 0): the crank turns about its coupler pin, relative to the
        // coupler, though the crank is P1's first link.
        let t = toml(&format!("{FOUR_BAR}\n((1, 0),)"));
        assert!(
            t.contains("[joints.P1]\nkind = \"revolute\"\nmarkers = [\"b.P1\", \"a.P1\"]"),
            "{t}"
        );
        assert!(t.contains("# (1, 0) is input P1_P0: angle of joint P1: a turns counter-clockwise relative to b, from the drawn pose; Pyslvs measures P1→P0 from the x axis (-116.565051° as drawn): the two agree while b does not turn"), "{t}");
        // A slot's link turned about its RP point turns with the block.
        let text = "M[J[R, P[0, 0], L[ground, a]], J[R, P[10, 0], L[a, b]], J[RP, A[0], P[20, 0], L[b, ground]]]\n((2, 1),)";
        let t = toml(text);
        assert!(
            t.contains("[joints.P2_ground]\nkind = \"revolute\"\nmarkers = [\"ground.P2\", \"P2_block.P2\"]"),
            "{t}"
        );
        assert!(t.contains("angle of joint P2_ground: P2_block (and b with it) turns counter-clockwise relative to ground"), "{t}");
        assert!(t.contains("Pyslvs's angle of P2→P1 is 180° + P2_P1"), "{t}");
    }

    #[test]
    fn the_sweep_is_a_full_turn_or_the_assembly_range() {
        let t = toml(&format!("{FOUR_BAR}\n((0, 1),)"));
        assert!(t.contains("# Input P0_P1 turns fully: the sweep is a full turn.\n[sweep]\ninput = \"P0_P1\"\nfrom = 0.0\nto = 360.0\nsteps = 361\ntrace = [\"b.P4\"]"), "{t}");
        // The rocker of the same four-bar rocks: its range, ends inside.
        let m = import_pmks("t.pmks", &format!("{FOUR_BAR}\n((3, 2),)"), None, "t")
            .unwrap()
            .mechanism;
        let s = m.sweep.unwrap();
        let (from, to) = (s.primary().from, s.primary().to);
        assert!(
            -180.0 < from && from < 0.0 && 0.0 < to && to < 180.0,
            "{from}..{to}"
        );
        // A slide: a block on ground pinned to a link of a rocker.
        let text = "M[J[RP, A[0], P[0, 0], L[ground, b]], J[R, P[50, 0], L[ground, a]], J[R, P[25, 27], L[a, b]]]\n((0, 0),)";
        let imported = import_pmks("t.pmks", text, None, "t").unwrap();
        assert!(imported
            .toml
            .contains("[inputs.P0_slide]\nkind = \"slide\"\njoint = \"P0\""));
        let s = imported.mechanism.sweep.unwrap();
        let reach = (25f64.powi(2) + 27f64.powi(2)).sqrt() * 2.0;
        let (from, to) = (s.primary().from, s.primary().to);
        // Rounded inward to hundredths (the mechanism is about 60 long).
        assert!(50.0 - reach < from && from < 50.0 - reach + 0.02, "{from}");
        assert!(50.0 + reach - 0.02 < to && to < 50.0 + reach, "{to}");
    }

    #[test]
    fn no_text_makes_it_panic() {
        // Every prefix of a valid expression, and every character replaced
        // by ones that matter to the grammar (or are not ASCII).
        let text = "M[J[R, P[0, 0], L[ground, a]], J[R, P[1, 1], L[a, b]], J[RP, A[30], color[(1, 2, 3)], P[3, 0], L[ground, b]]] ((0, 1),)";
        let mut results = 0;
        for (i, _) in text.char_indices() {
            results += usize::from(import_pmks("t.pmks", &text[..i], None, "t").is_ok());
            for c in [']', '[', ',', '(', '#', 'é', '9', '-', ' '] {
                let mut mutated = text.to_string();
                mutated.replace_range(i..i + 1, &c.to_string());
                results += usize::from(import_pmks("t.pmks", &mutated, None, "t").is_ok());
            }
        }
        assert!(import_pmks("t.pmks", text, None, "t").is_ok());
        assert!(results > 0);
        // Input pairs given may be anything.
        for pair in [(0, 0), (2, 2), (usize::MAX, 0), (1, 2), (2, 1)] {
            let _ = import_pmks("t.pmks", text, Some(&[pair]), "t");
        }
    }
}
