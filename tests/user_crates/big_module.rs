//! A generated module of any size compiles: a crate as a user writes one
//! (the README's build.rs and main.rs) compiles a 1,000-loop stress chain
//! (2,002 bodies, 3,002 steps) in a debug build, where rustc used to
//! overflow its stack on the one `solve` function, and its frames agree
//! with the interpreter. The same crate checks the README's example and the
//! naming of body and marker constants, collisions included.

use std::process::Command;

use dofplan::interp::Interpreter;
use dofplan_runtime::{Driver, Options};
use dofplan_tests::user_crate::UserCrate;

const LOOPS: usize = 1000;

/// The README's build.rs.
const BUILD_RS: &str = r#"fn main() -> Result<(), Box<dyn std::error::Error>> {
    dofplan::build::Config::new().compile_dir("mechanisms")?;
    Ok(())
}
"#;

/// The `src/main.rs` block of the README's build.rs section, verbatim.
fn readme_main() -> String {
    let readme =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/README.md")).expect("README.md");
    let start = readme
        .find("// src/main.rs")
        .expect("the README shows a src/main.rs using a compiled mechanism");
    let end = start + readme[start..].find("```").expect("the block ends");
    readme[start..end].to_string()
}

/// Runs the chain through a turn and prints every pose of every frame.
const CHAIN_RS: &str = r#"use dofplan_runtime::{Driver, Options};
use my_mechanisms::stress_loops_1000 as chain;

fn main() {
    let mut driver = Driver::new(chain::Plan, Options::default());
    for k in 0..12 {
        let theta = 30.0 * k as f64;
        let status = driver.frame(&[theta]);
        println!("frame {theta:?} {}", status.name());
        for p in driver.poses() {
            println!("{:?} {:?} {:?} {:?}", p.at[0], p.at[1], p.rot.c, p.rot.s);
        }
        let end = chain::marker::ROCKER_1000_R1000.world(driver.poses());
        println!("end {:?} {:?}", end[0], end[1]);
    }
}
"#;

/// A four-bar whose names collide once upper-cased (`coupler.P` and
/// `coupler.p`) or are keywords (`type`, `crank.fn`).
fn names_toml() -> String {
    let fourbar =
        std::fs::read_to_string(dofplan_tests::mechanisms_dir().join("fourbar.toml")).expect("bundled");
    let out = fourbar
        .replace("name = \"fourbar\"", "name = \"names\"")
        .replace("P = [3, 3.5] }", "P = [3, 3.5], p = [2, 3] }")
        .replace(
            "markers = { A = [0, 0], B = [1, 1] }",
            "markers = { A = [0, 0], B = [1, 1], fn = [0.5, 0.5] }",
        )
        .replace("[bodies.rocker]", "[bodies.type]")
        .replace("\"rocker.", "\"type.");
    for part in [
        "\"names\"",
        "p = [2, 3]",
        "fn = [0.5, 0.5]",
        "[bodies.type]",
        "\"type.C\"",
    ] {
        assert!(out.contains(part), "the fixture has {part}");
    }
    out
}

const NAMES_RS: &str = r#"use my_mechanisms::names::{body, marker, State};

fn main() {
    assert_eq!(body::GROUND, 0);
    assert_eq!(body::TYPE, 3);
    // In the file's order: `P` keeps the plain name, `p` is numbered.
    assert_eq!((marker::COUPLER_P.name, marker::COUPLER_P.body, marker::COUPLER_P.local), ("coupler.P", 2, [3.0, 3.5]));
    assert_eq!((marker::COUPLER_P_2.name, marker::COUPLER_P_2.body, marker::COUPLER_P_2.local), ("coupler.p", 2, [2.0, 3.0]));
    assert_eq!((marker::CRANK_FN.name, marker::CRANK_FN.local), ("crank.fn", [0.5, 0.5]));
    assert_eq!(marker::TYPE_C.body, body::TYPE);
    assert_eq!(State::DRAWN.marker(marker::COUPLER_P_2), [2.0, 3.0]);
    println!("names ok");
}
"#;

fn run(krate: &UserCrate, bin: &str) -> String {
    let exe = krate
        .dir()
        .parent()
        .expect("under target/user-crates")
        .join("target/debug")
        .join(bin);
    let out = Command::new(&exe)
        .output()
        .unwrap_or_else(|e| panic!("{}: {e}", exe.display()));
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        out.status.success(),
        "{bin} failed:\n{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    stdout
}

#[test]
fn a_thousand_loop_chain_builds_in_debug_and_agrees_with_the_interpreter() {
    let chain = dofplan_tests::stress::stress_chain(LOOPS);
    let krate = UserCrate::new("my_mechanisms");
    krate
        .file("build.rs", BUILD_RS)
        .file(&format!("mechanisms/stress_loops_{LOOPS}.toml"), &chain)
        .file(
            "mechanisms/fourbar.toml",
            &std::fs::read_to_string(dofplan_tests::mechanisms_dir().join("fourbar.toml")).expect("bundled"),
        )
        .file("mechanisms/names.toml", &names_toml())
        .file("src/main.rs", &readme_main())
        .file("src/bin/chain.rs", CHAIN_RS)
        .file("src/bin/names.rs", NAMES_RS);
    let out = krate.build();
    assert!(
        out.status.success(),
        "the build failed:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );

    // The README's example runs and prints the coupler point.
    let readme = run(&krate, "my_mechanisms");
    assert!(readme.starts_with("solved: coupler.P at ("), "{readme}");
    assert_eq!(run(&krate, "names"), "names ok\n");

    // The split solve against the interpreter, frame by frame.
    let file = krate.dir().join(format!("mechanisms/stress_loops_{LOOPS}.toml"));
    let m = dofplan::load_file(&file).unwrap_or_else(|e| panic!("{e}"));
    let plan = dofplan_tests::plan(&m);
    let size = plan.size;
    let mut interpreted = Driver::new(Interpreter::new(plan), Options::default());
    let printed = run(&krate, "chain");
    let mut lines = printed.lines();
    let number = |s: &str| s.parse::<f64>().unwrap_or_else(|e| panic!("{s}: {e}"));
    for k in 0..12 {
        let theta = 30.0 * f64::from(k);
        let status = interpreted.frame(&[theta]);
        assert_eq!(
            lines.next(),
            Some(format!("frame {theta:?} {}", status.name()).as_str())
        );
        assert!(status.is_solved(), "the chain turns fully: {status:?}");
        for (b, p) in interpreted.poses().iter().enumerate() {
            let line = lines.next().expect("a pose per body");
            let v: Vec<f64> = line.split(' ').map(number).collect();
            let d = ((v[0] - p.at[0]).abs().max((v[1] - p.at[1]).abs()) / size)
                .max((v[2] - p.rot.c).abs())
                .max((v[3] - p.rot.s).abs());
            assert!(
                d <= 1e-12,
                "frame {k} body {b}: compiled and interpreted differ by {d:e}"
            );
        }
        let end = lines.next().expect("the end marker");
        let rocker = interpreted.poses().len() - 1;
        assert_eq!(m.bodies[rocker].name, format!("rocker_{LOOPS}"));
        let local = m.bodies[rocker]
            .markers
            .iter()
            .find(|mk| mk.name == format!("R{LOOPS}"))
            .expect("the last rocker has its R marker")
            .at;
        let want = interpreted.poses()[rocker].world(local);
        let got: Vec<f64> = end.trim_start_matches("end ").split(' ').map(number).collect();
        assert!(
            (got[0] - want[0]).abs().max((got[1] - want[1]).abs()) <= 1e-12 * size,
            "frame {k}: {end}"
        );
    }
}
