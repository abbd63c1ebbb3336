//! The OBJ reader with `t` tags: `parse_obj`, then `Mesh::from_obj` (topology, tags, bounds),
//! then for small meshes the Catmull–Clark surface's isolation and patches
//! (`Surface::with_table`). The surface gets a table with no sections, made once: isolation
//! reads none, and the embedded default table would be checksummed (57 MB) at every input.

#![no_main]

use std::sync::OnceLock;

use libfuzzer_sys::fuzz_target;
use subtess::{Mesh, Scheme, StencilTable, Surface};
use table_format::{Precision, SchemeId, TableMeta};

/// Meshes up to this many faces (and four times as many vertices) are also made into a
/// surface: isolation refines at most `MAX_STEPS` = 3 times, 64 times the faces.
const SURFACE_FACES: usize = 64;

fn empty_table(corners: bool) -> &'static [u8] {
    static TABLES: [OnceLock<Vec<u8>>; 2] = [OnceLock::new(), OnceLock::new()];
    TABLES[usize::from(corners)].get_or_init(|| {
        let meta = TableMeta {
            scheme: SchemeId::CatmullClark,
            precision: Precision::F32,
            corners,
        };
        table_format::encode(meta, &[]).expect("an empty Catmull-Clark table encodes")
    })
}

fuzz_target!(|data: &[u8]| {
    // Files are read as UTF-8 text (`read_to_string`): other bytes never reach the parser.
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(obj) = subtess::io::obj::parse_obj(text) else {
        return;
    };
    let Ok((mesh, _warnings)) = Mesh::from_obj(&obj) else {
        return;
    };
    if mesh.faces() > SURFACE_FACES || mesh.positions.len() > 4 * SURFACE_FACES {
        return;
    }
    let corners = mesh.boundary == subtess::BoundaryMode::EdgeAndCorner;
    let table = StencilTable::from_bytes(empty_table(corners)).expect("the empty table is valid");
    let _ = Surface::with_table(&mesh, Scheme::CatmullClark, table);
});
