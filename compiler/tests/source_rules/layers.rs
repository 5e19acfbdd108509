//! The layers point one way (ARCHITECTURE.md, "Layers").
//!
//! Reads the `crate::`, `super::`, `self::` and child-module paths of every
//! source file of the compiler's library and of the runtime (not their
//! tests, not the binary) and checks two rules:
//!
//! - **no import circle** between files: file A imports file B when A's
//!   code names a path into B. A submodule naming its own ancestor does not
//!   count (that is how Rust shares a module's items with its parts), but
//!   an ancestor naming a submodule does, so a circle through a `mod.rs`
//!   is found;
//! - **nothing imports upward**: the crate's top-level modules are ranked
//!   in layers ([`COMPILER`], [`RUNTIME`]) and a module names only modules
//!   of lower layers.
//!
//! The reading is textual (comments dropped, `#[cfg(test)]` modules cut),
//! which is enough for this code base's style: paths are written out, not
//! built by macros.

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};

/// The compiler's stages, lowest first. A module may name only modules of
/// an earlier line.
const COMPILER: &[&[&str]] = &[
    // How numbers are printed.
    &["format"],
    // Files read and validated; joints as equations.
    &["model"],
    // The plan IR: the contract between analysis and the back ends.
    &["plan"],
    // The back ends: they take a plan and nothing above it.
    &["interp", "emit"],
    // DOF analysis: makes plans (and runs them, to pick drawn branches).
    &["analysis"],
    // Pure Newton-Raphson, the baseline, and the planned drag.
    &["numeric"],
    // Which joints cannot all close: above analysis and Newton, run by
    // the loader's callers.
    &["conflict"],
    // What users run on top of plans; importers load and plan what they
    // write; forces from a plan's rates.
    &["assemble", "simulate", "import", "forces"],
    // Synthesis writes its solutions as `assemble` rewrites a file.
    &["synth"],
    &["render", "build"],
    // The commands' reports: they may draw (`analyze --svg`).
    &["report"],
    // The editor shows the reports in its panels.
    &["edit"],
];

/// The runtime's layers, lowest first: the scalar layer (`Real`, `Jet2`,
/// factors) imports nothing of the crate; Newton's solver and the frame
/// reports build on it, poses and lanes on those, and the steps that
/// place bodies (closed form, numeric clusters) on poses.
const RUNTIME: &[&[&str]] = &[
    &["scalar"],
    // Newton-Raphson and its linear algebra.
    &["numeric"],
    // What a frame reports: breaks, policies, the context steps write to.
    &["frame"],
    // What both dimensions' clusters share (their Newton options, how a
    // solve is reported to the frame).
    &["numeric/cluster"],
    &["planar"],
    &["lanes"],
    &["drive"],
    &["rates"],
    &["spatial"],
    &["marker", "batch"],
    // What a compiled design module's `prepare` calls.
    &["design"],
];

/// A module path inside its crate (`["analysis", "spatial", "planner"]`).
type ModPath = Vec<String>;

/// The library's source files by module path (tests and binaries left out).
fn modules(root: &Path) -> BTreeMap<ModPath, PathBuf> {
    let mut out = BTreeMap::new();
    let mut stack = vec![root.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for entry in fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            let name = path.file_name().unwrap().to_string_lossy().into_owned();
            if path.is_dir() {
                if name != "bin" {
                    stack.push(path);
                }
                continue;
            }
            if !name.ends_with(".rs") || name == "tests.rs" {
                continue;
            }
            let rel = path.strip_prefix(root).unwrap().with_extension("");
            let mut m: ModPath = rel.iter().map(|s| s.to_string_lossy().into_owned()).collect();
            if matches!(m.last().map(String::as_str), Some("mod" | "lib")) {
                m.pop();
            }
            out.insert(m, path);
        }
    }
    out
}

/// The code of a file without comments and without its inline
/// `#[cfg(test)]` module (cut from the attribute to the end: tests come
/// last here; a `tests.rs` of its own is not read at all).
fn code(text: &str) -> String {
    let text = match text.find("#[cfg(test)]\nmod tests {") {
        Some(at) => &text[..at],
        None => text,
    };
    let mut out = String::with_capacity(text.len());
    for line in text.lines() {
        // A `//` inside a string would cut a line short; this code base
        // writes no paths after such strings.
        let line = match line.find("//") {
            Some(at) if !line[..at].contains('"') => &line[..at],
            _ => line,
        };
        out.push_str(line);
        out.push('\n');
    }
    out
}

/// Every path written in `code`, with `use` groups expanded
/// (`a::{b, c::d}` gives `a::b` and `a::c::d`).
fn paths(code: &str) -> Vec<Vec<String>> {
    let chars: Vec<char> = code.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        if is_ident_start(c) && (i == 0 || !(is_ident(chars[i - 1]) || chars[i - 1] == ':')) {
            let mut prefix = Vec::new();
            i = path(&chars, i, &mut prefix, &mut out);
        } else {
            i += 1;
        }
    }
    out
}

/// Reads a path starting at `i` under `prefix`, pushing every full path
/// to `out`; returns where it ends.
fn path(chars: &[char], mut i: usize, prefix: &mut Vec<String>, out: &mut Vec<Vec<String>>) -> usize {
    let depth = prefix.len();
    loop {
        let start = i;
        while i < chars.len() && is_ident(chars[i]) {
            i += 1;
        }
        if i > start {
            prefix.push(chars[start..i].iter().collect());
        }
        if chars[i..].starts_with(&[':', ':']) {
            i += 2;
            if chars.get(i) == Some(&'{') {
                i = group(chars, i + 1, prefix, out);
                break;
            }
            if chars.get(i) == Some(&'*') {
                i += 1;
                out.push(prefix.clone());
                break;
            }
            continue;
        }
        out.push(prefix.clone());
        break;
    }
    prefix.truncate(depth);
    i
}

/// Reads a `{a, b::c, self}` group after its `{`; returns past its `}`.
fn group(chars: &[char], mut i: usize, prefix: &mut Vec<String>, out: &mut Vec<Vec<String>>) -> usize {
    loop {
        while i < chars.len() && (chars[i].is_whitespace() || chars[i] == ',') {
            i += 1;
        }
        match chars.get(i) {
            None => return i,
            Some('}') => return i + 1,
            Some(c) if is_ident_start(*c) => {
                i = path(chars, i, prefix, out);
                // `x as y`: the alias names nothing new.
                while i < chars.len() && !matches!(chars[i], ',' | '}') {
                    i += 1;
                }
            }
            Some(_) => i += 1,
        }
    }
}

fn is_ident_start(c: char) -> bool {
    c.is_ascii_alphabetic() || c == '_'
}

fn is_ident(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_'
}

/// A file's `pub use` statements taken out of its code: what they export
/// is followed to where it is defined rather than counted as an import of
/// the file (a `mod.rs` that re-exports its parts is their front door).
fn exports(code: &str) -> (String, Vec<String>) {
    let mut rest = String::with_capacity(code.len());
    let mut stmts = Vec::new();
    let mut i = 0;
    while i < code.len() {
        let line_end = code[i..].find('\n').map_or(code.len(), |e| i + e + 1);
        let line = code[i..line_end].trim_start();
        let export = ["pub use ", "pub(crate) use ", "pub(super) use "]
            .iter()
            .find_map(|p| line.strip_prefix(p));
        match export {
            Some(_) => {
                let end = code[i..].find(';').map_or(code.len(), |e| i + e + 1);
                let stmt = &code[i..end];
                stmts.push(stmt[stmt.find("use ").unwrap() + 4..].to_string());
                i = end;
            }
            None => {
                rest.push_str(&code[i..line_end]);
                i = line_end;
            }
        }
    }
    (rest, stmts)
}

/// The child modules a file declares (`mod x;`).
fn children(code: &str) -> BTreeSet<String> {
    code.lines()
        .filter_map(|l| {
            let l = l.trim();
            let l = ["pub ", "pub(crate) ", "pub(super) "]
                .iter()
                .find_map(|p| l.strip_prefix(p))
                .unwrap_or(l);
            l.strip_prefix("mod ")?.strip_suffix(';').map(str::to_string)
        })
        .collect()
}

/// A path as written in module `m` (which declares `kids`), made absolute;
/// `None` for a path outside the crate.
fn absolute(m: &ModPath, kids: &BTreeSet<String>, p: &[String]) -> Option<ModPath> {
    // A lone name (`mod load;`, a local variable) is no path.
    if p.len() < 2 {
        return None;
    }
    let mut base: ModPath = match p[0].as_str() {
        "crate" => vec![],
        "self" => m.clone(),
        "super" => m[..m.len().saturating_sub(1)].to_vec(),
        kid if kids.contains(kid) => {
            let mut b = m.clone();
            b.push(kid.to_string());
            b
        }
        _ => return None,
    };
    let mut rest = &p[1..];
    while rest.first().map(String::as_str) == Some("super") {
        base.pop();
        rest = &rest[1..];
    }
    base.extend(rest.iter().cloned());
    Some(base)
}

/// File-level imports: module → the modules its code names.
fn imports(root: &Path) -> BTreeMap<ModPath, BTreeSet<ModPath>> {
    let files = modules(root);
    // Each file's code without its exports, and what it exports: name →
    // the absolute path it stands for.
    let mut bodies = BTreeMap::new();
    let mut exported: BTreeMap<ModPath, BTreeMap<String, ModPath>> = BTreeMap::new();
    for (m, file) in &files {
        let text = code(&fs::read_to_string(file).unwrap());
        let kids = children(&text);
        let (rest, stmts) = exports(&text);
        let names = exported.entry(m.clone()).or_default();
        for stmt in &stmts {
            let alias = stmt
                .split(" as ")
                .nth(1)
                .map(|a| a.trim_end_matches(';').trim().to_string());
            for p in paths(stmt) {
                if let Some(abs) = absolute(m, &kids, &p) {
                    let name = alias.clone().unwrap_or_else(|| p.last().unwrap().clone());
                    names.insert(name, abs);
                }
            }
        }
        bodies.insert(m.clone(), (rest, kids));
    }
    // The file defining what a path names: the longest prefix that is a
    // file, followed through that file's exports.
    let resolve = |mut path: ModPath| -> Option<ModPath> {
        for _ in 0..8 {
            let target = (0..=path.len())
                .rev()
                .map(|n| &path[..n])
                .find(|t| files.contains_key(*t))?;
            let next = path.get(target.len());
            match next.and_then(|n| exported.get(target)?.get(n)) {
                Some(to) => {
                    let mut p = to.clone();
                    p.extend(path[target.len() + 1..].iter().cloned());
                    path = p;
                }
                None => return Some(target.to_vec()),
            }
        }
        None
    };
    let mut edges = BTreeMap::new();
    for (m, (text, kids)) in &bodies {
        let mut to = BTreeSet::new();
        for p in paths(text) {
            let Some(target) = absolute(m, kids, &p).and_then(&resolve) else {
                continue;
            };
            let ancestor = target.len() < m.len() && m[..target.len()] == *target;
            if target != *m && !ancestor {
                to.insert(target);
            }
        }
        edges.insert(m.clone(), to);
    }
    edges
}

/// The import circles (strongly connected components of more than one
/// file), each as its files and the imports inside it.
fn circles(edges: &BTreeMap<ModPath, BTreeSet<ModPath>>) -> Vec<Vec<String>> {
    // Tarjan's algorithm, iterative enough for a few hundred files.
    struct Tarjan<'a> {
        edges: &'a BTreeMap<ModPath, BTreeSet<ModPath>>,
        index: BTreeMap<&'a ModPath, (usize, usize)>,
        stack: Vec<&'a ModPath>,
        on: BTreeSet<&'a ModPath>,
        next: usize,
        found: Vec<Vec<&'a ModPath>>,
    }
    impl<'a> Tarjan<'a> {
        fn visit(&mut self, v: &'a ModPath) {
            self.index.insert(v, (self.next, self.next));
            self.next += 1;
            self.stack.push(v);
            self.on.insert(v);
            for w in self.edges.get(v).into_iter().flatten() {
                if !self.index.contains_key(w) {
                    self.visit(w);
                    let low = self.index[w].1.min(self.index[v].1);
                    self.index.get_mut(v).unwrap().1 = low;
                } else if self.on.contains(w) {
                    let low = self.index[w].0.min(self.index[v].1);
                    self.index.get_mut(v).unwrap().1 = low;
                }
            }
            if self.index[v].0 == self.index[v].1 {
                let mut comp = Vec::new();
                loop {
                    let w = self.stack.pop().unwrap();
                    self.on.remove(w);
                    comp.push(w);
                    if w == v {
                        break;
                    }
                }
                if comp.len() > 1 {
                    self.found.push(comp);
                }
            }
        }
    }
    let mut t = Tarjan {
        edges,
        index: BTreeMap::new(),
        stack: vec![],
        on: BTreeSet::new(),
        next: 0,
        found: vec![],
    };
    for v in edges.keys() {
        if !t.index.contains_key(v) {
            t.visit(v);
        }
    }
    let name = |m: &ModPath| m.join("/");
    t.found
        .iter()
        .map(|comp| {
            let inside: BTreeSet<&ModPath> = comp.iter().copied().collect();
            let mut lines = Vec::new();
            for a in comp {
                for b in &edges[*a] {
                    if inside.contains(b) {
                        lines.push(format!("{} -> {}", name(a), name(b)));
                    }
                }
            }
            lines.sort();
            lines
        })
        .collect()
}

/// The imports that name a module of the same or a higher layer. A
/// layer's entry is a module path (`numeric/cluster`); a file takes the
/// rank of the longest entry it is under.
fn upward(edges: &BTreeMap<ModPath, BTreeSet<ModPath>>, layers: &[&[&str]]) -> Vec<String> {
    let entry = |m: &ModPath| -> Option<(usize, usize)> {
        if m.is_empty() {
            return None;
        }
        let found = (layers.iter().enumerate())
            .flat_map(|(rank, l)| l.iter().enumerate().map(move |(k, e)| (rank, k, *e)))
            .filter(|(_, _, e)| {
                let e: Vec<&str> = e.split('/').collect();
                e.len() <= m.len() && e.iter().zip(m).all(|(a, b)| *a == b.as_str())
            })
            .max_by_key(|(_, _, e)| e.split('/').count());
        match found {
            Some((rank, k, _)) => Some((rank, k)),
            None => panic!("the module `{}` has no layer: add it to the table", m.join("/")),
        }
    };
    let mut out = Vec::new();
    for (a, bs) in edges {
        for b in bs {
            if let (Some(ea), Some(eb)) = (entry(a), entry(b)) {
                if ea != eb && eb.0 >= ea.0 {
                    out.push(format!("{} -> {}", a.join("/"), b.join("/")));
                }
            }
        }
    }
    out
}

fn check(crate_src: &str, layers: &[&[&str]]) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join(crate_src);
    let edges = imports(&root);
    if let Ok(m) = std::env::var("LAYERS_DEBUG") {
        eprintln!(
            "{m}: {:?}",
            edges.get(&m.split('/').map(str::to_string).collect::<ModPath>())
        );
    }
    assert!(edges.len() > 10, "read {} files under {crate_src}", edges.len());
    let circles = circles(&edges);
    assert!(
        circles.is_empty(),
        "import circles in {crate_src}:\n{}",
        circles
            .iter()
            .map(|c| c.join("\n"))
            .collect::<Vec<_>>()
            .join("\n--\n")
    );
    let up = upward(&edges, layers);
    assert!(
        up.is_empty(),
        "imports running up the layers in {crate_src}:\n{}",
        up.join("\n")
    );
}

#[test]
fn the_compiler_layers_point_one_way() {
    check("compiler/src", COMPILER);
}

#[test]
fn the_runtime_layers_point_one_way() {
    check("runtime/src", RUNTIME);
}

/// The reader finds what it must: a circle planted in a small tree, an
/// upward import, grouped uses and child-module paths.
#[test]
fn the_reader_finds_circles_and_upward_imports() {
    let dir = std::env::temp_dir().join(format!("dofplan-layers-{}", std::process::id()));
    let _ = fs::remove_dir_all(&dir);
    fs::create_dir_all(dir.join("a")).unwrap();
    fs::write(dir.join("lib.rs"), "pub mod a;\npub mod b;\n").unwrap();
    fs::write(
        dir.join("a/mod.rs"),
        "mod x;\npub use x::Thing;\npub fn helper() { x::g() }\n",
    )
    .unwrap();
    fs::write(
        dir.join("a/x.rs"),
        "use crate::b::{self, Other as O};\npub struct Thing;\n",
    )
    .unwrap();
    fs::write(
        dir.join("b.rs"),
        "// crate::c::Nothing is a comment\nuse super::a::{helper, Thing}; // Thing from a/x, through a\npub struct Other;\n#[cfg(test)]\nmod tests { use crate::c; }\n",
    )
    .unwrap();
    let edges = imports(&dir);
    let found = circles(&edges);
    assert_eq!(found, vec![vec!["a -> a/x", "a/x -> b", "b -> a", "b -> a/x"]]);
    let up = upward(&edges, &[&["b"], &["a"]]);
    assert_eq!(up, vec!["b -> a".to_string(), "b -> a/x".to_string()]);
    let _ = fs::remove_dir_all(&dir);
}
