//! The integrator's closed-form and self-consistency cases (`render_integrator.rs`) on the
//! packet kernel: eight paths per thread, the lane models in f32 lanes, the other
//! materials through their f64 models lane by lane.

const KERNEL: Kernel = Kernel::Packet;

include!("integrator_cases/cases.rs");
