//! The path tracer against closed forms and against itself: the white furnace, a
//! Lambertian plane under point, directional and disk lights, the three estimators (NEE
//! only, BSDF only, MIS) agreeing block by block, and determinism across thread counts.
//!
//! These cases run on the scalar kernel; `render_integrator_packet.rs` runs the same ones
//! on the packet kernel.

const KERNEL: Kernel = Kernel::Scalar;

include!("integrator_cases/cases.rs");
