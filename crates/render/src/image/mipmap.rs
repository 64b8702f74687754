//! A mip-mapped image texture: the image pyramid of Williams' "Pyramidal parametrics"
//! (SIGGRAPH 1983) with bilinear lookups inside a level and trilinear filtering across
//! levels, the level chosen from the uv footprint of a pixel as in pbrt-v4's `MIPMap`.
//!
//! **Texture space.** uv = (0, 0) is the top-left corner of the image (row 0), u grows to the
//! right and v downwards; texel (x, y) of a w×h level covers [x/w, (x+1)/w] × [y/h, (y+1)/h]
//! and its centre is at ((x + ½)/w, (y + ½)/h). This is Mitsuba 3's `bitmap` convention; its
//! OBJ loader flips v on load (`flip_tex_coords`, default on) so v-up mesh coordinates land
//! on the right rows — mesh loaders feeding this texture should do the same.
//!
//! **Pyramid.** Each level halves the previous one (sizes rounded down, never below 1), and
//! every coarse texel is the exact area average of the finer level over the coarse texel's
//! footprint. For an even size that is the 2×2 box; for an odd size n = 2m + 1 reduced to m
//! texels, coarse texel i spans (2m+1)/m fine texels and takes fine texels 2i, 2i+1, 2i+2
//! with weights (m − i, m, i + 1)/(2m + 1). The reduction is separable, exact for any size
//! (no resampling to a power of two, so no ringing), preserves the image mean exactly, and
//! keeps each level aligned with [0, 1]² so every level is indexed by the same uv. Levels are
//! built in f64 and stored in f32.

use facette_bsdf::{ParamError, ParamResult, Spectrum};
use glam::DVec2;
use rayon::prelude::*;

use super::rgb_image::{to_spectrum, RgbImage};

/// What a lookup outside [0, 1]² sees.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum WrapMode {
    /// The image tiles the plane.
    #[default]
    Repeat,
    /// Edge texels extend outwards.
    Clamp,
    /// The image tiles the plane, every other copy mirrored (seamless at the edges).
    Mirror,
}

impl WrapMode {
    pub const NAMES: [&'static str; 3] = ["repeat", "clamp", "mirror"];

    /// Parses `repeat`, `clamp` or `mirror` (scene files).
    pub fn parse(name: &str) -> ParamResult<Self> {
        match name {
            "repeat" => Ok(WrapMode::Repeat),
            "clamp" => Ok(WrapMode::Clamp),
            "mirror" => Ok(WrapMode::Mirror),
            _ => Err(ParamError::UnknownChoice {
                what: "wrap mode".into(),
                given: name.into(),
                valid: Self::NAMES.join(", "),
            }),
        }
    }

    /// The texel index that integer coordinate `i` reads in a row of `n` texels.
    #[inline]
    pub fn index(self, i: i64, n: usize) -> usize {
        let n = n as i64;
        if (0..n).contains(&i) {
            return i as usize;
        }
        let k = match self {
            WrapMode::Repeat => i.rem_euclid(n),
            WrapMode::Clamp => i.clamp(0, n - 1),
            WrapMode::Mirror => {
                let p = i.rem_euclid(2 * n);
                if p < n {
                    p
                } else {
                    2 * n - 1 - p
                }
            }
        };
        k as usize
    }
}

#[derive(Clone, Debug)]
struct Level {
    width: usize,
    height: usize,
    data: Vec<[f32; 3]>,
}

/// Per coarse texel, the (fine index, weight) taps of the area-average reduction of a row
/// of `n` texels (see the module documentation).
fn reduction_taps(n: usize) -> Vec<[(usize, f64); 3]> {
    if n == 1 {
        return vec![[(0, 1.0), (0, 0.0), (0, 0.0)]];
    }
    let m = n / 2;
    if n % 2 == 0 {
        (0..m)
            .map(|i| [(2 * i, 0.5), (2 * i + 1, 0.5), (2 * i, 0.0)])
            .collect()
    } else {
        let inv = 1.0 / n as f64;
        (0..m)
            .map(|i| {
                [
                    (2 * i, (m - i) as f64 * inv),
                    (2 * i + 1, m as f64 * inv),
                    (2 * i + 2, (i + 1) as f64 * inv),
                ]
            })
            .collect()
    }
}

impl Level {
    fn reduce(&self) -> Level {
        let tx = reduction_taps(self.width);
        let ty = reduction_taps(self.height);
        let (w, h) = (tx.len(), ty.len());
        let mut data = vec![[0f32; 3]; w * h];
        data.par_chunks_mut(w).enumerate().for_each(|(j, row)| {
            for (i, out) in row.iter_mut().enumerate() {
                let mut acc = [0f64; 3];
                for &(y, wy) in &ty[j] {
                    if wy == 0.0 {
                        continue;
                    }
                    for &(x, wx) in &tx[i] {
                        if wx == 0.0 {
                            continue;
                        }
                        let p = self.data[y * self.width + x];
                        let wgt = wx * wy;
                        for c in 0..3 {
                            acc[c] += wgt * p[c] as f64;
                        }
                    }
                }
                *out = acc.map(|v| v as f32);
            }
        });
        Level {
            width: w,
            height: h,
            data,
        }
    }
}

/// A mip-mapped RGB image (see the module documentation for conventions).
#[derive(Clone, Debug)]
pub struct MipMap {
    levels: Vec<Level>,
    wrap: WrapMode,
}

impl MipMap {
    /// Builds the pyramid of `image` down to 1×1.
    pub fn new(image: RgbImage, wrap: WrapMode) -> Self {
        let (width, height) = (image.width(), image.height());
        let mut levels = vec![Level {
            width,
            height,
            data: image.into_data(),
        }];
        loop {
            let last = levels.last().expect("level 0 exists");
            if last.width == 1 && last.height == 1 {
                break;
            }
            let next = last.reduce();
            levels.push(next);
        }
        MipMap { levels, wrap }
    }

    /// Number of levels (1 for a 1×1 image; ⌊log₂ max(w, h)⌋ + 1 in general).
    pub fn levels(&self) -> usize {
        self.levels.len()
    }

    /// Size of level `level` (0 is the full image).
    pub fn level_size(&self, level: usize) -> (usize, usize) {
        let l = &self.levels[level.min(self.levels.len() - 1)];
        (l.width, l.height)
    }

    pub fn wrap(&self) -> WrapMode {
        self.wrap
    }

    /// The mean of the image (the 1×1 level).
    pub fn average(&self) -> Spectrum {
        to_spectrum(self.levels.last().expect("level 0 exists").data[0])
    }

    /// Texel (x, y) of `level`, the wrap mode applied to out-of-range coordinates.
    #[inline]
    pub fn texel(&self, level: usize, x: i64, y: i64) -> Spectrum {
        let l = &self.levels[level.min(self.levels.len() - 1)];
        let xi = self.wrap.index(x, l.width);
        let yi = self.wrap.index(y, l.height);
        to_spectrum(l.data[yi * l.width + xi])
    }

    /// Bilinear interpolation between the four texel centres around `uv` on `level`.
    /// Non-finite coordinates read as 0.
    pub fn bilinear(&self, level: usize, uv: DVec2) -> Spectrum {
        let level = level.min(self.levels.len() - 1);
        let l = &self.levels[level];
        // Far outside [0, 1] only the fractional position matters for repeat/mirror, and
        // clamp is saturated; bounding the coordinate keeps the integer maths in range.
        const LIMIT: f64 = 1e15;
        let fin = |v: f64| {
            if v.is_finite() {
                v.clamp(-LIMIT, LIMIT)
            } else {
                0.0
            }
        };
        let x = fin(uv.x) * l.width as f64 - 0.5;
        let y = fin(uv.y) * l.height as f64 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (xi, yi) = (x0 as i64, y0 as i64);
        let t00 = self.texel(level, xi, yi);
        let t10 = self.texel(level, xi + 1, yi);
        let t01 = self.texel(level, xi, yi + 1);
        let t11 = self.texel(level, xi + 1, yi + 1);
        (t00 * (1.0 - fx) + t10 * fx) * (1.0 - fy) + (t01 * (1.0 - fx) + t11 * fx) * fy
    }

    /// The continuous level of detail for a uv footprint `[du/dx, dv/dx, du/dy, dv/dy]`:
    /// log₂ of the longer of the two footprint axes measured in level-0 texels, clamped to
    /// [0, levels − 1]. A zero, NaN or magnifying footprint gives 0 (the sharpest level);
    /// an infinite one the coarsest.
    pub fn level_of_detail(&self, derivs: [f64; 4]) -> f64 {
        let l0 = &self.levels[0];
        let (w, h) = (l0.width as f64, l0.height as f64);
        let ax = DVec2::new(derivs[0] * w, derivs[1] * h).length();
        let ay = DVec2::new(derivs[2] * w, derivs[3] * h).length();
        let width = ax.max(ay);
        if !(width > 1.0) {
            return 0.0;
        }
        width.log2().min((self.levels.len() - 1) as f64)
    }

    /// Trilinearly filtered lookup: bilinear on the two levels bracketing the level of
    /// detail of the footprint (see [`MipMap::level_of_detail`]), linearly blended.
    pub fn lookup(&self, uv: DVec2, derivs: [f64; 4]) -> Spectrum {
        let lod = self.level_of_detail(derivs);
        let l0 = lod.floor();
        let t = lod - l0;
        let l0 = l0 as usize;
        if t == 0.0 || l0 + 1 >= self.levels.len() {
            return self.bilinear(l0, uv);
        }
        self.bilinear(l0, uv) * (1.0 - t) + self.bilinear(l0 + 1, uv) * t
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn checker(w: usize, h: usize) -> RgbImage {
        RgbImage::from_fn(w, h, |x, y| [((x + y) % 2) as f32; 3]).unwrap()
    }

    #[test]
    fn level_sizes_halve_down_to_one() {
        let m = MipMap::new(RgbImage::filled(13, 5, [1.0; 3]).unwrap(), WrapMode::Repeat);
        let sizes: Vec<_> = (0..m.levels()).map(|l| m.level_size(l)).collect();
        assert_eq!(sizes, vec![(13, 5), (6, 2), (3, 1), (1, 1)]);
        let m = MipMap::new(
            RgbImage::filled(1024, 1, [1.0; 3]).unwrap(),
            WrapMode::Repeat,
        );
        assert_eq!(m.levels(), 11);
        let m = MipMap::new(RgbImage::filled(1, 1, [1.0; 3]).unwrap(), WrapMode::Repeat);
        assert_eq!(m.levels(), 1);
    }

    #[test]
    fn constant_images_stay_constant_at_every_level() {
        for &(w, h) in &[(16, 16), (7, 5), (1, 9), (33, 2), (3, 3)] {
            let c = [0.3f32, 1.7, 12.25];
            let m = MipMap::new(RgbImage::filled(w, h, c).unwrap(), WrapMode::Repeat);
            for l in 0..m.levels() {
                let (lw, lh) = m.level_size(l);
                for y in 0..lh as i64 {
                    for x in 0..lw as i64 {
                        assert_eq!(m.texel(l, x, y), to_spectrum(c), "{w}×{h} level {l}");
                    }
                }
            }
            // And every filtered lookup returns it.
            for k in 0..50 {
                let uv = DVec2::new(k as f64 * 0.137 - 2.0, k as f64 * 0.071);
                let d = 10f64.powf(k as f64 / 10.0 - 3.0);
                let v = m.lookup(uv, [d, 0.0, 0.0, d * 0.5]);
                assert!((v - to_spectrum(c)).max_component().abs() < 1e-6);
            }
        }
    }

    #[test]
    fn a_fine_checker_averages_to_its_mean() {
        let m = MipMap::new(checker(64, 64), WrapMode::Repeat);
        for l in 1..m.levels() {
            let (lw, lh) = m.level_size(l);
            for y in 0..lh as i64 {
                for x in 0..lw as i64 {
                    assert_eq!(m.texel(l, x, y), Spectrum::splat(0.5));
                }
            }
        }
        // Odd sizes: the mean is preserved exactly at every level.
        let img = checker(13, 7);
        let mean = img.mean();
        let m = MipMap::new(img, WrapMode::Repeat);
        for l in 0..m.levels() {
            let (lw, lh) = m.level_size(l);
            let mut s = Spectrum::ZERO;
            for y in 0..lh as i64 {
                for x in 0..lw as i64 {
                    s += m.texel(l, x, y);
                }
            }
            let level_mean = s / (lw * lh) as f64;
            assert!(
                (level_mean - mean).max_component().abs() < 1e-6,
                "level {l}"
            );
        }
        assert!((m.average() - mean).max_component().abs() < 1e-6);
        // A wide footprint over the 64² checker reads its mean; a tiny one reads a texel.
        let m = MipMap::new(checker(64, 64), WrapMode::Repeat);
        let far = m.lookup(DVec2::new(0.3, 0.6), [0.2, 0.0, 0.0, 0.2]);
        assert!((far - Spectrum::splat(0.5)).max_component().abs() < 1e-6);
        let near = m.lookup(DVec2::new(0.5 / 64.0, 0.5 / 64.0), [1e-4, 0.0, 0.0, 1e-4]);
        assert_eq!(near, Spectrum::ZERO);
    }

    #[test]
    fn odd_reduction_weights_are_area_overlaps() {
        // n = 5 → 2 texels, each 2.5 fine texels wide: (1, 1, ½)/2.5 and (½, 1, 1)/2.5.
        let t = reduction_taps(5);
        assert_eq!(t.len(), 2);
        let w0: Vec<f64> = t[0].iter().map(|p| p.1 * 2.5).collect();
        let w1: Vec<f64> = t[1].iter().map(|p| p.1 * 2.5).collect();
        assert!((w0[0] - 1.0).abs() < 1e-12 && (w0[1] - 1.0).abs() < 1e-12);
        assert!((w0[2] - 0.5).abs() < 1e-12 && (w1[0] - 0.5).abs() < 1e-12);
        assert_eq!((t[1][0].0, t[1][2].0), (2, 4));
    }

    #[test]
    fn level_of_detail_follows_the_longer_footprint_axis() {
        let m = MipMap::new(
            RgbImage::filled(256, 128, [1.0; 3]).unwrap(),
            WrapMode::Repeat,
        );
        assert_eq!(m.levels(), 9);
        let texel = 1.0 / 256.0;
        assert_eq!(m.level_of_detail([texel, 0.0, 0.0, 0.0]), 0.0);
        assert!((m.level_of_detail([4.0 * texel, 0.0, 0.0, texel]) - 2.0).abs() < 1e-12);
        // The v axis is measured in v texels (128 of them).
        assert!((m.level_of_detail([0.0, 0.0, 0.0, 8.0 / 128.0]) - 3.0).abs() < 1e-12);
        // Diagonal footprints use their length; the longer axis wins.
        let d = 16.0 * texel / 2f64.sqrt();
        assert!((m.level_of_detail([d, d * 2.0, texel, 0.0]) - 4.0).abs() < 1e-12);
        // Clamped to the pyramid; degenerate inputs are safe.
        assert_eq!(m.level_of_detail([10.0, 0.0, 0.0, 0.0]), 8.0);
        assert_eq!(m.level_of_detail([f64::INFINITY, 0.0, 0.0, 0.0]), 8.0);
        assert_eq!(m.level_of_detail([f64::NAN, 0.0, 0.0, 0.0]), 0.0);
        assert_eq!(m.level_of_detail([1e-9, 0.0, 0.0, 0.0]), 0.0);
        // Between levels the lookup blends the two.
        let ramp = RgbImage::from_fn(4, 1, |x, _| [x as f32; 3]).unwrap();
        let m = MipMap::new(ramp, WrapMode::Clamp);
        let uv = DVec2::new(0.125, 0.5); // centre of texel 0 at level 0 (value 0)
        let lvl1 = m.bilinear(1, uv); // level 1 = [0.5, 2.5]
        assert_eq!(lvl1[0], 0.5);
        let blend = m.lookup(uv, [2f64.sqrt() / 4.0, 0.0, 0.0, 0.0]); // lod ½
        assert!(
            (blend - (m.bilinear(0, uv) + lvl1) * 0.5)
                .max_component()
                .abs()
                < 1e-12
        );
    }

    #[test]
    fn bilinear_hits_texel_centres_and_blends_between() {
        let img = RgbImage::from_fn(4, 2, |x, y| [(x + 10 * y) as f32; 3]).unwrap();
        let m = MipMap::new(img, WrapMode::Clamp);
        let at = |u: f64, v: f64| m.bilinear(0, DVec2::new(u, v))[0];
        assert_eq!(at(0.125, 0.25), 0.0);
        assert_eq!(at(0.875, 0.75), 13.0);
        assert!((at(0.25, 0.25) - 0.5).abs() < 1e-12);
        assert!((at(0.125, 0.5) - 5.0).abs() < 1e-12);
    }

    #[test]
    fn wrap_modes() {
        let img = RgbImage::from_fn(4, 1, |x, _| [x as f32; 3]).unwrap();
        let at = |mode, u: f64| MipMap::new(img.clone(), mode).bilinear(0, DVec2::new(u, 0.5))[0];
        // Texel centres: 0.125, 0.375, 0.625, 0.875.
        assert_eq!(at(WrapMode::Repeat, 1.375), 1.0);
        assert_eq!(at(WrapMode::Repeat, -0.625), 1.0);
        assert!((at(WrapMode::Repeat, 0.0) - 1.5).abs() < 1e-12); // blends texels 3 and 0
        assert_eq!(at(WrapMode::Clamp, 7.0), 3.0);
        assert_eq!(at(WrapMode::Clamp, -3.0), 0.0);
        assert_eq!(at(WrapMode::Clamp, 0.0), 0.0);
        assert_eq!(at(WrapMode::Mirror, 1.125), 3.0); // mirrored copy: 3 2 1 0
        assert_eq!(at(WrapMode::Mirror, 1.875), 0.0);
        assert_eq!(at(WrapMode::Mirror, -0.125), 0.0);
        assert_eq!(at(WrapMode::Mirror, 2.125), 0.0); // third copy is upright again
        assert_eq!(at(WrapMode::Mirror, 1.0), 3.0); // seamless edge
        for mode in [WrapMode::Repeat, WrapMode::Clamp, WrapMode::Mirror] {
            for u in [f64::NAN, f64::INFINITY, -1e300, 1e300] {
                assert!(at(mode, u).is_finite());
            }
        }
        assert_eq!(WrapMode::parse("mirror").unwrap(), WrapMode::Mirror);
        assert!(WrapMode::parse("wrap")
            .unwrap_err()
            .to_string()
            .contains("repeat"));
    }
}
