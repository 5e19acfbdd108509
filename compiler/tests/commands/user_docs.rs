//! The pages a user reads: README.md, the landing page, and every chapter
//! of the user guide, `docs/guide/*.md`. Tests that check what the docs
//! quote (commands, their output, pictures) read them all.

use std::path::PathBuf;

/// The repository's root.
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// (path from the root, text) of README.md, then of every `docs/guide/*.md`
/// in the order of their names.
pub fn user_docs() -> Vec<(String, String)> {
    let root = root();
    let mut paths = vec!["README.md".to_string()];
    let mut chapters: Vec<String> = std::fs::read_dir(root.join("docs/guide"))
        .map(|dir| {
            dir.map(|entry| entry.expect("a readable entry of docs/guide").file_name())
                .map(|name| name.to_string_lossy().into_owned())
                .filter(|name| name.ends_with(".md"))
                .map(|name| format!("docs/guide/{name}"))
                .collect()
        })
        .unwrap_or_default();
    chapters.sort();
    paths.extend(chapters);
    paths
        .into_iter()
        .map(|path| {
            let text = std::fs::read_to_string(root.join(&path)).unwrap_or_else(|e| panic!("{path}: {e}"));
            (path, text)
        })
        .collect()
}
