//! Procedural normal maps of the four kinds CCM19 Fig. 7 renders: a scratched surface, a
//! brushed one, a very rough (bumpy) one and a flake / metallic-paint one. Every map tiles
//! (all constructions are periodic), any size from 1 to [`MAX_GENERATED_SIZE`] per side is
//! accepted, and the result is a pure function of (kind, size, seed): the random streams are
//! keyed by row, scratch or cell index, never by thread.
//!
//! | kind | construction | RMS slope (x, y) |
//! |---|---|---|
//! | `scratched` | flat plate with 0.4·H straight grooves (random direction, length 5–45 % of the map, half-width 0.7–1.6 texel, parabolic profile, depth 0.15–0.6 × half-width), deepest groove wins; analytic gradient | ≈ 0.1 |
//! | `brushed` | white noise filtered with a Gaussian of σ = 48 texels along x and 0.7 texel along y, scaled to an RMS y-slope of 0.15 | ≈ (0.003, 0.15) |
//! | `bumpy` | white noise filtered with an isotropic Gaussian of σ = 3 texels, scaled to an RMS slope of 0.45 per axis ("very rough") | ≈ 0.45 |
//! | `flakes` | periodic Voronoi cells on a jittered grid of 6-texel spacing; each cell a flat flake with a Gaussian random slope (σ = 0.15 per axis, ≈ 8.5°), minus the map's mean slope | ≈ 0.15 |
//!
//! Heights are in texel units, so the slope of a texel is the height gradient.

use super::normal_map::NormalMap;
use crate::error::{ParamError, ParamResult};
use crate::math::rng::{mix_seed, Pcg32, RandomSource};
use rayon::prelude::*;

/// Largest generated width/height.
pub const MAX_GENERATED_SIZE: usize = 4096;

/// The kinds of generated maps.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum NormalMapKind {
    Scratched,
    Brushed,
    Bumpy,
    Flakes,
}

impl NormalMapKind {
    pub const NAMES: &'static [&'static str] = &["scratched", "brushed", "bumpy", "flakes"];

    pub fn parse(s: &str) -> ParamResult<Self> {
        match s {
            "scratched" => Ok(NormalMapKind::Scratched),
            "brushed" => Ok(NormalMapKind::Brushed),
            "bumpy" | "very-rough" => Ok(NormalMapKind::Bumpy),
            "flakes" | "metallic-paint" => Ok(NormalMapKind::Flakes),
            other => Err(ParamError::UnknownChoice {
                what: "normal map kind".into(),
                given: other.into(),
                valid: Self::NAMES.join(", "),
            }),
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            NormalMapKind::Scratched => "scratched",
            NormalMapKind::Brushed => "brushed",
            NormalMapKind::Bumpy => "bumpy",
            NormalMapKind::Flakes => "flakes",
        }
    }
}

/// Generates a `size`×`size` map.
pub fn generate(kind: NormalMapKind, size: usize, seed: u64) -> ParamResult<NormalMap> {
    if size == 0 || size > MAX_GENERATED_SIZE {
        return Err(ParamError::OutOfRange {
            name: "resolution".into(),
            value: size as f64,
            expected: format!("1 <= resolution <= {MAX_GENERATED_SIZE}"),
        });
    }
    let slopes = match kind {
        NormalMapKind::Scratched => scratched(size, seed),
        NormalMapKind::Brushed => {
            let h = filtered_noise(size, seed, 48.0, 0.7);
            slopes_of_heights(&h, size, Target::RmsY(0.15))
        }
        NormalMapKind::Bumpy => {
            let h = filtered_noise(size, seed, 3.0, 3.0);
            slopes_of_heights(&h, size, Target::RmsBoth(0.45))
        }
        NormalMapKind::Flakes => flakes(size, seed),
    };
    NormalMap::from_slopes(size, size, slopes)
}

/// How a height field is scaled before its gradient becomes the map.
enum Target {
    /// RMS of the y slope.
    RmsY(f64),
    /// RMS of the slope per axis (average of both).
    RmsBoth(f64),
}

/// Periodic central differences of a height field, scaled to the target roughness.
fn slopes_of_heights(h: &[f64], n: usize, target: Target) -> Vec<[f32; 2]> {
    let at = |x: i64, y: i64| {
        let xi = x.rem_euclid(n as i64) as usize;
        let yi = y.rem_euclid(n as i64) as usize;
        h[yi * n + xi]
    };
    let grad: Vec<[f64; 2]> = (0..n * n)
        .into_par_iter()
        .with_min_len(4096)
        .map(|k| {
            let (x, y) = ((k % n) as i64, (k / n) as i64);
            [
                0.5 * (at(x + 1, y) - at(x - 1, y)),
                0.5 * (at(x, y + 1) - at(x, y - 1)),
            ]
        })
        .collect();
    let count = (n * n) as f64;
    let rms_x = (grad.iter().map(|g| g[0] * g[0]).sum::<f64>() / count).sqrt();
    let rms_y = (grad.iter().map(|g| g[1] * g[1]).sum::<f64>() / count).sqrt();
    let scale = match target {
        Target::RmsY(t) => t / rms_y.max(1e-300),
        Target::RmsBoth(t) => t / (0.5 * (rms_x + rms_y)).max(1e-300),
    };
    grad.iter()
        .map(|g| [(g[0] * scale) as f32, (g[1] * scale) as f32])
        .collect()
}

/// White noise (one stream per row) filtered by a periodic, separable, approximately
/// Gaussian kernel of standard deviations (σ_x, σ_y): three passes of box filters per axis.
fn filtered_noise(n: usize, seed: u64, sigma_x: f64, sigma_y: f64) -> Vec<f64> {
    let mut h: Vec<f64> = (0..n)
        .into_par_iter()
        .flat_map_iter(|y| {
            let mut rng = Pcg32::new(mix_seed(seed, y as u64), 0x6e6f6973);
            (0..n)
                .map(move |_| rng.next_f64() - 0.5)
                .collect::<Vec<_>>()
        })
        .collect();
    // Rows (x direction).
    h.par_chunks_mut(n)
        .for_each(|row| blur_periodic(row, sigma_x));
    // Columns: transpose, blur rows, transpose back.
    let mut t = transpose(&h, n);
    t.par_chunks_mut(n)
        .for_each(|col| blur_periodic(col, sigma_y));
    transpose(&t, n)
}

fn transpose(a: &[f64], n: usize) -> Vec<f64> {
    (0..n * n)
        .into_par_iter()
        .with_min_len(4096)
        .map(|k| a[(k % n) * n + k / n])
        .collect()
}

/// Three periodic box filters whose combined variance is σ² (box width w: variance
/// (w² − 1)/12 per pass).
fn blur_periodic(v: &mut [f64], sigma: f64) {
    let n = v.len();
    let w = ((4.0 * sigma * sigma + 1.0).sqrt().round() as usize).max(1) | 1;
    if w == 1 || n < 2 {
        return;
    }
    let r = (w / 2) as i64;
    let mut tmp = vec![0.0; n];
    for _ in 0..3 {
        let at = |i: i64| v[i.rem_euclid(n as i64) as usize];
        let mut s: f64 = (-r..=r).map(at).sum();
        for (i, t) in tmp.iter_mut().enumerate() {
            *t = s / w as f64;
            let i = i as i64;
            s += at(i + r + 1) - at(i - r);
        }
        v.copy_from_slice(&tmp);
    }
}

/// A flat plate with straight parabolic grooves; each texel takes the deepest groove.
fn scratched(n: usize, seed: u64) -> Vec<[f32; 2]> {
    let nf = n as f64;
    let count = ((0.4 * nf).round() as usize).max(1);
    // depth (positive = below the plate) and gradient of the deepest groove per texel.
    let mut depth = vec![0.0f64; n * n];
    let mut grad = vec![[0.0f32; 2]; n * n];
    for s in 0..count {
        let mut rng = Pcg32::new(mix_seed(seed, s as u64), 0x73637261);
        let cx = rng.next_f64() * nf;
        let cy = rng.next_f64() * nf;
        let angle = rng.next_f64() * std::f64::consts::PI;
        let length = (0.05 + 0.4 * rng.next_f64()) * nf;
        let half_width = 0.7 + 0.9 * rng.next_f64();
        let d0 = half_width * (0.15 + 0.45 * rng.next_f64());
        let (dy, dx) = angle.sin_cos();
        // Unit normal of the groove's axis in the plane.
        let (nx, ny) = (-dy, dx);
        let steps = (length.ceil() as i64).max(1);
        let reach = half_width.ceil() as i64 + 1;
        for t in -steps / 2..=steps / 2 {
            let px = cx + dx * t as f64;
            let py = cy + dy * t as f64;
            for oy in -reach..=reach {
                for ox in -reach..=reach {
                    let tx = (px.floor() as i64 + ox).rem_euclid(n as i64);
                    let ty = (py.floor() as i64 + oy).rem_euclid(n as i64);
                    // Texel centre relative to the groove, unwrapped near (px, py).
                    let ux = px.floor() + ox as f64 + 0.5 - cx;
                    let uy = py.floor() + oy as f64 + 0.5 - cy;
                    let along = ux * dx + uy * dy;
                    if along.abs() > 0.5 * length {
                        continue;
                    }
                    let across = ux * nx + uy * ny;
                    let q = across / half_width;
                    if q.abs() >= 1.0 {
                        continue;
                    }
                    // The groove fades in over the last 10 % of its length at each end.
                    let e = ((0.5 * length - along.abs()) / (0.1 * length)).min(1.0);
                    let d = d0 * e * (1.0 - q * q);
                    let k = ty as usize * n + tx as usize;
                    if d > depth[k] {
                        depth[k] = d;
                        // Height h = −d: ∇h = d0 e 2q/w · n̂ (+ the fade's along term).
                        let g_across = d0 * e * 2.0 * q / half_width;
                        let g_along = if e < 1.0 {
                            -d0 * (1.0 - q * q) * along.signum() / (0.1 * length)
                        } else {
                            0.0
                        };
                        // ∇(−d) = −∂d/∂across n̂ − ∂d/∂along t̂.
                        grad[k] = [
                            (g_across * nx - g_along * dx) as f32,
                            (g_across * ny - g_along * dy) as f32,
                        ];
                    }
                }
            }
        }
    }
    grad
}

/// Periodic Voronoi flakes on a jittered grid; each flake a flat facet of random slope.
fn flakes(n: usize, seed: u64) -> Vec<[f32; 2]> {
    let cells = ((n as f64 / 6.0).round() as usize).max(1);
    let cell = n as f64 / cells as f64;
    // Per cell: seed point and slope.
    let sites: Vec<([f64; 2], [f32; 2])> = (0..cells * cells)
        .map(|c| {
            let mut rng = Pcg32::new(mix_seed(seed, c as u64), 0x666c616b);
            let (cx, cy) = ((c % cells) as f64, (c / cells) as f64);
            let p = [
                (cx + 0.1 + 0.8 * rng.next_f64()) * cell,
                (cy + 0.1 + 0.8 * rng.next_f64()) * cell,
            ];
            let (gx, gy) = super::lobe::standard_normal_2d(rng.next_2d());
            (p, [(0.15 * gx) as f32, (0.15 * gy) as f32])
        })
        .collect();
    let slopes: Vec<[f32; 2]> = (0..n * n)
        .into_par_iter()
        .with_min_len(4096)
        .map(|k| {
            let (x, y) = ((k % n) as f64 + 0.5, (k / n) as f64 + 0.5);
            let (ci, cj) = ((x / cell) as i64, (y / cell) as i64);
            let mut best = (f64::INFINITY, [0.0f32; 2]);
            for oj in -1..=1 {
                for oi in -1..=1 {
                    let (gi, gj) = (ci + oi, cj + oj);
                    let wi = gi.rem_euclid(cells as i64) as usize;
                    let wj = gj.rem_euclid(cells as i64) as usize;
                    let (p, s) = sites[wj * cells + wi];
                    // Shift the site by whole periods to the copy next to (x, y).
                    let px = p[0] + (gi - wi as i64) as f64 * cell;
                    let py = p[1] + (gj - wj as i64) as f64 * cell;
                    let d = (px - x).powi(2) + (py - y).powi(2);
                    if d < best.0 {
                        best = (d, s);
                    }
                }
            }
            best.1
        })
        .collect();
    // Zero mean slope, as for any periodic height field: a non-zero mean would tilt the
    // whole plate, and a tilted patch seen with the renderer's cos θ_i is not energy
    // conserving (docs/glints.md).
    let count = (n * n) as f64;
    let mx = slopes.iter().map(|s| s[0] as f64).sum::<f64>() / count;
    let my = slopes.iter().map(|s| s[1] as f64).sum::<f64>() / count;
    slopes
        .iter()
        .map(|s| [(s[0] as f64 - mx) as f32, (s[1] as f64 - my) as f32])
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn maps_are_deterministic_and_seed_dependent() {
        for &kind in &[
            NormalMapKind::Scratched,
            NormalMapKind::Brushed,
            NormalMapKind::Bumpy,
            NormalMapKind::Flakes,
        ] {
            let a = generate(kind, 96, 5).unwrap();
            let b = generate(kind, 96, 5).unwrap();
            let c = generate(kind, 96, 6).unwrap();
            assert_eq!(a, b, "{kind:?}");
            assert_ne!(a, c, "{kind:?}");
            let rms = a.rms_slope();
            assert!(rms[0].is_finite() && rms[1] > 0.005, "{kind:?} {rms:?}");
        }
    }

    #[test]
    fn roughness_matches_each_kind() {
        let b = generate(NormalMapKind::Brushed, 256, 1)
            .unwrap()
            .rms_slope();
        assert!((b[1] - 0.15).abs() < 1e-3 && b[0] < 0.05, "brushed {b:?}");
        let v = generate(NormalMapKind::Bumpy, 256, 1).unwrap().rms_slope();
        assert!((0.5 * (v[0] + v[1]) - 0.45).abs() < 1e-3, "bumpy {v:?}");
        let f = generate(NormalMapKind::Flakes, 256, 1).unwrap().rms_slope();
        assert!(
            (f[0] - 0.15).abs() < 0.03 && (f[1] - 0.15).abs() < 0.03,
            "flakes {f:?}"
        );
        let s = generate(NormalMapKind::Scratched, 256, 1).unwrap();
        let flat = s
            .slopes()
            .iter()
            .filter(|v| v[0] == 0.0 && v[1] == 0.0)
            .count();
        let frac = flat as f64 / s.texels() as f64;
        assert!(frac > 0.3 && frac < 0.95, "scratched flat fraction {frac}");
    }

    #[test]
    fn sizes_are_checked_and_odd_sizes_work() {
        assert!(generate(NormalMapKind::Bumpy, 0, 1).is_err());
        let e = generate(NormalMapKind::Bumpy, 5000, 1)
            .unwrap_err()
            .to_string();
        assert!(e.contains("resolution"), "{e}");
        let m = generate(NormalMapKind::Flakes, 37, 2).unwrap();
        assert_eq!((m.width(), m.height()), (37, 37));
        assert!(NormalMapKind::parse("wood")
            .unwrap_err()
            .to_string()
            .contains("scratched, brushed, bumpy, flakes"));
    }
}
