//! cargo-fuzz target `vv_run`: the body is `subgram_fuzz::vv_run` (fuzz/src/lib.rs),
//! which `cargo test` also runs on the seed corpus and on every finding
//! (tests/it/fuzz_replay.rs).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| subgram_fuzz::vv_run(data));
