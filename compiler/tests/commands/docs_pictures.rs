//! The pictures the README and the user guide show are what their commands
//! write today.
//!
//! Every `dofplan … --svg docs/NAME.svg` command quoted in README.md or a
//! chapter of `docs/guide/` is run once from the repository root, as a
//! reader would run it, with the picture written to a scratch file instead;
//! the committed `docs/NAME.svg` must be byte for byte the same. A change to
//! the drawing code then shows up as a failing test until the pictures are
//! regenerated with those commands.

use std::path::Path;
use std::process::Command;

use crate::user_docs::{root, user_docs};

/// The commands of a page (README.md or a guide chapter) that write a
/// picture into `docs/`: every backquoted span that starts with `dofplan `
/// and has `--svg docs/` (a span may be broken over two lines).
fn picture_commands(page: &str) -> Vec<Vec<String>> {
    page.split('`')
        .skip(1)
        .step_by(2)
        .map(|span| span.split_whitespace().map(str::to_string).collect::<Vec<_>>())
        .filter(|words| {
            words.first().is_some_and(|w| w == "dofplan")
                && words
                    .windows(2)
                    .any(|w| w[0] == "--svg" && w[1].starts_with("docs/"))
        })
        .collect()
}

#[test]
fn committed_pictures_equal_their_commands_output() {
    let root = root();
    // Every page's commands, each once (the README shows a picture the
    // guide shows too).
    let mut commands: Vec<Vec<String>> = Vec::new();
    for (_, text) in user_docs() {
        for words in picture_commands(&text) {
            if !commands.contains(&words) {
                commands.push(words);
            }
        }
    }
    assert!(
        commands.len() >= 2,
        "the README and the guide quote their picture commands: {commands:?}"
    );
    let scratch = std::env::temp_dir().join(format!("dofplan-docs-{}", std::process::id()));
    std::fs::create_dir_all(&scratch).unwrap();
    let mut stale = Vec::new();
    for words in &commands {
        let at = words.iter().position(|w| w == "--svg").unwrap() + 1;
        let committed = words[at].clone();
        let fresh = scratch.join(Path::new(&committed).file_name().unwrap());
        let mut args: Vec<String> = words[1..].to_vec();
        args[at - 1] = fresh.display().to_string();
        let out = Command::new(env!("CARGO_BIN_EXE_dofplan"))
            .args(&args)
            .current_dir(&root)
            .output()
            .expect("the dofplan binary runs");
        assert!(
            out.status.success(),
            "`{}` failed: {}",
            words.join(" "),
            String::from_utf8_lossy(&out.stderr)
        );
        let want = std::fs::read(&fresh).expect("the command wrote its picture");
        let have = std::fs::read(root.join(&committed)).unwrap_or_default();
        if want != have {
            stale.push(format!("{committed} (regenerate: `{}`)", words.join(" ")));
        }
    }
    std::fs::remove_dir_all(&scratch).ok();
    assert!(
        stale.is_empty(),
        "committed pictures differ from what the commands the docs quote write:\n{}",
        stale.join("\n")
    );
}

#[test]
fn the_commands_are_found_across_line_breaks() {
    let text = "gives `dofplan analyze a.toml --svg\ndocs/x.svg` and `dofplan check b.toml` and \
                (`dofplan simulate c.toml --svg docs/y.svg`)";
    let found = picture_commands(text);
    assert_eq!(
        found,
        vec![
            vec!["dofplan", "analyze", "a.toml", "--svg", "docs/x.svg"],
            vec!["dofplan", "simulate", "c.toml", "--svg", "docs/y.svg"],
        ]
    );
}
