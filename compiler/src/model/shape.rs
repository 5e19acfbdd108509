//! A look at a file's arrays before it is parsed: an array longer than any
//! the format has is refused at its first value too many, before a parser
//! builds it.
//!
//! The TOML parser builds its whole document (every token, every value)
//! before handing it over, and the syntax tree holds every value again: a
//! 50 MB array of numbers in one marker took 45 s and 3 GB only to be told
//! a marker has two coordinates. This scan walks the file's tokens once,
//! keeping only the key path of the arrays open at the point, and counts
//! their values. The parsers still judge everything else: the scan reports
//! nothing but an array too long, and stops quietly where the text is not
//! valid (the parser then says why).

use std::borrow::Cow;

/// A byte range in the text, as `source::Span`: the one-pass reader in
/// `source` takes its limits from here, so this module names nothing of it.
type Span = std::ops::Range<usize>;

/// The most coordinates a marker's point or direction has (`[x, y, z]`).
pub const MAX_COORDINATES: usize = 3;

/// The most values of any other array but `sweep.trace`: a joint's or a
/// constraint's pair of markers, a swept input's `[from, to]`, and points.
pub const MAX_VALUES: usize = 3;

/// An array longer than the format allows where it is written.
#[derive(Debug)]
pub struct TooLong {
    /// The first value too many.
    pub span: Span,
    /// What is wrong, naming the marker or the key path.
    pub message: String,
    /// What to do.
    pub help: String,
}

/// Whether the array at `path` holds a marker's coordinates (`[x, y]`, or
/// the table form's `at`, `dir` and the spatial `x`, `z`).
fn is_point(path: &[Cow<str>]) -> bool {
    match path {
        [bodies, _, markers, _] => bodies == "bodies" && markers == "markers",
        [bodies, _, markers, _, field] => {
            bodies == "bodies" && markers == "markers" && matches!(field.as_ref(), "at" | "dir" | "x" | "z")
        }
        _ => false,
    }
}

/// The most values the array at `path` may have (`None`: no limit).
fn limit(path: &[Cow<str>]) -> Option<usize> {
    match path {
        // Every marker of the file may be traced.
        [sweep, trace] if sweep == "sweep" && trace == "trace" => None,
        _ if is_point(path) => Some(MAX_COORDINATES),
        _ => Some(MAX_VALUES),
    }
}

/// The error for the array at `path` having a value (at `span`) more than
/// its [`limit`].
fn refusal(path: &[Cow<str>], span: Span) -> TooLong {
    let key = path.join(".");
    if is_point(path) {
        TooLong {
            span,
            message: format!(
                "marker `{}.{}` has more than {MAX_COORDINATES} coordinates (`{key}`): this is the first one too many",
                path[1], path[3]
            ),
            help: "a point is [x, y], or [x, y, z] in a spatial mechanism (`dimension = 3`)".into(),
        }
    } else {
        let what = if key.is_empty() {
            "the top-level array".to_string()
        } else {
            format!("`{key}`")
        };
        TooLong {
            span,
            message: format!("{what} has more than {MAX_VALUES} values: this is the first one too many"),
            help: format!(
                "no array of a mechanism file but `sweep.trace` has more than {MAX_VALUES} values \
                 (a point is [x, y] or [x, y, z], a joint's markers a pair [\"body.marker\", \"body.marker\"], \
                 a swept input [from, to]): is the key misspelt, or is this the right file?"
            ),
        }
    }
}

/// An open array: its key path's length, its limit and values so far.
struct Open {
    /// The path's length when it opened (the path is restored to it when
    /// it closes, and the path up to it is the array's).
    depth: usize,
    limit: Option<usize>,
    count: usize,
    /// Whether the next token that starts a value is a new value (after
    /// `[` or `,`), rather than part of the one being read.
    expecting: bool,
}

impl Open {
    fn new(path: &[Cow<str>]) -> Open {
        Open {
            depth: path.len(),
            limit: limit(path),
            count: 0,
            expecting: true,
        }
    }

    /// A value starts at `span` if one is expected: counted, refused past
    /// the limit. `path` starts with the array's.
    fn value(&mut self, path: &[Cow<str>], span: Span) -> Result<(), TooLong> {
        if !self.expecting {
            return Ok(());
        }
        self.expecting = false;
        self.count += 1;
        match self.limit {
            Some(most) if self.count > most => Err(refusal(&path[..self.depth], span)),
            _ => Ok(()),
        }
    }
}

/// An open container of either format: an array, or a table whose key
/// path ends at `depth`.
enum Frame {
    Array(Open),
    Table { depth: usize },
}

/// The first array of a TOML text longer than the format allows.
pub fn check_toml(text: &str) -> Option<TooLong> {
    walk_toml(text, None, &mut |_, _| false)
}

/// Whether a TOML text says `dimension = 3` at its top level, read off its
/// tokens (up to that key) rather than parsed; given the start of a text
/// (cut after a new line), also whether that holds however the text goes
/// on (the key was read, or a table header ended the top-level keys).
pub fn toml_says_spatial_in(text: &str) -> (bool, bool) {
    let mut spatial = false;
    let mut decided = false;
    // Top-level keys come before the first table header: the walk stops
    // there (a 50 MB file is not read to its end for a key it cannot have).
    walk_toml(text, Some(&mut decided), &mut |path, at| {
        let is_dimension = matches!(path, [key] if key == "dimension");
        if is_dimension {
            // The value is the rest of its line (a comment aside).
            let rest = &text[at..];
            let value = rest[..rest.find(['\n', '#']).unwrap_or(rest.len())].trim();
            spatial = toml_integer(value) == Some(3);
        }
        is_dimension
    });
    (spatial, decided || spatial)
}

/// A TOML integer's value (`+3`, `0x3`, `1_000`), or `None` for anything
/// else.
fn toml_integer(value: &str) -> Option<i64> {
    let digits = value.strip_prefix('+').unwrap_or(value).replace('_', "");
    let (radix, digits) = match digits.get(..2) {
        Some("0x") => (16, &digits[2..]),
        Some("0o") => (8, &digits[2..]),
        Some("0b") => (2, &digits[2..]),
        _ => (10, &digits[..]),
    };
    i64::from_str_radix(digits, radix).ok()
}

/// Walks a TOML text's arrays (see the module's doc), calling `scalar`
/// with the key path and offset of each value at the top level that is not
/// an array or a table; it returns whether to stop. With `top_only`, the
/// walk stops at the first table header, and says so there.
fn walk_toml(
    text: &str,
    top_only: Option<&mut bool>,
    scalar: &mut dyn FnMut(&[Cow<str>], usize) -> bool,
) -> Option<TooLong> {
    use toml_parser::lexer::TokenKind as T;

    let source = toml_parser::Source::new(text);
    // The key path of the value being read: the table header's, then the
    // keys of inline tables and the dotted key before `=`.
    let mut path: Vec<Cow<str>> = Vec::new();
    let mut frames: Vec<Frame> = Vec::new();
    // Reading a key (at a line's start, after `{` or a `,` in an inline
    // table) or a table header, rather than a value.
    let mut in_key = true;
    let mut in_header = false;
    // Where the path starts for the key being read.
    let mut key_base = 0usize;
    for token in source.lex() {
        let span = token.span().start()..token.span().end();
        let starts_value = matches!(
            token.kind(),
            T::Atom
                | T::BasicString
                | T::LiteralString
                | T::MlBasicString
                | T::MlLiteralString
                | T::LeftSquareBracket
                | T::LeftCurlyBracket
        );
        match token.kind() {
            T::Whitespace | T::Comment => {}
            // A new line at the top level: a key or a header next, in the
            // current table. (Inside an array or an inline table, a new
            // line is white space.)
            T::Newline if frames.is_empty() => {
                in_key = true;
                in_header = false;
                path.truncate(key_base);
            }
            T::Newline => {}
            T::Eof => break,
            T::LeftSquareBracket if frames.is_empty() && in_key => {
                if let Some(header) = top_only {
                    *header = true;
                    break;
                }
                // A table header (`[[` for an array of tables): its keys
                // are the table's path.
                in_header = true;
                path.clear();
                key_base = 0;
            }
            T::RightSquareBracket if in_header => {
                // `]` or `]]`: the header's keys are the path from here on.
                key_base = path.len();
            }
            T::Dot if in_key => {}
            T::Atom | T::BasicString | T::LiteralString if in_key => {
                let mut key = Cow::Borrowed("");
                if let Some(raw) = source.get(token) {
                    raw.decode_key(&mut key, &mut ());
                }
                path.push(key);
            }
            T::Equals if in_key && !in_header => in_key = false,
            T::Comma => match frames.last_mut() {
                Some(Frame::Array(open)) => {
                    open.expecting = true;
                    path.truncate(open.depth);
                }
                Some(Frame::Table { depth }) => {
                    path.truncate(*depth);
                    in_key = true;
                }
                None => return None,
            },
            T::RightSquareBracket => match frames.pop() {
                Some(Frame::Array(open)) => path.truncate(open.depth),
                _ => return None,
            },
            T::RightCurlyBracket => match frames.pop() {
                Some(Frame::Table { depth }) => path.truncate(depth),
                _ => return None,
            },
            _ if starts_value && !in_key => {
                if let Some(Frame::Array(open)) = frames.last_mut() {
                    if open.expecting {
                        // An array's values are under its own path, marked
                        // as such.
                        path.truncate(open.depth);
                        if let Err(e) = open.value(&path, span.clone()) {
                            return Some(e);
                        }
                        if matches!(token.kind(), T::LeftSquareBracket | T::LeftCurlyBracket) {
                            path.push("[]".into());
                        }
                    }
                }
                match token.kind() {
                    T::LeftSquareBracket => frames.push(Frame::Array(Open::new(&path))),
                    T::LeftCurlyBracket => {
                        frames.push(Frame::Table { depth: path.len() });
                        in_key = true;
                    }
                    _ if frames.is_empty() && scalar(&path, span.start) => return None,
                    _ => {}
                }
            }
            // Anything else is the parser's to report.
            _ => {}
        }
    }
    None
}

/// The first array of a JSON text longer than the format allows.
pub fn check_json(text: &str) -> Option<TooLong> {
    walk_json(text, &mut |_, _| false)
}

/// Whether a JSON text says `"dimension": 3` at its top level, read off
/// its text (up to that key) rather than parsed.
pub fn json_says_spatial(text: &str) -> bool {
    let mut spatial = false;
    walk_json(text, &mut |path, value| {
        let is_dimension = matches!(path, [key] if key == "dimension");
        if is_dimension {
            spatial = value == "3";
        }
        is_dimension
    });
    spatial
}

/// Walks a JSON text's arrays (see the module's doc), calling `scalar`
/// with the key path and text of each value of the top-level object that
/// is not an array or an object; it returns whether to stop.
fn walk_json(text: &str, scalar: &mut dyn FnMut(&[Cow<str>], &str) -> bool) -> Option<TooLong> {
    let bytes = text.as_bytes();
    let mut path: Vec<Cow<str>> = Vec::new();
    let mut frames: Vec<Frame> = Vec::new();
    // In an object: whether a key is expected next (after `{` or `,`).
    let mut in_key = false;
    let mut i = 0;
    while i < bytes.len() {
        let c = bytes[i];
        let start = i;
        match c {
            b' ' | b'\t' | b'\n' | b'\r' => {
                i += 1;
                continue;
            }
            b'"' => {
                // A string: to its closing quote, past escapes.
                i += 1;
                while i < bytes.len() && bytes[i] != b'"' {
                    i += if bytes[i] == b'\\' { 2 } else { 1 };
                }
                i = (i + 1).min(bytes.len());
                if in_key {
                    let raw = text.get(start + 1..i.saturating_sub(1)).unwrap_or_default();
                    // Escapes are rare in keys; decoded, they would only
                    // pick a message.
                    path.push(Cow::Owned(
                        serde_json::from_str::<String>(&text[start..i]).unwrap_or_else(|_| raw.to_string()),
                    ));
                    in_key = false;
                    continue;
                }
            }
            b':' => {
                i += 1;
                continue;
            }
            b',' => {
                i += 1;
                match frames.last_mut() {
                    Some(Frame::Array(open)) => {
                        open.expecting = true;
                        path.truncate(open.depth);
                    }
                    Some(Frame::Table { depth }) => {
                        path.truncate(*depth);
                        in_key = true;
                    }
                    None => return None,
                }
                continue;
            }
            b']' | b'}' => {
                i += 1;
                match (frames.pop(), c) {
                    (Some(Frame::Array(open)), b']') => path.truncate(open.depth),
                    (Some(Frame::Table { depth }), b'}') => path.truncate(depth),
                    _ => return None,
                }
                in_key = false;
                continue;
            }
            b'[' | b'{' => i += 1,
            _ => {
                // A number, `true`, `false`, `null` (or not JSON at all):
                // to the next delimiter.
                while i < bytes.len()
                    && !matches!(bytes[i], b',' | b']' | b'}' | b':' | b' ' | b'\t' | b'\n' | b'\r')
                {
                    i += 1;
                }
            }
        }
        if in_key {
            // Not a key where one is due: the parser's to report.
            return None;
        }
        // A value starts at `start`.
        if let Some(Frame::Array(open)) = frames.last_mut() {
            if open.expecting {
                path.truncate(open.depth);
                let end = text[start..]
                    .chars()
                    .next()
                    .map_or(start, |ch| start + ch.len_utf8());
                if let Err(e) = open.value(&path, start..end) {
                    return Some(e);
                }
                if matches!(c, b'[' | b'{') {
                    path.push("[]".into());
                }
            }
        }
        match c {
            b'[' => frames.push(Frame::Array(Open::new(&path))),
            b'{' => {
                frames.push(Frame::Table { depth: path.len() });
                in_key = true;
            }
            _ if matches!(frames[..], [Frame::Table { .. }]) && scalar(&path, &text[start..i]) => {
                return None
            }
            _ => {}
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The text at the refused value, and the message.
    fn refused(text: &str, json: bool) -> Option<(String, String)> {
        let t = if json { check_json(text) } else { check_toml(text) }?;
        Some((text[t.span].to_string(), t.message))
    }

    #[test]
    fn every_bundled_mechanism_passes() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        let mut seen = 0;
        let mut dirs = vec![root.join("mechanisms"), root.join("tests/fixtures")];
        while let Some(dir) = dirs.pop() {
            for entry in std::fs::read_dir(&dir).unwrap() {
                let path = entry.unwrap().path();
                if path.is_dir() {
                    dirs.push(path);
                    continue;
                }
                let Ok(text) = std::fs::read_to_string(&path) else {
                    continue;
                };
                let e = path.extension().and_then(|e| e.to_str());
                if e == Some("toml") {
                    assert!(check_toml(&text).is_none(), "{}", path.display());
                    seen += 1;
                } else if e == Some("json") {
                    assert!(check_json(&text).is_none(), "{}", path.display());
                    seen += 1;
                }
            }
        }
        assert!(seen > 20, "{seen} files");
    }

    #[test]
    fn a_fourth_coordinate_is_refused_in_every_form() {
        let cases = [
            "[bodies.b]\nmarkers = { A = [1, 2, 3, 4.5, 6] }\n",
            "[bodies.b]\nmarkers = { A = [0, 0], C = [\n  1,\n  2, # comment\n  3,\n  4.5,\n] }\n",
            "[bodies.b.markers]\nA = [1, 2, 3, 4.5]\n",
            "bodies.b.markers.A = [1, 2, 3, 4.5]\n",
            "[bodies.\"b\"]\nmarkers.A.at = [1, 2, 3, 4.5]\n",
            "bodies = { b = { markers = { A = { dir = [1, 2, 3, 4.5] } } } }\n",
        ];
        for text in cases {
            let (at, message) = refused(text, false).unwrap_or_else(|| panic!("{text}"));
            assert_eq!(at, "4", "{text}");
            assert!(
                message.starts_with("marker `b.") && message.contains("more than 3 coordinates"),
                "{message}"
            );
        }
        let json = r#"{"bodies": {"b": {"markers": {"A": [0, 0], "C": {"at": [1, 2, 3, 4.5]}}}}}"#;
        assert_eq!(
            refused(json, true).map(|r| r.0),
            Some("4".into()),
            "the value's first character"
        );
    }

    #[test]
    fn three_values_and_long_traces_pass() {
        let trace: Vec<String> = (0..100).map(|i| format!("\"b.M{i}\"")).collect();
        let toml = format!(
            "[bodies.b]\nmarkers = {{ A = [1, 2, 3], B = {{ at = [1, 2], dir = [0, 1] }} }}\n\
             [joints.J]\nmarkers = [\"a.b\", \"c.d\", \"e.f\"]\n[sweep]\ntrace = [{}]\n",
            trace.join(", ")
        );
        assert!(refused(&toml, false).is_none());
        let json = format!(
            r#"{{"sweep": {{"trace": [{}]}}, "joints": {{"J": {{"markers": ["a", "b"]}}}}}}"#,
            trace.join(",")
        );
        assert!(refused(&json, true).is_none());
    }

    #[test]
    fn any_other_array_is_refused_past_three_values() {
        let (at, message) = refused(
            "[joints.J]\nmarkers = [\"a.A\", \"b.B\", \"c.C\", \"d.D\"]\n",
            false,
        )
        .unwrap();
        assert_eq!(
            (
                at.as_str(),
                message.starts_with("`joints.J.markers` has more than 3 values")
            ),
            ("\"d.D\"", true)
        );
        let (at, message) = refused("tags = [[1], [2], [3], [4, 5]]", false).unwrap();
        assert_eq!(
            (at.as_str(), message.starts_with("`tags` has more")),
            ("[", true),
            "{message}"
        );
        let (at, _) = refused("x = [[1, 2, 3, 4]]", false).unwrap();
        assert_eq!(at, "4");
        let (at, message) = refused("[1, 2, 3, {\"a\": 1}]", true).unwrap();
        assert_eq!(
            (at.as_str(), message.starts_with("the top-level array")),
            ("{", true),
            "{message}"
        );
        // Strings hold brackets and commas that are not the array's.
        assert!(refused("x = [\"a, b, c, d\", '[1,2,3,4]', \"\"\"\n,,,\"\"\"]", false).is_none());
        assert!(refused(r#"{"x": ["a, \"b, c, d", "[1,2,3,4]"]}"#, true).is_none());
        // A date with a space is one value.
        assert!(refused("x = [1979-05-27 07:32:00Z, 1, 2]", false).is_none());
    }

    #[test]
    fn the_dimension_is_read_off_the_tokens() {
        for (text, spatial) in [
            ("dimension = 3\n", true),
            ("name = \"x\" # [a]\ndimension = +3 # three\n[bodies.b]\n", true),
            ("dimension = 0x3", true),
            ("x = [\n  1,\n]\ndimension = 3", true),
            ("dimension = 3.0\n", false),
            ("dimension = 3e0\n", false),
            ("dimension = 2\n", false),
            ("dimension = \"3\"\n", false),
            ("[a]\ndimension = 3\n", false),
            ("a.dimension = 3\n", false),
            ("a = { dimension = 3 }\n", false),
            ("s = \"\"\"\ndimension = 3\n\"\"\"\n", false),
        ] {
            assert_eq!(toml_says_spatial_in(text).0, spatial, "{text}");
        }
        for (text, spatial) in [
            (r#"{"dimension": 3}"#, true),
            (r#"{"name": "x", "bodies": {"a": [1]}, "dimension": 3}"#, true),
            (r#"{"dimension": 3.0}"#, false),
            (r#"{"dimension": "3"}"#, false),
            (r#"{"a": {"dimension": 3}}"#, false),
            (r#"[{"dimension": 3}]"#, false),
        ] {
            assert_eq!(json_says_spatial(text), spatial, "{text}");
        }
        // Every bundled file: as its parse says.
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../mechanisms");
        for dir in [root.clone(), root.join("spatial")] {
            for entry in std::fs::read_dir(&dir).unwrap() {
                let path = entry.unwrap().path();
                if path.extension().and_then(|e| e.to_str()) != Some("toml") {
                    continue;
                }
                let text = std::fs::read_to_string(&path).unwrap();
                let parsed = crate::model::source::parse_toml(&text).unwrap();
                let crate::model::source::NodeKind::Table(top) = parsed.kind else {
                    panic!()
                };
                let three = top.iter().any(|(k, v)| {
                    k.name == "dimension" && matches!(v.kind, crate::model::source::NodeKind::Int(3))
                });
                assert_eq!(toml_says_spatial_in(&text).0, three, "{}", path.display());
                // Every start of it that decides decides the same.
                for (cut, _) in text.match_indices('\n') {
                    let (spatial, decided) = toml_says_spatial_in(&text[..=cut]);
                    assert!(!decided || spatial == three, "{} cut at {cut}", path.display());
                }
            }
        }
    }

    #[test]
    fn text_that_is_not_valid_is_left_to_the_parser() {
        for text in ["]]]", "x = ]", "[a\nb = [1,,,,,,]", "{", "}", "= [1, 2, 3, 4"] {
            let _ = check_toml(text);
            let _ = check_json(text);
        }
        assert!(refused("{1: [1, 2, 3, 4]}", true).is_none());
    }
}
