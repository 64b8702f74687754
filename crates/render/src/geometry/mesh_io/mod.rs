//! Mesh files: Wavefront OBJ (through `tobj`) and PLY (a bounded reader of our own, see
//! [`ply`]), ASCII and binary.
//!
//! Readers return [`MeshData`] — one mesh per file, every group/object merged — and
//! report errors with the file's path and, when it can be known, the line:
//! a missing file, malformed content (the parser's message), a file without triangles,
//! indices out of range, non-finite coordinates.
//!
//! Texture coordinates follow Mitsuba 3's loaders: OBJ `v` is flipped (`v ↦ 1 − v`,
//! Mitsuba's `flip_tex_coords`, on by default there and in [`read_mesh`]), PLY uvs are
//! taken as stored.

pub mod obj;
pub mod ply;

use super::error::{GeometryError, GeometryResult};
use super::mesh_data::MeshData;
use super::transform::Transform;
use super::triangle_mesh::TriangleMesh;
use std::path::Path;

pub use obj::read_obj;
pub use ply::read_ply;

/// The bytes of a mesh file, its size checked against `limits::MESH_FILE_BYTES` before it
/// is read into memory; `format` names it in the error.
fn read_mesh_bytes(path: &Path, format: &'static str) -> GeometryResult<Vec<u8>> {
    if let Ok(m) = std::fs::metadata(path) {
        facette_bsdf::limits::MESH_FILE_BYTES
            .check(m.len())
            .map_err(|e| {
                GeometryError::Malformed {
                    format,
                    message: e.to_string(),
                }
                .in_file(path, None)
            })?;
    }
    std::fs::read(path).map_err(|source| GeometryError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// Reads an `.obj` or `.ply` file (by extension, case-insensitive) with Mitsuba's
/// defaults (OBJ texture coordinates flipped).
pub fn read_mesh(path: &Path) -> GeometryResult<MeshData> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("obj") => read_obj(path, true),
        Some("ply") => read_ply(path),
        _ => Err(GeometryError::UnknownMeshFormat {
            path: path.to_path_buf(),
        }),
    }
}

/// Reads a mesh file and builds the mesh placed by `to_world`; validation errors
/// (indices, non-finite values) name the file.
pub fn load_mesh(
    path: &Path,
    to_world: &Transform,
    flip_normals: bool,
) -> GeometryResult<TriangleMesh> {
    read_mesh(path)?
        .into_mesh(to_world, flip_normals)
        .map_err(|e| match e {
            e @ GeometryError::InFile { .. } => e,
            e => e.in_file(path, None),
        })
}
