//! The checks that need the shared corpus beside the project: the lpfg
//! programs of `corpus/lpfg` in the folder that `SUBGRAM_SHARED` names
//! (relative to the project root, or absolute). This target is not part of
//! a plain `cargo test` (`test = false` in Cargo.toml); run it with
//!
//! ```sh
//! SUBGRAM_SHARED=../shared cargo test --test shared
//! ```
//!
//! as `.ci/run` does. Without the variable, or with a folder that lacks a
//! file, every test here fails and says why: nothing passes without
//! checking.

use std::path::PathBuf;

#[path = "../it/golden.rs"]
mod golden;
mod lpfg;
mod render;
mod solid;
#[allow(dead_code)]
#[path = "../it/support.rs"]
mod support;
mod vlab;

/// The shared folder that `SUBGRAM_SHARED` names; panics when the variable
/// is not set or the folder has no `corpus/lpfg`.
pub fn shared() -> PathBuf {
    let Some(dir) = std::env::var_os("SUBGRAM_SHARED") else {
        panic!(
            "SUBGRAM_SHARED is not set. The `shared` tests check the lpfg programs of the \
             shared corpus: run them as `SUBGRAM_SHARED=../shared cargo test --test shared` \
             with the shared folder beside the project"
        );
    };
    let dir = support::root().join(dir);
    assert!(
        dir.join("corpus/lpfg").is_dir(),
        "SUBGRAM_SHARED names {}, which has no corpus/lpfg folder",
        dir.display()
    );
    dir
}

/// `$SUBGRAM_SHARED/corpus/lpfg/NAME`; panics when it is missing.
pub fn corpus(name: &str) -> PathBuf {
    let p = shared().join("corpus/lpfg").join(name);
    assert!(
        p.is_file(),
        "{} is missing from the shared corpus (SUBGRAM_SHARED)",
        p.display()
    );
    p
}
