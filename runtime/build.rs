//! Tells the tests whether the models beside the repository are there.
//!
//! `../shared/models` (next to the repository, not in it: a fresh clone does not have it) holds
//! the real meshes many integration tests read. Where it is a folder this sets
//! `cfg(shared_models)`, and the tests that need it run; elsewhere they are marked
//! `#[cfg_attr(not(shared_models), ignore = "...")]` and show as *ignored*, not as passed.
//! `SUBTESS_SHARED_MODELS=DIR` names another folder (relative paths from `runtime/`); a
//! folder that does not exist builds as if `../shared` were absent. The tests read the folder
//! chosen here from `env!("SUBTESS_MODELS_DIR")`.
//!
//! The folder itself is not watched (a `rerun-if-changed` on an absent path would rebuild the
//! crate and its ~100 MB test binary on every run): after adding or removing `../shared` in an
//! existing build, `touch runtime/build.rs` (or `cargo clean -p subtess`).

use std::path::Path;

fn main() {
    println!("cargo::rerun-if-changed=build.rs");
    println!("cargo::rerun-if-env-changed=SUBTESS_SHARED_MODELS");
    println!("cargo::rustc-check-cfg=cfg(shared_models)");
    let manifest = std::env::var("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR");
    let dir = match std::env::var("SUBTESS_SHARED_MODELS") {
        Ok(dir) if !dir.is_empty() => Path::new(&manifest).join(dir),
        _ => Path::new(&manifest).join("../../shared/models"),
    };
    if dir.is_dir() {
        println!("cargo::rustc-cfg=shared_models");
    }
    println!("cargo::rustc-env=SUBTESS_MODELS_DIR={}", dir.display());
}
