//! The unidirectional path tracer: next-event estimation to one light per vertex chosen by
//! power, BSDF sampling, multiple importance sampling of both with the power heuristic
//! (Veach 1997), Russian roulette, delta lobes, stochastic BSDFs (their `eval` is an
//! unbiased estimate drawn from the same random stream), and radiance scaling across
//! refraction (the BSDF's radiance-mode weights carry (η_o/η_i)²; Russian roulette looks at
//! the throughput with that factor removed, as pbrt-v4 does).
//!
//! Shading uses the shading normal's frame; a direction whose side of the geometric normal
//! disagrees with its side of the shading normal is discarded (no light leaks through
//! interpolated normals). Texture footprints come from the camera ray's differentials at
//! the first vertex; later vertices point-sample their textures.

use crate::geometry::{Ray, RayDifferential, SurfaceHit, Vec3};
use crate::lights::Light;
use crate::scene::Scene;
use facette_bsdf::math::rng::{Pcg32, RandomSource};
use facette_bsdf::{BsdfContext, LobeFlags, Spectrum};

#[inline]
fn power_heuristic(a: f64, b: f64) -> f64 {
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

/// Radiance arriving at the camera along `ray`.
pub fn radiance(
    scene: &Scene,
    ray: Ray,
    rd: Option<RayDifferential>,
    rng: &mut Pcg32,
    strategy: Strategy,
) -> Spectrum {
    let settings = scene.integrator;
    let ctx = BsdfContext::RADIANCE;
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
        let hit = scene.geometry.intersect(&ray);
        let Some(hit) = hit else {
            if let Some(env) = scene.environment {
                if let Light::Environment(e) = &scene.lights[env as usize] {
                    let le = e.eval(ray.dir);
                    let w = match strategy {
                        _ if delta_prev => 1.0,
                        Strategy::Mis => {
                            let pl = scene.selector.probability(env as usize) * e.pdf(ray.dir);
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
                            * light.pdf_area_hit(&scene.geometry, prev_p, hit.p, hit.ng);
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
        let derivs = match (&rd, segment) {
            (Some(d), 1) => hit.uv_derivatives(d),
            _ => [0.0; 4],
        };
        let material = &scene.materials[scene.shape_material[hit.shape as usize] as usize];
        let Some(bsdf) = material.bsdf(hit.uv, derivs) else {
            break;
        };
        let frame = hit.shading_frame();
        let wo = frame.to_local(-ray.dir);
        let flags = bsdf.flags();
        // Next-event estimation.
        if flags.has_smooth_part() && strategy != Strategy::BsdfOnly {
            l += beta * sample_light(scene, &hit, &frame, wo, &*bsdf, rng, strategy);
        }
        // Continue by BSDF sampling.
        let Some(s) = bsdf.sample(wo, &ctx, rng) else {
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
            if !(q > 0.0) || rng.next_f64() >= q {
                break;
            }
            beta /= q;
        }
        ray = hit.spawn_ray(wi);
    }
    l
}

/// The shading-normal side of a world direction must match its geometric side.
#[inline]
fn consistent_side(hit: &SurfaceHit, wi_world: Vec3, wi_local: Vec3) -> bool {
    wi_world.dot(hit.ng) * wi_local.z > 0.0
}

/// One light sample: its MIS-weighted contribution (without the path throughput).
fn sample_light(
    scene: &Scene,
    hit: &SurfaceHit,
    frame: &facette_bsdf::math::Frame,
    wo: Vec3,
    bsdf: &dyn facette_bsdf::Bsdf,
    rng: &mut Pcg32,
    strategy: Strategy,
) -> Spectrum {
    let Some((k, p_select)) = scene.selector.select(rng.next_f64()) else {
        return Spectrum::ZERO;
    };
    let u = rng.next_2d();
    let light = &scene.lights[k];
    let Some(ls) = light.sample(&scene.geometry, hit.p, hit.ng, u) else {
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
    if scene.geometry.occluded_ray(&ls.shadow) {
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
