//! Fuzz target `obj_reader`: see `tests/fuzz_harness/mod.rs` (shared with `tests/fuzz_smoke.rs`).
#![no_main]

#[path = "../../tests/fuzz_harness/mod.rs"]
mod harness;

libfuzzer_sys::fuzz_target!(|data: &[u8]| harness::obj(data));
