//! Generates the default stencil table into OUT_DIR (see `src/lib.rs` for why it is not
//! checked in).

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    let out = std::env::var_os("OUT_DIR").map(std::path::PathBuf::from);
    let Some(out) = out else {
        eprintln!("OUT_DIR is not set");
        std::process::exit(1);
    };
    match stencilgen::table::default_table() {
        Ok(bytes) => {
            if let Err(e) = std::fs::write(out.join("catmull-clark.subtess"), bytes) {
                eprintln!("cannot write the default table: {e}");
                std::process::exit(1);
            }
        }
        Err(e) => {
            eprintln!("cannot generate the default table: {e}");
            std::process::exit(1);
        }
    }
}
