//! Vertex normals for meshes that have none, as Mitsuba 3 makes them (unless a shape says
//! `face_normals`): each vertex takes the sum of the unit normals of its triangles
//! weighted by the triangle's angle at that vertex (Thürmer & Wüthrich, "Computing vertex
//! normals from polygonal facets", JGT 3(1), 1998), computed on the world-space
//! positions, as Mitsuba does after applying `to_world`.

use super::{MeshData, Transform, Vec3};

/// Gives `data` angle-weighted vertex normals computed in world space (placed by
/// `to_world`) and returned to object space, so that the mesh's own normal transform
/// takes them back exactly. A vertex whose triangles are all degenerate keeps the normal
/// of no triangle: it gets +z (such a vertex is never hit by a ray).
pub fn add_vertex_normals(data: &mut MeshData, to_world: &Transform) {
    let world: Vec<Vec3> = data.positions.iter().map(|p| to_world.point(*p)).collect();
    let mut sums = vec![Vec3::ZERO; world.len()];
    for t in data.indices.chunks_exact(3) {
        let idx = [t[0] as usize, t[1] as usize, t[2] as usize];
        if idx.iter().any(|&i| i >= world.len()) {
            // Left for the mesh's own validation to report.
            return;
        }
        let [a, b, c] = idx.map(|i| world[i]);
        let n = (b - a).cross(c - a).normalize_or_zero();
        if n == Vec3::ZERO {
            continue;
        }
        for k in 0..3 {
            let p = world[idx[k]];
            let d0 = (world[idx[(k + 1) % 3]] - p).normalize_or_zero();
            let d1 = (world[idx[(k + 2) % 3]] - p).normalize_or_zero();
            let angle = d0.dot(d1).clamp(-1.0, 1.0).acos();
            sums[idx[k]] += n * angle;
        }
    }
    let m = to_world.matrix();
    let linear_t = glam::DMat3::from_cols(
        m.x_axis.truncate(),
        m.y_axis.truncate(),
        m.z_axis.truncate(),
    )
    .transpose();
    data.normals = Some(
        sums.into_iter()
            .map(|s| {
                let n = s.normalize_or_zero();
                let n = if n == Vec3::ZERO { Vec3::Z } else { n };
                // The mesh maps object normals by the inverse transpose: Mᵀ undoes it.
                (linear_t * n).normalize_or_zero()
            })
            .collect(),
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_tetrahedron_corner_gets_the_angle_weighted_mean_of_its_faces() {
        // Corner of the unit cube's positive octant: three right-angled faces meet at the
        // origin, each with angle π/2, so the normal is −(1, 1, 1)/√3 (outward).
        let mut data = MeshData {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z],
            normals: None,
            uvs: None,
            indices: vec![0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3],
        };
        let t = Transform::scale(Vec3::new(2.0, 1.0, 1.0)).unwrap();
        add_vertex_normals(&mut data, &t);
        let mesh = data.into_mesh(&t, false).unwrap();
        let n0 = mesh.normals().unwrap()[0];
        // In world space the faces at the origin are still the three coordinate planes.
        let expect = -Vec3::ONE.normalize();
        assert!((n0 - expect).length() < 1e-12, "{n0}");
    }
}
