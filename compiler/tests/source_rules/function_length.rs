//! Functions a reader can hold (ARCHITECTURE.md, "Architecture
//! invariants"): no function of the compiler (its binary included) or of
//! the runtime is longer than [`MOST_LINES`] lines, tests left out.
//!
//! A function's length runs from its `fn` line to its closing brace,
//! counted by matching braces outside strings, characters and comments.

use std::fs;
use std::path::{Path, PathBuf};

/// The longest a function may be, in lines.
const MOST_LINES: usize = 120;

/// Every `.rs` file under `dir`, but `tests.rs` files (test modules).
fn sources(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            sources(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs")
            && path.file_name().is_some_and(|n| n != "tests.rs")
        {
            out.push(path);
        }
    }
}

/// A line without its string and character literals and its comment, so
/// that the braces left are code's.
fn code_of(line: &str) -> String {
    let mut out = String::new();
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '"' => {
                // To the closing quote, escapes skipped.
                while let Some(d) = chars.next() {
                    match d {
                        '\\' => {
                            chars.next();
                        }
                        '"' => break,
                        _ => {}
                    }
                }
            }
            // A character literal ('{', '\'') but not a lifetime ('a).
            '\'' => {
                let rest: String = chars.clone().take(3).collect();
                if rest.starts_with('\\') {
                    chars.next();
                    chars.next();
                    chars.next();
                } else if rest.chars().nth(1) == Some('\'') {
                    chars.next();
                    chars.next();
                }
            }
            '/' if chars.peek() == Some(&'/') => break,
            _ => out.push(c),
        }
    }
    out
}

/// The functions of `text` longer than `most` lines: (first line, name,
/// lines). An inline `#[cfg(test)] mod tests` is not read.
fn long_functions(text: &str, most: usize) -> Vec<(usize, String, usize)> {
    let lines: Vec<&str> = text.lines().collect();
    let end = (0..lines.len())
        .find(|&i| {
            lines[i].starts_with("#[cfg(test)]")
                && lines.get(i + 1).is_some_and(|l| l.starts_with("mod tests {"))
        })
        .unwrap_or(lines.len());
    let mut found = Vec::new();
    let mut i = 0;
    while i < end {
        let code = code_of(lines[i]);
        let name = code
            .split_whitespace()
            .skip_while(|w| *w != "fn")
            .nth(1)
            .map(|w| w.split(['(', '<']).next().unwrap_or(w).to_string());
        let Some(name) = name.filter(|n| !n.is_empty()) else {
            i += 1;
            continue;
        };
        // From the signature to the matching brace of its body (none for
        // a declaration ending in `;`).
        let (mut depth, mut opened, mut j) = (0i64, false, i);
        while j < end {
            let code = code_of(lines[j]);
            for c in code.chars() {
                match c {
                    '{' => {
                        depth += 1;
                        opened = true;
                    }
                    '}' => depth -= 1,
                    _ => {}
                }
            }
            if (opened && depth <= 0) || (!opened && code.trim_end().ends_with(';')) {
                break;
            }
            j += 1;
        }
        let length = j - i + 1;
        if opened && length > most {
            found.push((i + 1, name, length));
        }
        // Functions nested in this one are inside its length already.
        i = j + 1;
    }
    found
}

#[test]
fn no_function_is_longer_than_a_reader_can_hold() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut files = Vec::new();
    sources(&root.join("compiler/src"), &mut files);
    sources(&root.join("runtime/src"), &mut files);
    assert!(files.len() > 100, "read {} files", files.len());
    files.sort();
    let mut long = Vec::new();
    for file in &files {
        let text = fs::read_to_string(file).unwrap();
        for (line, name, length) in long_functions(&text, MOST_LINES) {
            let path = file.strip_prefix(&root).unwrap_or(file).display().to_string();
            long.push(format!("{path}:{line}: `{name}` is {length} lines"));
        }
    }
    assert!(
        long.is_empty(),
        "functions over {MOST_LINES} lines (split them by concern):\n{}",
        long.join("\n")
    );
}

/// The reader measures what it should: braces in strings, characters and
/// comments are not counted, a declaration has no body, and test modules
/// are left out.
#[test]
fn the_reader_counts_lines_by_braces_of_code() {
    let mut text = String::from("fn short() {\n    let s = \"}}}\"; // }\n    let c = '{';\n}\n");
    text.push_str("fn decl(x: u8);\n");
    text.push_str("pub(crate) fn long<'a>(x: &'a str) {\n");
    for _ in 0..5 {
        text.push_str("    if x.is_empty() {\n        return;\n    }\n");
    }
    text.push_str("}\n#[cfg(test)]\nmod tests {\n    fn very_long() {\n");
    text.push_str(&"    let _ = 1;\n".repeat(50));
    text.push_str("    }\n}\n");
    assert_eq!(long_functions(&text, 10), vec![(6, "long".to_string(), 17)]);
    assert_eq!(
        long_functions(&text, 3),
        vec![(1, "short".to_string(), 4), (6, "long".to_string(), 17)]
    );
}
