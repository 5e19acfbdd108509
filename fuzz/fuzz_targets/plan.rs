//! The planner on arbitrary files (TOML, or JSON when the text starts with
//! `{`): load, analyse, the rank cross-check and the plan's explanation.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = dofplan_tests::fuzzing::plan(data);
});
