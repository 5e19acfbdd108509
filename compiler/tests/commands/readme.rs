//! The README shows what some commands print; those outputs must be what
//! the binary really prints. Every "`dofplan …` prints:" in README.md is
//! followed by a code block: the command is run from the workspace root and
//! its output compared with the block, line for line.

use std::path::PathBuf;
use std::process::Command;

fn workspace() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// (command words, the block shown) for every "`dofplan …` prints:".
fn shown_outputs(readme: &str) -> Vec<(Vec<String>, String)> {
    let mut found = Vec::new();
    let mut rest = readme;
    while let Some(at) = rest.find("`dofplan ") {
        let after = &rest[at + 1..];
        let Some(end) = after.find('`') else { break };
        let command = &after[..end];
        let tail = &after[end + 1..];
        rest = tail;
        // The command may wrap onto the next line of the paragraph.
        let Some(block) = tail.strip_prefix(" prints:\n\n```\n") else {
            continue;
        };
        let Some(close) = block.find("\n```") else { break };
        let words = command.split_whitespace().skip(1).map(String::from).collect();
        found.push((words, block[..close + 1].to_string()));
    }
    found
}

#[test]
fn every_output_the_readme_shows_is_what_the_binary_prints() {
    let readme = std::fs::read_to_string(workspace().join("README.md")).expect("README.md");
    let shown = shown_outputs(&readme);
    assert!(
        shown.len() >= 2,
        "the README shows the plan and the simulate summary: {shown:?}"
    );
    for (words, block) in shown {
        let o = Command::new(env!("CARGO_BIN_EXE_dofplan"))
            .args(&words)
            .current_dir(workspace())
            .env_remove("NO_COLOR")
            .output()
            .expect("run dofplan");
        assert!(
            o.status.success(),
            "dofplan {words:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        let printed = String::from_utf8(o.stdout).expect("UTF-8 output");
        assert_eq!(
            printed,
            block,
            "README.md shows `dofplan {}` printing something else",
            words.join(" ")
        );
    }
}
