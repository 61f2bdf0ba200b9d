//! cargo-fuzz target `serve_request`: the body is `subgram_fuzz::serve_request` (fuzz/src/lib.rs),
//! which `cargo test` also runs on the seed corpus and on every finding
//! (tests/it/fuzz_replay.rs).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| subgram_fuzz::serve_request(data));
