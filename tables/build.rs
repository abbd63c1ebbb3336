//! Generates the default stencil tables into OUT_DIR (see `src/lib.rs` for why they are not
//! checked in).

type Generator = fn() -> Result<Vec<u8>, stencilgen::StencilError>;

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    let out = std::env::var_os("OUT_DIR").map(std::path::PathBuf::from);
    let Some(out) = out else {
        eprintln!("OUT_DIR is not set");
        std::process::exit(1);
    };
    let tables: [(&str, Generator); 5] = [
        ("catmull-clark.subtess", stencilgen::table::default_table),
        (
            "catmull-clark-corners.subtess",
            stencilgen::table::default_corner_table,
        ),
        (
            "loop.subtess",
            stencilgen::triangle_table::default_loop_table,
        ),
        (
            "butterfly.subtess",
            stencilgen::butterfly_table::default_butterfly_table,
        ),
        (
            "sqrt3.subtess",
            stencilgen::sqrt3_table::default_sqrt3_table,
        ),
    ];
    for (name, generate) in tables {
        match generate() {
            Ok(bytes) => {
                if let Err(e) = std::fs::write(out.join(name), bytes) {
                    eprintln!("cannot write the table {name}: {e}");
                    std::process::exit(1);
                }
            }
            Err(e) => {
                eprintln!("cannot generate the table {name}: {e}");
                std::process::exit(1);
            }
        }
    }
}
