//! The syntax tree a mechanism file is read into before validation: TOML
//! and JSON both become [`Node`]s, so validation is written once.
//!
//! TOML nodes carry byte spans (through `toml::Spanned`), which turn into
//! `file:line:column` in errors. JSON nodes carry none — `serde_json` keeps
//! no positions past syntax errors — so errors about JSON files name the
//! path inside the document (`joints.A.markers[1]`) instead.

use std::borrow::Cow;
use std::fmt;
use std::marker::PhantomData;
use std::ops::Range;

use serde::de::{DeserializeSeed, Deserializer, MapAccess, SeqAccess, Visitor};

mod toml;

/// A byte range in the source text.
pub type Span = Range<usize>;

/// Where a value or key is written, in 8 bytes rather than the 24 of an
/// `Option<Span>`: a 50 MB file has millions of them. Positions past 4 GiB
/// are not kept (such a text is far over the size a file may have).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct At {
    start: u32,
    end: u32,
}

impl At {
    /// No position (JSON values, and texts past 4 GiB).
    pub const NONE: At = At {
        start: u32::MAX,
        end: u32::MAX,
    };

    /// The position of a byte range.
    pub fn new(span: Span) -> At {
        match (u32::try_from(span.start), u32::try_from(span.end)) {
            (Ok(start), Ok(end)) if end != u32::MAX => At { start, end },
            _ => At::NONE,
        }
    }

    /// A position, if known.
    pub fn of(span: Option<Span>) -> At {
        span.map_or(At::NONE, At::new)
    }

    /// The byte range, if known.
    pub fn span(self) -> Option<Span> {
        (self != At::NONE).then_some(self.start as usize..self.end as usize)
    }
}

/// A value of the file with the position it came from. Strings and keys
/// borrow the text (`'s`) where they are written without escapes.
#[derive(Clone, Debug, PartialEq)]
pub struct Node<'s> {
    /// Where the value is written (TOML only).
    pub at: At,
    /// The value.
    pub kind: NodeKind<'s>,
}

impl Node<'_> {
    /// Where the value is written (TOML only).
    pub fn span(&self) -> Option<Span> {
        self.at.span()
    }
}

/// A table key with the position it came from.
#[derive(Clone, Debug, PartialEq)]
pub struct Key<'s> {
    /// The key text.
    pub name: Cow<'s, str>,
    /// Where the key is written (TOML only).
    pub at: At,
}

impl Key<'_> {
    /// Where the key is written (TOML only).
    pub fn span(&self) -> Option<Span> {
        self.at.span()
    }
}

/// The value of a [`Node`].
#[derive(Clone, Debug, PartialEq)]
pub enum NodeKind<'s> {
    /// A table (TOML) or object (JSON), in document order.
    Table(Vec<(Key<'s>, Node<'s>)>),
    /// An array.
    Array(Vec<Node<'s>>),
    /// A string.
    Str(Cow<'s, str>),
    /// An integer.
    Int(i64),
    /// A float (may be NaN or infinite: TOML allows `nan` and `inf`, and
    /// validation rejects them with a position).
    Float(f64),
    /// A boolean.
    Bool(bool),
    /// Anything else (a TOML date): rejected by validation.
    Other(&'static str),
}

impl NodeKind<'_> {
    /// The name of the value's type for "expected …, found …" errors.
    pub fn type_name(&self) -> &'static str {
        match self {
            NodeKind::Table(_) => "a table",
            NodeKind::Array(_) => "an array",
            NodeKind::Str(_) => "a string",
            NodeKind::Int(_) => "an integer",
            NodeKind::Float(_) => "a float",
            NodeKind::Bool(_) => "a boolean",
            NodeKind::Other(what) => what,
        }
    }
}

/// A syntax error with its position when the parser reports one.
#[derive(Debug)]
pub struct SyntaxError {
    /// What is wrong.
    pub message: String,
    /// Where (byte range), when known.
    pub span: Option<Span>,
}

/// Reads TOML text into a [`Node`] tree with spans.
///
/// A well-formed file is read in one pass over its tokens, straight into
/// the tree (`toml::read`). Anything that pass does not take (a syntax
/// error, a date, an array of tables...) is read again by the `toml`
/// crate, whose document and messages are the reference: the tree is the
/// same either way, and so is every error.
pub fn parse_toml(text: &str) -> Result<Node<'_>, SyntaxError> {
    match read_toml(text) {
        Some(node) => Ok(node),
        None => parse_toml_by_serde(text),
    }
}

/// The one-pass reading of [`parse_toml`], or `None` for a text it leaves
/// to the `toml` crate.
pub(crate) fn read_toml(text: &str) -> Option<Node<'_>> {
    toml::read(text)
}

/// Reads TOML text through the `toml` crate's document and serde.
pub(crate) fn parse_toml_by_serde(text: &str) -> Result<Node<'_>, SyntaxError> {
    let de = ::toml::de::Deserializer::parse(text).map_err(|e| SyntaxError {
        message: e.message().to_string(),
        span: e.span(),
    })?;
    let kind = de
        .deserialize_any(KindVisitor::<true>(PhantomData))
        .map_err(|e| SyntaxError {
            message: e.message().to_string(),
            span: e.span(),
        })?;
    Ok(Node {
        at: At::new(0..text.len()),
        kind,
    })
}

/// Reads JSON text into a [`Node`] tree (no spans; a syntax error gets
/// one, from serde_json's line and column).
pub fn parse_json(text: &str) -> Result<Node<'_>, SyntaxError> {
    let mut de = serde_json::Deserializer::from_str(text);
    let kind = (&mut de)
        .deserialize_any(KindVisitor::<false>(PhantomData))
        .and_then(|k| de.end().map(|_| k))
        .map_err(|e| SyntaxError {
            message: strip_position(&e.to_string()),
            span: Some(json_error_span(text, &e)),
        })?;
    Ok(Node { at: At::NONE, kind })
}

/// The byte range a serde_json error points at.
///
/// serde_json's column is the number of bytes read on the error's line, so
/// it is the 1-based byte column of the last byte read: the offending
/// character for a syntax error (`[1 2]` → column 4, the `2`), but for an
/// unexpected end of input the last character *before* the end (`[1, 2` →
/// column 5; an empty last line → column 0). The position of the error is
/// where the missing text belongs, one past it. Converting to a byte offset
/// here also turns bytes into characters when the line is not ASCII.
fn json_error_span(text: &str, e: &serde_json::Error) -> Span {
    let line_start = text
        .split_inclusive('\n')
        .take(e.line().saturating_sub(1))
        .map(str::len)
        .sum::<usize>();
    let mut at = match e.classify() {
        serde_json::error::Category::Eof => line_start + e.column(),
        _ => line_start + e.column().saturating_sub(1),
    }
    .min(text.len());
    while !text.is_char_boundary(at) {
        at -= 1;
    }
    let len = text[at..].chars().next().map_or(0, char::len_utf8);
    at..at + len
}

/// serde_json appends " at line L column C" to its messages; the position is
/// reported separately.
fn strip_position(message: &str) -> String {
    match message.rfind(" at line ") {
        Some(i) => message[..i].to_string(),
        None => message.to_string(),
    }
}

/// Deserializes one value. `SPANNED` is true for TOML, whose deserializer
/// hands out spans through `toml::Spanned`.
struct NodeSeed<const SPANNED: bool>;

impl<'de, const SPANNED: bool> DeserializeSeed<'de> for NodeSeed<SPANNED> {
    type Value = Node<'de>;

    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<Node<'de>, D::Error> {
        if SPANNED {
            let spanned = <::toml::Spanned<Kind<'de, SPANNED>> as serde::Deserialize>::deserialize(d)?;
            let span = spanned.span();
            Ok(Node {
                at: At::new(span),
                kind: spanned.into_inner().0,
            })
        } else {
            Ok(Node {
                at: At::NONE,
                kind: d.deserialize_any(KindVisitor::<SPANNED>(PhantomData))?,
            })
        }
    }
}

/// A key, spanned in TOML.
struct KeySeed<const SPANNED: bool>;

impl<'de, const SPANNED: bool> DeserializeSeed<'de> for KeySeed<SPANNED> {
    type Value = Key<'de>;

    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<Key<'de>, D::Error> {
        if SPANNED {
            let spanned = <::toml::Spanned<Text<'de>> as serde::Deserialize>::deserialize(d)?;
            let span = spanned.span();
            Ok(Key {
                name: spanned.into_inner().0,
                at: At::new(span),
            })
        } else {
            Ok(Key {
                name: <Text<'de> as serde::Deserialize>::deserialize(d)?.0,
                at: At::NONE,
            })
        }
    }
}

/// A string that borrows the text when it can.
struct Text<'de>(Cow<'de, str>);

impl<'de> serde::Deserialize<'de> for Text<'de> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct TextVisitor;
        impl<'de> Visitor<'de> for TextVisitor {
            type Value = Text<'de>;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a string")
            }
            fn visit_borrowed_str<E>(self, v: &'de str) -> Result<Text<'de>, E> {
                Ok(Text(Cow::Borrowed(v)))
            }
            fn visit_str<E>(self, v: &str) -> Result<Text<'de>, E> {
                Ok(Text(Cow::Owned(v.to_string())))
            }
            fn visit_string<E>(self, v: String) -> Result<Text<'de>, E> {
                Ok(Text(Cow::Owned(v)))
            }
        }
        d.deserialize_str(TextVisitor)
    }
}

struct Kind<'de, const SPANNED: bool>(NodeKind<'de>);

impl<'de, const SPANNED: bool> serde::Deserialize<'de> for Kind<'de, SPANNED> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(KindVisitor::<SPANNED>(PhantomData)).map(Kind)
    }
}

struct KindVisitor<const SPANNED: bool>(PhantomData<()>);

impl<'de, const SPANNED: bool> Visitor<'de> for KindVisitor<SPANNED> {
    type Value = NodeKind<'de>;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a mechanism value")
    }

    fn visit_bool<E>(self, v: bool) -> Result<NodeKind<'de>, E> {
        Ok(NodeKind::Bool(v))
    }

    fn visit_i64<E>(self, v: i64) -> Result<NodeKind<'de>, E> {
        Ok(NodeKind::Int(v))
    }

    fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<NodeKind<'de>, E> {
        match i64::try_from(v) {
            Ok(i) => Ok(NodeKind::Int(i)),
            Err(_) => Ok(NodeKind::Float(v as f64)),
        }
    }

    fn visit_f64<E>(self, v: f64) -> Result<NodeKind<'de>, E> {
        Ok(NodeKind::Float(v))
    }

    fn visit_borrowed_str<E>(self, v: &'de str) -> Result<NodeKind<'de>, E> {
        Ok(NodeKind::Str(Cow::Borrowed(v)))
    }

    fn visit_str<E>(self, v: &str) -> Result<NodeKind<'de>, E> {
        Ok(NodeKind::Str(Cow::Owned(v.to_string())))
    }

    fn visit_string<E>(self, v: String) -> Result<NodeKind<'de>, E> {
        Ok(NodeKind::Str(Cow::Owned(v)))
    }

    fn visit_unit<E>(self) -> Result<NodeKind<'de>, E> {
        Ok(NodeKind::Other("null"))
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<NodeKind<'de>, A::Error> {
        let mut items = Vec::new();
        while let Some(item) = seq.next_element_seed(NodeSeed::<SPANNED>)? {
            items.push(item);
        }
        Ok(NodeKind::Array(items))
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<NodeKind<'de>, A::Error> {
        let mut entries = Vec::new();
        while let Some(key) = map.next_key_seed(KeySeed::<SPANNED>)? {
            let value = map.next_value_seed(NodeSeed::<SPANNED>)?;
            entries.push((key, value));
        }
        Ok(NodeKind::Table(entries))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn toml_nodes_carry_spans_in_document_order() {
        let text = "b = 1\na = [1.5, 2]\n[t]\nx = \"y\"\n";
        let node = parse_toml(text).unwrap();
        let NodeKind::Table(entries) = node.kind else {
            panic!("not a table")
        };
        let names: Vec<_> = entries.iter().map(|(k, _)| k.name.as_ref()).collect();
        assert_eq!(names, ["b", "a", "t"]);
        let span = entries[1].1.span().unwrap();
        assert_eq!(&text[span], "[1.5, 2]");
    }

    /// The character a JSON syntax error points at, and where it is.
    fn json_error_at(text: &str) -> (String, usize) {
        let span = parse_json(text).unwrap_err().span.expect("a span");
        (text[span.clone()].to_string(), span.start)
    }

    #[test]
    fn json_errors_point_at_the_offending_character() {
        // serde_json reports these at its columns 4, 9 (the `}` after a
        // trailing comma), 1 of line 3, and 11 — bytes, the `é` is two.
        assert_eq!(json_error_at("[1 2]"), ("2".into(), 3));
        assert_eq!(json_error_at("{\"a\": 1,}"), ("}".into(), 8));
        assert_eq!(json_error_at("[1,\n2,\n]"), ("]".into(), 7));
        assert_eq!(json_error_at("{\"\u{e9}\": tru}"), ("}".into(), 10));
    }

    #[test]
    fn json_errors_at_the_end_point_past_the_last_character() {
        // serde_json's columns 5, 0 (of line 2) and 1: the last character
        // read, or none at all.
        assert_eq!(json_error_at("[1, 2"), (String::new(), 5));
        assert_eq!(json_error_at("{\"a\":\n"), (String::new(), 6));
        assert_eq!(json_error_at("{"), (String::new(), 1));
    }
}
