//! Geometry: rays, transforms, shapes, meshes and the BVH.
