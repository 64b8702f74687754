//! A lane model's spectral parameters, the ones textures drive: the same on every lane
//! (the model's own) or one value per lane (a texture read at each lane's shading point).
//!
//! The lane models read them through [`ColorSource`], so that a textured material runs the
//! same vectorized code as an untextured one — no model rebuilt per shading point, no
//! allocation — and an untextured one compiles to exactly what it did before (its own values
//! splatted where they are used).

use super::il::interfaced_lambertian::{body_factor, specular_probability};
use super::lane_models::LaneBsdf;
use crate::lanes::{channels, map_channels, Real};
use crate::math::INV_PI;
use crate::Spectrum;

/// A lane model's spectral parameters, one value per lane (`R` a lane type), or one shading
/// point's (`R = f64`). What each field means depends on the model; a field a model does not
/// read is left at the model's own value.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LaneColors<R> {
    /// Lambert's `reflectance`; the conductor's and the dielectric's reflection tint
    /// (`specular_reflectance`); IL's body factor K_d/(π n_i² (1 − K_d r_i)) [IL18 eq. 13].
    pub tint: [R; 3],
    /// The dielectric's transmission tint (`specular_transmittance`).
    pub transmit_tint: [R; 3],
    /// IL's probability of sampling its specular lobe [IL18 §4.1].
    pub specular_probability: R,
}

impl<R: Real> LaneColors<R> {
    /// Lane `i` takes the shading point `point(i)`'s values.
    #[inline(always)]
    pub fn from_points<'a>(point: impl Fn(usize) -> &'a LaneColors<f64>) -> LaneColors<R> {
        LaneColors {
            tint: channels(|c| R::from_fn(|i| point(i).tint[c])),
            transmit_tint: channels(|c| R::from_fn(|i| point(i).transmit_tint[c])),
            specular_probability: R::from_fn(|i| point(i).specular_probability),
        }
    }
}

/// Where a lane model reads its spectral parameters: each accessor gets the model's own value
/// and returns the lanes'.
pub trait ColorSource<R: Real> {
    fn tint(&self, own: &[f64; 3]) -> [R; 3];
    fn transmit_tint(&self, own: &[f64; 3]) -> [R; 3];
    fn specular_probability(&self, own: f64) -> R;
}

/// The model's own parameters on every lane.
#[derive(Clone, Copy, Debug)]
pub struct OwnColors;

impl<R: Real> ColorSource<R> for OwnColors {
    #[inline(always)]
    fn tint(&self, own: &[f64; 3]) -> [R; 3] {
        map_channels(*own, R::splat)
    }
    #[inline(always)]
    fn transmit_tint(&self, own: &[f64; 3]) -> [R; 3] {
        map_channels(*own, R::splat)
    }
    #[inline(always)]
    fn specular_probability(&self, own: f64) -> R {
        R::splat(own)
    }
}

impl<R: Real> ColorSource<R> for LaneColors<R> {
    #[inline(always)]
    fn tint(&self, _: &[f64; 3]) -> [R; 3] {
        self.tint
    }
    #[inline(always)]
    fn transmit_tint(&self, _: &[f64; 3]) -> [R; 3] {
        self.transmit_tint
    }
    #[inline(always)]
    fn specular_probability(&self, _: f64) -> R {
        self.specular_probability
    }
}

/// A spectral parameter of a lane model that a texture drives, found once from its key
/// ([`LaneBsdf::color_param`]) and set at each shading point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LaneColorParam {
    /// `reflectance` (Lambert) or `specular_reflectance` (conductor, dielectric).
    Tint,
    /// `specular_transmittance` (dielectric).
    TransmitTint,
    /// IL's `kd`: its body factor and its lobe-choice probability follow from it, through
    /// the interface's index n_i and diffuse reflectances r_e and r_i.
    Kd { ni: f64, re: f64, ri: f64 },
}

impl LaneColorParam {
    /// Puts the parameter's value `v` into a shading point's colors.
    #[inline]
    pub fn set(self, colors: &mut LaneColors<f64>, v: Spectrum) {
        match self {
            LaneColorParam::Tint => colors.tint = v.0,
            LaneColorParam::TransmitTint => colors.transmit_tint = v.0,
            LaneColorParam::Kd { ni, re, ri } => {
                colors.tint = body_factor(v, ni, ri).0.map(|k| k * INV_PI);
                colors.specular_probability = specular_probability(v, ni, re, ri);
            }
        }
    }
}

impl LaneBsdf {
    /// The model's own spectral parameters.
    pub fn colors(&self) -> LaneColors<f64> {
        let mut c = LaneColors {
            tint: [0.0; 3],
            transmit_tint: [0.0; 3],
            specular_probability: 1.0,
        };
        match self {
            LaneBsdf::Lambert { reflectance } => c.tint = *reflectance,
            LaneBsdf::Conductor { tint, .. } => c.tint = *tint,
            LaneBsdf::Dielectric {
                reflect_tint,
                transmit_tint,
                ..
            } => {
                c.tint = *reflect_tint;
                c.transmit_tint = *transmit_tint;
            }
            LaneBsdf::Il {
                body,
                specular_probability,
                ..
            } => {
                c.tint = *body;
                c.specular_probability = *specular_probability;
            }
        }
        c
    }

    /// The model with `colors` in place of its own spectral parameters.
    pub fn with_colors(&self, colors: &LaneColors<f64>) -> LaneBsdf {
        let mut m = self.clone();
        match &mut m {
            LaneBsdf::Lambert { reflectance } => *reflectance = colors.tint,
            LaneBsdf::Conductor { tint, .. } => *tint = colors.tint,
            LaneBsdf::Dielectric {
                reflect_tint,
                transmit_tint,
                ..
            } => {
                *reflect_tint = colors.tint;
                *transmit_tint = colors.transmit_tint;
            }
            LaneBsdf::Il {
                body,
                specular_probability,
                ..
            } => {
                *body = colors.tint;
                *specular_probability = colors.specular_probability;
            }
        }
        m
    }

    /// The spectral parameter a material key names for this model (the recipe's texturable
    /// spectrum keys), if it has one.
    pub fn color_param(&self, key: &str) -> Option<LaneColorParam> {
        match (self, key) {
            (LaneBsdf::Lambert { .. }, "reflectance")
            | (LaneBsdf::Conductor { .. }, "specular_reflectance")
            | (LaneBsdf::Dielectric { .. }, "specular_reflectance") => Some(LaneColorParam::Tint),
            (LaneBsdf::Dielectric { .. }, "specular_transmittance") => {
                Some(LaneColorParam::TransmitTint)
            }
            (LaneBsdf::Il { ni, re, ri, .. }, "kd") => Some(LaneColorParam::Kd {
                ni: *ni,
                re: *re,
                ri: *ri,
            }),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lanes::{F32x8, F64x8};
    use crate::recipe::MaterialRecipe;

    /// The recipe of a material given as TOML lines.
    fn recipe(s: &str) -> MaterialRecipe {
        MaterialRecipe::parse(&s.parse().unwrap(), std::path::Path::new(".")).unwrap()
    }

    /// A texture's value set through a color parameter gives the model the recipe builds
    /// with that value, for every texturable spectrum key of every lane model.
    #[test]
    fn a_textured_color_equals_the_model_built_with_that_value() {
        let cases = [
            ("type = 'lambert'\nreflectance = 0.5", "reflectance"),
            (
                "type = 'conductor'\ndistribution = 'ggx'\nalpha = 0.3\nmaterial = 'Au'",
                "specular_reflectance",
            ),
            (
                "type = 'dielectric'\ndistribution = 'beckmann'\nalpha = 0.3",
                "specular_reflectance",
            ),
            (
                "type = 'dielectric'\ndistribution = 'beckmann'\nalpha = 0.3",
                "specular_transmittance",
            ),
            (
                "type = 'il'\nkd = 0.5\nni = 1.5\ndistribution = 'ggx'\nalpha = 0.2\nmasking = 'smith'",
                "kd",
            ),
        ];
        let v = Spectrum([0.8, 0.25, 0.05]);
        for (table, key) in cases {
            let mut r = recipe(table);
            let model = r.lane_model().unwrap();
            let param = model.color_param(key).unwrap();
            let mut colors = model.colors();
            param.set(&mut colors, v);
            r.set_spectrum(key, v).unwrap();
            let expected = r.lane_model().unwrap();
            assert_eq!(colors, expected.colors(), "{table} {key}");
            let baked = model.with_colors(&colors);
            assert_eq!(
                format!("{baked:?}"),
                format!("{expected:?}"),
                "{table} {key}"
            );
        }
        // Keys a model does not have.
        let lambert = recipe("type = 'lambert'\nreflectance = 0.5")
            .lane_model()
            .unwrap();
        assert_eq!(lambert.color_param("kd"), None);
        assert_eq!(lambert.color_param("specular_transmittance"), None);
    }

    /// Lanes gathered from shading points hold each point's values, in f64 and f32 lanes.
    #[test]
    fn colors_gather_lane_by_lane() {
        let points: Vec<LaneColors<f64>> = (0..8)
            .map(|i| LaneColors {
                tint: [i as f64, 0.5, 0.25 * i as f64],
                transmit_tint: [1.0, i as f64 / 8.0, 0.0],
                specular_probability: i as f64 / 10.0,
            })
            .collect();
        let d: LaneColors<F64x8> = LaneColors::from_points(|i| &points[i]);
        let s: LaneColors<F32x8> = LaneColors::from_points(|i| &points[i]);
        for (i, p) in points.iter().enumerate() {
            for c in 0..3 {
                assert_eq!(d.tint[c].lane(i), p.tint[c]);
                assert_eq!(d.transmit_tint[c].lane(i), p.transmit_tint[c]);
                assert_eq!(s.tint[c].lane(i), p.tint[c] as f32 as f64);
            }
            assert_eq!(d.specular_probability.lane(i), p.specular_probability);
        }
    }
}
