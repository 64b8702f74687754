//! Eight camera samples' numbers at once, for the render kernel: each lane asks for its own
//! dimension (the lanes' paths are at different vertices), and the values are exactly those
//! of the lane's [`SampleStream`], computed by the same hashes written once over 32-bit lanes
//! ([`short_index_point`], [`independent_point`]): eight Sobol points cost about what one
//! costs lane by lane, in AVX2 `vpmulld`s, shifts and logic.
//!
//! A lane's numbers are computed in lanes when its sample has a lane form — a Sobol sample
//! whose index has at most 32 bits (every image up to 65536² pixels at up to 2^32 / pixels
//! samples), or any independent sample — and otherwise read from its stream (stratified
//! samples, Sobol beyond 32 index bits).

use super::sobol::{short_index_point, DimSeeds};
use super::{independent_point, split, Layout, PixelSampler, SampleStream};
use facette_bsdf::lanes::{Bits32, Real};

/// The dimensions whose Sobol seeds are tabulated per render (a path of up to 36 vertices
/// at 7 dimensions each); deeper dimensions hash their seeds lane by lane.
pub(crate) const TABULATED_DIMENSIONS: u32 = 256;

/// The Sobol seeds ([`DimSeeds`]) of the first [`TABULATED_DIMENSIONS`] dimensions under the
/// render's common key, one table per seed, so that eight lanes at eight dimensions read
/// theirs with three gathers (lane by lane, the look-ups had cost about 60 instructions a
/// camera sample on `bench-sphere`).
#[derive(Clone, Debug, Default)]
pub(crate) struct SeedTable {
    field: Vec<u32>,
    s0: Vec<u32>,
    s1: Vec<u32>,
}

impl SeedTable {
    pub(crate) fn new(key: u64) -> SeedTable {
        let seeds: Vec<DimSeeds> = (0..TABULATED_DIMENSIONS)
            .map(|d| DimSeeds::new(key, d))
            .collect();
        SeedTable {
            field: seeds.iter().map(|s| s.field).collect(),
            s0: seeds.iter().map(|s| s.s0).collect(),
            s1: seeds.iter().map(|s| s.s1).collect(),
        }
    }

    pub(crate) fn is_empty(&self) -> bool {
        self.field.is_empty()
    }

    /// Each lane's seeds of its dimension `dims[i]` (field, s0, s1) under `key`: gathered
    /// where every lane's dimension is tabulated, hashed lane by lane otherwise.
    #[inline(always)]
    fn lanes<B: Bits32>(&self, dims: B, key: u64) -> [B; 3] {
        // Three tables of one length: the gathers' bound checks are then one computation,
        // shared with this test (written as `gather` writes its own, so that LLVM sees the
        // same computation).
        let n = self.field.len();
        if dims.all_below(n.min(1 << 31) as u32) {
            return [
                dims.gather(&self.field[..n]),
                dims.gather(&self.s0[..n]),
                dims.gather(&self.s1[..n]),
            ];
        }
        let mut s = [DimSeeds::new(key, 0); 8];
        for (i, s) in s.iter_mut().enumerate().take(B::LANES) {
            let d = dims.lane(i);
            *s = match self.field.get(d as usize) {
                Some(&field) => DimSeeds {
                    field,
                    s0: self.s0[d as usize],
                    s1: self.s1[d as usize],
                },
                None => DimSeeds::new(key, d),
            };
        }
        [
            B::from_fn(|i| s[i].field),
            B::from_fn(|i| s[i].s0),
            B::from_fn(|i| s[i].s1),
        ]
    }
}

/// The lanes `i` of `set` in `dst` take lane `from[i]` of `src`: one permutation and one
/// blend in the integer lanes `B` (the render kernel's refill moves its lane arrays so).
#[inline(always)]
pub(crate) fn move_lanes<B: Bits32>(dst: &mut [u32; 8], src: &[u32; 8], from: &[u8; 8], set: u8) {
    let moved = B::from_fn(|i| src[i]).permute(from);
    let v = B::blend_bits(set, moved, B::from_fn(|i| dst[i]));
    *dst = std::array::from_fn(|i| v.lane(i));
}

/// Eight camera samples' sampler state: two words per lane (a Sobol sample's reversed
/// index; an independent sample's key), and the lanes that have them.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct SampleLanes {
    words: [[u32; 8]; 2],
    /// Lane i has a lane form where bit i is set.
    fast: u8,
}

impl SampleLanes {
    /// Lane `i` takes the state of `stream`.
    #[cfg(test)]
    pub(crate) fn set(&mut self, i: usize, sampler: &PixelSampler, stream: &SampleStream) {
        self.set_words(i, sampler.lane_words(stream));
    }

    /// The lanes with a lane form.
    #[inline(always)]
    pub(crate) fn fast(&self) -> u8 {
        self.fast
    }

    /// The lanes `i` of `set` take lane `src[i]` of `from`; `taken` is the set of those
    /// lanes of `from`.
    #[inline(always)]
    pub(crate) fn take<B: Bits32>(
        &mut self,
        set: u8,
        from: &SampleLanes,
        src: &[u8; 8],
        taken: u8,
    ) {
        for (w, f) in self.words.iter_mut().zip(&from.words) {
            move_lanes::<B>(w, f, src, set);
        }
        let kept = self.fast & !set;
        self.fast = if from.fast & taken == taken {
            kept | set
        } else {
            let mut rest = set;
            let mut fast = kept;
            while rest != 0 {
                let i = rest.trailing_zeros() as usize;
                rest &= rest - 1;
                fast |= ((from.fast >> src[i]) & 1) << i;
            }
            fast
        };
    }

    /// Lane `i` takes the lane form `words` ([`PixelSampler::lane_words_at`]), or none.
    #[inline]
    fn set_words(&mut self, i: usize, words: Option<[u32; 2]>) {
        match words {
            Some(w) => {
                self.words[0][i] = w[0];
                self.words[1][i] = w[1];
                self.fast |= 1 << i;
            }
            None => self.fast &= !(1 << i),
        }
    }
}

impl PixelSampler {
    /// The lane form of camera sample `sample_index` of pixel (x, y), where it has one:
    /// `lane_words(&self.stream(x, y, sample_index))` without making the stream (whose
    /// generator seeding, pattern state and copies cost the render kernel about 200
    /// instructions a camera sample when no model drew from it).
    #[inline]
    pub(crate) fn lane_words_at(&self, x: usize, y: usize, sample_index: u64) -> Option<[u32; 2]> {
        match &self.layout {
            super::Layout::Sobol(z) => z.lane_word_at(x, y, sample_index).map(|w| [w, 0]),
            super::Layout::Independent => Some(super::split(
                self.independent_key(self.pixel(x, y), sample_index),
            )),
            super::Layout::Stratified(_) => None,
        }
    }

    /// The lane forms of camera samples `(xs[i], ys[i], samples[i])`, i < `n` (lanes from
    /// `n` on have none): [`lane_words_at`](Self::lane_words_at) of each, in the integer
    /// lanes `B` where the Sobol layout allows it ([`ZSobol::lane_words`]), lane by lane
    /// otherwise.
    ///
    /// [`ZSobol::lane_words`]: super::sobol::ZSobol::lane_words
    #[inline(always)]
    pub(crate) fn lane_words_batch<B: Bits32>(
        &self,
        xs: &[u32; 8],
        ys: &[u32; 8],
        samples: &[u32; 8],
        n: usize,
    ) -> SampleLanes {
        let mut out = SampleLanes::default();
        if let Layout::Sobol(z) = &self.layout {
            if let Some(words) = z.lane_words::<B>(xs, ys, samples, n) {
                for i in 0..8 {
                    out.words[0][i] = words.lane(i);
                }
                out.fast = ((1u32 << n) - 1) as u8;
                return out;
            }
        }
        if let Layout::Independent = &self.layout {
            // Each lane's key: the pixel's half, then the sample's, by the lanes' 64-bit hash
            // (`independent_key` for all eight at once; lanes from n on are unused).
            let pixels = std::array::from_fn(|i| self.pixel(xs[i] as usize, ys[i] as usize));
            let pixel_keys = B::mix_seeds(&[self.seed ^ super::INDEPENDENT_TAG; 8], &pixels);
            let keys = B::mix_seeds(&pixel_keys, &samples.map(u64::from));
            for (i, &key) in keys.iter().enumerate().take(n) {
                out.set_words(i, Some(split(key)));
            }
            return out;
        }
        for i in 0..n {
            let (x, y, s) = (xs[i] as usize, ys[i] as usize, samples[i] as u64);
            out.set_words(i, self.lane_words_at(x, y, s));
        }
        out
    }

    /// The lane form of a stream's sample, where it has one.
    #[cfg(test)]
    fn lane_words(&self, stream: &SampleStream) -> Option<[u32; 2]> {
        match &stream.pattern {
            super::Pattern::Sobol(z) => z.lane_word().map(|w| [w, 0]),
            super::Pattern::Independent { key } => Some(super::split(*key)),
            super::Pattern::Stratified(_) => None,
        }
    }

    /// Each lane of `active`'s value of its dimension `dims[i]` (and of `dims[i] + 1` as the
    /// second coordinate where `pair`): the values of `streams[i].get_1d` / `get_2d` at that
    /// dimension, in lanes of `S` (never 1). Inactive lanes hold a harmless ½. The hashes
    /// run in the integer lanes `B` (`U32x8` or, in the kernel's AVX2 build, the register
    /// lanes `U32x8Avx2`: the same bits).
    #[inline(always)]
    pub(crate) fn get_lanes<S: Real, B: Bits32>(
        &self,
        lanes: &SampleLanes,
        streams: &mut [SampleStream],
        dims: B,
        active: u8,
        pair: bool,
    ) -> (S, S) {
        let words = |k: usize| B::from_fn(|i| lanes.words[k][i]);
        let (x, y) = match &self.layout {
            Layout::Sobol(z) if !self.dim_seeds.is_empty() => {
                let seeds = self.dim_seeds.lanes(dims, z.common_key());
                short_index_point(words(0), z.index_bits(), seeds, pair)
            }
            Layout::Independent => independent_point([words(0), words(1)], dims),
            _ => (B::splat(1 << 31), B::splat(1 << 31)),
        };
        let (mut x, mut y): (S, S) = (x.unit(), y.unit());
        let slow = active & !lanes.fast;
        if slow != 0 {
            // Stream values are exact 32-bit fractions in f64: cut to S's precision below 1.
            let below_one = 1.0 - (-(S::DIGITS as f64)).exp2();
            let mut fx = [0.5; 8];
            let mut fy = [0.5; 8];
            for i in (0..8).filter(|i| slow & (1 << i) != 0) {
                let st = &mut streams[i];
                st.set_dimension(dims.lane(i));
                if pair {
                    let v = st.get_2d();
                    (fx[i], fy[i]) = (v.x, v.y);
                } else {
                    fx[i] = st.get_1d();
                }
            }
            let fast = lanes.fast;
            let patch = |v: S, f: &[f64; 8]| {
                S::from_fn(|i| {
                    if fast & (1 << i) != 0 {
                        v.lane(i)
                    } else {
                        f[i]
                    }
                })
                .min(S::splat(below_one))
            };
            x = patch(x, &fx);
            y = patch(y, &fy);
        }
        (x, y)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampler::SamplerKind;
    use facette_bsdf::lanes::{F32x8, F64x8, U32x8};

    /// Every lane's value is its stream's, to the bit in f64 lanes and to f32 rounding (and
    /// never 1) in f32 lanes, for lanes at different dimensions, inside and beyond the tabulated
    /// ones, for every kind and for a Sobol index too wide for the lane form.
    #[test]
    fn lanes_draw_what_their_streams_draw() {
        let layouts = [
            (SamplerKind::Sobol, 64, 48, 64),
            (SamplerKind::Sobol, 1 << 17, 4, 1 << 12),
            (SamplerKind::Independent, 64, 48, 64),
            (SamplerKind::Stratified, 64, 48, 64),
        ];
        for (kind, w, h, spp) in layouts {
            let sampler = PixelSampler::new(kind, 9, w, h, spp);
            let wide = kind == SamplerKind::Sobol && w > 65536;
            for round in 0..64u32 {
                let mut streams: Vec<SampleStream> = (0..8)
                    .map(|i| {
                        let x = (round as usize * 7 + i * 13) % w;
                        let y = (round as usize + i) % h;
                        sampler.stream(x, y, ((round + i as u32) % spp as u32) as u64)
                    })
                    .collect();
                let mut lanes = SampleLanes::default();
                for (i, st) in streams.iter().enumerate() {
                    lanes.set(i, &sampler, st);
                    // The words made without the stream are the stream's, also for sample
                    // numbers beyond the spp (another key).
                    let x = (round as usize * 7 + i * 13) % w;
                    let y = (round as usize + i) % h;
                    for s in [(round + i as u32) % spp as u32, spp as u32 + round] {
                        assert_eq!(
                            sampler.lane_words_at(x, y, s as u64),
                            sampler.lane_words(&sampler.stream(x, y, s as u64)),
                            "{kind:?} {w} ({x}, {y}) sample {s}"
                        );
                    }
                }
                let expect_fast = if kind == SamplerKind::Stratified || wide {
                    0
                } else {
                    0xff
                };
                assert_eq!(lanes.fast, expect_fast, "{kind:?} {w}");
                // The batch form gives each lane its `lane_words_at`, in the array and the
                // register integer lanes, for full and short batches and with a sample
                // number beyond the spp among them (then lane by lane).
                for (beyond, n) in [(false, 8), (false, 5), (true, 8)] {
                    let xs = std::array::from_fn(|i| ((round as usize * 7 + i * 13) % w) as u32);
                    let ys = std::array::from_fn(|i| ((round as usize + i) % h) as u32);
                    let ss: [u32; 8] = std::array::from_fn(|i| match i {
                        3 if beyond => spp as u32 + round,
                        _ => (round + i as u32) % spp as u32,
                    });
                    let batch = sampler.lane_words_batch::<U32x8>(&xs, &ys, &ss, n);
                    for i in 0..8 {
                        let (x, y, s) = (xs[i] as usize, ys[i] as usize, ss[i] as u64);
                        let expect = (i < n).then(|| sampler.lane_words_at(x, y, s)).flatten();
                        assert_eq!((batch.fast >> i) & 1 == 1, expect.is_some(), "{kind:?}");
                        if let Some(words) = expect {
                            assert_eq!([batch.words[0][i], batch.words[1][i]], words);
                        }
                    }
                    #[cfg(target_arch = "x86_64")]
                    if facette_bsdf::lanes::avx2::available() {
                        let r = sampler
                            .lane_words_batch::<facette_bsdf::lanes::U32x8Avx2>(&xs, &ys, &ss, n);
                        assert_eq!((r.words, r.fast), (batch.words, batch.fast), "{kind:?}");
                    }
                }
                let dims = U32x8::from_fn(|i| (round * 5 + i as u32 * 37) % 300);
                for pair in [false, true] {
                    let active = 0b1011_1101;
                    let (x, y) =
                        sampler.get_lanes::<F64x8, U32x8>(&lanes, &mut streams, dims, active, pair);
                    let (x32, y32) =
                        sampler.get_lanes::<F32x8, U32x8>(&lanes, &mut streams, dims, active, pair);
                    // The AVX2 build's register lanes hash to the same bits.
                    #[cfg(target_arch = "x86_64")]
                    if facette_bsdf::lanes::avx2::available() {
                        use facette_bsdf::lanes::{F32x8Avx2, U32x8Avx2};
                        let (xr, yr) = sampler.get_lanes::<F32x8Avx2, U32x8Avx2>(
                            &lanes,
                            &mut streams,
                            U32x8Avx2::from_array(dims.0),
                            active,
                            pair,
                        );
                        assert_eq!((xr.to_array(), yr.to_array()), (x32.0, y32.0), "{kind:?}");
                    }
                    for i in (0..8).filter(|i| active & (1 << i) != 0) {
                        let mut st = streams[i].clone();
                        st.set_dimension(dims.lane(i));
                        let (ex, ey) = if pair {
                            let v = st.get_2d();
                            (v.x, v.y)
                        } else {
                            (st.get_1d(), 0.0)
                        };
                        assert_eq!(x.lane(i).to_bits(), ex.to_bits(), "{kind:?} lane {i}");
                        assert!((x32.lane(i) - ex).abs() < 1e-7 && x32.lane(i) < 1.0);
                        if pair {
                            assert_eq!(y.lane(i).to_bits(), ey.to_bits(), "{kind:?} lane {i}");
                            assert!((y32.lane(i) - ey).abs() < 1e-7 && y32.lane(i) < 1.0);
                        }
                    }
                }
            }
        }
    }
}
