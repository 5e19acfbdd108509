//! Where an editor may read and write: files of one directory (the one the
//! editor was started in), nothing outside it.

use std::io;
use std::path::{Path, PathBuf};

/// The file `name` of `dir`, if it is one an editor may open or save: a
/// plain file name (no folder, no `..`), ending in `.toml`, of a file that
/// is not a link out of `dir`. `name` may omit the extension.
pub fn file_in(dir: &Path, name: &str) -> Result<PathBuf, String> {
    let name = name.trim();
    if name.is_empty() {
        return Err("give the file a name".to_string());
    }
    let plain = !name.contains(['/', '\\']) && name != "." && name != ".." && !name.starts_with('.');
    if !plain {
        return Err(format!(
            "`{name}` is not a plain file name: files are read and saved in {} only",
            dir.display()
        ));
    }
    let file = if name.ends_with(".toml") {
        name.to_string()
    } else if name.contains('.') {
        return Err(format!("`{name}`: mechanism files are saved as .toml"));
    } else {
        format!("{name}.toml")
    };
    let path = dir.join(&file);
    // A link inside the directory that points elsewhere is still outside it.
    if let Ok(meta) = std::fs::symlink_metadata(&path) {
        if meta.file_type().is_symlink() {
            return Err(format!(
                "{file} is a link: files are read and saved in {} only",
                dir.display()
            ));
        }
    }
    Ok(path)
}

/// The `.toml` files of `dir`, sorted by name: what the editor offers to
/// open.
pub fn files(dir: &Path) -> io::Result<Vec<String>> {
    let mut out: Vec<String> = std::fs::read_dir(dir)?
        .filter_map(Result::ok)
        .filter(|e| e.file_type().is_ok_and(|t| t.is_file()))
        .filter_map(|e| e.file_name().into_string().ok())
        .filter(|n| n.ends_with(".toml") && !n.starts_with('.'))
        .collect();
    out.sort();
    Ok(out)
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
    fn only_plain_toml_names_of_the_directory() {
        let dir = Path::new("/some/dir");
        assert_eq!(file_in(dir, "linkage").unwrap(), dir.join("linkage.toml"));
        assert_eq!(file_in(dir, "linkage.toml").unwrap(), dir.join("linkage.toml"));
        for bad in [
            "",
            "../x",
            "/etc/passwd",
            "a/b.toml",
            "..",
            ".hidden",
            "x.json",
            "a\\b",
        ] {
            assert!(file_in(dir, bad).is_err(), "{bad:?} accepted");
        }
    }
}
