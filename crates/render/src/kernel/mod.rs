//! Which path-tracing kernel renders: the scalar one ([`integrator::radiance`], one camera
//! sample at a time, f64 throughout) or the packet one ([`packet`]: eight camera samples in
//! flight per thread, advanced together one path segment per step, finished lanes refilled
//! at once, the materials that vectorize evaluated and sampled for all eight lanes in one
//! f32 call). Both draw the same numbers from the same sample streams, so their images
//! agree within the f32 rounding of the material computations.
//!
//! [`integrator::radiance`]: crate::integrator::radiance

pub mod packet;

/// A render kernel.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Kernel {
    /// One camera sample at a time, f64.
    #[default]
    Scalar,
    /// Eight camera samples per thread in lock-step, materials in f32 lanes.
    Packet,
}

impl Kernel {
    /// The names in scene files and on the command line, in declaration order.
    pub const NAMES: [&'static str; 2] = ["scalar", "packet"];

    pub fn name(self) -> &'static str {
        Self::NAMES[self as usize]
    }

    /// The kernel of an exact lowercase name.
    pub fn parse(s: &str) -> Option<Kernel> {
        match s {
            "scalar" => Some(Kernel::Scalar),
            "packet" => Some(Kernel::Packet),
            _ => None,
        }
    }
}
