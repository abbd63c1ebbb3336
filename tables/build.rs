//! Generates the default stencil tables of the enabled features into OUT_DIR (see `src/lib.rs`
//! for why they are not checked in). A table whose feature is off is not generated: a
//! Catmull–Clark-only build skips the triangle tables' generation.

use std::time::Instant;

type Generator = fn() -> Result<Vec<u8>, stencilgen::StencilError>;

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    let out = std::env::var_os("OUT_DIR").map(std::path::PathBuf::from);
    let Some(out) = out else {
        eprintln!("OUT_DIR is not set");
        std::process::exit(1);
    };
    // (file, the cargo feature that embeds it, as the build script sees it: CARGO_FEATURE_*).
    let tables: [(&str, &str, Generator); 5] = [
        (
            "catmull-clark.subtess",
            "CARGO_FEATURE_CATMULL_CLARK",
            stencilgen::table::default_table,
        ),
        (
            "catmull-clark-corners.subtess",
            "CARGO_FEATURE_CATMULL_CLARK",
            stencilgen::table::default_corner_table,
        ),
        (
            "loop.subtess",
            "CARGO_FEATURE_LOOP",
            stencilgen::triangle_table::default_loop_table,
        ),
        (
            "butterfly.subtess",
            "CARGO_FEATURE_BUTTERFLY",
            stencilgen::butterfly_table::default_butterfly_table,
        ),
        (
            "sqrt3.subtess",
            "CARGO_FEATURE_SQRT3",
            stencilgen::sqrt3_table::default_sqrt3_table,
        ),
    ];
    for (name, feature, generate) in tables {
        if std::env::var_os(feature).is_none() {
            continue;
        }
        let start = Instant::now();
        match generate() {
            Ok(bytes) => {
                if let Err(e) = std::fs::write(out.join(name), &bytes) {
                    eprintln!("cannot write the table {name}: {e}");
                    std::process::exit(1);
                }
                // Not a cargo directive: kept in the build script's `output` file (and shown
                // by `cargo build -vv`), where docs/benchmarks.md reads the generation times.
                println!(
                    "generated {name}: {} bytes in {:.2} s",
                    bytes.len(),
                    start.elapsed().as_secs_f64()
                );
            }
            Err(e) => {
                eprintln!("cannot generate the table {name}: {e}");
                std::process::exit(1);
            }
        }
    }
}
