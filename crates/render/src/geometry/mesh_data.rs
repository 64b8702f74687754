//! Raw triangle-mesh arrays, as a loader or a generator produces them, before validation.

use super::error::GeometryResult;
use super::transform::Transform;
use super::triangle_mesh::TriangleMesh;
use super::{Vec2, Vec3};

/// Vertex arrays and a triangle index list (three `u32` per triangle, counter-clockwise
/// = front). Nothing is checked here: [`MeshData::into_mesh`] (through
/// [`TriangleMesh::new`]) validates counts, indices and finiteness.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshData {
    pub positions: Vec<Vec3>,
    /// Per-vertex shading normals (same count as `positions`) or none.
    pub normals: Option<Vec<Vec3>>,
    /// Per-vertex texture coordinates (same count as `positions`) or none.
    pub uvs: Option<Vec<Vec2>>,
    pub indices: Vec<u32>,
}

impl MeshData {
    #[inline]
    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }

    /// Validates the data and builds the mesh, placed by `to_world`.
    pub fn into_mesh(
        self,
        to_world: &Transform,
        flip_normals: bool,
    ) -> GeometryResult<TriangleMesh> {
        TriangleMesh::new(
            self.positions,
            self.normals,
            self.uvs,
            self.indices,
            to_world,
            flip_normals,
        )
    }
}
