//! The runtime's integration tests, one binary: every module links the embedded tables, and
//! one binary instead of one per file keeps the test build small (a table-linking binary is
//! about 100 MB) and links once. A module or test that needs a scheme's embedded table is
//! compiled only with that scheme's feature, so that the suite builds on every subset of the
//! tables and runs with one, e.g. `cargo test -p subtess --no-default-features --features
//! catmull-clark`.

// With a subset of the tables, the helpers of the tests left out go unused.
#![cfg_attr(
    not(all(
        feature = "catmull-clark",
        feature = "loop",
        feature = "butterfly",
        feature = "sqrt3"
    )),
    allow(unused)
)]

mod common;

mod bezier;
mod boundary_tessellation;
#[cfg(feature = "butterfly")]
mod butterfly_tessellation;
mod cli;
mod compact_tables;
mod dart_tables;
mod exact_eval;
mod face_varying;
mod fuzz_cases;
mod hostile;
mod lai_cheng;
#[cfg(feature = "loop")]
mod loop_tessellation;
mod mesh_output;
mod models;
#[cfg(feature = "opensubdiv")]
mod opensubdiv_fvar_parity;
#[cfg(feature = "opensubdiv")]
mod opensubdiv_parity;
#[cfg(feature = "opensubdiv")]
mod opensubdiv_random_tags;
mod patches;
mod precision;
mod rates;
mod reader_properties;
mod sharp_features;
mod sqrt3_boundary;
#[cfg(feature = "sqrt3")]
mod sqrt3_tessellation;
mod surface;
mod tables;
mod tagged_exact_eval;
mod tessellate;
#[cfg(all(
    feature = "catmull-clark",
    feature = "loop",
    feature = "butterfly",
    feature = "sqrt3"
))]
mod triangle_rates;
mod watertight;
