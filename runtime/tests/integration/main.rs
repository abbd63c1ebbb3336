//! The runtime's integration tests, one binary: every module links the embedded tables, and
//! one binary instead of one per file keeps the test build small (a table-linking binary is
//! about 100 MB) and links once.

mod common;

mod bezier;
mod boundary_tessellation;
mod butterfly_tessellation;
mod cli;
mod compact_tables;
mod dart_tables;
mod exact_eval;
mod face_varying;
mod fuzz_cases;
mod hostile;
mod lai_cheng;
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
mod sqrt3_tessellation;
mod surface;
mod tables;
mod tagged_exact_eval;
mod tessellate;
mod triangle_rates;
mod watertight;
