//! The MERL binary BRDF format (Matusik et al. 2003, "A Data-Driven Reflectance Model"):
//! isotropic BRDFs tabulated in Rusinkiewicz's half/difference angles.
//!
//! | bytes | content |
//! |---|---|
//! | 12 | three int32 (little-endian) dimensions: 90 (θ_h), 90 (θ_d), 180 (φ_d); product N = 1 458 000 |
//! | 8·3·N | float64 values, channel-major (all red, then green, then blue); within a channel, index = φ_d + 180 (θ_d + 90 θ_h) |
//!
//! A stored value times its channel's scale (1/1500, 1.15/1500, 1.66/1500 for R, G, B) is
//! f in 1/sr; negative values mark invalid (unmeasured) bins. Bins: θ_h non-linear,
//! index ⌊√(θ_h/(π/2))·90⌋ (dense near the specular peak); θ_d linear over [0, π/2), 1° per
//! bin; φ_d linear over [0, π), 1° per bin (φ_d and φ_d + π are the same pair by
//! reciprocity). φ_h is absent: the BRDF is isotropic.
//!
//! Directions from angles: h = (sin θ_h, 0, cos θ_h), d = (sin θ_d cos φ_d, sin θ_d sin φ_d,
//! cos θ_d) expressed in h's frame, i = R_y(θ_h) d and o = R_y(θ_h) d' with d' the
//! difference vector at φ_d + π. Lookups take the bin that contains the pair; the writer
//! evaluates a model at bin centres (θ_h at the centre of the index, (k + ½)² /90 · 90°).

#![allow(clippy::needless_range_loop)] // channel loops index the per-channel scales

use facette_bsdf::math::rng::{Pcg32, RandomSource};
use facette_bsdf::storage::atomic_file::write_atomically;
use facette_bsdf::{Spectrum, Vec3};
use rayon::prelude::*;
use std::f64::consts::{FRAC_PI_2, PI};
use std::path::Path;
use thiserror::Error;

pub const THETA_H_BINS: usize = 90;
pub const THETA_D_BINS: usize = 90;
pub const PHI_D_BINS: usize = 180;
/// Bins per channel.
pub const BINS: usize = THETA_H_BINS * THETA_D_BINS * PHI_D_BINS;
/// Per-channel factors from stored values to f (1/sr).
pub const SCALES: [f64; 3] = [1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0];
/// Size of a MERL file in bytes.
pub const FILE_BYTES: usize = 12 + 8 * 3 * BINS;

#[derive(Debug, Error)]
pub enum MerlError {
    #[error("{path}: {source}")]
    Io {
        path: String,
        #[source]
        source: std::io::Error,
    },
    #[error("{path}: not a MERL BRDF file: {reason}")]
    Invalid { path: String, reason: String },
}

/// A measured isotropic BRDF on the MERL grid, values in 1/sr (negative = invalid).
#[derive(Clone, Debug)]
pub struct MerlBrdf {
    /// Channel-major: `values[c * BINS + index]`.
    values: Vec<f64>,
}

/// Bin index of (θ_h, θ_d, φ_d) indices.
#[inline]
pub fn bin_index(ih: usize, id: usize, ip: usize) -> usize {
    ip + PHI_D_BINS * (id + THETA_D_BINS * ih)
}

/// The (θ_h, θ_d, φ_d) indices of a bin.
#[inline]
pub fn bin_indices(index: usize) -> (usize, usize, usize) {
    (
        index / (PHI_D_BINS * THETA_D_BINS),
        (index / PHI_D_BINS) % THETA_D_BINS,
        index % PHI_D_BINS,
    )
}

/// θ_h index: ⌊√(θ_h/(π/2))·90⌋, clamped.
#[inline]
pub fn theta_h_index(theta_h: f64) -> usize {
    if theta_h.is_nan() || theta_h <= 0.0 {
        return 0;
    }
    ((theta_h / FRAC_PI_2).sqrt() * THETA_H_BINS as f64).min(THETA_H_BINS as f64 - 1.0) as usize
}

/// θ_d index: linear over [0, π/2).
#[inline]
pub fn theta_d_index(theta_d: f64) -> usize {
    ((theta_d.max(0.0) / FRAC_PI_2 * THETA_D_BINS as f64) as usize).min(THETA_D_BINS - 1)
}

/// φ_d index: φ_d folded into [0, π), linear.
#[inline]
pub fn phi_d_index(phi_d: f64) -> usize {
    let mut p = phi_d.rem_euclid(2.0 * PI);
    if p >= PI {
        p -= PI;
    }
    ((p / PI * PHI_D_BINS as f64) as usize).min(PHI_D_BINS - 1)
}

/// Centre angles (θ_h, θ_d, φ_d) of a bin, radians.
pub fn bin_centre(ih: usize, id: usize, ip: usize) -> (f64, f64, f64) {
    let u = (ih as f64 + 0.5) / THETA_H_BINS as f64;
    (
        u * u * FRAC_PI_2,
        (id as f64 + 0.5) / THETA_D_BINS as f64 * FRAC_PI_2,
        (ip as f64 + 0.5) / PHI_D_BINS as f64 * PI,
    )
}

#[inline]
fn rot_y(v: Vec3, a: f64) -> Vec3 {
    let (s, c) = a.sin_cos();
    Vec3::new(v.x * c + v.z * s, v.y, -v.x * s + v.z * c)
}

#[inline]
fn rot_z(v: Vec3, a: f64) -> Vec3 {
    let (s, c) = a.sin_cos();
    Vec3::new(v.x * c - v.y * s, v.x * s + v.y * c, v.z)
}

/// The pair (i, o) of half/difference angles (φ_h = 0).
pub fn directions_from_angles(theta_h: f64, theta_d: f64, phi_d: f64) -> (Vec3, Vec3) {
    let (st, ct) = theta_d.sin_cos();
    let (sp, cp) = phi_d.sin_cos();
    let d = Vec3::new(st * cp, st * sp, ct);
    let d2 = Vec3::new(-d.x, -d.y, d.z);
    (rot_y(d, theta_h), rot_y(d2, theta_h))
}

/// Half/difference angles (θ_h, φ_h, θ_d, φ_d) of a pair of unit directions.
pub fn angles_from_directions(i: Vec3, o: Vec3) -> (f64, f64, f64, f64) {
    let h = (i + o).normalize_or_zero();
    let theta_h = h.z.clamp(-1.0, 1.0).acos();
    let phi_h = h.y.atan2(h.x);
    let d = rot_y(rot_z(i, -phi_h), -theta_h);
    (theta_h, phi_h, d.z.clamp(-1.0, 1.0).acos(), d.y.atan2(d.x))
}

impl MerlBrdf {
    /// Parses a file's bytes; `path` names it in errors.
    pub fn from_bytes(bytes: &[u8], path: &str) -> Result<MerlBrdf, MerlError> {
        let bad = |reason: String| MerlError::Invalid {
            path: path.to_string(),
            reason,
        };
        if bytes.len() < 12 {
            return Err(bad(format!(
                "{} bytes, shorter than the 12-byte header of three int32 dimensions",
                bytes.len()
            )));
        }
        let dims: Vec<i32> = (0..3)
            .map(|k| i32::from_le_bytes(bytes[4 * k..4 * k + 4].try_into().expect("4 bytes")))
            .collect();
        // Checked before any arithmetic on them: three random int32s overflow a product.
        let product = dims.iter().try_fold(1i64, |p, &d| p.checked_mul(d as i64));
        if dims.iter().any(|&d| d <= 0) || product != Some(BINS as i64) {
            let product = product.map_or("more than 2^63".to_string(), |p| p.to_string());
            return Err(bad(format!(
                "dimensions {} × {} × {} (product {product}); a MERL file has 90 × 90 × 180 = {BINS}",
                dims[0], dims[1], dims[2]
            )));
        }
        if dims != [90, 90, 180] {
            return Err(bad(format!(
                "dimensions {} × {} × {}: the bins are laid out as θ_h = 90, θ_d = 90, φ_d = 180, in that order",
                dims[0], dims[1], dims[2]
            )));
        }
        if bytes.len() != FILE_BYTES {
            return Err(bad(format!(
                "{} bytes; expected {FILE_BYTES} (12 header bytes + 3 × {BINS} float64 values){}",
                bytes.len(),
                if bytes.len() < FILE_BYTES {
                    " — the file is truncated"
                } else {
                    " — trailing bytes"
                }
            )));
        }
        let mut values = Vec::with_capacity(3 * BINS);
        for c in 0..3 {
            for k in 0..BINS {
                let o = 12 + 8 * (c * BINS + k);
                let v = f64::from_le_bytes(bytes[o..o + 8].try_into().expect("8 bytes"));
                if v.is_nan() || v.is_infinite() {
                    return Err(bad(format!(
                        "value {v} at channel {c}, bin {k}: values must be finite (negative marks an invalid bin)"
                    )));
                }
                values.push(if v < 0.0 { -1.0 } else { v * SCALES[c] });
            }
        }
        Ok(MerlBrdf { values })
    }

    /// Reads a MERL file.
    pub fn load(path: &Path) -> Result<MerlBrdf, MerlError> {
        let p = path.display().to_string();
        // The format has one size: a larger file is refused before it is read into memory
        // (a shorter one is read, for the message about its header).
        if let Ok(m) = std::fs::metadata(path) {
            if m.is_file() && m.len() > FILE_BYTES as u64 {
                return Err(MerlError::Invalid {
                    path: p,
                    reason: format!(
                        "{} bytes; a MERL file has exactly {FILE_BYTES} (12 header bytes + 3 × {BINS} float64 values)",
                        m.len()
                    ),
                });
            }
        }
        let bytes = std::fs::read(path).map_err(|e| MerlError::Io {
            path: p.clone(),
            source: e,
        })?;
        Self::from_bytes(&bytes, &p)
    }

    /// The file's bytes.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(FILE_BYTES);
        for d in [90i32, 90, 180] {
            out.extend_from_slice(&d.to_le_bytes());
        }
        for c in 0..3 {
            for k in 0..BINS {
                let v = self.values[c * BINS + k];
                let stored = if v < 0.0 { -1.0 } else { v / SCALES[c] };
                out.extend_from_slice(&stored.to_le_bytes());
            }
        }
        out
    }

    /// Writes a MERL file atomically.
    pub fn save(&self, path: &Path) -> Result<(), MerlError> {
        write_atomically(path, &self.to_bytes()).map_err(|e| MerlError::Io {
            path: path.display().to_string(),
            source: e,
        })
    }

    /// Tabulates `f(i, o)` at every bin centre whose two directions are above the surface;
    /// `None` (and the bins below the horizon) are stored as invalid.
    pub fn from_fn(f: impl Fn(usize, Vec3, Vec3) -> Option<Spectrum> + Sync) -> MerlBrdf {
        let rows: Vec<Vec<Option<Spectrum>>> = (0..THETA_H_BINS)
            .into_par_iter()
            .map(|ih| {
                let mut row = Vec::with_capacity(THETA_D_BINS * PHI_D_BINS);
                for id in 0..THETA_D_BINS {
                    for ip in 0..PHI_D_BINS {
                        let (th, td, pd) = bin_centre(ih, id, ip);
                        let (i, o) = directions_from_angles(th, td, pd);
                        let v = if i.z > 0.0 && o.z > 0.0 {
                            f(bin_index(ih, id, ip), i, o)
                                .filter(|s| s.is_finite() && !s.has_negative())
                        } else {
                            None
                        };
                        row.push(v);
                    }
                }
                row
            })
            .collect();
        let mut values = vec![-1.0; 3 * BINS];
        for (k, v) in rows.into_iter().flatten().enumerate() {
            if let Some(s) = v {
                for c in 0..3 {
                    values[c * BINS + k] = s[c];
                }
            }
        }
        MerlBrdf { values }
    }

    /// The value of bin `index`, `None` when invalid.
    #[inline]
    pub fn bin(&self, index: usize) -> Option<Spectrum> {
        let s = Spectrum::rgb(
            self.values[index],
            self.values[BINS + index],
            self.values[2 * BINS + index],
        );
        (!s.has_negative()).then_some(s)
    }

    /// f(i, o) from the bin containing the pair (nearest-bin lookup); `None` for invalid
    /// bins and directions below the surface.
    pub fn lookup(&self, i: Vec3, o: Vec3) -> Option<Spectrum> {
        if i.z <= 0.0 || o.z <= 0.0 {
            return None;
        }
        let (th, _, td, pd) = angles_from_directions(i, o);
        self.bin(bin_index(
            theta_h_index(th),
            theta_d_index(td),
            phi_d_index(pd),
        ))
    }

    /// Number of valid bins.
    pub fn valid_bins(&self) -> usize {
        (0..BINS).filter(|&k| self.bin(k).is_some()).count()
    }

    /// Multiplies every valid value by 1 + `relative`·N(0, 1) (clamped at zero), with a
    /// fixed seed: synthetic measurement noise for tests.
    pub fn with_multiplicative_noise(mut self, relative: f64, seed: u64) -> MerlBrdf {
        let mut rng = Pcg32::new(seed, 11);
        for v in self.values.iter_mut() {
            // Draw for every entry so that the noise of a bin does not depend on the others.
            let n = standard_normal(&mut rng);
            if *v >= 0.0 {
                *v = (*v * (1.0 + relative * n)).max(0.0);
            }
        }
        self
    }
}

/// A standard normal number (Box–Muller).
pub fn standard_normal(rng: &mut dyn RandomSource) -> f64 {
    let u1 = 1.0 - rng.next_f64();
    let u2 = rng.next_f64();
    (-2.0 * u1.ln()).sqrt() * (2.0 * PI * u2).cos()
}

#[cfg(test)]
mod tests {
    use super::*;
    use facette_bsdf::math::spherical_direction;

    #[test]
    fn angles_round_trip_and_bins_contain_their_centres() {
        for &(th, td, pd) in &[(0.3, 0.5, 1.0), (0.01, 1.2, 2.9), (1.0, 0.2, 0.1)] {
            let (i, o) = directions_from_angles(th, td, pd);
            let (th2, ph2, td2, pd2) = angles_from_directions(i, o);
            assert!((th - th2).abs() < 1e-9 && ph2.abs() < 1e-9 && (td - td2).abs() < 1e-9);
            assert!((pd - pd2).abs() < 1e-9, "{pd} {pd2}");
            assert!(((i + o).normalize() - Vec3::new(th.sin(), 0.0, th.cos())).length() < 1e-9);
        }
        for ih in [0, 1, 45, 89] {
            for (id, ip) in [(0, 0), (30, 90), (89, 179)] {
                let (th, td, pd) = bin_centre(ih, id, ip);
                assert_eq!(
                    (theta_h_index(th), theta_d_index(td), phi_d_index(pd)),
                    (ih, id, ip)
                );
                assert_eq!(bin_indices(bin_index(ih, id, ip)), (ih, id, ip));
            }
        }
        // φ_d and φ_d + π are the same bin (reciprocity).
        assert_eq!(phi_d_index(0.3), phi_d_index(0.3 + PI));
    }

    #[test]
    fn writes_and_reads_back_with_channel_scales() {
        let f = |_: usize, i: Vec3, o: Vec3| Some(Spectrum::rgb(0.1, 0.2, 0.3) * (1.0 + i.z * o.z));
        let m = MerlBrdf::from_fn(f);
        let bytes = m.to_bytes();
        assert_eq!(bytes.len(), FILE_BYTES);
        // The stored red value of a bin is f / (1/1500).
        let k = bin_index(10, 20, 30);
        let stored = f64::from_le_bytes(bytes[12 + 8 * k..12 + 8 * k + 8].try_into().unwrap());
        assert!((stored * SCALES[0] - m.bin(k).unwrap()[0]).abs() < 1e-12);
        let back = MerlBrdf::from_bytes(&bytes, "mem").unwrap();
        let (i, o) = (spherical_direction(0.4, 0.0), spherical_direction(0.7, 2.0));
        let v = back.lookup(i, o).unwrap();
        let exact = f(0, i, o).unwrap();
        assert!((v[2] / exact[2] - 1.0).abs() < 0.05, "{v:?} {exact:?}");
        // Below the horizon: invalid bins.
        let below = (0..BINS).filter(|&k| back.bin(k).is_none()).count();
        assert!(below > 0 && below < BINS / 2, "{below}");
        assert_eq!(back.valid_bins() + below, BINS);
    }

    #[test]
    fn malformed_files_are_clear_errors() {
        let e = MerlBrdf::from_bytes(&[1, 2, 3], "a.binary")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("a.binary") && e.contains("shorter than the 12-byte header"),
            "{e}"
        );
        let mut b = Vec::new();
        for d in [90i32, 90, 90] {
            b.extend_from_slice(&d.to_le_bytes());
        }
        let e = MerlBrdf::from_bytes(&b, "x").unwrap_err().to_string();
        assert!(e.contains("90 × 90 × 180"), "{e}");
        let mut b = Vec::new();
        for d in [90i32, 90, 180] {
            b.extend_from_slice(&d.to_le_bytes());
        }
        b.extend_from_slice(&[0u8; 800]);
        let e = MerlBrdf::from_bytes(&b, "x").unwrap_err().to_string();
        assert!(e.contains("truncated"), "{e}");
        let mut b = Vec::new();
        for d in [180i32, 90, 90] {
            b.extend_from_slice(&d.to_le_bytes());
        }
        let e = MerlBrdf::from_bytes(&b, "x").unwrap_err().to_string();
        assert!(e.contains("in that order"), "{e}");
    }
}
