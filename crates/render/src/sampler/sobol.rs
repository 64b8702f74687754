//! Owen-scrambled Sobol points in Morton order: the design of pbrt-v4's `ZSobolSampler`
//! (Ahmed & Wonka 2020, "Screen-Space Blue-Noise Diffusion of Monte Carlo Sampling Error
//! via Hierarchical Ordering of Pixels", SIGGRAPH Asia; Pharr, Jakob & Humphreys,
//! "Physically Based Rendering", 4th ed., §8.7).
//!
//! Why this design: the samples of all pixels are taken from ONE Sobol sequence. The index
//! of a camera sample is the pixel's Morton (Z-order) code followed by the sample number,
//! so a pixel's samples are an aligned block of the sequence — a (0, m, 2)-net in every
//! pair of dimensions, i.e. stratified like a jittered grid and better — and a 2 × 2 block
//! of pixels is the next larger aligned block, and so on up the quadtree. Each dimension
//! then scrambles that index: every bit is flipped or not by a hash of the bits above it
//! (a nested, Owen scramble of the index tree, done in constant time by Burley's hash-based
//! scramble of the bit-reversed index): the pixel blocks stay aligned blocks, but
//! neighbouring pixels get unrelated point sets in every dimension, and since together
//! they still form a larger net, their errors are negatively correlated — the error is
//! spread as blue noise over the image. (pbrt-v4 permutes the base-4 digits instead, each
//! by a hash of the digits above it — all 24 permutations of a Morton digit rather than the
//! 8 a base-2 scramble reaches — at one hash per digit: measured here, that loop made a
//! Sobol render 1.4–1.75× slower per sample than an independent one; the base-2 scramble
//! keeps every property the tests check at a small constant cost.)
//!
//! Only the first two Sobol dimensions are ever needed: 1D samples use dimension 0 and 2D
//! samples dimensions 0 and 1 (a (0, 2)-sequence), each camera-sample dimension with its
//! own index permutation and its own Owen scramble (`hash::owen_scramble`, Burley 2020),
//! so no generator tables for higher dimensions are needed.
//!
//! The index holds at most 64 bits. Pixel quadtree levels that do not fit (a huge image
//! at a huge sample count: 2 · log2(resolution) + log2(spp) > 64) are folded into the
//! hashes instead: the image is cut into tiles of 2^levels × 2^levels pixels, each one
//! independently scrambled ZSobol pattern. Likewise, sample-index bits above 32 (which the
//! 32-column generator matrices cannot resolve) select an independent Owen scramble, and
//! sample numbers at or above the rounded-up spp (which have no place in the pixel's
//! block) an independent tile; nothing overflows and every sample keeps its own numbers.

use super::hash::{laine_karras, laine_karras_lanes, owen_scramble};
use facette_bsdf::lanes::Bits32;
use facette_bsdf::math::rng::mix_seed;
use glam::DVec2;

/// ⌈log2 n⌉ (0 for n ≤ 1).
pub(crate) fn ceil_log2(n: u64) -> u32 {
    if n <= 1 {
        0
    } else {
        64 - (n - 1).leading_zeros()
    }
}

/// The generator matrix of Sobol dimension 1, column j (the image of index bit j) as a
/// 32-bit fraction: Pascal's triangle mod 2, i.e. output digit i (of weight 2^-(i+1)) is set
/// iff C(j, i) is odd, which by Lucas' theorem is iff the bits of i are a subset of those
/// of j. With dimension 0 (the identity, the van der Corput sequence) it gives the
/// (0, 2)-sequence in base 2 (Sobol 1967; Niederreiter 1992, §4.5). The sampler applies it
/// without the columns ([`sobol_1_reversed`]); the tests check that against them.
#[cfg(test)]
const SOBOL_1: [u32; 32] = pascal_mod2_columns();

#[cfg(test)]
const fn pascal_mod2_columns() -> [u32; 32] {
    let mut cols = [0u32; 32];
    let mut j = 0;
    while j < 32 {
        let mut i = 0;
        while i < 32 {
            if i & j == i {
                cols[j] |= 1 << (31 - i);
            }
            i += 1;
        }
        j += 1;
    }
    cols
}

/// Sobol dimension 0 of `index` as a 32-bit fraction: the van der Corput radical inverse,
/// the bits of the index mirrored around the binary point.
#[cfg(test)]
#[inline]
fn sobol_0(index: u32) -> u32 {
    index.reverse_bits()
}

/// `owen_scramble(sobol_0(index), seed)`: the radical inverse is a bit reversal, and the
/// scramble's first reversal undoes it.
#[inline]
fn scrambled_sobol_0(index: u32, seed: u32) -> u32 {
    laine_karras(index, seed).reverse_bits()
}

/// The generator matrix of dimension 1 applied to every byte value at each of the four
/// byte positions of an index: `SOBOL_1_BYTES[k][b]` is the xor of the columns of the set
/// bits of `b << 8k`, so a product costs four lookups instead of one xor per set bit.
#[cfg(test)]
const SOBOL_1_BYTES: [[u32; 256]; 4] = sobol_1_byte_tables();

#[cfg(test)]
const fn sobol_1_byte_tables() -> [[u32; 256]; 4] {
    let mut t = [[0u32; 256]; 4];
    let mut k = 0;
    while k < 4 {
        let mut b = 0;
        while b < 256 {
            let mut v = 0u32;
            let mut bit = 0;
            while bit < 8 {
                if b & (1 << bit) != 0 {
                    v ^= SOBOL_1[8 * k + bit];
                }
                bit += 1;
            }
            t[k][b] = v;
            b += 1;
        }
        k += 1;
    }
    t
}

/// `sobol_1(index).reverse_bits()`, lane by lane, without a table. Dimension 1's generator
/// matrix is Pascal's triangle mod 2 (`SOBOL_1`: column j has bit 31 − i set where i ⊆ j
/// bitwise, by Lucas' theorem), so bit i of the reversed product is the xor of the index
/// bits j ⊇ i: the superset transform over the five bits of a position, five shift-and-xor
/// steps (in lanes: 15 vector operations in place of 32 byte-table loads).
#[inline(always)]
fn sobol_1_reversed<B: Bits32>(index: B) -> B {
    let mut r = index;
    for (s, m) in [
        (1, 0x5555_5555),
        (2, 0x3333_3333),
        (4, 0x0f0f_0f0f),
        (8, 0x00ff_00ff),
        (16, 0x0000_ffff),
    ] {
        r = r ^ (r.shr(s) & B::splat(m));
    }
    r
}

/// Sobol dimension 1 of `index` as a 32-bit fraction: the xor of the generator columns of
/// the index's set bits, a byte at a time.
#[cfg(test)]
#[inline]
fn sobol_1(index: u32) -> u32 {
    let b = index.to_le_bytes();
    SOBOL_1_BYTES[0][b[0] as usize]
        ^ SOBOL_1_BYTES[1][b[1] as usize]
        ^ SOBOL_1_BYTES[2][b[2] as usize]
        ^ SOBOL_1_BYTES[3][b[3] as usize]
}

/// A 32-bit fraction as an `f64` in [0, 1). Exact: the largest value, 1 − 2⁻³², is
/// representable, so no clamp below 1 is needed (unlike in `f32`, where pbrt clamps).
#[inline]
fn to_unit(bits: u32) -> f64 {
    bits as f64 * (1.0 / (1u64 << 32) as f64)
}

/// Nested uniform (Owen) scramble of the low `bits` bits of `index` under `key`: each bit is
/// flipped by a hash of the more significant bits. Burley's hash-based scramble
/// ([`owen_scramble`]) does it for 32 bits with the field placed at the top of the word (the
/// bits below it are scrambled too and dropped). A wider field is cut in two words, the high
/// one scrambled on its own and the low one under a key that also hashes the high word's
/// bits, which keeps the nesting across the cut.
fn nested_scramble(index: u64, bits: u32, key: u64) -> u64 {
    let field = |v: u32, width: u32, seed: u32| -> u32 {
        if width == 0 {
            0
        } else {
            owen_scramble(v << (32 - width), seed) >> (32 - width)
        }
    };
    if bits <= 32 {
        return field(index as u32, bits, key as u32) as u64;
    }
    let high = (index >> 32) as u32;
    let high_scrambled = field(high, bits - 32, key as u32);
    let low_scrambled = owen_scramble(index as u32, (mix_seed(key, high as u64) >> 32) as u32);
    ((high_scrambled as u64) << 32) | low_scrambled as u64
}

/// The hashes of one dimension of a sample whose index has at most 32 bits (every image of
/// up to 65536² pixels at up to 2^32 / pixels samples): the nested scramble's key and the
/// Owen seeds of the point's two coordinates — what [`ZSobolSample::dimension`] derives
/// from the sample's key, in the form the render kernel tabulates per dimension (the key is
/// one constant per render there).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct DimSeeds {
    pub(crate) field: u32,
    pub(crate) s0: u32,
    pub(crate) s1: u32,
}

impl DimSeeds {
    #[inline]
    pub(crate) fn new(key: u64, dim: u32) -> DimSeeds {
        let dim_key = mix_seed(key, dim as u64);
        // The index bits above 32 are zero.
        let h = mix_seed(dim_key ^ OWEN_TAG, 0);
        DimSeeds {
            field: dim_key as u32,
            s0: h as u32,
            s1: (h >> 32) as u32,
        }
    }
}

/// The scrambled point of one dimension of a sample whose index has `bits` ≤ 32 bits,
/// from `reversed` = the index's bits reversed at the top of the word
/// (`(index << (32 − bits)).reverse_bits()`, a per-sample constant): the nested scramble of
/// the index ([`nested_scramble`]), then Sobol dimension 0 scrambled and, if `pair`,
/// dimension 1 scrambled — [`ZSobolSample::get_1d`] / [`get_2d`](ZSobolSample::get_2d)
/// written once over lanes, for one sample and for eight.
#[inline(always)]
pub(crate) fn short_index_point<B: Bits32>(
    reversed: B,
    bits: u32,
    seeds: [B; 3],
    pair: bool,
) -> (B, B) {
    let index = if bits == 0 {
        B::splat(0)
    } else {
        laine_karras_lanes(reversed, seeds[0])
            .reverse()
            .shr(32 - bits)
    };
    let x = laine_karras_lanes(index, seeds[1]).reverse();
    let y = if pair {
        laine_karras_lanes(sobol_1_reversed(index), seeds[2]).reverse()
    } else {
        B::splat(0)
    };
    (x, y)
}

/// Interleaves the bits of x (even positions) and y (odd positions): the Morton code.
#[inline]
pub(crate) fn morton2(x: u32, y: u32) -> u64 {
    spread_bits(x) | (spread_bits(y) << 1)
}

/// Moves bit k of `v` to bit 2k.
#[inline]
fn spread_bits(v: u32) -> u64 {
    let mut v = v as u64;
    v = (v | (v << 16)) & 0x0000_ffff_0000_ffff;
    v = (v | (v << 8)) & 0x00ff_00ff_00ff_00ff;
    v = (v | (v << 4)) & 0x0f0f_0f0f_0f0f_0f0f;
    v = (v | (v << 2)) & 0x3333_3333_3333_3333;
    (v | (v << 1)) & 0x5555_5555_5555_5555
}

/// Domain separation of the hashes (arbitrary odd constants).
const ZSOBOL_TAG: u64 = 0x5a50_b01d_0000_0001;
const OWEN_TAG: u64 = 0x0e4e_5c2a_0000_0005;

/// The layout of one render's sample indices: built once from the image size and the
/// TOTAL sample count.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct ZSobol {
    seed: u64,
    /// ⌈log2 spp⌉: the sample number's bits at the bottom of the index (≤ 64).
    log2_spp: u32,
    /// Pixel quadtree levels in the index: ⌈log2 max(width, height)⌉, reduced so that
    /// 2 · levels + log2_spp ≤ 64. Coarser levels go to the tile hash.
    levels: u32,
    /// The key of the samples of tile (0, 0) within the spp ([`ZSobol::common_key`]).
    common_key: u64,
}

impl ZSobol {
    pub(crate) fn new(seed: u64, width: usize, height: usize, spp: usize) -> ZSobol {
        let log2_spp = ceil_log2(spp.max(1) as u64);
        let image_levels = ceil_log2(width.max(height).max(1) as u64);
        // The 64-bit index holds 2·levels + log2_spp bits: keep the finest pixel levels
        // that fit (a tile of up to 2^levels pixels on a side per independent pattern).
        let levels = image_levels.min((64 - log2_spp) / 2);
        ZSobol {
            seed,
            log2_spp,
            levels,
            common_key: mix_seed(mix_seed(mix_seed(seed ^ ZSOBOL_TAG, 0), 0), 0),
        }
    }

    /// Bits of the (per-dimension permuted) index in use.
    #[inline]
    pub(crate) fn index_bits(&self) -> u32 {
        2 * self.levels + self.log2_spp
    }

    /// The index of a camera sample (its pixel's Morton code in the tile, then the sample
    /// number) and what did not fit in it: the tile and the sample number's high part.
    #[inline(always)]
    fn index_of(&self, x: usize, y: usize, sample_index: u64) -> (u64, [u64; 3]) {
        let (x, y) = (x as u64, y as u64);
        // levels ≤ 32, so the in-tile coordinates fit in u32 and the shifts in u64.
        let in_tile = (1u64 << self.levels) - 1;
        let morton = morton2((x & in_tile) as u32, (y & in_tile) as u32);
        let (tile_x, tile_y) = (x >> self.levels, y >> self.levels);
        // Sample numbers beyond the pixel's block (only if a caller exceeds the spp given at
        // construction) start a fresh pattern rather than spilling into the pixel bits.
        let (low, extra) = if self.log2_spp >= 64 {
            (sample_index, 0)
        } else {
            let mask = (1u64 << self.log2_spp) - 1;
            (sample_index & mask, sample_index >> self.log2_spp)
        };
        let index = morton.checked_shl(self.log2_spp).unwrap_or(0) | low;
        (index, [tile_x, tile_y, extra])
    }

    /// An index of at most 32 bits reversed at the top of the word (0 for wider ones).
    #[inline(always)]
    fn reversed(&self, index: u64) -> u32 {
        let bits = self.index_bits();
        if bits == 0 || bits > 32 {
            0
        } else {
            ((index as u32) << (32 - bits)).reverse_bits()
        }
    }

    /// The state of one camera sample.
    #[inline]
    pub(crate) fn start(&self, x: usize, y: usize, sample_index: u64) -> ZSobolSample {
        let (index, rest) = self.index_of(x, y, sample_index);
        // 0, 0, 0 for every pixel of an image that fits: then `key` is one constant per
        // seed and this is exactly the ZSobol design.
        let key = if rest == [0, 0, 0] {
            // The same three hashes, made once per render.
            self.common_key
        } else {
            let [tile_x, tile_y, extra] = rest;
            mix_seed(
                mix_seed(mix_seed(self.seed ^ ZSOBOL_TAG, tile_x), tile_y),
                extra,
            )
        };
        ZSobolSample {
            layout: *self,
            index,
            key,
            reversed: self.reversed(index),
        }
    }

    /// [`start`](Self::start)`(x, y, sample_index).lane_word()` without making the sample:
    /// the render kernel's lanes need only this word unless a model draws further numbers.
    #[inline]
    pub(crate) fn lane_word_at(&self, x: usize, y: usize, sample_index: u64) -> Option<u32> {
        if self.index_bits() > 32 {
            return None;
        }
        let (index, rest) = self.index_of(x, y, sample_index);
        if rest != [0, 0, 0] {
            // Another tile or a sample number beyond the spp: the key decides (a hash that
            // equals the common key by chance gives the lane form, as in `lane_word`).
            return self.start(x, y, sample_index).lane_word();
        }
        Some(self.reversed(index))
    }

    /// [`lane_word_at`](Self::lane_word_at) of the samples `(xs[i], ys[i], samples[i])`, i <
    /// `n`, in the integer lanes `B` (lanes from `n` on hold 0), where the layout alone
    /// gives each of them its lane form: an index of at most 32 bits and every sample
    /// number within the spp. `None` otherwise (ask lane by lane).
    ///
    /// An index of at most 32 bits leaves no pixel level to the tile hash (2·levels ≤ 32 −
    /// log2_spp keeps `levels` at the image's, see [`ZSobol::new`]): every pixel is in tile
    /// (0, 0), its coordinates are below 2^16, and a sample number below 2^log2_spp has no
    /// extra part, so the key is the common one. Then the word is the Morton code and the
    /// sample number, reversed: about 25 vector instructions for eight camera samples
    /// against about 120 scalar ones a sample.
    #[inline(always)]
    pub(crate) fn lane_words<B: Bits32>(
        &self,
        xs: &[u32; 8],
        ys: &[u32; 8],
        samples: &[u32; 8],
        n: usize,
    ) -> Option<B> {
        let bits = self.index_bits();
        let active = ((1u32 << n) - 1) as u8;
        let lanes = |a: &[u32; 8]| B::blend_bits(active, B::from_fn(|i| a[i]), B::splat(0));
        let s = lanes(samples);
        // A sample number beyond the spp has another key: no lane form.
        if bits > 32 || (self.log2_spp < 32 && !s.shr(self.log2_spp).all_below(1)) {
            return None;
        }
        if bits == 0 {
            return Some(B::splat(0));
        }
        // Bit k of a 16-bit value to bit 2k. A function, not a closure: a closure is
        // compiled with this generic function's instruction set, not the AVX2 kernel's.
        #[inline(always)]
        fn spread<B: Bits32>(v: B) -> B {
            let v = (v | v.shl(8)) & B::splat(0x00ff_00ff);
            let v = (v | v.shl(4)) & B::splat(0x0f0f_0f0f);
            let v = (v | v.shl(2)) & B::splat(0x3333_3333);
            (v | v.shl(1)) & B::splat(0x5555_5555)
        }
        // log2_spp ≤ bits ≤ 32; at 32 there is no pixel level (and no shift by 32).
        let index = if self.log2_spp >= 32 {
            s
        } else {
            (spread(lanes(xs)) | spread(lanes(ys)).shl(1)).shl(self.log2_spp) | s
        };
        Some(index.shl(32 - bits).reverse())
    }

    /// The key of every sample when the index has at most 32 bits (one tile) and the sample
    /// number is within the render's spp: what the render kernel's per-dimension table of
    /// [`DimSeeds`] is built from.
    pub(crate) fn common_key(&self) -> u64 {
        self.common_key
    }
}

/// One camera sample of a [`ZSobol`] layout.
#[derive(Clone, Debug)]
pub(crate) struct ZSobolSample {
    layout: ZSobol,
    /// Morton code of the pixel (in its tile), then the sample number.
    index: u64,
    /// Hash of the seed and of what did not fit in `index`.
    key: u64,
    /// For an index of at most 32 bits, its bits reversed at the top of the word (the
    /// argument of [`short_index_point`]).
    reversed: u32,
}

impl ZSobolSample {
    /// The sample's index in the Sobol sequence of dimension `dim`: a nested (Owen)
    /// scramble of the `index_bits()` bits of the index under `dim_key` — each bit flipped
    /// by a hash of the bits above it, so that the map is a bijection taking each aligned
    /// block (a pixel's samples, a 2 × 2 block of pixels, …) to an aligned block, and the
    /// first 2^k samples of a pixel to an aligned sub-block.
    fn permuted_index(&self, dim_key: u64) -> u64 {
        nested_scramble(self.index, self.layout.index_bits(), dim_key)
    }

    /// The hash of dimension `dim` and the two Owen seeds of its point.
    #[inline]
    fn dimension(&self, dim: u32) -> (u32, [u32; 2]) {
        let dim_key = mix_seed(self.key, dim as u64);
        let index = self.permuted_index(dim_key);
        // Index bits above the 32 generator columns: an independent scramble.
        let h = mix_seed(dim_key ^ OWEN_TAG, index >> 32);
        (index as u32, [h as u32, (h >> 32) as u32])
    }

    /// The lane form of this sample, where it has one: its reversed index (an index of at
    /// most 32 bits under the render's common key, [`ZSobol::common_key`]).
    #[inline]
    pub(crate) fn lane_word(&self) -> Option<u32> {
        let bits = self.layout.index_bits();
        (bits <= 32 && self.key == self.layout.common_key).then_some(self.reversed)
    }

    /// The point of dimension `dim` (and `dim + 1` if `pair`) as 32-bit fractions.
    #[inline]
    fn point(&self, dim: u32, pair: bool) -> (u32, u32) {
        let bits = self.layout.index_bits();
        if bits <= 32 {
            let s = DimSeeds::new(self.key, dim);
            return short_index_point(self.reversed, bits, [s.field, s.s0, s.s1], pair);
        }
        let (index, seeds) = self.dimension(dim);
        (
            scrambled_sobol_0(index, seeds[0]),
            if pair {
                owen_scramble(sobol_1_reversed(index).reverse_bits(), seeds[1])
            } else {
                0
            },
        )
    }

    /// Camera-sample dimension `dim` as one number: Sobol dimension 0, scrambled.
    pub(crate) fn get_1d(&self, dim: u32) -> f64 {
        to_unit(self.point(dim, false).0)
    }

    /// Camera-sample dimensions `dim` and `dim + 1` as one pair: Sobol dimensions 0 and 1 of
    /// one index, each with its own scramble. Its first coordinate equals `get_1d(dim)`.
    pub(crate) fn get_2d(&self, dim: u32) -> DVec2 {
        let (x, y) = self.point(dim, true);
        DVec2::new(to_unit(x), to_unit(y))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every elementary interval of area 2^-m (2^a × 2^(m−a) cells) holds one point.
    fn is_02_net(points: &[(u32, u32)], m: u32) -> bool {
        assert_eq!(points.len(), 1 << m);
        (0..=m).all(|a| {
            let mut seen = vec![false; 1 << m];
            points.iter().all(|&(x, y)| {
                let cell = ((x as u64 >> (32 - a)) << (m - a)) | (y as u64 >> (32 - (m - a)));
                // A shift by 32 of a u32 widened to u64 is 0: the whole axis, one cell.
                let cell = cell as usize;
                !std::mem::replace(&mut seen[cell], true)
            })
        })
    }

    #[test]
    fn sampler_sobol_generators() {
        // The first columns of the Pascal matrix mod 2 (the classic Sobol dimension 2).
        assert_eq!(
            &SOBOL_1[..6],
            &[
                0x8000_0000,
                0xc000_0000,
                0xa000_0000,
                0xf000_0000,
                0x8800_0000,
                0xcc00_0000
            ]
        );
        assert_eq!(sobol_0(1), 0x8000_0000);
        assert_eq!(sobol_0(6), 0x6000_0000);
        // The unscrambled pair is a (0, 2)-sequence: every aligned block of 2^m points is a
        // (0, m, 2)-net.
        for m in 0..=8u32 {
            for block in 0..(1u32 << (11 - m)) {
                let pts: Vec<(u32, u32)> = (block << m..(block + 1) << m)
                    .map(|i| (sobol_0(i), sobol_1(i)))
                    .collect();
                assert!(is_02_net(&pts, m), "m {m} block {block}");
            }
        }
        // The shortcut for the scrambled first dimension is the scramble itself, and the
        // table-free reversed dimension 1 is the matrix product (column by column) reversed,
        // one lane at a time and eight.
        let by_columns = |i: u32| {
            (0..32)
                .filter(|j| i & (1 << j) != 0)
                .fold(0u32, |v, j| v ^ SOBOL_1[j])
        };
        let mut h = 0x1234_5678_9abc_def0u64;
        for k in 0..10_000u32 {
            h = mix_seed(h, 1);
            let (i, seed) = (h as u32, (h >> 32) as u32);
            assert_eq!(scrambled_sobol_0(i, seed), owen_scramble(sobol_0(i), seed));
            for i in [i, k, u32::MAX - k] {
                assert_eq!(sobol_1(i), by_columns(i));
                assert_eq!(sobol_1_reversed(i), by_columns(i).reverse_bits(), "{i:#x}");
            }
            let lanes = facette_bsdf::lanes::U32x8::from_fn(|l| i.rotate_left(l as u32 * 4));
            let r = sobol_1_reversed(lanes);
            for l in 0..8 {
                assert_eq!(r.lane(l), sobol_1_reversed(lanes.lane(l)));
            }
        }
    }

    /// The lane form of a short index (at most 32 bits) gives the general path's points, to
    /// the bit: the fast path changes no image.
    #[test]
    fn sampler_short_index_points_are_the_general_points() {
        for (w, h, spp) in [(8, 8, 16), (512, 384, 256), (1, 1, 1), (65536, 65536, 1)] {
            let z = ZSobol::new(5, w, h, spp);
            assert!(z.index_bits() <= 32);
            let mut r = 0x9e37_79b9_7f4a_7c15u64;
            for _ in 0..4000 {
                r = mix_seed(r, 3);
                let (x, y) = ((r % w as u64) as usize, ((r >> 20) % h as u64) as usize);
                let s = (r >> 40) % spp as u64;
                let dim = (r >> 58) as u32 * 5 + (r & 7) as u32;
                let zs = z.start(x, y, s);
                let (index, seeds) = zs.dimension(dim);
                let general = (
                    scrambled_sobol_0(index, seeds[0]),
                    owen_scramble(sobol_1(index), seeds[1]),
                );
                assert_eq!(zs.point(dim, true), general, "{w}x{h} {spp} spp");
                assert_eq!(zs.lane_word(), Some(zs.reversed));
            }
        }
        // A sample beyond the spp has its own key: no lane form.
        assert_eq!(ZSobol::new(1, 4, 4, 4).start(0, 0, 4).lane_word(), None);
    }

    #[test]
    fn sampler_nested_scramble_and_morton() {
        for bits in [1u32, 4, 9, 12, 32, 33, 40] {
            let limit = 1u64 << bits;
            // Small fields: every value; wide ones: 4096 spread values. Outputs stay in the
            // field and are distinct (a bijection).
            let values: Vec<u64> = if bits <= 12 {
                (0..limit).collect()
            } else {
                (0..4096u64)
                    .map(|i| i.wrapping_mul(0x9E37_79B9_7F4A_7C15) % limit)
                    .collect()
            };
            let mut seen = std::collections::HashSet::new();
            for &v in &values {
                let out = nested_scramble(v, bits, 99);
                assert!(out < limit, "bits {bits}: {out} outside the field");
                assert!(seen.insert(out), "bits {bits}: not a bijection");
                // Nested: the least significant bit does not affect the others.
                assert_eq!(out >> 1, nested_scramble(v ^ 1, bits, 99) >> 1);
                // … and a pixel's block (the low 4 bits) stays one block.
                if bits > 4 {
                    assert_eq!(out >> 4, nested_scramble(v ^ 0b1011, bits, 99) >> 4);
                }
            }
        }

        assert_eq!(morton2(0, 0), 0);
        assert_eq!(morton2(1, 0), 1);
        assert_eq!(morton2(0, 1), 2);
        assert_eq!(morton2(3, 3), 15);
        assert_eq!(morton2(u32::MAX, u32::MAX), u64::MAX);
        assert_eq!(morton2(u32::MAX, 0), 0x5555_5555_5555_5555);
        assert_eq!(ceil_log2(1), 0);
        assert_eq!(ceil_log2(2), 1);
        assert_eq!(ceil_log2(5), 3);
        assert_eq!(ceil_log2(u64::MAX), 64);
    }

    #[test]
    fn sampler_index_permutation_is_a_block_preserving_bijection() {
        // 8 × 8 pixels (3 levels) with 16 and 8 samples: 10 and 9 index bits.
        for spp in [16usize, 8, 1] {
            let z = ZSobol::new(11, 8, 8, spp);
            let bits = z.index_bits();
            for dim in [0u32, 1, 7] {
                let mut seen = vec![false; 1 << bits];
                for y in 0..8 {
                    for x in 0..8 {
                        let first = z
                            .start(x, y, 0)
                            .permuted_index(mix_seed(z.start(x, y, 0).key, dim as u64));
                        for s in 0..spp as u64 {
                            let zs = z.start(x, y, s);
                            let i = zs.permuted_index(mix_seed(zs.key, dim as u64));
                            assert!(!std::mem::replace(&mut seen[i as usize], true));
                            // The pixel's samples stay in one aligned block of spp.
                            assert_eq!(i >> z.log2_spp, first >> z.log2_spp);
                        }
                    }
                }
                assert!(seen.iter().all(|&b| b));
            }
        }
    }

    #[test]
    fn sampler_zsobol_folds_what_does_not_fit() {
        // 65536² pixels and 2^20 samples fit in 52 bits.
        let z = ZSobol::new(1, 65536, 65536, 1 << 20);
        assert_eq!((z.levels, z.log2_spp), (16, 20));
        // 2^40 samples leave 24 bits: 12 levels, the image cut into 16 × 16 tiles.
        let z = ZSobol::new(1, 65536, 65536, 1 << 40);
        assert_eq!((z.levels, z.log2_spp), (12, 40));
        let a = z.start(5, 7, 3);
        let b = z.start(5 + 4096, 7, 3);
        assert_eq!(a.index, b.index);
        assert_ne!(a.key, b.key);
        assert_ne!(a.get_2d(0), b.get_2d(0));
        // An odd log2 spp leaves an odd bit unused rather than splitting a level.
        let z = ZSobol::new(1, 1 << 20, 1, (1 << 41) - 5);
        assert_eq!((z.levels, z.log2_spp), (11, 41));
        // The extreme: every bit is the sample's.
        let z = ZSobol::new(1, usize::MAX, usize::MAX, usize::MAX);
        assert_eq!((z.levels, z.log2_spp), (0, 64));
        let s = z.start(usize::MAX, usize::MAX, u64::MAX);
        assert_eq!(s.index, u64::MAX);
        for d in 0..4 {
            let v = s.get_2d(d);
            assert!((0.0..1.0).contains(&v.x) && (0.0..1.0).contains(&v.y));
        }
        // Sample numbers beyond the spp given do not spill into the next pixel's block: they
        // reuse the pixel's own block under another key (an independent pattern).
        let z = ZSobol::new(1, 4, 4, 4);
        let (a, b, c) = (z.start(0, 0, 4), z.start(0, 0, 0), z.start(1, 0, 0));
        assert_eq!(a.index, b.index);
        assert_ne!(a.key, b.key);
        assert_ne!(a.index, c.index);
        assert_ne!(a.get_2d(0), b.get_2d(0));
    }
}
