//! Which path-tracing kernel renders: the scalar one ([`integrator::radiance`], one camera
//! sample at a time, f64 throughout) or the packet one ([`packet`]: eight camera samples in
//! flight per thread, advanced together one path segment per step, finished lanes refilled
//! at once, the materials that vectorize evaluated and sampled for all eight lanes in one
//! f32 call). Both draw the same numbers from the same sample streams, so their images
//! agree within the f32 rounding of the material computations.
//!
//! [`integrator::radiance`]: crate::integrator::radiance

mod model_calls;
pub mod packet;

/// A render kernel.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Kernel {
    /// The faster of the two for the scene ([`Kernel::resolve`]).
    #[default]
    Auto,
    /// One camera sample at a time, f64.
    Scalar,
    /// Eight camera samples per thread in lock-step, materials in f32 lanes.
    Packet,
}

impl Kernel {
    /// The names in scene files and on the command line, in declaration order.
    pub const NAMES: [&'static str; 3] = ["auto", "scalar", "packet"];

    pub fn name(self) -> &'static str {
        Self::NAMES[self as usize]
    }

    /// The kernel of an exact lowercase name.
    pub fn parse(s: &str) -> Option<Kernel> {
        match s {
            "auto" => Some(Kernel::Auto),
            "scalar" => Some(Kernel::Scalar),
            "packet" => Some(Kernel::Packet),
            _ => None,
        }
    }

    /// The kernel that renders: `Auto` is the packet kernel unless the scene's hierarchy is
    /// too large to be traversed as packets
    /// ([`PACKET_TRAVERSAL_MAX_NODES`](crate::geometry::scene_geometry::PACKET_TRAVERSAL_MAX_NODES)).
    /// There the packet kernel queries the geometry lane by lane and gains nothing: on
    /// `scenes/mesh.toml` (1 M triangles) the two render at the same speed (0.90 and 0.91
    /// Msamples/s), against 1.3–2.6× for the packet kernel on the bench spheres
    /// (docs/performance.md).
    pub fn resolve(self, geometry: &crate::geometry::SceneGeometry) -> Kernel {
        match self {
            Kernel::Auto if geometry.packet_traversal() => Kernel::Packet,
            Kernel::Auto => Kernel::Scalar,
            k => k,
        }
    }
}
