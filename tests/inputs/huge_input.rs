//! Huge files get a short error, early: a 50 MB file on one line is not
//! echoed whole, an array longer than the format allows is refused at its
//! first value too many (before a parser builds it), and a file over the
//! size limit is refused unread.
//!
//! The files (`dofplan_tests::huge`) are written by the test into a
//! temporary directory; positions are computed from the text written,
//! independently of the loader.

use std::path::{Path, PathBuf};

use dofplan::load_any;
use dofplan::model::{ModelError, MAX_FILE_BYTES};
use dofplan_tests::huge::{self, HUGE};

/// An error's rendering stays within this many bytes, whatever the file.
const SHORT: usize = 2_000;

/// A fresh directory for one test.
fn scratch(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("dofplan-huge-{test}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Writes `text` to `dir/name` and loads it, which must fail.
fn refused(dir: &Path, name: &str, text: &str) -> (String, ModelError) {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    let e = load_any(&path).expect_err("a bad file");
    (path.display().to_string(), e)
}

/// 1-based line and column (in characters) of byte `offset` of `text`.
fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset];
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    (
        before.matches('\n').count() + 1,
        before[line_start..].chars().count() + 1,
    )
}

/// One error, rendered short (with and without colour), at `position`,
/// with `needles` in it.
fn assert_short(e: &ModelError, position: &str, needles: &[&str]) {
    assert_eq!(e.diagnostics.len(), 1, "{e}");
    for colour in [false, true] {
        let shown = e.render(colour);
        let head: String = shown.chars().take(SHORT).collect();
        assert!(shown.len() < SHORT, "{} bytes:\n{head}", shown.len());
        assert!(shown.contains(position), "no {position} in:\n{shown}");
    }
    let shown = e.render(false);
    for n in needles {
        assert!(shown.contains(n), "no {n:?} in:\n{shown}");
    }
    let plain = e.to_string();
    assert!(plain.len() < SHORT && plain.starts_with(position), "{plain}");
}

#[test]
fn a_50_mb_line_is_shown_as_a_window_around_the_error() {
    let dir = scratch("line");
    // A key that never gets its `=`: the error is at the end of the line.
    let (file, e) = refused(&dir, "one_line.toml", &huge::one_line());
    let help = format!("help: line 1 is {HUGE} bytes long: is this the right file?");
    assert_short(
        &e,
        &format!("{file}:1:{}", HUGE + 1),
        &["TOML syntax error", "1 │ ...xxx", &help],
    );
    // A string, or a JSON string, that never ends.
    for (name, text, syntax) in [
        ("unterminated.toml", huge::unterminated(), "TOML syntax error"),
        ("one_line.json", huge::one_line_json(), "JSON syntax error"),
    ] {
        let (file, e) = refused(&dir, name, &text);
        let help = format!("help: line 1 is {} bytes long", text.len());
        assert_short(&e, &format!("{file}:1:"), &[syntax, "1 │ ...aaa", &help]);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_50_mb_line_with_an_error_in_its_middle_points_at_it() {
    let dir = scratch("middle");
    let text = huge::middle();
    let (line, col) = line_col(&text, text.find('@').unwrap());
    let (file, e) = refused(&dir, "middle.toml", &text);
    let help = format!("help: line 1 is {} bytes long", text.len() - 1);
    assert_short(&e, &format!("{file}:{line}:{col}"), &["TOML syntax error", &help]);
    // The source line shown is cut on both sides, and the caret is under
    // the `@`.
    let shown = e.render(false);
    let source = shown.lines().find(|l| l.starts_with("1 │")).expect("the line");
    assert!(
        source.starts_with("1 │ ...") && source.ends_with("..."),
        "{shown}"
    );
    let caret = shown.lines().find(|l| l.contains('^')).expect("a caret");
    let column = caret.chars().position(|c| c == '^').unwrap();
    assert_eq!(source.chars().nth(column), Some('@'), "{shown}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_50_mb_coordinate_array_is_refused_at_its_fourth_value() {
    let dir = scratch("array");
    for (name, text) in [("array.toml", huge::array()), ("array.json", huge::array_json())] {
        // The fourth coordinate: the second 0.5 after the two zeros.
        let fourth = text.find("[0, 0, 0.5, 0.5").unwrap() + "[0, 0, 0.5, ".len();
        let (line, col) = line_col(&text, fourth);
        let (file, e) = refused(&dir, name, &text);
        assert_short(
            &e,
            &format!("{file}:{line}:{col}"),
            &[
                "marker `ground.A` has more than 3 coordinates",
                "help: a point is [x, y], or [x, y, z]",
            ],
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_file_over_the_limit_is_refused_unread() {
    let dir = scratch("limit");
    let path = dir.join("huge.toml");
    // Sparse: no disk is written, and the loader reads none of it.
    let f = std::fs::File::create(&path).unwrap();
    f.set_len(MAX_FILE_BYTES + 1).unwrap();
    let e = load_any(&path).expect_err("too large");
    let file = path.display().to_string();
    assert_short(
        &e,
        &file,
        &[
            &format!(
                "the file is {} bytes (256 MiB), more than the 256 MiB",
                MAX_FILE_BYTES + 1
            ),
            "help: is this the right file?",
            "dofplan::load_any_str",
        ],
    );
    assert!(!dofplan::model::is_spatial_file(&path));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_files_are_50_mb() {
    for (name, text) in huge::FILES {
        let len = text().len();
        assert!((HUGE..HUGE + 2_000).contains(&len), "{name}: {len} bytes");
    }
}

#[test]
fn a_file_with_hundreds_of_errors_shows_the_first_hundred_and_counts_the_rest() {
    // The bundled four-bar with 250 unknown keys after its name: 250
    // errors.
    let text = std::fs::read_to_string(dofplan_tests::mechanisms_dir().join("fourbar.toml")).unwrap();
    let keys: String = (0..250).map(|i| format!("unknown_{i} = 1\n")).collect();
    let text = text.replacen("name = \"fourbar\"\n", &format!("name = \"fourbar\"\n{keys}"), 1);
    let e = dofplan::load_str("many.toml", &text, dofplan::model::Format::Toml).expect_err("unknown keys");
    assert_eq!(e.diagnostics.len(), 250, "{e}");
    let shown = e.render(false);
    let errors: Vec<&str> = shown.lines().filter(|l| l.starts_with("error")).collect();
    assert_eq!(errors.len(), 101, "{shown}");
    assert!(errors[99].contains("unknown key `unknown_99`"), "{}", errors[99]);
    assert_eq!(
        errors[100],
        "error: 150 more errors in many.toml, not shown: fix the 100 above and check again"
    );
}

#[test]
fn the_dimension_is_read_off_a_files_start_however_far_its_top_level_keys_go() {
    use dofplan::model::is_spatial_file;
    let dir = scratch("dimension");
    let write = |name: &str, text: &str| {
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        path
    };
    // The key past the first reads (64 KiB, then twice as much each time),
    // after a long comment block and after a long top-level value.
    let comments = "# a line of comment about the mechanism, long enough\n".repeat(10_000);
    assert!(is_spatial_file(&write(
        "late.toml",
        &format!("{comments}dimension = 3\n")
    )));
    let long = format!("name = \"{}\"\ndimension = 3\n", "x".repeat(300_000));
    assert!(is_spatial_file(&write("long_line.toml", &long)));
    // Lines of a multi-line string that start with `[` are not headers.
    let rows = "[not a header]\n".repeat(20_000);
    let string = format!("notes = \"\"\"\n{rows}\"\"\"\ndimension = 3\n[bodies.a]\n");
    assert!(is_spatial_file(&write("string.toml", &string)));
    // A header ends the top-level keys: a `dimension` after it is a
    // table's, wherever the read stops.
    let after = format!("[bodies.a]\n{comments}dimension = 3\n");
    assert!(!is_spatial_file(&write("after_header.toml", &after)));
    // Without a new line to cut at, the whole file is read.
    let one_line = format!("dimension = 3 # {}", "y".repeat(200_000));
    assert!(is_spatial_file(&write("one_line.toml", &one_line)));
    assert!(!is_spatial_file(&write(
        "planar.toml",
        &format!("{comments}name = \"p\"\n")
    )));
    std::fs::remove_dir_all(&dir).unwrap();
}
