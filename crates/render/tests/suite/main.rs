//! facette-render's integration tests, one module per former test file, in one binary:
//! the workspace links once instead of once per file, and libtest spreads the long tests
//! of every module over the threads. `render_allocations` stays a binary of its own
//! (its counting global allocator must see one render at a time).

mod common;
mod geometry_bvh;
mod geometry_mesh_io;
mod geometry_shapes;
mod image_environment;
mod image_io;
mod image_sky;
mod image_texture;
mod light_sampling;
mod render_glints;
mod render_integrator;
mod render_integrator_packet;
mod render_packet_kernel;
mod render_scenes;
mod scene_mitsuba;
mod scene_mitsuba_errors;
mod scene_mitsuba_render;
mod scene_robustness;
