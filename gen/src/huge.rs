//! Files of 50 MB that a mechanism loader must answer quickly and briefly:
//! one line of 50 MB, and a marker with 10 million coordinates. The
//! huge-input tests load them (`tests/inputs/huge_input.rs`); `cargo run --release
//! -p dofplan-gen -- huge DIR` writes them for measuring `dofplan check` on
//! them.

/// The size the files are made to (bytes, about).
pub const HUGE: usize = 50_000_000;

/// A file's name, and the function that writes its text.
pub type File = (&'static str, fn() -> String);

/// The files.
pub const FILES: [File; 6] = [
    ("one_line.toml", one_line),
    ("unterminated.toml", unterminated),
    ("middle.toml", middle),
    ("one_line.json", one_line_json),
    ("array.toml", array),
    ("array.json", array_json),
];

/// One key of 50 MB that never gets its `=`: an error at the line's end.
pub fn one_line() -> String {
    "x".repeat(HUGE)
}

/// A string that never ends: an error at the end of the line.
pub fn unterminated() -> String {
    format!("name = \"{}", "a".repeat(HUGE))
}

/// Two 25 MB strings with an `@` between: an error in the middle of the
/// line, at the `@` (the strings are of `é`, two bytes each: columns are
/// not bytes).
pub fn middle() -> String {
    let half = "\u{e9}".repeat(HUGE / 4);
    format!("t = \"{half}\" @ \"{half}\"\n")
}

/// JSON: a string that never ends.
pub fn one_line_json() -> String {
    format!("{{\"name\": \"{}", "a".repeat(HUGE))
}

/// The ten million coordinates after marker `ground.A`'s two.
fn coordinates() -> String {
    ", 0.5".repeat(HUGE / 5)
}

/// The bundled four-bar with 10 million more coordinates for marker
/// `ground.A` (line 14).
pub fn array() -> String {
    // The bundled file, built in: the generator runs from any folder.
    let text = include_str!("../../mechanisms/fourbar.toml");
    let at = "A = [0, 0], D = [4, 0]";
    assert!(text.contains(at), "fourbar.toml's ground has {at}");
    text.replacen(at, &format!("A = [0, 0{}], D = [4, 0]", coordinates()), 1)
}

/// JSON: the ground of a four-bar with 10 million more coordinates for
/// marker `ground.A` (line 2).
pub fn array_json() -> String {
    format!(
        "{{\"name\": \"fourbar\",\n \"bodies\": {{\"ground\": {{\"fixed\": true, \"markers\": {{\"A\": [0, 0{}]}}}}}}}}\n",
        coordinates()
    )
}
