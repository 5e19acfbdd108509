//! The README and the user guide show what some commands print; those
//! outputs must be what the binary really prints. Every "`dofplan …`
//! prints:" in README.md or a chapter of `docs/guide/` is followed by a
//! code block: the command is run from the workspace root and its output
//! compared with the block, line for line.

use std::process::Command;

use crate::user_docs::{root, user_docs};

/// (command words, the block shown) for every "`dofplan …` prints:".
fn shown_outputs(text: &str) -> Vec<(Vec<String>, String)> {
    let mut found = Vec::new();
    let mut rest = text;
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
fn every_output_the_docs_show_is_what_the_binary_prints() {
    let shown: Vec<(String, Vec<String>, String)> = user_docs()
        .into_iter()
        .flat_map(|(path, text)| {
            shown_outputs(&text)
                .into_iter()
                .map(move |(words, block)| (path.clone(), words, block))
        })
        .collect();
    // The planar plan and simulate summary, the spatial check, plan and
    // simulate summary, and the spatial analyze summary.
    assert!(
        shown.len() >= 6,
        "the README and the guide show six outputs or more: {shown:?}"
    );
    for (path, words, block) in shown {
        let o = Command::new(env!("CARGO_BIN_EXE_dofplan"))
            .args(&words)
            .current_dir(root())
            .env_remove("NO_COLOR")
            .output()
            .expect("run dofplan");
        assert!(
            o.status.success(),
            "{path}: dofplan {words:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        let printed = String::from_utf8(o.stdout).expect("UTF-8 output");
        assert_eq!(
            printed,
            block,
            "{path} shows `dofplan {}` printing something else",
            words.join(" ")
        );
    }
}
