//! The pixel samplers: the random numbers of each camera sample.
//!
//! A camera sample (pixel, sample number s) draws its numbers as *dimensions*: the camera
//! takes the first few, each path vertex a fixed block after them (see the integrator).
//! A sampler decides how the values of one dimension are spread over the pixel's samples:
//!
//! - [`SamplerKind::Sobol`] (the default): Owen-scrambled Sobol points in Morton order, the
//!   design of pbrt-v4's `ZSobolSampler` (Ahmed & Wonka 2020): each pixel's samples form a
//!   (0, m, 2)-net in every pair of dimensions, and the error is spread as blue noise
//!   across pixels ([`sobol`]).
//! - [`SamplerKind::Stratified`]: jittered strata per dimension, shuffled across
//!   dimensions by a hash permutation (Kensler 2013) ([`stratified`]).
//! - [`SamplerKind::Independent`]: independent uniform numbers, each a counter-based hash
//!   of (seed, pixel, sample number, dimension) (`hash::pcg4d`).
//!
//! Every value is a pure function of the seed, the construction arguments, the pixel, the
//! sample number and the dimension — nothing depends on which samples were drawn before or
//! on which thread — so a render split into parts (`--part K/N`: the samples with
//! s mod N = K of the same total) or into passes reproduces a single render bit for bit.
//! The layouts depend on the TOTAL sample count (a pixel's samples are one block of the
//! sequence), which is why [`PixelSampler`] is built once per render.
//!
//! Numbers without a dimension (a stochastic BSDF's evaluation, draws beyond a vertex's
//! block) come from [`SampleStream::rng`], the sample's own PCG stream, and a BSDF's sample
//! routine gets its dimensions and then that stream through a [`PrefixedSource`].
//!
//! The render kernel draws the numbers of eight camera samples at once ([`lanes`]): the
//! same values, from the same hashes written once over 32-bit lanes.

pub mod hash;
pub(crate) mod lanes;
pub mod prefixed_source;
pub mod sobol;
pub mod stratified;

pub use prefixed_source::PrefixedSource;

use facette_bsdf::math::rng::{mix_seed, Pcg32};
use glam::DVec2;
use sobol::{ZSobol, ZSobolSample};
use stratified::{Strata, StrataSample};

/// Which sampler a render uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum SamplerKind {
    /// Owen-scrambled Sobol in Morton order (pbrt-v4's ZSobol).
    #[default]
    Sobol,
    /// Independent uniform numbers, a hash of (seed, pixel, sample, dimension) each.
    Independent,
    /// Jittered strata per dimension.
    Stratified,
}

impl SamplerKind {
    /// The names of the kinds, in declaration order (also their codes in part files).
    pub const NAMES: [&'static str; 3] = ["sobol", "independent", "stratified"];

    const ALL: [SamplerKind; 3] = [
        SamplerKind::Sobol,
        SamplerKind::Independent,
        SamplerKind::Stratified,
    ];

    /// The kind's name in scene files and on the command line.
    pub fn name(self) -> &'static str {
        Self::NAMES[self as usize]
    }

    /// The kind of an exact lowercase name.
    pub fn parse(s: &str) -> Option<SamplerKind> {
        Self::NAMES
            .iter()
            .position(|&n| n == s)
            .map(|i| Self::ALL[i])
    }
}

/// The layout of one kind.
#[derive(Clone, Copy, Debug)]
enum Layout {
    Sobol(ZSobol),
    Independent,
    Stratified(Strata),
}

/// Built once per render: the sample-index layout depends on the image size and the TOTAL
/// spp (so `--part K/N` renders, which take sample indices s with s % N == K of the same
/// total, get exactly the values a single render would).
#[derive(Clone, Debug)]
pub struct PixelSampler {
    kind: SamplerKind,
    seed: u64,
    /// For the PCG stream's pixel number, y · width + x.
    width: u64,
    layout: Layout,
    /// Sobol with an index of at most 32 bits: each dimension's seeds under the render's
    /// common key, for the first [`lanes::TABULATED_DIMENSIONS`] dimensions (the render
    /// kernel's lanes read them; empty otherwise).
    dim_seeds: lanes::SeedTable,
}

/// Domain separation of the independent sampler's per-sample key (an arbitrary odd
/// constant), and the fourth word of its hash.
const INDEPENDENT_TAG: u64 = 0x1dec_0de5_0000_0007;
const INDEPENDENT_WORD: u32 = 0x6a09_e667;

/// The independent sampler's point of dimension `dim` (the first coordinate its 1D
/// value): the hash of the sample's key and the dimension, over lanes.
#[inline(always)]
pub(crate) fn independent_point<B: facette_bsdf::lanes::Bits32>(key: [B; 2], dim: B) -> (B, B) {
    let v = hash::pcg4d([key[0], key[1], dim, B::splat(INDEPENDENT_WORD)]);
    (v[0], v[1])
}

impl PixelSampler {
    /// The sampler of a `width` × `height` render of `spp` samples per pixel. Every size is
    /// accepted: an spp of 0 counts as 1, and what does not fit the Sobol index's 64 bits
    /// is folded into its hashes (see [`sobol`]).
    pub fn new(
        kind: SamplerKind,
        seed: u64,
        width: usize,
        height: usize,
        spp: usize,
    ) -> PixelSampler {
        let layout = match kind {
            SamplerKind::Sobol => Layout::Sobol(ZSobol::new(seed, width, height, spp)),
            SamplerKind::Independent => Layout::Independent,
            SamplerKind::Stratified => Layout::Stratified(Strata::new(seed, spp)),
        };
        let dim_seeds = match &layout {
            Layout::Sobol(z) if z.index_bits() <= 32 => lanes::SeedTable::new(z.common_key()),
            _ => lanes::SeedTable::default(),
        };
        PixelSampler {
            kind,
            seed,
            width: width as u64,
            layout,
            dim_seeds,
        }
    }

    pub fn kind(&self) -> SamplerKind {
        self.kind
    }

    /// The renderer's seeding since before samplers existed: (y · width + x) as u64
    /// (wrapping only where that product overflowed usize anyway).
    #[inline(always)]
    fn pixel(&self, x: usize, y: usize) -> u64 {
        (y as u64).wrapping_mul(self.width).wrapping_add(x as u64)
    }

    /// An independent sample's key.
    #[inline(always)]
    fn independent_key(&self, pixel: u64, sample_index: u64) -> u64 {
        mix_seed(self.independent_pixel_key(pixel), sample_index)
    }

    /// The pixel's part of [`independent_key`](Self::independent_key).
    #[inline(always)]
    fn independent_pixel_key(&self, pixel: u64) -> u64 {
        mix_seed(self.seed ^ INDEPENDENT_TAG, pixel)
    }

    /// The stream of one camera sample: a pure function of (seed, pixel, sample_index).
    #[inline]
    pub fn stream(&self, x: usize, y: usize, sample_index: u64) -> SampleStream {
        let pixel = self.pixel(x, y);
        let rng = Pcg32::new(mix_seed(self.seed, pixel), sample_index);
        let pattern = match &self.layout {
            Layout::Sobol(z) => Pattern::Sobol(z.start(x, y, sample_index)),
            Layout::Independent => Pattern::Independent {
                key: self.independent_key(pixel, sample_index),
            },
            Layout::Stratified(s) => Pattern::Stratified(s.start(x, y, sample_index)),
        };
        SampleStream {
            rng,
            dimension: 0,
            pattern,
        }
    }
}

/// The per-sample state of one kind.
#[derive(Clone, Debug)]
enum Pattern {
    Sobol(ZSobolSample),
    Independent { key: u64 },
    Stratified(StrataSample),
}

/// One camera sample's random numbers.
#[derive(Clone, Debug)]
pub struct SampleStream {
    rng: Pcg32,
    /// The next dimension.
    dimension: u32,
    pattern: Pattern,
}

/// A 64-bit key as the two 32-bit words of the hashes.
#[inline(always)]
fn split(key: u64) -> [u32; 2] {
    [key as u32, (key >> 32) as u32]
}

/// A 32-bit fraction as an `f64` in [0, 1) (exact).
#[inline(always)]
fn to_unit(bits: u32) -> f64 {
    bits as f64 * (1.0 / (1u64 << 32) as f64)
}

impl SampleStream {
    /// Next dimension, uniform in [0, 1) (never 1.0).
    pub fn get_1d(&mut self) -> f64 {
        let d = self.dimension;
        let v = match &self.pattern {
            Pattern::Sobol(z) => z.get_1d(d),
            Pattern::Independent { key } => {
                let (x, _) = independent_point(split(*key), d);
                to_unit(x)
            }
            Pattern::Stratified(s) => s.get_1d(d),
        };
        self.dimension = d.wrapping_add(1);
        v
    }

    /// Next two dimensions as a pair (for Sobol: the two dimensions of one scrambled
    /// (0,2)-sequence pair).
    pub fn get_2d(&mut self) -> DVec2 {
        let d = self.dimension;
        let v = match &self.pattern {
            Pattern::Sobol(z) => z.get_2d(d),
            Pattern::Independent { key } => {
                let (x, y) = independent_point(split(*key), d);
                DVec2::new(to_unit(x), to_unit(y))
            }
            Pattern::Stratified(s) => s.get_2d(d),
        };
        self.dimension = d.wrapping_add(2);
        v
    }

    /// Next dimension where the caller reads it (`used`), else the dimension is skipped and
    /// ½ returned: the sampler then does no work for a number nobody reads — a pinhole
    /// camera's lens, the light choice among one light, a point light's position, a
    /// one-lobe material's lobe — and every other dimension keeps its value (a value is a
    /// function of its dimension), so images do not change.
    #[inline]
    pub fn get_1d_where(&mut self, used: bool) -> f64 {
        if used {
            self.get_1d()
        } else {
            self.dimension = self.dimension.wrapping_add(1);
            0.5
        }
    }

    /// [`get_2d`](Self::get_2d) where `used`, else the pair is skipped and (½, ½) returned
    /// (see [`get_1d_where`](Self::get_1d_where)).
    #[inline]
    pub fn get_2d_where(&mut self, used: bool) -> DVec2 {
        if used {
            self.get_2d()
        } else {
            self.dimension = self.dimension.wrapping_add(2);
            DVec2::splat(0.5)
        }
    }

    /// Jump to dimension `d` (the integrator gives each path vertex a fixed block of
    /// dimensions).
    pub fn set_dimension(&mut self, d: u32) {
        self.dimension = d;
    }

    /// The sample's free PCG stream: for random numbers that have no dimension (stochastic
    /// BSDF evaluation, draws beyond a vertex's block). Seeded as the renderer always has:
    /// `Pcg32::new(mix_seed(seed, (y * width + x) as u64), sample_index)`.
    pub fn rng(&mut self) -> &mut Pcg32 {
        &mut self.rng
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use facette_bsdf::math::quadrature::GaussLegendre;
    use facette_bsdf::math::special::erfinv;

    const KINDS: [SamplerKind; 3] = SamplerKind::ALL;

    /// A hash of every kind's streams over pixels inside and beyond one Sobol tile, sample
    /// numbers inside and beyond the spp, and their first dimensions and fallback generator:
    /// the value recorded when the streams last changed on purpose. A change that moves it
    /// changes every image (docs/scale-out.md must then say so).
    #[test]
    fn streams_are_the_recorded_ones() {
        let mut h = 0u64;
        for kind in KINDS {
            for (w, ht, spp) in [(64, 48, 16), (3000, 2, 5), (1 << 17, 3, 4)] {
                let sampler = PixelSampler::new(kind, 11, w, ht, spp);
                for k in 0..200usize {
                    let (x, y) = ((k * 7919) % w, (k * 31) % ht);
                    for s in [0u64, 1, 3, spp as u64 + 2] {
                        let mut st = sampler.stream(x, y, s);
                        for _ in 0..6 {
                            h = mix_seed(h, st.get_1d().to_bits());
                        }
                        h = mix_seed(h, st.rng.next_u32() as u64);
                    }
                }
            }
        }
        assert_eq!(h, 0x1d70_4359_0bb3_9253, "{h:#x}");
    }

    /// `n` values of a stream: `get_1d`s, or the coordinates of `get_2d`s.
    fn draw(st: &mut SampleStream, n: usize, two_d: bool) -> Vec<u64> {
        let mut out = Vec::with_capacity(n);
        while out.len() < n {
            if two_d {
                let p = st.get_2d();
                out.extend([p.x.to_bits(), p.y.to_bits()]);
            } else {
                out.push(st.get_1d().to_bits());
            }
        }
        out
    }

    #[test]
    fn sampler_kind_names() {
        for (i, k) in KINDS.iter().enumerate() {
            assert_eq!(k.name(), SamplerKind::NAMES[i]);
            assert_eq!(SamplerKind::parse(k.name()), Some(*k));
        }
        assert_eq!(SamplerKind::default(), SamplerKind::Sobol);
        assert_eq!(SamplerKind::parse("Sobol"), None);
        assert_eq!(SamplerKind::parse(" sobol"), None);
        assert_eq!(SamplerKind::parse(""), None);
    }

    #[test]
    fn sampler_streams_are_pure() {
        for kind in KINDS {
            let s = PixelSampler::new(kind, 42, 64, 48, 32);
            assert_eq!(s.kind(), kind);
            for two_d in [false, true] {
                let a = draw(&mut s.stream(5, 7, 3), 40, two_d);
                // Same coordinates from another sampler built alike, after other streams.
                let t = PixelSampler::new(kind, 42, 64, 48, 32);
                let _ = draw(&mut t.stream(6, 7, 3), 40, two_d);
                assert_eq!(a, draw(&mut t.stream(5, 7, 3), 40, two_d), "{kind:?}");
                // Other pixels, indices and seeds differ.
                for other in [
                    s.stream(6, 7, 3),
                    s.stream(5, 8, 3),
                    s.stream(5, 7, 4),
                    PixelSampler::new(kind, 43, 64, 48, 32).stream(5, 7, 3),
                ] {
                    let b = draw(&mut other.clone(), 40, two_d);
                    let same = a.iter().zip(&b).filter(|(x, y)| x == y).count();
                    assert!(same <= 2, "{kind:?}: {same} of 40 values equal");
                }
            }
            // set_dimension(d) then get_1d / get_2d equals drawing d values first.
            {
                let all = draw(&mut s.stream(9, 1, 17), 30, false);
                for (d, &value) in all.iter().enumerate() {
                    let mut st = s.stream(9, 1, 17);
                    st.set_dimension(d as u32);
                    assert_eq!(st.get_1d().to_bits(), value, "{kind:?} dim {d}");
                }
                // get_2d takes two dimensions.
                let mut a = s.stream(9, 1, 17);
                a.set_dimension(4);
                let _ = a.get_2d();
                let mut b = s.stream(9, 1, 17);
                b.set_dimension(6);
                assert_eq!(a.get_1d(), b.get_1d());
            }
        }
    }

    #[test]
    fn sampler_rng_is_the_renderers_stream() {
        let (seed, w) = (1234u64, 320usize);
        for kind in KINDS {
            let s = PixelSampler::new(kind, seed, w, 200, 64);
            for (x, y, i) in [(0usize, 0usize, 0u64), (319, 199, 63), (17, 5, 1000)] {
                let mut reference = Pcg32::new(mix_seed(seed, (y * w + x) as u64), i);
                let mut st = s.stream(x, y, i);
                // Dimensioned draws do not touch the PCG stream.
                let _ = st.get_2d();
                let _ = st.get_1d();
                for _ in 0..8 {
                    assert_eq!(st.rng().next_u32(), reference.next_u32());
                }
            }
        }
    }

    #[test]
    fn sampler_values_in_range() {
        let in_range = |v: f64| (0.0..1.0).contains(&v);
        let check = |s: &PixelSampler, x: usize, y: usize, i: u64| {
            let mut st = s.stream(x, y, i);
            for _ in 0..40 {
                assert!(in_range(st.get_1d()), "{:?} {x},{y} #{i}", s.kind());
                let p = st.get_2d();
                assert!(
                    in_range(p.x) && in_range(p.y),
                    "{:?} {x},{y} #{i}",
                    s.kind()
                );
            }
        };
        for kind in KINDS {
            // The largest image, 2^20 spp; and beyond what fits in 64 index bits.
            for spp in [1usize << 20, (1 << 20) + 1, 1 << 40, usize::MAX] {
                let s = PixelSampler::new(kind, 7, 65536, 65536, spp);
                for (x, y) in [
                    (0, 0),
                    (65535, 65535),
                    (65535, 0),
                    (0, 65535),
                    (31415, 27182),
                ] {
                    for i in [0u64, 1, (1 << 20) - 1, 1 << 20, 123_456, u64::MAX] {
                        check(&s, x, y, i);
                    }
                }
            }
            // Many ordinary pixels and samples.
            let s = PixelSampler::new(kind, 3, 40, 30, 24);
            for y in 0..30 {
                for x in 0..40 {
                    for i in 0..24 {
                        check(&s, x, y, i);
                    }
                }
            }
            // Degenerate sizes.
            check(&PixelSampler::new(kind, 0, 0, 0, 0), 0, 0, 0);
            check(&PixelSampler::new(kind, 0, 1, 1, 1), 0, 0, 5);
        }
        // The clamp of stratified values: the last stratum with the largest jitter.
        let v = ((15.0 + hash::hash_unit(u64::MAX)) / 16.0).min(hash::ONE_MINUS_EPSILON);
        assert!(v < 1.0);
    }

    /// The chi-square quantile of `dof` degrees of freedom at upper-tail probability `alpha`,
    /// by the Wilson–Hilferty cube-root normal approximation (1931): the render crate has no
    /// statrs, and at 63 degrees of freedom the approximation is within a fraction of a
    /// percent of the exact quantile in the tails used here.
    fn chi2_quantile(dof: f64, alpha: f64) -> f64 {
        let z = std::f64::consts::SQRT_2 * erfinv(1.0 - 2.0 * alpha);
        let c = 2.0 / (9.0 * dof);
        dof * (1.0 - c + z * c.sqrt()).powi(3)
    }

    #[test]
    fn sampler_marginals_pass_chi_square() {
        // Per kind: 13 one-dimensional marginals (64 bins), 7 `get_2d` pairs and 6 pairs of
        // consecutive `get_1d` dimensions (8 × 8 bins: are neighbouring dimensions
        // independent?), each over 64 × 64 pixels × 16 samples; 78 tests at an overall
        // level of 1e-3 (Šidák). One-sided: stratified patterns are closer to uniform than
        // chance (a tiny statistic), which is their point.
        let (w, h, spp, bins) = (64usize, 64usize, 16u64, 64usize);
        let tests = 3 * (13 + 7 + 6);
        let alpha = 1.0 - (1.0 - 1e-3f64).powf(1.0 / tests as f64);
        let bound = chi2_quantile((bins - 1) as f64, alpha);
        let n = (w * h) as f64 * spp as f64;
        let expected = n / bins as f64;
        let stat = |counts: &[u64]| {
            counts
                .iter()
                .map(|&c| (c as f64 - expected).powi(2) / expected)
                .sum::<f64>()
        };
        for kind in KINDS {
            let s = PixelSampler::new(kind, 99, w, h, spp as usize);
            let mut hist = vec![vec![0u64; bins]; 13];
            let mut hist2 = vec![vec![0u64; bins]; 7];
            let mut pairs = vec![vec![0u64; bins]; 6];
            for y in 0..h {
                for x in 0..w {
                    for i in 0..spp {
                        let mut st = s.stream(x, y, i);
                        let v: Vec<f64> = (0..13).map(|_| st.get_1d()).collect();
                        for (hd, &u) in hist.iter_mut().zip(&v) {
                            hd[(u * bins as f64) as usize] += 1;
                        }
                        for (k, hd) in pairs.iter_mut().enumerate() {
                            let (a, b) = (v[2 * k], v[2 * k + 1]);
                            hd[(b * 8.0) as usize * 8 + (a * 8.0) as usize] += 1;
                        }
                        for (k, hd) in hist2.iter_mut().enumerate() {
                            st.set_dimension(2 * k as u32);
                            let p = st.get_2d();
                            hd[(p.y * 8.0) as usize * 8 + (p.x * 8.0) as usize] += 1;
                        }
                    }
                }
            }
            let worst = hist
                .iter()
                .chain(&hist2)
                .chain(&pairs)
                .map(|c| stat(c))
                .fold(0.0, f64::max);
            println!(
                "{kind:?}: largest chi2 {worst:.1} (dof {}, bound {bound:.1})",
                bins - 1
            );
            for (d, c) in hist.iter().enumerate() {
                let x = stat(c);
                assert!(x < bound, "{kind:?} dim {d}: chi2 {x:.1} ≥ {bound:.1}");
            }
            for (k, c) in hist2.iter().enumerate() {
                let x = stat(c);
                assert!(
                    x < bound,
                    "{kind:?} dims {}+{}: chi2 {x:.1} ≥ {bound:.1}",
                    2 * k,
                    2 * k + 1
                );
            }
            for (k, c) in pairs.iter().enumerate() {
                let x = stat(c);
                assert!(
                    x < bound,
                    "{kind:?} 1D dims {} and {}: chi2 {x:.1}",
                    2 * k,
                    2 * k + 1
                );
            }
        }
    }

    /// Every elementary interval of area 1/2^m (2^a × 2^(m−a) cells) holds one point.
    fn assert_02_net(points: &[DVec2], m: u32, what: &str) {
        assert_eq!(points.len(), 1 << m);
        for a in 0..=m {
            let (nx, ny) = ((1u64 << a) as f64, (1u64 << (m - a)) as f64);
            let mut seen = vec![false; 1 << m];
            for p in points {
                let cell = (p.x * nx) as usize * (1 << (m - a)) + (p.y * ny) as usize;
                assert!(!seen[cell], "{what}: two points in a {nx} × {ny} cell");
                seen[cell] = true;
            }
        }
    }

    #[test]
    fn sampler_sobol_pixels_are_nets() {
        for (spp, m) in [(16usize, 4u32), (64, 6), (256, 8), (32, 5)] {
            let s = PixelSampler::new(SamplerKind::Sobol, 5, 37, 21, spp);
            for (x, y) in [(0usize, 0usize), (36, 20), (11, 3)] {
                for d in [0u32, 1, 2, 5, 9, 30] {
                    let pts: Vec<DVec2> = (0..spp as u64)
                        .map(|i| {
                            let mut st = s.stream(x, y, i);
                            st.set_dimension(d);
                            st.get_2d()
                        })
                        .collect();
                    assert_02_net(&pts, m, &format!("spp {spp} pixel {x},{y} dims {d}+1"));
                    // The 1D values: one per 1/spp stratum.
                    let mut strata = vec![0; spp];
                    for i in 0..spp as u64 {
                        let mut st = s.stream(x, y, i);
                        st.set_dimension(d);
                        strata[(st.get_1d() * spp as f64) as usize] += 1;
                    }
                    assert!(strata.iter().all(|&c| c == 1), "spp {spp} dim {d}");
                    // Progressive: every aligned group of 4 samples is stratified in 2 × 2
                    // (for even log2 spp; with odd log2 spp, groups of 2 in 2 × 1 and 1 × 2).
                    let g = if m % 2 == 0 { 4 } else { 2 };
                    for group in pts.chunks(g) {
                        assert_02_net(group, g.trailing_zeros(), "a group of the first samples");
                    }
                }
            }
        }
    }

    #[test]
    fn sampler_stratified_pixels_fill_their_strata() {
        let s = PixelSampler::new(SamplerKind::Stratified, 5, 37, 21, 16);
        for (x, y) in [(0usize, 0usize), (36, 20), (11, 3)] {
            for d in [0u32, 1, 2, 5, 9, 30] {
                let mut strata = [0; 16];
                let mut cells = [0; 16];
                for i in 0..16 {
                    let mut st = s.stream(x, y, i);
                    st.set_dimension(d);
                    strata[(st.get_1d() * 16.0) as usize] += 1;
                    st.set_dimension(d);
                    let p = st.get_2d();
                    cells[(p.y * 4.0) as usize * 4 + (p.x * 4.0) as usize] += 1;
                }
                assert!(strata.iter().all(|&c| c == 1), "dim {d}: {strata:?}");
                assert!(cells.iter().all(|&c| c == 1), "dims {d}+1: {cells:?}");
            }
        }
    }

    #[test]
    fn sampler_variance_ratios() {
        let f = |x: f64, y: f64| (-(x - 0.3).powi(2) - (y - 0.6).powi(2)).exp() * (1.0 + x * y);
        let gl = GaussLegendre::shared64();
        let exact = gl.integrate(0.0, 1.0, |x| gl.integrate(0.0, 1.0, |y| f(x, y)));
        let (w, h, spp) = (16usize, 16usize, 64u64);
        let mse = |kind: SamplerKind, dim: u32| {
            let s = PixelSampler::new(kind, 2024, w, h, spp as usize);
            let mut sum = 0.0;
            for y in 0..h {
                for x in 0..w {
                    let est = (0..spp)
                        .map(|i| {
                            let mut st = s.stream(x, y, i);
                            st.set_dimension(dim);
                            let p = st.get_2d();
                            f(p.x, p.y)
                        })
                        .sum::<f64>()
                        / spp as f64;
                    sum += (est - exact).powi(2);
                }
            }
            sum / (w * h) as f64
        };
        for dim in [0u32, 7] {
            let independent = mse(SamplerKind::Independent, dim);
            let sobol = mse(SamplerKind::Sobol, dim) / independent;
            let stratified = mse(SamplerKind::Stratified, dim) / independent;
            println!(
                "dims {dim}+{}: MSE independent {independent:.3e}; \
                 sobol / independent {sobol:.2e}, stratified / independent {stratified:.2e}",
                dim + 1
            );
            assert!(sobol < 1.0 / 20.0, "sobol / independent {sobol}");
            assert!(
                stratified < 1.0 / 3.0,
                "stratified / independent {stratified}"
            );
        }
    }

    #[test]
    fn sampler_parts_reproduce_a_single_render() {
        // A render of 12 samples per pixel (Sobol rounds to 16) split in 3 parts: part K
        // takes s with s % 3 == K, built separately, drawing pixels in another order.
        let (w, h, spp, parts) = (9usize, 7usize, 12usize, 3u64);
        for kind in KINDS {
            let single = PixelSampler::new(kind, 77, w, h, spp);
            let mut whole = Vec::new();
            for y in 0..h {
                for x in 0..w {
                    for s in 0..spp as u64 {
                        whole.push(((x, y, s), draw(&mut single.stream(x, y, s), 24, s % 2 == 1)));
                    }
                }
            }
            for k in 0..parts {
                let part = PixelSampler::new(kind, 77, w, h, spp);
                for ((x, y, s), values) in whole.iter().rev() {
                    if s % parts == k {
                        let got = draw(&mut part.stream(*x, *y, *s), 24, s % 2 == 1);
                        assert_eq!(&got, values, "{kind:?} part {k} pixel {x},{y} #{s}");
                    }
                }
            }
        }
        // The independent stream does not even depend on the total.
        let a = PixelSampler::new(SamplerKind::Independent, 5, 10, 10, 4);
        let b = PixelSampler::new(SamplerKind::Independent, 5, 10, 99, 4096);
        assert_eq!(
            draw(&mut a.stream(3, 3, 2), 10, true),
            draw(&mut b.stream(3, 3, 2), 10, true)
        );
    }
}
