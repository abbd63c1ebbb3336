//! Writing triangle meshes: Wavefront OBJ (positions, normals, triangles).

use std::io::Write;
use std::path::Path;

use crate::triangle_mesh::TriangleMesh;
use crate::RuntimeError;

/// Write `mesh` as OBJ (`v`, `vn`, `f a//a b//b c//c`).
pub fn write_obj(mesh: &TriangleMesh, path: &Path) -> Result<(), RuntimeError> {
    let io = |source: std::io::Error| RuntimeError::Io {
        path: path.display().to_string(),
        source,
    };
    let file = std::fs::File::create(path).map_err(io)?;
    let mut w = std::io::BufWriter::new(file);
    writeln!(
        w,
        "# subtess dual-grid tessellation: {} vertices, {} triangles",
        mesh.positions.len(),
        mesh.triangles.len()
    )
    .map_err(io)?;
    for p in &mesh.positions {
        writeln!(w, "v {} {} {}", p[0], p[1], p[2]).map_err(io)?;
    }
    for n in &mesh.normals {
        writeln!(w, "vn {} {} {}", n[0], n[1], n[2]).map_err(io)?;
    }
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|i| i + 1);
        writeln!(w, "f {a}//{a} {b}//{b} {c}//{c}").map_err(io)?;
    }
    w.flush().map_err(io)
}
