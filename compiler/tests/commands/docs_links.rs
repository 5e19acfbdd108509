//! The docs hold together: README.md stays a landing page of at most 400
//! lines, every chapter of the user guide is in its table of contents, and
//! every relative link in README.md, ARCHITECTURE.md and `docs/**/*.md`
//! leads to a file that exists and, for `#anchor` links, to a heading of
//! that file (as GitHub names headings).

use std::collections::HashMap;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// README.md, ARCHITECTURE.md and every `.md` under `docs/`, from the root.
fn markdown_pages() -> Vec<PathBuf> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
            .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
            .map(|entry| entry.expect("a readable entry").path())
            .collect();
        entries.sort();
        for path in entries {
            if path.is_dir() {
                walk(&path, out);
            } else if path.extension().is_some_and(|e| e == "md") {
                out.push(path);
            }
        }
    }
    let root = root();
    let mut pages = vec![root.join("README.md"), root.join("ARCHITECTURE.md")];
    walk(&root.join("docs"), &mut pages);
    pages
}

/// The text outside fenced code blocks and inline code spans, where links
/// and headings are: the lines of code blocks are left empty and code
/// spans (which may wrap onto the next line) blanked, so a line keeps its
/// number.
fn prose(markdown: &str) -> String {
    let mut out = String::new();
    let mut fence: Option<&str> = None;
    for line in markdown.lines() {
        let trimmed = line.trim_start();
        let marker = ["```", "~~~"].into_iter().find(|m| trimmed.starts_with(m));
        match (fence, marker) {
            (None, Some(m)) => fence = Some(m),
            (Some(open), Some(m)) if open == m => fence = None,
            (None, None) => out.push_str(line),
            _ => {}
        }
        out.push('\n');
    }
    // Code spans: a run of n backquotes up to the next run of exactly n.
    let chars: Vec<char> = out.chars().collect();
    let mut kept = String::with_capacity(out.len());
    let mut i = 0;
    while i < chars.len() {
        if chars[i] != '`' {
            kept.push(chars[i]);
            i += 1;
            continue;
        }
        let run = chars[i..].iter().take_while(|&&c| c == '`').count();
        let mut j = i + run;
        let mut close = None;
        while j < chars.len() {
            if chars[j] == '`' {
                let n = chars[j..].iter().take_while(|&&c| c == '`').count();
                if n == run {
                    close = Some(j + n);
                    break;
                }
                j += n;
            } else {
                j += 1;
            }
        }
        match close {
            Some(end) => {
                kept.extend(chars[i..end].iter().map(|&c| if c == '\n' { '\n' } else { ' ' }));
                i = end;
            }
            None => {
                kept.extend(&chars[i..i + run]);
                i += run;
            }
        }
    }
    kept
}

/// GitHub's anchor for a heading: lower case, every character but letters,
/// digits, `-`, `_` and spaces dropped, spaces made `-`.
fn slug(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter(|c| c.is_alphanumeric() || matches!(c, '-' | '_' | ' '))
        .map(|c| if c == ' ' { '-' } else { c })
        .collect()
}

/// The anchors of a page's headings, a repeated one numbered `-1`, `-2`, …
fn anchors(markdown: &str) -> Vec<String> {
    let mut fence: Option<&str> = None;
    let mut found: Vec<String> = Vec::new();
    let mut seen: HashMap<String, usize> = HashMap::new();
    for line in markdown.lines() {
        let trimmed = line.trim_start();
        if let Some(m) = ["```", "~~~"].into_iter().find(|m| trimmed.starts_with(m)) {
            match fence {
                None => fence = Some(m),
                Some(open) if open == m => fence = None,
                Some(_) => {}
            }
            continue;
        }
        if fence.is_some() {
            continue;
        }
        let hashes = line.chars().take_while(|&c| c == '#').count();
        if (1..=6).contains(&hashes) && line[hashes..].starts_with(' ') {
            let base = slug(&line[hashes..]);
            let seen = seen.entry(base.clone()).or_insert(0);
            found.push(if *seen == 0 {
                base
            } else {
                format!("{base}-{seen}")
            });
            *seen += 1;
        }
    }
    found
}

/// (line, target) of every inline link and image of a page's prose.
fn links(markdown: &str) -> Vec<(usize, String)> {
    let text = prose(markdown);
    let mut found = Vec::new();
    let mut from = 0;
    while let Some(at) = text[from..].find("](") {
        let start = from + at + 2;
        let rest = &text[start..];
        let end = rest
            .find(|c: char| c == ')' || c.is_whitespace())
            .unwrap_or(rest.len());
        let target = rest[..end].trim_start_matches('<').trim_end_matches('>');
        let line = text[..start].matches('\n').count() + 1;
        found.push((line, target.to_string()));
        from = start + end;
    }
    found
}

/// What is wrong with the relative links of one page, if anything.
fn broken_links(page: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(page).unwrap_or_else(|e| panic!("{}: {e}", page.display()));
    let dir = page.parent().expect("a page is in a folder");
    let mut broken = Vec::new();
    for (line, target) in links(&text) {
        if target.contains("://") || target.starts_with("mailto:") {
            continue;
        }
        let shown = page.strip_prefix(root()).unwrap_or(page);
        let at = format!("{}:{line}: ({target})", shown.display());
        let (path, anchor) = match target.split_once('#') {
            Some((path, anchor)) => (path, Some(anchor)),
            None => (target.as_str(), None),
        };
        let file = if path.is_empty() {
            page.to_path_buf()
        } else {
            dir.join(path)
        };
        if path.is_empty() && anchor.is_none() {
            broken.push(format!("{at} links nowhere"));
            continue;
        }
        if !file.exists() {
            broken.push(format!("{at}: no such file"));
            continue;
        }
        let Some(anchor) = anchor else { continue };
        if file.extension().is_none_or(|e| e != "md") {
            broken.push(format!("{at}: an anchor into a file that is not Markdown"));
            continue;
        }
        let headings = anchors(&std::fs::read_to_string(&file).expect("the linked page"));
        if !headings.iter().any(|h| h == anchor) {
            broken.push(format!("{at}: no such heading"));
        }
    }
    broken
}

#[test]
fn every_relative_link_of_the_docs_resolves() {
    let pages = markdown_pages();
    assert!(
        pages.iter().any(|p| p.ends_with("docs/guide/README.md")),
        "the user guide has a table of contents: {pages:?}"
    );
    let broken: Vec<String> = pages.iter().flat_map(|page| broken_links(page)).collect();
    assert!(broken.is_empty(), "broken links:\n{}", broken.join("\n"));
}

#[test]
fn the_readme_is_a_landing_page_of_at_most_400_lines() {
    let readme = std::fs::read_to_string(root().join("README.md")).expect("README.md");
    let lines = readme.lines().count();
    assert!(
        lines <= 400,
        "README.md has {lines} lines: move what is not set-up or a short tour into docs/guide/"
    );
}

#[test]
fn every_chapter_of_the_guide_is_in_its_table_of_contents() {
    let guide = root().join("docs/guide");
    let contents = std::fs::read_to_string(guide.join("README.md")).expect("docs/guide/README.md");
    let listed: Vec<String> = links(&contents).into_iter().map(|(_, target)| target).collect();
    let mut missing = Vec::new();
    for entry in std::fs::read_dir(&guide).expect("docs/guide") {
        let name = entry
            .expect("a readable entry")
            .file_name()
            .to_string_lossy()
            .into_owned();
        if name.ends_with(".md") && name != "README.md" && !listed.contains(&name) {
            missing.push(name);
        }
    }
    assert!(
        missing.is_empty(),
        "chapters not in docs/guide/README.md: {missing:?}"
    );
}

#[test]
fn anchors_are_github_s() {
    assert_eq!(
        slug(" Spatial mechanisms (`dimension = 3`)"),
        "spatial-mechanisms-dimension--3"
    );
    assert_eq!(
        slug(" Compiling mechanisms from your build.rs"),
        "compiling-mechanisms-from-your-buildrs"
    );
    assert_eq!(
        slug(" Many frames in one call: `solve_batch`"),
        "many-frames-in-one-call-solve_batch"
    );
    assert_eq!(
        anchors("# A\n\n```sh\n# not a heading\n```\n## A\n### A b\n# A\n"),
        vec!["a", "a-1", "a-b", "a-2"]
    );
}

#[test]
fn links_in_code_are_not_links() {
    let page = "[a](a.md) `[b](b.md)` and\n```\n[c](c.md)\n```\n`x\n[d](d.md)` [e\nf](e.md#g)\n";
    assert_eq!(
        links(page),
        vec![(1, "a.md".to_string()), (7, "e.md#g".to_string())]
    );
}
