//! Lights: point, spot and directional (delta) lights, area lights (emissive shapes) and
//! the environment (an importance-sampled map, or a constant radiance). Lights are chosen
//! for next-event estimation by [`LightSelector`]; an area light is
//! sampled by the solid angle its shape subtends from the shading point
//! ([`solid_angle_sampling`](crate::geometry::solid_angle_sampling)).

use crate::geometry::ray::ShadowEnd;
use crate::geometry::{SceneGeometry, Vec2, Vec3};
use crate::image::{ConstantEnvironment, EnvironmentMap};
use facette_bsdf::math::Frame;
use facette_bsdf::Spectrum;
use std::f64::consts::PI;

/// An environment: a map or a constant radiance, looked up by world direction.
#[derive(Clone, Debug)]
pub enum Environment {
    Map(Box<EnvironmentMap>),
    Constant(ConstantEnvironment),
}

impl Environment {
    #[inline]
    pub fn eval(&self, d: Vec3) -> Spectrum {
        match self {
            Environment::Map(m) => m.eval(d),
            Environment::Constant(c) => c.eval(d),
        }
    }

    #[inline]
    pub fn pdf(&self, d: Vec3) -> f64 {
        match self {
            Environment::Map(m) => m.pdf(d),
            Environment::Constant(c) => c.pdf(d),
        }
    }

    /// `(eval(d), pdf(d))`, for a map from one look-up of the direction's texel.
    #[inline]
    pub fn eval_pdf(&self, d: Vec3) -> (Spectrum, f64) {
        match self {
            Environment::Map(m) => m.eval_pdf(d),
            Environment::Constant(c) => (c.eval(d), c.pdf(d)),
        }
    }

    /// (direction, radiance, solid-angle pdf).
    #[inline]
    pub fn sample(&self, u: Vec2) -> Option<(Vec3, Spectrum, f64)> {
        let s = match self {
            Environment::Map(m) => m.sample(u),
            Environment::Constant(c) => c.sample(u),
        }?;
        Some((s.direction, s.radiance, s.pdf))
    }

    pub fn mean_radiance(&self) -> Spectrum {
        match self {
            Environment::Map(m) => m.mean_radiance(),
            Environment::Constant(c) => c.mean_radiance(),
        }
    }
}

/// A light of the scene.
#[derive(Clone, Debug)]
pub enum Light {
    /// Isotropic point light of intensity I (W/sr per channel).
    Point { position: Vec3, intensity: Spectrum },
    /// Spot light: intensity I along `frame.n`, full up to `beam` (radians), falling off
    /// linearly in angle to zero at `cutoff` (Mitsuba 3's `spot`).
    Spot {
        position: Vec3,
        frame: Frame,
        intensity: Spectrum,
        cutoff: f64,
        beam: f64,
    },
    /// Distant light arriving along `-direction`… i.e. travelling along `direction`, with
    /// irradiance E on surfaces facing it.
    Directional {
        direction: Vec3,
        irradiance: Spectrum,
    },
    /// An emissive shape: radiance L leaving its front side (both sides if `two_sided`).
    Area {
        shape: u32,
        radiance: Spectrum,
        two_sided: bool,
    },
    /// The environment, seen by rays that leave the scene.
    Environment(Environment),
}

/// A light sample for next-event estimation from a shading point.
#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    /// Unit direction from the shading point toward the light.
    pub wi: Vec3,
    /// Radiance (or, for delta lights, radiant intensity / distance²) arriving along `wi`.
    pub radiance: Spectrum,
    /// Solid-angle pdf of `wi` (1 for delta lights).
    pub pdf: f64,
    pub delta: bool,
    /// Where the shadow ray from the shading point ends ([`ShadowEnd::ray`] makes it).
    pub shadow: ShadowEnd,
}

impl Light {
    /// Whether the light is at infinity (the environment, a directional light).
    pub fn is_infinite(&self) -> bool {
        matches!(self, Light::Directional { .. } | Light::Environment(_))
    }

    /// Whether [`sample`](Self::sample) reads its `u` (a position on an area light, a
    /// direction of the environment); a delta light's sample is fixed.
    pub fn reads_position_numbers(&self) -> bool {
        !self.is_delta()
    }

    pub fn is_delta(&self) -> bool {
        matches!(
            self,
            Light::Point { .. } | Light::Spot { .. } | Light::Directional { .. }
        )
    }

    /// Spot falloff for a cosine to the axis.
    fn spot_falloff(cos: f64, cutoff: f64, beam: f64) -> f64 {
        let angle = cos.clamp(-1.0, 1.0).acos();
        if angle <= beam {
            1.0
        } else if angle >= cutoff {
            0.0
        } else {
            (cutoff - angle) / (cutoff - beam)
        }
    }

    /// Estimate of the emitted power (luminance), for light selection; `radius` is the
    /// scene's bounding-sphere radius.
    pub fn power(&self, geometry: &SceneGeometry, radius: f64) -> f64 {
        match self {
            Light::Point { intensity, .. } => 4.0 * PI * intensity.luminance(),
            Light::Spot {
                intensity,
                cutoff,
                beam,
                ..
            } => 2.0 * PI * (1.0 - 0.5 * (cutoff.cos() + beam.cos())) * intensity.luminance(),
            Light::Directional { irradiance, .. } => PI * radius * radius * irradiance.luminance(),
            Light::Area {
                shape,
                radiance,
                two_sided,
            } => {
                let sides = if *two_sided { 2.0 } else { 1.0 };
                PI * sides * geometry.shape_area(*shape) * radiance.luminance()
            }
            Light::Environment(e) => PI * PI * radius * radius * e.mean_radiance().luminance(),
        }
        .max(0.0)
    }

    /// Samples the light from the shading point `p`; the shadow ray is made from the
    /// sample's [`ShadowEnd`] with the point's geometric normal.
    pub fn sample(&self, geometry: &SceneGeometry, p: Vec3, u: Vec2) -> Option<LightSample> {
        match self {
            Light::Point {
                position,
                intensity,
            } => {
                let d = *position - p;
                let dist2 = d.length_squared();
                if dist2 <= 0.0 {
                    return None;
                }
                Some(LightSample {
                    wi: d / dist2.sqrt(),
                    radiance: *intensity / dist2,
                    pdf: 1.0,
                    delta: true,
                    shadow: ShadowEnd::Point(*position),
                })
            }
            Light::Spot {
                position,
                frame,
                intensity,
                cutoff,
                beam,
            } => {
                let d = *position - p;
                let dist2 = d.length_squared();
                if dist2 <= 0.0 {
                    return None;
                }
                let wi = d / dist2.sqrt();
                let f = Self::spot_falloff((-wi).dot(frame.n), *cutoff, *beam);
                if f <= 0.0 {
                    return None;
                }
                Some(LightSample {
                    wi,
                    radiance: *intensity * (f / dist2),
                    pdf: 1.0,
                    delta: true,
                    shadow: ShadowEnd::Point(*position),
                })
            }
            Light::Directional {
                direction,
                irradiance,
            } => {
                let wi = -*direction;
                Some(LightSample {
                    wi,
                    radiance: *irradiance,
                    pdf: 1.0,
                    delta: true,
                    shadow: ShadowEnd::Away(wi),
                })
            }
            Light::Area {
                shape,
                radiance,
                two_sided,
            } => {
                let s = geometry.sample_shape_from(*shape, p, u)?;
                let (q, nq) = (s.point, s.normal);
                if !(s.pdf > 0.0 && s.pdf.is_finite()) {
                    return None;
                }
                let d = q - p;
                let dist = d.length();
                if !(dist > 0.0) {
                    return None;
                }
                let wi = d / dist;
                let cos_l = nq.dot(-wi);
                if (cos_l <= 0.0 && !two_sided) || cos_l.abs() <= 1e-12 {
                    return None;
                }
                Some(LightSample {
                    wi,
                    radiance: *radiance,
                    pdf: s.pdf,
                    delta: false,
                    shadow: ShadowEnd::Surface { q, nq },
                })
            }
            Light::Environment(e) => {
                let (wi, radiance, pdf) = e.sample(u)?;
                if !(pdf > 0.0) {
                    return None;
                }
                Some(LightSample {
                    wi,
                    radiance,
                    pdf,
                    delta: false,
                    shadow: ShadowEnd::Away(wi),
                })
            }
        }
    }

    /// Solid-angle pdf with which `sample` from `p` produces the direction that hits this
    /// (area) light at `q` with normal `nq`, on primitive `prim` of its shape (the triangle
    /// of a mesh).
    pub fn pdf_area_hit(
        &self,
        geometry: &SceneGeometry,
        p: Vec3,
        q: Vec3,
        nq: Vec3,
        prim: u32,
    ) -> f64 {
        match self {
            Light::Area {
                shape, two_sided, ..
            } => {
                let cos_l = nq.dot(p - q);
                if cos_l <= 0.0 && !two_sided {
                    return 0.0;
                }
                geometry.shape_pdf_from(*shape, prim, p, q, nq)
            }
            _ => 0.0,
        }
    }

    /// Radiance leaving an area light's point with normal `n` toward `w`.
    #[inline]
    pub fn emitted(&self, n: Vec3, w: Vec3) -> Spectrum {
        match self {
            Light::Area {
                radiance,
                two_sided,
                ..
            } => {
                if n.dot(w) > 0.0 || *two_sided {
                    *radiance
                } else {
                    Spectrum::ZERO
                }
            }
            _ => Spectrum::ZERO,
        }
    }
}

/// Picks the light for next-event estimation. Lights at a finite distance are picked in
/// proportion to their power; each light at infinity (the environment, a directional
/// light) is picked as often as all finite lights together — pbrt-v4's rule for infinite
/// lights — because their power reaching the scene is not known from the scene's bounding
/// sphere: the estimate `π r² E` overstates an environment's share in a scene with a large
/// floor and starves the nearby lights that dominate direct lighting. Lights without power
/// are never picked (all uniformly when none has power).
#[derive(Clone, Debug)]
pub struct LightSelector {
    cdf: Vec<f64>,
    probs: Vec<f64>,
    /// More than one light can be chosen: the selection number matters.
    choice: bool,
    /// Some light reads its position pair (area and environment lights do; point, spot
    /// and directional lights do not).
    positions: bool,
}

impl LightSelector {
    /// `powers[k]` is light k's power estimate, `infinite[k]` whether it is at infinity,
    /// `reads_position[k]` whether its samples read their position pair.
    pub fn new(powers: &[f64], infinite: &[bool], reads_position: &[bool]) -> LightSelector {
        let n = powers.len();
        let usable = |k: usize| powers[k] > 0.0 && powers[k].is_finite();
        let at_infinity = |k: usize| infinite.get(k).copied().unwrap_or(false);
        let finite_total: f64 = (0..n)
            .filter(|&k| usable(k) && !at_infinity(k))
            .map(|k| powers[k])
            .sum();
        let n_infinite = (0..n).filter(|&k| usable(k) && at_infinity(k)).count();
        let finite_group = if finite_total > 0.0 && finite_total.is_finite() {
            1.0
        } else {
            0.0
        };
        let groups = n_infinite as f64 + finite_group;
        let probs: Vec<f64> = if groups > 0.0 {
            (0..n)
                .map(|k| match (usable(k), at_infinity(k)) {
                    (false, _) => 0.0,
                    (true, true) => 1.0 / groups,
                    (true, false) => powers[k] / finite_total / groups,
                })
                .collect()
        } else {
            vec![1.0 / n.max(1) as f64; n]
        };
        let mut cdf = Vec::with_capacity(n);
        let mut acc = 0.0;
        for p in &probs {
            acc += p;
            cdf.push(acc);
        }
        let choice = probs.iter().filter(|&&p| p > 0.0).count() > 1;
        LightSelector {
            cdf,
            probs,
            choice,
            positions: reads_position.iter().any(|&r| r),
        }
    }

    /// Whether [`select`](Self::select)'s result depends on its number (more than one
    /// light can be chosen); where it does not, the integrator leaves the dimension undrawn.
    #[inline]
    pub fn reads_selection_number(&self) -> bool {
        self.choice
    }

    /// Whether some light's [`Light::sample`] reads its position pair; where none does,
    /// the integrator leaves the two dimensions undrawn.
    #[inline]
    pub fn reads_position_numbers(&self) -> bool {
        self.positions
    }

    /// (light index, probability).
    #[inline]
    pub fn select(&self, u: f64) -> Option<(usize, f64)> {
        if self.cdf.is_empty() {
            return None;
        }
        let k = self
            .cdf
            .partition_point(|&c| c <= u)
            .min(self.cdf.len() - 1);
        let p = self.probs[k];
        (p > 0.0).then_some((k, p))
    }

    #[inline]
    pub fn probability(&self, k: usize) -> f64 {
        self.probs.get(k).copied().unwrap_or(0.0)
    }
}
