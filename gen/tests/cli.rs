//! `dofplan-gen` as a user runs it: the file it writes is the library's,
//! and a bad argument gets the usage, not a panic.

use std::process::Command;

fn gen(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_dofplan-gen"))
        .args(args)
        .output()
        .expect("dofplan-gen runs")
}

#[test]
fn stress_chain_writes_the_librarys_file() {
    let o = gen(&["stress-chain", "3"]);
    assert!(o.status.success());
    assert_eq!(
        String::from_utf8(o.stdout).unwrap(),
        dofplan_gen::stress::stress_chain(3)
    );
}

#[test]
fn bad_arguments_get_the_usage() {
    for args in [
        &["stress-chain", "0"][..],
        &["stress-chain", "x"],
        &["chain"],
        &[],
    ] {
        let o = gen(args);
        assert!(!o.status.success(), "{args:?}");
        let err = String::from_utf8(o.stderr).unwrap();
        assert!(
            err.contains("usage: dofplan-gen stress-chain LOOPS"),
            "{args:?}: {err}"
        );
    }
}

#[test]
fn huge_writes_the_files_it_lists() {
    let dir = std::env::temp_dir().join(format!("dofplan-gen-huge-{}", std::process::id()));
    let o = gen(&["huge", dir.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let listed = String::from_utf8(o.stdout).unwrap();
    assert_eq!(listed.lines().count(), dofplan_gen::huge::FILES.len());
    for (name, text) in dofplan_gen::huge::FILES {
        let written = std::fs::read_to_string(dir.join(name)).unwrap();
        assert!(written == text(), "{name}");
    }
    std::fs::remove_dir_all(&dir).ok();
}
