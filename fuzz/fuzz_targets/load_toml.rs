//! The loader on arbitrary TOML text: a clear error or a mechanism, never a
//! panic, and every error's span inside the file.
#![no_main]

use dofplan::model::Format;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = dofplan_tests::fuzzing::load(data, Format::Toml);
});
