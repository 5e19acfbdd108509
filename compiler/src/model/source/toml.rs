//! A well-formed TOML text read in one pass over `toml_parser`'s tokens,
//! straight into the [`Node`] tree.
//!
//! The `toml` crate lexes a whole text into a vector of tokens, turns them
//! into a vector of events, builds its own document from those, and only
//! then hands values to serde: for a 53 MB file that was 1.6 GB and
//! seconds before the first key was looked at. This reader keeps one token
//! of look-ahead and the tables still open.
//!
//! It takes the TOML that mechanism files are written in: tables by
//! `[header]`, dotted keys, arrays (of at most three values, but
//! `sweep.trace`), inline tables on one line, strings, integers, floats and
//! booleans. It builds the tree the `toml` crate's
//! document gives (the same order, the same spans: [`parse_toml`] is
//! checked against it) and applies the same rules on defining a table or
//! key twice. Anything else, and anything wrong, it gives up on (`None`):
//! [`parse_toml`] then reads the text with the `toml` crate, which says what
//! is wrong, or reads what this reader does not take (arrays of tables,
//! dates, newlines in inline tables, keys redefined in the ways TOML
//! allows...). An array too long is refused by `shape` before that.
//!
//! [`parse_toml`]: super::parse_toml

use foldhash::{HashMap, HashSet};
use std::borrow::Cow;

use toml_parser::decoder::ScalarKind;
use toml_parser::lexer::{Lexer, Token, TokenKind as T};
use toml_parser::{ParseError, Source, Span};

use super::{At, Key, Node, NodeKind};

/// Deeper nesting (arrays and inline tables, or keys in a path) is left to
/// the `toml` crate, which refuses it past its own limit.
const MAX_DEPTH: usize = 64;

/// Tables of more entries than this look keys up in a hash map.
const INDEXED: usize = 8;

/// The most values of an array but `sweep.trace`.
const MAX_VALUES: usize = {
    let (a, b) = (
        crate::model::shape::MAX_VALUES,
        crate::model::shape::MAX_COORDINATES,
    );
    if a > b {
        a
    } else {
        b
    }
};

/// Reads a TOML text, or `None` for anything this reader does not take
/// (see the module's doc).
pub fn read(text: &str) -> Option<Node<'_>> {
    let source = Source::new(text);
    let mut reader = Reader {
        source,
        lexer: source.lex(),
        peeked: [None, None],
        eof: None,
        depth: 0,
        long_ok: false,
        tables: Vec::new(),
        arrays: Vec::new(),
    };
    let root = reader.document()?;
    Some(Node {
        at: At::new(0..text.len()),
        kind: root.into_kind(),
    })
}

/// A table being built: one defined by a header or implicitly (by a
/// header's or a dotted key's path). Inline tables are built whole as
/// nodes.
struct Table<'s> {
    entries: Vec<(Key<'s>, Value<'s>)>,
    /// Entry by key, once there are more than [`INDEXED`].
    index: Option<HashMap<Cow<'s, str>, usize>>,
    at: At,
    /// Created by a path, not (yet) defined by a header.
    implicit: bool,
    /// Created or extended by a dotted key.
    dotted: bool,
}

/// A value of a table being built.
enum Value<'s> {
    /// A table that headers and dotted keys may still extend.
    Table(Box<Table<'s>>),
    /// A table a header defined, with no table in it: finished as a node
    /// when the next header starts, as nearly every body's and joint's is
    /// (a 50 MB file has 450,000 of them). A later header may still add a
    /// table to it (`[a]`, then `[a.b]`): it is opened again then.
    Closed(Node<'s>),
    /// Anything else, finished: a scalar, an array, an inline table.
    Node(Node<'s>),
}

impl<'s> Table<'s> {
    fn new(at: At, implicit: bool, dotted: bool) -> Table<'s> {
        Table {
            // A body's or a joint's table has two entries or so.
            entries: Vec::with_capacity(2),
            index: None,
            at,
            implicit,
            dotted,
        }
    }

    /// A [`Value::Closed`] table as it was before it was closed.
    fn reopened(node: Node<'s>) -> Table<'s> {
        let mut table = Table::new(node.at, false, false);
        if let NodeKind::Table(entries) = node.kind {
            for (key, node) in entries {
                table.push(key, Value::Node(node));
            }
        }
        table
    }

    fn find(&self, name: &str) -> Option<usize> {
        match &self.index {
            Some(index) => index.get(name).copied(),
            None => self.entries.iter().position(|(k, _)| k.name == name),
        }
    }

    /// Adds an entry whose key is not in the table yet.
    fn push(&mut self, key: Key<'s>, value: Value<'s>) -> usize {
        let at = self.entries.len();
        if let Some(index) = &mut self.index {
            index.insert(key.name.clone(), at);
        }
        self.entries.push((key, value));
        if self.index.is_none() && self.entries.len() > INDEXED {
            self.index = Some(
                self.entries
                    .iter()
                    .enumerate()
                    .map(|(i, (k, _))| (k.name.clone(), i))
                    .collect(),
            );
        }
        at
    }

    /// Adds an entry; `None` if the key is there already.
    fn insert(&mut self, key: Key<'s>, value: Value<'s>) -> Option<()> {
        if self.find(&key.name).is_some() {
            return None;
        }
        self.push(key, value);
        Some(())
    }

    /// The table at the end of `path` from this one, creating implicit
    /// tables on the way, by the `toml` crate's rules for a header's path
    /// (`dotted` false) and a dotted key's (true). `None` where it refuses.
    fn descend(&mut self, path: &[Key<'s>], dotted: bool) -> Option<&mut Table<'s>> {
        let mut table = self;
        for key in path {
            let i = match table.find(&key.name) {
                Some(i) => i,
                None => table.push(
                    key.clone(),
                    Value::Table(Box::new(Table::new(key.at, true, dotted))),
                ),
            };
            let value = &mut table.entries[i].1;
            if let Value::Closed(node) = value {
                let node = std::mem::replace(
                    node,
                    Node {
                        at: At::NONE,
                        kind: NodeKind::Bool(false),
                    },
                );
                *value = Value::Table(Box::new(Table::reopened(node)));
            }
            // An array, an inline table or a scalar cannot be extended.
            let Value::Table(t) = value else {
                return None;
            };
            if dotted {
                if !t.implicit {
                    return None;
                }
                t.dotted = true;
            }
            table = t;
        }
        Some(table)
    }

    fn into_kind(self) -> NodeKind<'s> {
        NodeKind::Table(
            self.entries
                .into_iter()
                .map(|(key, value)| {
                    let node = match value {
                        Value::Node(node) | Value::Closed(node) => node,
                        Value::Table(t) => Node {
                            at: t.at,
                            kind: t.into_kind(),
                        },
                    };
                    (key, node)
                })
                .collect(),
        )
    }
}

/// A table header being read: its path, key and span.
struct Header<'s> {
    path: Vec<Key<'s>>,
    key: Key<'s>,
    at: At,
}

struct Reader<'s> {
    source: Source<'s>,
    lexer: Lexer<'s>,
    /// Up to two tokens of look-ahead.
    peeked: [Option<Token>; 2],
    /// The lexer's last token, given again past the end.
    eof: Option<Token>,
    /// Arrays and inline tables open.
    depth: usize,
    /// The next array is `sweep.trace`, the one array of a mechanism file
    /// that may be long.
    long_ok: bool,
    /// Entries and items of the inline tables and arrays open, by depth:
    /// each is moved into a vector of its exact size when it closes.
    tables: Vec<Vec<(Key<'s>, Node<'s>)>>,
    arrays: Vec<Vec<Node<'s>>>,
}

/// Whether a decoder reported an error.
fn failed(errors: Option<ParseError>) -> bool {
    errors.is_some()
}

fn at(span: Span) -> At {
    At::new(span.start()..span.end())
}

impl<'s> Reader<'s> {
    /// The lexer's next token (it ends with `Eof`, given again after).
    fn pull(&mut self) -> Token {
        match self.lexer.next() {
            Some(t) => {
                if t.kind() == T::Eof {
                    self.eof = Some(t);
                }
                t
            }
            None => self.eof.expect("the lexer ends with Eof"),
        }
    }

    fn next(&mut self) -> Token {
        match self.peeked[0].take() {
            Some(t) => {
                self.peeked[0] = self.peeked[1].take();
                t
            }
            None => self.pull(),
        }
    }

    /// The kind of the token `i` (0 or 1) ahead.
    fn peek(&mut self, i: usize) -> T {
        for k in 0..=i {
            if self.peeked[k].is_none() {
                self.peeked[k] = Some(self.pull());
            }
        }
        self.peeked[i].expect("filled above").kind()
    }

    /// Skips white space (not new lines).
    fn skip_space(&mut self) {
        while self.peek(0) == T::Whitespace {
            self.next();
        }
    }

    /// Skips white space, comments and new lines (in an array).
    fn skip_lines(&mut self) -> Option<()> {
        loop {
            match self.peek(0) {
                T::Whitespace => {}
                T::Comment | T::Newline => self.check_trivia()?,
                _ => return Some(()),
            }
            self.next();
        }
    }

    /// Checks the next token, a comment or a new line, as the parser does
    /// (no control characters; `\r` only before `\n`).
    fn check_trivia(&mut self) -> Option<()> {
        let token = self.peeked[0].expect("peeked");
        let raw = self.source.get(token)?;
        let mut errors = None;
        match token.kind() {
            T::Comment => raw.decode_comment(&mut errors),
            _ => raw.decode_newline(&mut errors),
        }
        (!failed(errors)).then_some(())
    }

    /// The end of a line: white space, a comment, then a new line or the
    /// end of the text. Returns whether the text ended.
    fn end_of_line(&mut self) -> Option<bool> {
        self.skip_space();
        if self.peek(0) == T::Comment {
            self.check_trivia()?;
            self.next();
        }
        match self.peek(0) {
            T::Newline => {
                self.check_trivia()?;
                self.next();
                Some(false)
            }
            T::Eof => Some(true),
            _ => None,
        }
    }

    fn document(&mut self) -> Option<Table<'s>> {
        // As the `toml` crate's document: the table of the current header
        // is apart from the root until the next header.
        let mut root: Option<Table<'s>> = None;
        let mut current = Table::new(At::NONE, false, false);
        let mut header: Option<Header<'s>> = None;
        loop {
            match self.peek(0) {
                T::Whitespace => {
                    self.next();
                }
                T::Comment | T::Newline => {
                    self.check_trivia()?;
                    self.next();
                }
                T::Eof => break,
                T::LeftSquareBracket => {
                    let open = self.next();
                    // An array of tables (`[[`): left to the `toml` crate.
                    if self.peek(0) == T::LeftSquareBracket {
                        return None;
                    }
                    self.skip_space();
                    let (path, key) = self.key_path()?;
                    if self.peek(0) != T::RightSquareBracket {
                        return None;
                    }
                    let close = self.next();
                    let next = Header {
                        path,
                        key,
                        at: At::new(open.span().start()..close.span().end()),
                    };
                    let done = std::mem::replace(&mut current, Table::new(At::NONE, false, false));
                    finish(&mut root, done, header.take())?;
                    let root = root.as_mut().expect("set by finish");
                    let parent = root.descend(&next.path, false)?;
                    // A table that a path made implicitly, defined now by
                    // its header, moves to the end of its parent in the
                    // `toml` crate's document: left to it (rare).
                    if parent.find(&next.key.name).is_some() {
                        return None;
                    }
                    header = Some(next);
                    if self.end_of_line()? {
                        break;
                    }
                }
                T::Atom | T::BasicString | T::LiteralString => {
                    let (path, key) = self.key_path()?;
                    if self.peek(0) != T::Equals {
                        return None;
                    }
                    self.next();
                    self.skip_space();
                    self.long_ok = match &header {
                        Some(h) => h.path.is_empty() && h.key.name == "sweep" && path.is_empty(),
                        None => path.len() == 1 && path[0].name == "sweep",
                    } && key.name == "trace";
                    let value = self.value()?;
                    self.long_ok = false;
                    let dotted = !path.is_empty();
                    let parent = current.descend(&path, dotted)?;
                    if dotted && !parent.implicit {
                        return None;
                    }
                    parent.insert(key, Value::Node(value))?;
                    if self.end_of_line()? {
                        break;
                    }
                }
                _ => return None,
            }
        }
        finish(&mut root, current, header)?;
        root
    }

    /// A key, dotted or not, and the white space after it: the path before
    /// its last part, and the last part.
    fn key_path(&mut self) -> Option<(Vec<Key<'s>>, Key<'s>)> {
        let mut path = Vec::new();
        let mut key = self.simple_key()?;
        loop {
            self.skip_space();
            if self.peek(0) != T::Dot {
                return Some((path, key));
            }
            self.next();
            self.skip_space();
            path.push(std::mem::replace(&mut key, self.simple_key()?));
            if path.len() > MAX_DEPTH {
                return None;
            }
        }
    }

    fn simple_key(&mut self) -> Option<Key<'s>> {
        if !matches!(self.peek(0), T::Atom | T::BasicString | T::LiteralString) {
            return None;
        }
        let token = self.next();
        let raw = self.source.get(token)?;
        let mut name = Cow::Borrowed("");
        let mut errors = None;
        raw.decode_key(&mut name, &mut errors);
        if failed(errors) {
            return None;
        }
        Some(Key {
            name,
            at: at(token.span()),
        })
    }

    /// A value, the next token its first.
    fn value(&mut self) -> Option<Node<'s>> {
        match self.peek(0) {
            T::LeftSquareBracket => self.array(),
            T::LeftCurlyBracket => self.inline_table(),
            T::BasicString | T::LiteralString | T::MlBasicString | T::MlLiteralString => {
                let token = self.next();
                let raw = self.source.get(token)?;
                self.scalar(raw, token.span())
            }
            T::Atom | T::Dot => {
                // As the parser: a number or a date is atoms and dots, and
                // a date with a time may have a space before the time.
                let first = self.next();
                let mut end = first.span().end();
                loop {
                    match self.peek(0) {
                        T::Atom | T::Dot => end = self.next().span().end(),
                        T::Whitespace if self.peek(1) == T::Atom => {
                            self.next();
                            end = self.next().span().end();
                        }
                        _ => break,
                    }
                }
                let span = Span::new_unchecked(first.span().start(), end);
                let raw = self.source.get(span)?;
                self.scalar(raw, span)
            }
            _ => None,
        }
    }

    /// A string, number or boolean (a date is left to the `toml` crate).
    fn scalar(&mut self, raw: toml_parser::Raw<'s>, span: Span) -> Option<Node<'s>> {
        let mut decoded = Cow::Borrowed("");
        let mut errors = None;
        let kind = raw.decode_scalar(&mut decoded, &mut errors);
        if failed(errors) {
            return None;
        }
        let kind = match kind {
            ScalarKind::String => NodeKind::Str(decoded),
            ScalarKind::Boolean(b) => NodeKind::Bool(b),
            // Integers out of range of an i64, and floats that overflow,
            // are the `toml` crate's to convert or refuse.
            ScalarKind::Integer(radix) => NodeKind::Int(i64::from_str_radix(&decoded, radix.value()).ok()?),
            ScalarKind::Float => {
                let f: f64 = decoded.parse().ok()?;
                if f.is_infinite() && !decoded.contains("inf") {
                    return None;
                }
                NodeKind::Float(f)
            }
            ScalarKind::DateTime => return None,
        };
        Some(Node { at: at(span), kind })
    }

    fn enter(&mut self) -> Option<()> {
        self.depth += 1;
        (self.depth <= MAX_DEPTH).then_some(())
    }

    /// `[a, b, ...]`, over lines, with comments and a trailing comma. An
    /// array longer than any of a mechanism file (but `sweep.trace`) is
    /// left to the `toml` crate, after `shape` has refused it.
    fn array(&mut self) -> Option<Node<'s>> {
        let limit = if std::mem::take(&mut self.long_ok) {
            usize::MAX
        } else {
            MAX_VALUES
        };
        self.enter()?;
        let open = self.next();
        let level = self.depth - 1;
        if self.arrays.len() <= level {
            self.arrays.resize_with(level + 1, Vec::new);
        }
        loop {
            self.skip_lines()?;
            if self.peek(0) == T::RightSquareBracket {
                break;
            }
            if self.arrays[level].len() == limit {
                return None;
            }
            let value = self.value()?;
            self.arrays[level].push(value);
            self.skip_lines()?;
            match self.peek(0) {
                T::Comma => {
                    self.next();
                }
                T::RightSquareBracket => break,
                _ => return None,
            }
        }
        let close = self.next();
        self.depth -= 1;
        let items: Vec<Node<'s>> = self.arrays[level].drain(..).collect();
        Some(Node {
            at: At::new(open.span().start()..close.span().end()),
            kind: NodeKind::Array(items),
        })
    }

    /// `{ k = v, ... }` on one line, keys not dotted (anything else is
    /// left to the `toml` crate).
    fn inline_table(&mut self) -> Option<Node<'s>> {
        // `sweep.trace = { ... }`: the arrays in it are not the trace.
        self.long_ok = false;
        self.enter()?;
        let open = self.next();
        let level = self.depth - 1;
        if self.tables.len() <= level {
            self.tables.resize_with(level + 1, Vec::new);
        }
        let mut index: Option<HashSet<Cow<'s, str>>> = None;
        self.skip_space();
        if self.peek(0) != T::RightCurlyBracket {
            loop {
                let (path, key) = self.key_path()?;
                if !path.is_empty() || self.peek(0) != T::Equals {
                    return None;
                }
                self.next();
                self.skip_space();
                let value = self.value()?;
                let entries = &mut self.tables[level];
                let repeated = match &mut index {
                    Some(index) => !index.insert(key.name.clone()),
                    None => entries.iter().any(|(k, _)| k.name == key.name),
                };
                if repeated {
                    return None;
                }
                entries.push((key, value));
                if index.is_none() && entries.len() > INDEXED {
                    index = Some(entries.iter().map(|(k, _)| k.name.clone()).collect());
                }
                self.skip_space();
                match self.peek(0) {
                    T::Comma => {
                        self.next();
                        self.skip_space();
                    }
                    T::RightCurlyBracket => break,
                    _ => return None,
                }
            }
        }
        let close = self.next();
        self.depth -= 1;
        let entries: Vec<(Key<'s>, Node<'s>)> = self.tables[level].drain(..).collect();
        Some(Node {
            at: At::new(open.span().start()..close.span().end()),
            kind: NodeKind::Table(entries),
        })
    }
}

/// Ends the table of a header (or the top-level keys, before the first
/// header): it goes into its parent, by the `toml` crate's document.
fn finish<'s>(root: &mut Option<Table<'s>>, table: Table<'s>, header: Option<Header<'s>>) -> Option<()> {
    let Some(header) = header else {
        *root = Some(table);
        return Some(());
    };
    let root = root.as_mut().expect("the top level is finished first");
    let parent = root.descend(&header.path, false)?;
    let mut table = Table {
        at: header.at,
        ..table
    };
    // The key is not in the parent: the header's start made sure, and only
    // headers change the root's tables.
    let value = match table.entries.iter().all(|(_, v)| matches!(v, Value::Node(_))) {
        true => Value::Closed(Node {
            at: table.at,
            kind: table.into_kind(),
        }),
        false => {
            table.entries.shrink_to_fit();
            table.index = None;
            Value::Table(Box::new(table))
        }
    };
    parent.push(header.key, value);
    Some(())
}

#[cfg(test)]
mod tests {
    use super::super::parse_toml_by_serde;
    use super::*;

    /// What this reader makes of `text`, checked against the `toml`
    /// crate: the same tree when it takes the text, and it never takes
    /// what the crate refuses.
    fn agrees(text: &str) -> Option<Node<'_>> {
        let fast = read(text);
        let reference = parse_toml_by_serde(text);
        match (&fast, &reference) {
            // Compared as printed: NaN is not equal to itself.
            (Some(fast), Ok(reference)) => {
                assert_eq!(format!("{fast:?}"), format!("{reference:?}"), "{text}")
            }
            (Some(_), Err(e)) => panic!("taken, but the toml crate says {}: {text}", e.message),
            (None, _) => {}
        }
        fast
    }

    #[test]
    fn every_bundled_file_is_read_as_the_toml_crate_reads_it() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        let mut dirs = vec![root.join("mechanisms"), root.join("tests"), root.join("examples")];
        let mut taken = 0;
        while let Some(dir) = dirs.pop() {
            let Ok(entries) = std::fs::read_dir(&dir) else {
                continue;
            };
            for entry in entries {
                let path = entry.unwrap().path();
                if path.is_dir() {
                    dirs.push(path);
                    continue;
                }
                if path.extension().and_then(|e| e.to_str()) != Some("toml") {
                    continue;
                }
                let Ok(text) = std::fs::read_to_string(&path) else {
                    continue;
                };
                if agrees(&text).is_some() {
                    taken += 1;
                }
            }
        }
        assert!(taken > 20, "{taken} files taken");
    }

    #[test]
    fn what_it_takes_is_the_toml_crates_tree() {
        for text in [
            "name = \"x\"\n[bodies.a]\nfixed = true\nmarkers = { A = [0, 0], B = { at = [1.5, -2e3], dir = [0x1, 0] } }\n",
            "# comment\r\n\r\nb = 1 # after\na = [\n  1, # one\n  2,\n]\n[t]\nx = 'lit'\ny = \"esc\\u00e9\\n\"\n",
            "a.b.c = 1\na.b.d = true\na.e = [[1], [], [2, 3]]\n",
            "[a.b]\nx = 1\n[a.c]\ny = 2\n[a.b.z]\nw = 3\n",
            // A table finished at the next header, extended by a later one.
            "[a]\nk0 = 0\nk1 = 1\nk2 = 2\nk3 = 3\nk4 = 4\nk5 = 5\nk6 = 6\nk7 = 7\nk8 = 8\nk9 = 9\n[b]\n[a.t]\nv = 1\n[a.t.u]\n",
            "[ a . \"b c\" ]\n'd' . e = +1_000\n",
            "x = \"\"\"\nmulti\nline\"\"\"\ny = '''raw'''\nz = -inf\nn = nan\n",
            "e = {}\nf = [ ]\ng = {a = {b = {c = 1}}}\n",
            "big = { k0 = 0, k1 = 1, k2 = 2, k3 = 3, k4 = 4, k5 = 5, k6 = 6, k7 = 7, k8 = 8, k9 = 9, k10 = 10 }\n",
            "\u{feff}a = 1",
            "a = 1\n\n\n",
            "a = 1",
            "",
        ] {
            assert!(agrees(text).is_some(), "not taken: {text}");
        }
        // Many keys in one table (looked up by hash).
        let many: String = (0..50).map(|i| format!("[t.k{i}]\nv = {i}\n")).collect();
        assert!(agrees(&many).is_some());
    }

    #[test]
    fn what_it_leaves_to_the_toml_crate() {
        for text in [
            // Errors.
            "a = 1\na = 2\n",
            "[a]\n[a]\n",
            "[a]\nb = 1\n[a.b]\n",
            "[a]\nb = 1\n[c]\n[a]\n",
            "[a]\nb = 1\n[c]\n[a.b.d]\n",
            "a.b = 1\n[a]\n",
            "a = {x = 1}\na.y = 2\n",
            "a = [1]\na.y = 2\n",
            "a = 1\na.b = 2\n",
            "[a]\nb.c = 1\n[a.b]\n",
            "[a.b]\n[a]\nb = 1\n",
            "m = { A = 1, A = 2 }\n",
            "m = { k0 = 0, k1 = 1, k2 = 2, k3 = 3, k4 = 4, k5 = 5, k6 = 6, k7 = 7, k8 = 8, k9 = 9, k1 = 10 }\n",
            "a = 1 b = 2\n",
            "a = [1 2]\n",
            "a = [1,,2]\n",
            "a = [,]\n",
            "a =\n",
            "a = 99999999999999999999\n",
            "a = 1e999\n",
            "a = 1.\n",
            "a = \"unterminated\n",
            "a = \"bad \\q escape\"\n",
            "[a\nb = 1\n",
            "a = 1 # bell \u{7}\n",
            "a = 1\r",
            "\"\"\"k\"\"\" = 1\n",
            "a b = 1\n",
            "= 1\n",
            // Valid, but not this reader's.
            "[[a]]\nb = 1\n",
            "d = 1979-05-27\n",
            "t = 1979-05-27 07:32:00Z\n",
            "m = { a.b = 1 }\n",
            "m = {\n  a = 1\n}\n",
            "m = { a = 1, }\n",
            "[a.b]\nx = 1\n[a]\ny = 2\n",
            "u = 9223372036854775808\n",
        ] {
            assert!(agrees(text).is_none(), "taken: {text}");
        }
    }

    #[test]
    fn long_arrays_are_left_to_shape_and_the_toml_crate() {
        assert!(agrees("x = [1, 2, 3]\n").is_some());
        assert!(agrees("x = [1, 2, 3, 4]\n").is_none());
        assert!(agrees("[bodies.b]\nmarkers = { A = [1, 2, 3, 4] }\n").is_none());
        let trace: Vec<String> = (0..10).map(|i| format!("\"b.M{i}\"")).collect();
        let trace = trace.join(", ");
        for text in [
            format!("[sweep]\ntrace = [{trace}]\n"),
            format!("sweep.trace = [{trace}]\n"),
        ] {
            assert!(agrees(&text).is_some(), "{text}");
        }
        // Elsewhere, or nested, the limit holds.
        for text in [
            format!("[sweep]\nother = [{trace}]\n"),
            format!("[a.sweep]\ntrace = [{trace}]\n"),
            format!("[sweep]\ntrace = [[{trace}]]\n"),
            format!("sweep = {{ trace = [{trace}] }}\n"),
            format!("[sweep]\ntrace = {{ x = [{trace}] }}\n"),
        ] {
            assert!(agrees(&text).is_none(), "{text}");
        }
    }

    #[test]
    fn deep_nesting_is_left_to_the_toml_crate() {
        let deep = format!("a = {}1{}\n", "[".repeat(100), "]".repeat(100));
        assert!(agrees(&deep).is_none());
        let shallow = format!("a = {}1{}\n", "[".repeat(30), "]".repeat(30));
        assert!(agrees(&shallow).is_some());
        let long_key = format!("{} = 1\n", vec!["k"; 100].join("."));
        assert!(agrees(&long_key).is_none());
    }
}
