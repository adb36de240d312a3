//! Fuzz target `gear_pair_json`: the body is `fuzz_harness::gear_pair_json` (shared with `tests/fuzz_corpus.rs`).
#![no_main]

#[allow(dead_code)]
#[path = "../../tests/fuzz_harness/mod.rs"]
mod fuzz_harness;

libfuzzer_sys::fuzz_target!(|data: &[u8]| fuzz_harness::gear_pair_json(data));
