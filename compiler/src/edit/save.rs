//! Where an editor may read and write: files of one directory (the one the
//! editor was started in) and its folders, nothing outside it.

use std::io;
use std::path::{Component, Path, PathBuf};

/// Folders [`files`] does not look into: build output, and the folders of
/// other tools (hidden ones, whose names start with a dot, are skipped too).
const SKIPPED: [&str; 2] = ["target", "node_modules"];

/// How deep and how many files [`files`] looks at, so that an editor
/// started in a large tree (a home directory) still lists quickly.
const MAX_DEPTH: usize = 8;
const MAX_VISITED: usize = 20_000;

/// The most of a file [`looks_like_mechanism`] reads.
const MAX_SNIFF: u64 = 1 << 20;

/// The file `name` of `dir`, if it is one an editor may open or save: a
/// relative path of plain names (no `..`, no hidden names, no root) inside
/// `dir`, ending in `.toml`, with no link on the way (a link inside the
/// directory that points elsewhere is still outside it). `name` may omit
/// the extension.
pub fn file_in(dir: &Path, name: &str) -> Result<PathBuf, String> {
    let name = name.trim();
    if name.is_empty() {
        return Err("give the file a name".to_string());
    }
    let outside = || {
        format!(
            "`{name}` is not a file name inside the editor's folder: files are read and saved in {} and its folders only",
            dir.display()
        )
    };
    let relative = Path::new(name);
    let plain = !name.contains('\\')
        && !name.ends_with('/')
        && relative.components().all(|c| match c {
            Component::Normal(part) => part.to_str().is_some_and(|p| !p.starts_with('.')),
            _ => false,
        });
    if !plain {
        return Err(outside());
    }
    let file = if name.ends_with(".toml") {
        name.to_string()
    } else if relative.extension().is_some() {
        return Err(format!("`{name}`: mechanism files are saved as .toml"));
    } else {
        format!("{name}.toml")
    };
    let path = dir.join(&file);
    // No step of the way may be a link: a linked folder or file inside the
    // directory can point anywhere.
    let mut at = dir.to_path_buf();
    for part in Path::new(&file).components() {
        at.push(part);
        if let Ok(meta) = std::fs::symlink_metadata(&at) {
            if meta.file_type().is_symlink() {
                return Err(format!(
                    "{} is a link: files are read and saved in {} and its folders only",
                    at.strip_prefix(dir).unwrap_or(&at).display(),
                    dir.display()
                ));
            }
        }
    }
    Ok(path)
}

/// The mechanism files of `dir` and its folders (not `target/`,
/// `node_modules/` or hidden folders, and no links), as paths relative to
/// `dir` with `/` between names, sorted: what the editor offers to open.
/// A file is listed when it is a `.toml` that [`looks_like_mechanism`], so
/// `Cargo.toml` and other tools' files are left out while a mechanism file
/// with an error in it (which the editor opens to fix) is kept.
pub fn files(dir: &Path) -> io::Result<Vec<String>> {
    let mut out = Vec::new();
    let mut visited = 0;
    // The start directory itself must be readable: its error is reported.
    let top = std::fs::read_dir(dir)?;
    let mut pending = vec![(top, String::new(), 0usize)];
    while let Some((entries, prefix, depth)) = pending.pop() {
        for entry in entries.filter_map(Result::ok) {
            visited += 1;
            if visited > MAX_VISITED {
                break;
            }
            let Ok(name) = entry.file_name().into_string() else {
                continue;
            };
            if name.starts_with('.') {
                continue;
            }
            // `file_type` does not follow links: a link is neither.
            let Ok(kind) = entry.file_type() else {
                continue;
            };
            let relative = format!("{prefix}{name}");
            if kind.is_dir() && depth < MAX_DEPTH && !SKIPPED.contains(&name.as_str()) {
                if let Ok(sub) = std::fs::read_dir(entry.path()) {
                    pending.push((sub, format!("{relative}/"), depth + 1));
                }
            } else if kind.is_file() && name.ends_with(".toml") && looks_like_mechanism(&entry.path()) {
                out.push(relative);
            }
        }
    }
    out.sort();
    Ok(out)
}

/// Whether the TOML file at `path` reads as a mechanism file: a line
/// starting a `bodies` table (`[bodies.…]`, `[bodies]`, `bodies = …` or
/// `bodies.… = …`). Only its text is looked at, not parsed, so a file with
/// a syntax error in it still counts.
pub fn looks_like_mechanism(path: &Path) -> bool {
    use std::io::Read;
    let Ok(file) = std::fs::File::open(path) else {
        return false;
    };
    let mut bytes = Vec::new();
    if file.take(MAX_SNIFF).read_to_end(&mut bytes).is_err() {
        return false;
    }
    // Whether a key written `bodies…` starts the bodies table.
    let bodies = |key: &str| {
        let key = key.trim_start().trim_start_matches(['"', '\'']);
        key.strip_prefix("bodies").is_some_and(|rest| {
            let rest = rest.trim_start_matches(['"', '\'']).trim_start();
            rest.starts_with(['.', ']', '='])
        })
    };
    // A `bodies = …` key inside another table (`[dependencies]`) is not
    // the mechanism's: only a top-level one, or a `[bodies…]` header, is.
    let mut top_level = true;
    for line in String::from_utf8_lossy(&bytes).lines() {
        let line = line.trim_start();
        if let Some(header) = line.strip_prefix('[') {
            if bodies(header.trim_start_matches('[')) {
                return true;
            }
            top_level = false;
        } else if top_level && bodies(line) {
            return true;
        }
    }
    false
}

/// Writes `text` to `path` whole or not at all: into a temporary file of
/// the same directory, then renamed over `path`, so a failure half-way
/// never leaves a truncated mechanism file.
pub fn write(path: &Path, text: &str) -> io::Result<()> {
    let dir = path.parent().unwrap_or(Path::new("."));
    let name = path
        .file_name()
        .and_then(|n| n.to_str())
        .unwrap_or("mechanism.toml");
    let temp = dir.join(format!(".{name}.{}.tmp", std::process::id()));
    std::fs::write(&temp, text)?;
    std::fs::rename(&temp, path).inspect_err(|_| {
        let _ = std::fs::remove_file(&temp);
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_toml_names_inside_the_directory() {
        let dir = Path::new("/some/dir");
        assert_eq!(file_in(dir, "linkage").unwrap(), dir.join("linkage.toml"));
        assert_eq!(file_in(dir, "linkage.toml").unwrap(), dir.join("linkage.toml"));
        assert_eq!(
            file_in(dir, "mechanisms/fourbar.toml").unwrap(),
            dir.join("mechanisms/fourbar.toml"),
            "a file in a folder of the directory"
        );
        for bad in [
            "",
            "../x",
            "a/../../x",
            "/etc/passwd",
            "..",
            ".",
            "./x",
            ".hidden",
            "a/.git/x.toml",
            "a/",
            "x.json",
            "a\\b",
        ] {
            assert!(file_in(dir, bad).is_err(), "{bad:?} accepted");
        }
    }

    fn temp_tree(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("dofplan-save-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    #[test]
    fn files_lists_mechanisms_in_folders_but_not_build_hidden_or_other_toml() {
        let dir = temp_tree("files");
        let mechanism = "name = \"m\"\n[bodies.ground]\nfixed = true\nmarkers = { O = [0, 0] }\n";
        let write = |rel: &str, text: &str| {
            let path = dir.join(rel);
            std::fs::create_dir_all(path.parent().unwrap()).unwrap();
            std::fs::write(path, text).unwrap();
        };
        write("top.toml", mechanism);
        write("mechanisms/fourbar.toml", mechanism);
        write(
            "mechanisms/deep/er/one.toml",
            "# a comment\n[ bodies . \"ground\" ]\n",
        );
        // A syntax error further down: still a mechanism file, opened to fix.
        write(
            "mechanisms/typo.toml",
            "name = \"t\"\n[bodies.ground\nfixed = true\n",
        );
        write(
            "inline.toml",
            "name = \"i\"\nbodies = { ground = { fixed = true } }\n",
        );
        write(
            "Cargo.toml",
            "[package]\nname = \"x\"\n[dependencies]\nbodies = \"1\"\n",
        );
        write("rustfmt.toml", "max_width = 110\n");
        write("target/release/copy.toml", mechanism);
        write("node_modules/pkg/copy.toml", mechanism);
        write(".hidden/copy.toml", mechanism);
        write("mechanisms/.copy.toml", mechanism);
        write("mechanisms/fourbar.json", "{\"bodies\": {}}");
        #[cfg(unix)]
        {
            std::os::unix::fs::symlink(dir.join("mechanisms"), dir.join("linked")).unwrap();
            std::os::unix::fs::symlink(dir.join("top.toml"), dir.join("link.toml")).unwrap();
        }
        assert_eq!(
            files(&dir).unwrap(),
            [
                "inline.toml",
                "mechanisms/deep/er/one.toml",
                "mechanisms/fourbar.toml",
                "mechanisms/typo.toml",
                "top.toml"
            ]
        );
        #[cfg(unix)]
        {
            let why = file_in(&dir, "linked/fourbar.toml").unwrap_err();
            assert!(why.contains("linked is a link"), "{why}");
        }
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn the_repository_lists_its_mechanisms_not_its_cargo_files() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        let listed = files(&root).unwrap();
        assert!(
            listed.iter().any(|f| f == "mechanisms/fourbar.toml"),
            "{listed:?}"
        );
        assert!(
            listed.iter().any(|f| f == "mechanisms/spatial/rssr.toml"),
            "{listed:?}"
        );
        assert!(
            !listed
                .iter()
                .any(|f| f.ends_with("Cargo.toml") || f == "rustfmt.toml"),
            "{listed:?}"
        );
        assert!(!listed.iter().any(|f| f.starts_with("target/")), "{listed:?}");
    }
}
