//! The interpreter on arbitrary files: a planned mechanism run over a few
//! frames of its sweep, extreme input values and a short drag; frames that
//! claim a valid pose must hold their joints.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = dofplan_tests::fuzzing::interpret(data);
});
