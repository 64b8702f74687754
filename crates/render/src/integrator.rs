//! The unidirectional path tracer: next-event estimation to one light per vertex chosen by
//! power, BSDF sampling, multiple importance sampling of both with the power heuristic
//! (Veach 1997), Russian roulette, delta lobes, stochastic BSDFs (their `eval` is an
//! unbiased estimate drawn from the same random stream), and radiance scaling across
//! refraction (the BSDF's radiance-mode weights carry (η_o/η_i)²; Russian roulette looks at
//! the throughput with that factor removed, as pbrt-v4 does).
//!
//! Random numbers come from the camera sample's [`SampleStream`], in a fixed layout of
//! dimensions so that a low-discrepancy sampler stratifies each decision across the
//! pixel's samples: the camera takes dimensions 0–3 (filter, lens), and the path vertex
//! `k` (the first hit is 0) the block of [`VERTEX_DIMENSIONS`] starting at
//! `CAMERA_DIMENSIONS + k · VERTEX_DIMENSIONS`: light selection (1), light position (2),
//! BSDF lobe (1), BSDF direction (2), Russian roulette (1). The block does not depend on
//! how many numbers earlier vertices used. Numbers without a dimension — a stochastic
//! BSDF's evaluation, a sampler's draws beyond its lobe and direction — come from the
//! sample's own PCG stream.
//!
//! A number nothing reads is not drawn: a pinhole camera's lens pair, the light choice
//! when one light can be chosen, the position pair when every light is a delta light, the
//! lobe number of a model that has one lobe (the BSDF's source draws its numbers as the
//! model asks, [`PrefixedSource`]). A dimensioned sampler's value does not depend on which
//! other dimensions were drawn, so this saves the sampler's hashing and changes no image;
//! the independent sampler still draws them all, in its old order.
//!
//! Shading uses the shading normal's frame; a direction whose side of the geometric normal
//! disagrees with its side of the shading normal is discarded (no light leaks through
//! interpolated normals). Texture footprints come from the camera ray's differentials at
//! the first vertex; later vertices point-sample their textures.

use crate::geometry::{HitDetail, Ray, RayDifferential, SurfaceHit, Vec3};
use crate::lights::Light;
use crate::pixel_footprint::{pixel_shading, PixelRay};
use crate::sampler::{PrefixedSource, SampleStream};
use crate::scene::Scene;
use facette_bsdf::{BsdfContext, LobeFlags, Spectrum};

/// Dimensions the camera sample takes: the filter offset (2) and the lens position (2).
pub const CAMERA_DIMENSIONS: u32 = 4;
/// Dimensions each path vertex takes: light selection (1), light position (2), BSDF lobe
/// (1), BSDF direction (2), Russian roulette (1).
pub const VERTEX_DIMENSIONS: u32 = 7;

#[inline]
pub(crate) fn power_heuristic(a: f64, b: f64) -> f64 {
    let (a2, b2) = (a * a, b * b);
    if a2 + b2 == 0.0 {
        0.0
    } else {
        a2 / (a2 + b2)
    }
}

/// Which estimators contribute (the full integrator uses both; the others exist to test
/// that each is unbiased on its own).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Strategy {
    /// Next-event estimation and BSDF sampling combined by MIS.
    Mis,
    /// Light sampling only (emitters hit by BSDF samples are ignored).
    NeeOnly,
    /// BSDF sampling only (no shadow rays).
    BsdfOnly,
}

/// The BSDF context of a render: radiance transport, and whether the density of a BSDF
/// sample is read. Only MIS reads it, to weight emission that the sampled ray finds, and
/// only a light that is not a delta light can be found: with delta lights only, or another
/// strategy, models may skip computing it ([`BsdfContext::skip_sample_pdf`]).
pub(crate) fn bsdf_context(scene: &Scene, strategy: Strategy) -> BsdfContext {
    let read = strategy == Strategy::Mis && scene.lights.iter().any(|l| !l.is_delta());
    if read {
        BsdfContext::RADIANCE
    } else {
        BsdfContext::RADIANCE.without_sample_pdf()
    }
}

/// Radiance arriving at the camera along `ray`.
pub fn radiance(
    scene: &Scene,
    ray: Ray,
    rd: Option<RayDifferential>,
    pixel: Option<PixelRay>,
    sampler: &mut SampleStream,
    strategy: Strategy,
) -> Spectrum {
    let settings = scene.integrator;
    let ctx = bsdf_context(scene, strategy);
    let mut l = Spectrum::ZERO;
    let mut beta = Spectrum::ONE;
    let mut ray = ray;
    let mut delta_prev = true;
    let mut prev_pdf = 0.0;
    let mut prev_p = ray.origin;
    let mut eta_scale = 1.0;
    // Segment count: the camera ray is segment 1.
    let mut segment = 1u32;
    loop {
        // Untextured materials read no uv: the hit's details are completed only for the
        // materials that do (textures, glints).
        let hit = scene.geometry.intersect_with(&ray, HitDetail::Shading);
        let Some(mut hit) = hit else {
            if let Some(env) = scene.environment {
                if let Light::Environment(e) = &scene.lights[env as usize] {
                    let (le, pdf) = e.eval_pdf(ray.dir);
                    let w = match strategy {
                        _ if delta_prev => 1.0,
                        Strategy::Mis => {
                            let pl = scene.selector.probability(env as usize) * pdf;
                            power_heuristic(prev_pdf, pl)
                        }
                        Strategy::NeeOnly => 0.0,
                        Strategy::BsdfOnly => 1.0,
                    };
                    l += beta * le * w;
                }
            }
            break;
        };
        // Emission of an area light.
        if let Some(li) = scene.shape_light[hit.shape as usize] {
            let light = &scene.lights[li as usize];
            let le = light.emitted(hit.ng, -ray.dir);
            if !le.is_black() {
                let w = match strategy {
                    _ if delta_prev => 1.0,
                    Strategy::Mis => {
                        let pl = scene.selector.probability(li as usize)
                            * light.pdf_area_hit(&scene.geometry, prev_p, hit.p, hit.ng, hit.prim);
                        power_heuristic(prev_pdf, pl)
                    }
                    Strategy::NeeOnly => 0.0,
                    Strategy::BsdfOnly => 1.0,
                };
                l += beta * le * w;
            }
        }
        if segment >= settings.max_depth {
            break;
        }
        let material = &scene.materials[scene.shape_material[hit.shape as usize] as usize];
        let mut derivs = [0.0; 4];
        // The pixel's footprint replaces the hit's uv, derivatives and frame (glints with
        // `footprint = "pixel"` at a camera ray's hit).
        let mut centre = None;
        if material.reads_surface_details() {
            scene.geometry.complete_hit(&mut hit);
            if let (Some(d), 1) = (&rd, segment) {
                centre = pixel
                    .filter(|_| material.reads_pixel_footprint())
                    .and_then(|p| pixel_shading(scene, &hit, ray.dir, &p));
                if centre.is_none() {
                    derivs = hit.uv_derivatives(d);
                }
            }
        }
        let (uv, derivs, frame) = match centre {
            Some(c) => (c.uv, c.derivs, c.frame),
            None => (hit.uv, derivs, hit.shading_frame()),
        };
        let Some(bsdf) = material.bsdf(uv, derivs) else {
            break;
        };
        let wo = frame.to_local(-ray.dir);
        let flags = bsdf.flags();
        // This vertex's block of dimensions; a decision that is not taken (no light
        // sampling from a delta BSDF, no roulette yet) leaves its dimensions undrawn.
        let block = CAMERA_DIMENSIONS + (segment - 1) * VERTEX_DIMENSIONS;
        // Next-event estimation.
        if flags.has_smooth_part() && strategy != Strategy::BsdfOnly {
            let u = light_numbers(scene, sampler, block);
            l += beta * sample_light(scene, &hit, &frame, wo, &*bsdf, u, sampler, strategy);
        }
        // Continue by BSDF sampling (the lobe and direction numbers are drawn as the
        // model asks for them).
        let mut source = PrefixedSource::new(sampler, block + 3);
        let Some(s) = bsdf.sample(wo, &ctx, &mut source) else {
            break;
        };
        let wi = frame.to_world(s.wi);
        if !consistent_side(&hit, wi, s.wi) || s.weight.is_black() {
            break;
        }
        beta *= s.weight;
        delta_prev = s.lobe.is_delta();
        prev_pdf = s.pdf;
        prev_p = hit.p;
        if s.lobe.intersects(LobeFlags::TRANSMISSION) {
            eta_scale *= s.eta * s.eta;
        }
        segment += 1;
        if segment > settings.rr_depth {
            let q = (beta.max_component() * eta_scale).min(0.95);
            sampler.set_dimension(block + 6);
            if !(q > 0.0) || sampler.get_1d() >= q {
                break;
            }
            beta /= q;
        }
        ray = hit.spawn_ray(wi);
    }
    l
}

/// A vertex's light-selection number and light-position pair, from its block of dimensions
/// starting at `block`; a number no light reads is left undrawn (see
/// [`SampleStream::get_1d_where`]).
#[inline]
pub(crate) fn light_numbers(
    scene: &Scene,
    sampler: &mut SampleStream,
    block: u32,
) -> (f64, crate::geometry::Vec2) {
    sampler.set_dimension(block);
    let select = sampler.get_1d_where(scene.selector.reads_selection_number());
    let position = sampler.get_2d_where(scene.selector.reads_position_numbers());
    (select, position)
}

/// The shading-normal side of a world direction must match its geometric side.
#[inline]
fn consistent_side(hit: &SurfaceHit, wi_world: Vec3, wi_local: Vec3) -> bool {
    wi_world.dot(hit.ng) * wi_local.z > 0.0
}

/// One light sample, from the light-selection and light-position numbers `u`: its
/// MIS-weighted contribution (without the path throughput).
#[allow(clippy::too_many_arguments)]
fn sample_light(
    scene: &Scene,
    hit: &SurfaceHit,
    frame: &facette_bsdf::math::Frame,
    wo: Vec3,
    bsdf: &dyn facette_bsdf::Bsdf,
    u: (f64, crate::geometry::Vec2),
    sampler: &mut SampleStream,
    strategy: Strategy,
) -> Spectrum {
    let Some((k, p_select)) = scene.selector.select(u.0) else {
        return Spectrum::ZERO;
    };
    let u = u.1;
    let rng = sampler.rng();
    let light = &scene.lights[k];
    let Some(ls) = light.sample(&scene.geometry, hit.p, u) else {
        return Spectrum::ZERO;
    };
    if ls.radiance.is_black() {
        return Spectrum::ZERO;
    }
    let wi = frame.to_local(ls.wi);
    if !consistent_side(hit, ls.wi, wi) {
        return Spectrum::ZERO;
    }
    let ctx = BsdfContext::RADIANCE;
    let f = bsdf.eval(wo, wi, &ctx, rng) * wi.z.abs();
    if f.is_black() {
        return Spectrum::ZERO;
    }
    if scene
        .geometry
        .occluded_ray(&ls.shadow.ray::<f64>(hit.p, hit.ng))
    {
        return Spectrum::ZERO;
    }
    let pl = p_select * ls.pdf;
    let w = if ls.delta || strategy == Strategy::NeeOnly {
        1.0
    } else {
        power_heuristic(pl, bsdf.pdf(wo, wi, &ctx))
    };
    f * ls.radiance * (w / pl)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::load_scene_str;
    use std::path::Path;

    fn scene(extra: &str) -> Scene {
        let src = format!(
            r#"
            [camera]
            position = [0, 0, 4]
            target = [0, 0, 0]
            [[objects]]
            shape = "sphere"
            radius = 1
            material = {{ type = "diffuse" }}
            {extra}
            "#
        );
        load_scene_str(&src, Path::new("t.toml")).unwrap()
    }

    /// MIS reads a BSDF sample's density only where a sampled ray can find emission: not
    /// with delta lights only, and never without MIS.
    #[test]
    fn a_sample_density_is_read_only_where_mis_weighs_found_emission() {
        let point = scene("[[lights]]\ntype = \"point\"\nposition = [2, 2, 2]\nintensity = 5");
        let sky = scene("[[lights]]\ntype = \"constant\"\nradiance = 1.0");
        let area = scene(
            "[[objects]]\nshape = \"sphere\"\ncenter = [3, 0, 0]\nradius = 0.5\nemission = 2.0",
        );
        let skips = |s: &Scene, strategy| bsdf_context(s, strategy).skip_sample_pdf;
        assert!(skips(&point, Strategy::Mis));
        assert!(!skips(&sky, Strategy::Mis));
        assert!(!skips(&area, Strategy::Mis));
        for s in [&point, &sky, &area] {
            assert!(skips(s, Strategy::NeeOnly) && skips(s, Strategy::BsdfOnly));
        }
    }
}
