//! The film: per-pixel sums and sample counts, the reconstruction filter, the NaN/Inf guard,
//! and conversion to an image. Filtering is done by importance sampling the filter (the
//! sample's position within the pixel is drawn from the filter and the sample counts for
//! its own pixel only, as in pbrt-v4): pixels stay independent, so tiles render in parallel
//! and the result does not depend on the thread count.

use crate::geometry::Vec2;
use crate::image::RgbImage;
use facette_bsdf::lanes::Real;
use facette_bsdf::math::special::erfinv_approx_lanes;
use facette_bsdf::Spectrum;

/// Reconstruction filter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Filter {
    /// Uniform over the pixel.
    Box,
    /// Gaussian of standard deviation `stddev` pixels, truncated at `radius` pixels; build
    /// it with [`Filter::gaussian`].
    Gaussian {
        stddev: f64,
        radius: f64,
        /// erf(radius / (stddev √2)): the truncated mass, cached for sampling.
        mass: f64,
    },
}

impl Filter {
    pub const NAMES: &'static [&'static str] = &["box", "gaussian"];

    /// A Gaussian filter (both arguments in pixels, positive).
    pub fn gaussian(stddev: f64, radius: f64) -> Filter {
        let mass = facette_bsdf::math::special::erf(radius / (stddev * std::f64::consts::SQRT_2));
        Filter::Gaussian {
            stddev,
            radius,
            mass,
        }
    }

    /// The standard deviation of the sample offsets along x (and y), in pixels: 1/√12 for
    /// the box; for the truncated Gaussian σ √(1 − 2a φ(a)/(2Φ(a) − 1)), a = radius/σ, φ
    /// and Φ the standard normal density and distribution. Footprints that stand for the
    /// whole pixel take this width (`crate::pixel_footprint`).
    pub fn stddev(&self) -> f64 {
        match *self {
            Filter::Box => (1.0f64 / 12.0).sqrt(),
            Filter::Gaussian {
                stddev,
                radius,
                mass,
            } => {
                let a = radius / stddev;
                let density = (-0.5 * a * a).exp() / (2.0 * std::f64::consts::PI).sqrt();
                stddev * (1.0 - 2.0 * a * density / mass).max(0.0).sqrt()
            }
        }
    }

    /// Offset from the pixel centre for the unit sample `u`.
    pub fn sample(&self, u: Vec2) -> Vec2 {
        let (x, y) = self.sample_lanes(u.x, u.y);
        Vec2::new(x, y)
    }

    /// [`sample`](Self::sample) over lanes, its one source.
    #[inline(always)]
    pub fn sample_lanes<R: Real>(&self, u0: R, u1: R) -> (R, R) {
        match *self {
            Filter::Box => (u0 - R::splat(0.5), u1 - R::splat(0.5)),
            Filter::Gaussian {
                stddev,
                radius,
                mass,
            } => {
                // Separable truncated Gaussian by inverting the normal CDF restricted to
                // [−radius, radius]; Giles' erfinv (1e-7 relative) is ample for placing a
                // sample within a pixel and 5× cheaper than the refined one.
                // A function, not a closure: a closure is compiled on its own, for the
                // baseline CPU, and called out of line from the render kernel's AVX2 code.
                #[inline(always)]
                fn offset<R: Real>(x: R, stddev: f64, radius: f64, mass: f64) -> R {
                    let y = (R::splat(2.0) * x - R::one()) * R::splat(mass);
                    let k = R::splat(stddev * std::f64::consts::SQRT_2);
                    (k * erfinv_approx_lanes(y)).clamp(-radius, radius)
                }
                (
                    offset(u0, stddev, radius, mass),
                    offset(u1, stddev, radius, mass),
                )
            }
        }
    }
}

/// Accumulated samples of an image.
#[derive(Clone, Debug)]
pub struct Film {
    pub width: usize,
    pub height: usize,
    /// Per-pixel sum of sample radiance.
    pub sums: Vec<[f64; 3]>,
    /// Per-pixel sum of squared sample radiance (for noise estimates).
    pub sq_sums: Vec<[f64; 3]>,
    /// Per-pixel count of samples that reached the film (including discarded ones, which
    /// count as zero radiance).
    pub counts: Vec<u32>,
    /// Samples whose radiance was NaN, infinite or negative, replaced by zero.
    pub discarded: u64,
}

impl Film {
    pub fn new(width: usize, height: usize) -> Film {
        Film {
            width,
            height,
            sums: vec![[0.0; 3]; width * height],
            sq_sums: vec![[0.0; 3]; width * height],
            counts: vec![0; width * height],
            discarded: 0,
        }
    }

    /// Adds a sample to pixel `index`; returns false when it was discarded.
    #[inline]
    pub fn add(&mut self, index: usize, l: Spectrum) -> bool {
        self.counts[index] += 1;
        if !l.is_finite() || l.has_negative() {
            self.discarded += 1;
            return false;
        }
        let (s, q) = (self.sums[index], self.sq_sums[index]);
        let sums = [s[0] + l[0], s[1] + l[1], s[2] + l[2]];
        let sq = [q[0] + l[0] * l[0], q[1] + l[1] * l[1], q[2] + l[2] * l[2]];
        // A finite sample can still overflow the sum (or its square): such a sample is
        // discarded like a non-finite one, so that a pixel never becomes infinite.
        if !sums.iter().chain(&sq).all(|v| v.is_finite()) {
            self.discarded += 1;
            return false;
        }
        self.sums[index] = sums;
        self.sq_sums[index] = sq;
        true
    }

    /// Per-pixel mean radiance.
    pub fn image(&self) -> RgbImage {
        let data = self
            .sums
            .iter()
            .zip(&self.counts)
            .map(|(s, &n)| {
                if n == 0 {
                    [0.0; 3]
                } else {
                    let k = 1.0 / n as f64;
                    // A mean beyond f32 (only from sums near f64's limit) saturates
                    // rather than becoming an infinite pixel.
                    let m = |v: f64| (v * k).min(f32::MAX as f64) as f32;
                    [m(s[0]), m(s[1]), m(s[2])]
                }
            })
            .collect();
        RgbImage::new(self.width, self.height, data).expect("film size is consistent")
    }

    /// Mean radiance over the pixel block `[x0, x1) × [y0, y1)` (each pixel's mean weighted
    /// equally) and its standard error from the per-pixel sample variances, per channel.
    pub fn block_mean(&self, x0: usize, y0: usize, x1: usize, y1: usize) -> ([f64; 3], [f64; 3]) {
        let (mut mean, mut var) = ([0.0; 3], [0.0; 3]);
        let mut pixels = 0.0;
        for y in y0..y1.min(self.height) {
            for x in x0..x1.min(self.width) {
                let i = y * self.width + x;
                let n = self.counts[i] as f64;
                if n == 0.0 {
                    continue;
                }
                pixels += 1.0;
                for c in 0..3 {
                    let m = self.sums[i][c] / n;
                    mean[c] += m;
                    // Unbiased sample variance of the pixel's mean.
                    if n > 1.0 {
                        let v = ((self.sq_sums[i][c] - n * m * m) / (n - 1.0)).max(0.0);
                        var[c] += v / n;
                    }
                }
            }
        }
        if pixels == 0.0 {
            return ([0.0; 3], [0.0; 3]);
        }
        (mean.map(|m| m / pixels), var.map(|v| v.sqrt() / pixels))
    }

    /// Total samples accumulated.
    pub fn total_samples(&self) -> u64 {
        self.counts.iter().map(|&c| c as u64).sum()
    }
}

/// Bit-for-bit equality (sums compared by their bits): merged distributed renders are
/// checked against in-process ones with it.
impl PartialEq for Film {
    fn eq(&self, o: &Film) -> bool {
        let bits = |v: &[[f64; 3]]| v.iter().flatten().map(|x| x.to_bits()).collect::<Vec<_>>();
        self.width == o.width
            && self.height == o.height
            && self.counts == o.counts
            && self.discarded == o.discarded
            && bits(&self.sums) == bits(&o.sums)
            && bits(&self.sq_sums) == bits(&o.sq_sums)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stddev_is_the_spread_of_the_sampled_offsets() {
        // The offsets of 200,000 stratified unit samples: their standard deviation is the
        // filter's stated one (to the quadrature's 1e-4), for the box, a Gaussian cut far
        // out, and one cut at 1.2σ where truncation narrows it by a third.
        for filter in [
            Filter::Box,
            Filter::gaussian(0.5, 2.0),
            Filter::gaussian(0.5, 0.6),
        ] {
            let n = 200_000;
            let var = (0..n)
                .map(|k| {
                    let u = (k as f64 + 0.5) / n as f64;
                    filter.sample(Vec2::new(u, 0.5)).x.powi(2)
                })
                .sum::<f64>()
                / n as f64;
            let s = filter.stddev();
            assert!(
                (var.sqrt() - s).abs() < 1e-4 * s,
                "{filter:?}: {} vs {s}",
                var.sqrt()
            );
        }
        assert!(Filter::gaussian(0.5, 0.6).stddev() < 0.7 * 0.5);
    }

    #[test]
    fn non_finite_samples_are_discarded_and_counted() {
        let mut f = Film::new(2, 1);
        assert!(f.add(0, Spectrum::splat(1.0)));
        assert!(!f.add(0, Spectrum::splat(f64::NAN)));
        assert!(!f.add(1, Spectrum::rgb(1.0, -1.0, 0.0)));
        assert_eq!(f.discarded, 2);
        let img = f.image();
        assert_eq!(img.get(0, 0), [0.5, 0.5, 0.5]);
        assert_eq!(img.get(1, 0), [0.0, 0.0, 0.0]);
    }

    #[test]
    fn gaussian_filter_samples_stay_within_the_radius() {
        let g = Filter::gaussian(0.5, 1.5);
        for k in 0..1000 {
            let u = Vec2::new(
                (k as f64 + 0.5) / 1000.0,
                ((k * 7) % 1000) as f64 / 1000.0 + 0.0005,
            );
            let o = g.sample(u);
            assert!(o.x.abs() <= 1.5 + 1e-9 && o.y.abs() <= 1.5 + 1e-9);
        }
    }
}
