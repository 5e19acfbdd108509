//! Snapshots of every bundled mechanism's explained plan and generated
//! Rust, planar and spatial, so every change to a plan is a reviewable
//! diff. The generated snapshot is also exactly the source
//! `dofplan-generated` compiles (checked below), so a snapshot that would
//! not compile fails the build.

use dofplan::emit::{emit, emit_spatial};
use dofplan_tests::{bundled, bundled_spatial, generated_source, load, load_spatial, plan, plan_spatial};

fn settings() -> insta::Settings {
    let mut s = insta::Settings::clone_current();
    s.set_prepend_module_to_snapshot(false);
    s.set_omit_expression(true);
    s
}

#[test]
fn explained_plans() {
    settings().bind(|| {
        for name in bundled() {
            let p = plan(&load(&name));
            insta::assert_snapshot!(format!("plan_{name}"), p.explain_all());
        }
    });
}

#[test]
fn generated_rust() {
    settings().bind(|| {
        for name in bundled() {
            let p = plan(&load(&name));
            insta::assert_snapshot!(format!("emit_{name}"), emit(&p));
        }
    });
}

/// The four-bar's design module (`Config::design`): the same steps as its
/// `solve`, every number the drawing fixes read from the candidate's
/// geometry, and `prepare`, which computes them from the parameters.
#[test]
fn the_fourbar_design_module_is_snapshotted() {
    let m = load("fourbar");
    let design = dofplan::synth::planar::Design::new(&m).expect("a design");
    let code = dofplan::emit::emit_design(&plan(&m), &design.table()).expect("closed form");
    settings().bind(|| insta::assert_snapshot!("design_fourbar", code));
}

#[test]
fn compiled_crate_holds_exactly_the_snapshotted_source() {
    for name in bundled() {
        let compiled = dofplan_generated::source(&name).expect("compiled");
        assert_eq!(
            compiled,
            generated_source(&name),
            "{name}: dofplan-generated is stale"
        );
    }
}

/// The drag demo compiled by `Config::drag`: the open chain with its end
/// pinned to the XY carriage.
#[test]
fn the_compiled_drag_is_snapshotted_too() {
    let m = dofplan::load_file(&dofplan_tests::mechanisms_dir().join("drag/open_chain_15.toml"))
        .unwrap_or_else(|e| panic!("{e}"));
    let end = m.find_marker("link_15.E").expect("bundled");
    let c = dofplan::numeric::planar::drag::carriage(&m, end).expect("has a ground");
    let p = plan(&c);
    settings().bind(|| {
        insta::assert_snapshot!("plan_open_chain_15_drag", p.explain_all());
        insta::assert_snapshot!("emit_open_chain_15_drag", emit(&p));
    });
    let compiled = dofplan_generated::source("open_chain_15_drag_link_15_e").expect("compiled");
    assert_eq!(compiled, emit(&p), "dofplan-generated is stale");
}

/// Spatial plans (`mechanisms/spatial/`), as `dofplan plan` prints them.
#[test]
fn explained_spatial_plans() {
    settings().bind(|| {
        for name in bundled_spatial() {
            let p = plan_spatial(&load_spatial(&name));
            insta::assert_snapshot!(format!("plan_spatial_{name}"), p.explain_all());
        }
    });
}

/// Spatial modules, as `dofplan emit` prints them and `dofplan::build`
/// writes them.
#[test]
fn generated_spatial_rust() {
    settings().bind(|| {
        for name in bundled_spatial() {
            let p = plan_spatial(&load_spatial(&name));
            insta::assert_snapshot!(format!("emit_spatial_{name}"), emit_spatial(&p));
        }
    });
}

#[test]
fn compiled_crate_holds_exactly_the_snapshotted_spatial_source() {
    for name in bundled_spatial() {
        let m = load_spatial(&name);
        let module = dofplan::emit::ident_for(&m.name);
        let compiled = dofplan_generated::source(&module).expect("compiled");
        assert_eq!(
            compiled,
            emit_spatial(&plan_spatial(&m)),
            "{name}: dofplan-generated is stale"
        );
    }
}

/// The spatial plan-fragment table the planner reads, as `dofplan
/// fragments` prints it: a change to a fragment is a reviewable diff.
#[test]
fn the_spatial_fragment_table() {
    settings().bind(|| {
        insta::assert_snapshot!(
            "fragments_spatial",
            dofplan::analysis::spatial::fragments::table()
        );
    });
}

/// The geared mechanisms' plans and generated Rust (`mechanisms/gears/`):
/// a geared body's rotation and a rack's slide, affine in the inputs.
#[test]
fn geared_plans_and_rust_are_snapshotted() {
    settings().bind(|| {
        for name in ["epicyclic", "rack_pinion"] {
            let path = dofplan_tests::mechanisms_dir().join(format!("gears/{name}.toml"));
            let p = plan(&dofplan::load_file(&path).unwrap_or_else(|e| panic!("{e}")));
            insta::assert_snapshot!(format!("plan_gears_{name}"), p.explain_all());
            let code = emit(&p);
            assert_eq!(
                dofplan_generated::source(name),
                Some(code.as_str()),
                "{name}: stale"
            );
            insta::assert_snapshot!(format!("emit_gears_{name}"), code);
        }
    });
}
