//! The tabulated body term of interfaced Lambertian  [TSBRM §4.3].
//!
//! The body integral I(θ_i, θ_o, φ) = ∫ T(i,m) T(o,m) D(m) G(i,o,m) |i·m||o·m|/(|i·n||o·n|) dω_m
//! (IL18 eq. 13 without its K_d/(π n_i² (1 − r_i K_d)) prefactor, so one table serves every
//! K_d) is stored on a regular grid θ_i, θ_o ∈ [0°, 90°], φ = |φ_o − φ_i| ∈ [0°, 180°] (the
//! integral of an isotropic distribution depends on the azimuth difference only and is even
//! in it), and interpolated trilinearly — bilinear in (θ_o, φ), then linear in θ_i, as
//! TSBRM Fig. 9. Anisotropic distributions would need φ_i as a fourth dimension; tables are
//! refused for them.
//!
//! Entries are computed either with the same N microfacet normals for the whole table
//! (randomized QMC, 8 rotations of a Hammersley set drawn from the D(m)|m·n| sampler), so
//! the table is smooth and each entry carries a standard error, or — with
//! [`TableEntries::Adaptive`] (`facette tabulate --tolerance`) — deterministically, each
//! entry by the adaptive quadrature of `evaluation = "quadrature"`
//! ([`MicrofacetIntegral::integrate`]: IL18 eq. 13 over the hemisphere of normals, cut at
//! its kinks) to a relative tolerance, with its error estimate. Only θ_i ≤ θ_o is
//! computed, the rest by reciprocity.
//!
//! ## File format (`.fctab`, version 2, little-endian)
//!
//! A framed file (`crate::storage::framed`: magic `FCTBODY1`, u32 format version 2, u64
//! payload length, payload, CRC-32); version 1 files (the same payload, unframed) are
//! still read. The payload:
//!
//! | bytes | content |
//! |---|---|
//! | 4 | u32 length L of the header |
//! | L | UTF-8 TOML header: `model = "il-body"`, `ni`, `distribution`, `masking`, `step_deg`, `n_theta`, `n_phi`, `samples` (0 for adaptive entries), `tolerance` (adaptive entries only), `max_stderr` and `mean_stderr` (relative standard errors — for adaptive entries relative error estimates — of the entries below the grazing row), `facette_version` |
//! | 8·n_theta²·n_phi | f64 entries, θ_i-major, then θ_o, then φ |

use crate::error::{ParamError, ParamResult};
use crate::fresnel::fresnel_dielectric;
use crate::limits;
use crate::math::rng::{mix_seed, Pcg32, RandomSource};
use crate::math::warp::hammersley;
use crate::math::{fmt_num, spherical_direction, Vec3, PI};
use crate::microfacet::integral::{check_tolerance, MicrofacetIntegral, TableEntries};
use crate::microfacet::specular_lobe::SpecularLobe;
use crate::microfacet::Distribution;
use rayon::prelude::*;

use crate::storage::atomic_file::write_atomically;
use crate::storage::framed::Framed;

const FRAME: Framed = Framed {
    magic: b"FCTBODY1",
    version: 2,
    legacy_version: Some(1),
    what: "facette IL body table",
};

/// A tabulated IL body integral.
#[derive(Clone, Debug)]
pub struct BodyTable {
    pub ni: f64,
    /// `describe()` of the distribution it was built for.
    pub distribution: String,
    pub masking: String,
    pub step_deg: f64,
    pub n_theta: usize,
    pub n_phi: usize,
    /// Microfacets per entry (sampled entries; 0 for adaptive ones).
    pub samples: usize,
    /// The relative tolerance of adaptive entries (`None`: sampled entries).
    pub tolerance: Option<f64>,
    /// Largest and mean relative standard error (sampled entries) or relative error
    /// estimate (adaptive entries) of the entries below the grazing row.
    pub max_stderr: f64,
    pub mean_stderr: f64,
    data: Vec<f64>,
}

/// Errors reading a table file.
#[derive(Debug, thiserror::Error)]
pub enum TableError {
    #[error("{path}: {reason}")]
    Invalid { path: String, reason: String },
    #[error("{path}: {source}")]
    Io {
        path: String,
        #[source]
        source: std::io::Error,
    },
}

impl BodyTable {
    /// Builds the table for the microfacet part of an IL material (the lobe's distribution
    /// and masking) and index `ni`, with grid step `step_deg` (must divide 90) and `samples`
    /// microfacets per entry. `progress(done, total)` is called as rows complete.
    pub fn build(
        lobe: &SpecularLobe,
        ni: f64,
        step_deg: f64,
        samples: usize,
        progress: &(dyn Fn(usize, usize) + Sync),
    ) -> ParamResult<BodyTable> {
        Self::build_with(lobe, ni, step_deg, TableEntries::Samples(samples), progress)
    }

    /// [`BodyTable::build`] with sampled or adaptive entries (see the module notes).
    pub fn build_with(
        lobe: &SpecularLobe,
        ni: f64,
        step_deg: f64,
        entries: TableEntries,
        progress: &(dyn Fn(usize, usize) + Sync),
    ) -> ParamResult<BodyTable> {
        let (grid, rows) = compute_rows(lobe, ni, step_deg, entries, &|_| true, progress)?;
        Ok(BodyTable::assemble(grid, rows))
    }

    /// The table from its grid and all its θ_i rows in order (each entry computed
    /// independently, so rows from separate parts assemble into exactly the table that
    /// [`BodyTable::build`] makes).
    pub(crate) fn assemble(grid: TableGrid, rows: Vec<TableRow>) -> BodyTable {
        let (n_theta, n_phi) = (grid.n_theta, grid.n_phi);
        let mut data = vec![0.0; n_theta * n_theta * n_phi];
        let (mut max_se, mut sum_se, mut count) = (0.0f64, 0.0, 0usize);
        for row in rows {
            let ti = row.theta_i;
            for (to, ph, v, se) in row.entries {
                data[(ti * n_theta + to) * n_phi + ph] = v;
                data[(to * n_theta + ti) * n_phi + ph] = v; // reciprocity
                                                            // Relative standard error, over the entries below the grazing row (where the
                                                            // integrand's 1/cos θ makes the estimate noisy but the interpolation weight
                                                            // of the node vanishes with cos θ).
                if ti + 1 < n_theta && to + 1 < n_theta && v > 0.0 {
                    let rel = se / v;
                    max_se = max_se.max(rel);
                    sum_se += rel;
                    count += 1;
                }
            }
        }
        BodyTable {
            ni: grid.ni,
            distribution: grid.distribution,
            masking: grid.masking,
            step_deg: grid.step_deg,
            n_theta,
            n_phi,
            samples: grid.samples,
            tolerance: grid.tolerance,
            max_stderr: max_se,
            mean_stderr: sum_se / count.max(1) as f64,
            data,
        }
    }

    /// Trilinear lookup for an upper-hemisphere pair.
    pub fn lookup(&self, i: Vec3, o: Vec3) -> f64 {
        let step = self.step_deg.to_radians();
        let ti = i.z.clamp(-1.0, 1.0).acos() / step;
        let to = o.z.clamp(-1.0, 1.0).acos() / step;
        let (si, so) = (
            (i.x * i.x + i.y * i.y).sqrt(),
            (o.x * o.x + o.y * o.y).sqrt(),
        );
        let cos_dphi = if si > 1e-12 && so > 1e-12 {
            ((i.x * o.x + i.y * o.y) / (si * so)).clamp(-1.0, 1.0)
        } else {
            1.0
        };
        let ph = cos_dphi.acos() / step;
        let nt = (self.n_theta - 1) as f64;
        let np = (self.n_phi - 1) as f64;
        let (ti, to, ph) = (ti.clamp(0.0, nt), to.clamp(0.0, nt), ph.clamp(0.0, np));
        let cell = |x: f64, n: usize| {
            let k = crate::math::cell_index(x, n - 1);
            (k, x - k as f64)
        };
        let (a, fa) = cell(ti, self.n_theta);
        let (b, fb) = cell(to, self.n_theta);
        let (c, fc) = cell(ph, self.n_phi);
        let at = |x: usize, y: usize, z: usize| self.data[(x * self.n_theta + y) * self.n_phi + z];
        let bilinear = |x: usize| {
            let v0 = at(x, b, c) * (1.0 - fc) + at(x, b, c + 1) * fc;
            let v1 = at(x, b + 1, c) * (1.0 - fc) + at(x, b + 1, c + 1) * fc;
            v0 * (1.0 - fb) + v1 * fb
        };
        bilinear(a) * (1.0 - fa) + bilinear(a + 1) * fa
    }

    /// The table's grid values (θ_i-major, then θ_o, then φ).
    pub fn values(&self) -> &[f64] {
        &self.data
    }

    /// Refuses a table built for other microfacet parameters.
    pub fn check_matches(&self, ni: f64, lobe: &SpecularLobe) -> ParamResult<()> {
        let d = lobe.ndf.describe();
        let m = lobe.masking.name();
        if (self.ni - ni).abs() > 1e-12 || self.distribution != d || self.masking != m {
            return Err(ParamError::Invalid(format!(
                "the table was built for ni = {}, {}, masking {}; this material has ni = {}, {}, masking {}",
                fmt_num(self.ni),
                self.distribution,
                self.masking,
                fmt_num(ni),
                d,
                m
            )));
        }
        Ok(())
    }

    fn header(&self) -> String {
        format!(
            "model = \"il-body\"\nni = {}\ndistribution = \"{}\"\nmasking = \"{}\"\nstep_deg = {}\nn_theta = {}\nn_phi = {}\nsamples = {}\n{}max_stderr = {:e}\nmean_stderr = {:e}\nfacette_version = \"{}\"\n",
            self.ni,
            self.distribution,
            self.masking,
            self.step_deg,
            self.n_theta,
            self.n_phi,
            self.samples,
            tolerance_line(self.tolerance),
            self.max_stderr,
            self.mean_stderr,
            env!("CARGO_PKG_VERSION")
        )
    }

    /// Serializes to the documented binary format.
    pub fn to_bytes(&self) -> Vec<u8> {
        let header = self.header();
        let mut payload = Vec::with_capacity(4 + header.len() + 8 * self.data.len());
        payload.extend_from_slice(&(header.len() as u32).to_le_bytes());
        payload.extend_from_slice(header.as_bytes());
        for v in &self.data {
            payload.extend_from_slice(&v.to_le_bytes());
        }
        FRAME.frame(&payload)
    }

    /// Parses the binary format; `path` names the source in errors.
    pub fn from_bytes(bytes: &[u8], path: &str) -> Result<BodyTable, TableError> {
        let bad = |reason: String| TableError::Invalid {
            path: path.to_string(),
            reason,
        };
        let payload = FRAME
            .unframe(bytes)
            .map_err(|e| bad(e.to_string()))?
            .payload;
        let Some(hlen) = payload.get(..4) else {
            return Err(bad("the contents end before the header length".into()));
        };
        let hlen = u32::from_le_bytes(hlen.try_into().unwrap()) as usize;
        if 4 + hlen > payload.len() {
            return Err(bad("header length exceeds the file".into()));
        }
        let header = std::str::from_utf8(&payload[4..4 + hlen])
            .map_err(|_| bad("header is not UTF-8".into()))?;
        let h: toml::Table =
            toml::from_str(header).map_err(|e| bad(format!("header: {}", e.message())))?;
        let f = |k: &str| -> Result<f64, TableError> {
            match h.get(k) {
                Some(toml::Value::Float(x)) => Ok(*x),
                Some(toml::Value::Integer(x)) => Ok(*x as f64),
                _ => Err(bad(format!("header lacks number `{k}`"))),
            }
        };
        let s = |k: &str| -> Result<String, TableError> {
            match h.get(k) {
                Some(toml::Value::String(x)) => Ok(x.clone()),
                _ => Err(bad(format!("header lacks string `{k}`"))),
            }
        };
        if s("model")? != "il-body" {
            return Err(bad(format!(
                "model `{}` is not an IL body table",
                s("model")?
            )));
        }
        let count_of = |k: &str| -> Result<usize, TableError> {
            match h.get(k) {
                Some(toml::Value::Integer(x)) if *x >= 0 => Ok(*x as usize),
                _ => Err(bad(format!("header: `{k}` must be a whole number ≥ 0"))),
            }
        };
        let grid = TableGrid {
            ni: f("ni")?,
            distribution: s("distribution")?,
            masking: s("masking")?,
            step_deg: f("step_deg")?,
            n_theta: count_of("n_theta")?,
            n_phi: count_of("n_phi")?,
            samples: count_of("samples")?,
            tolerance: match h.get("tolerance") {
                None => None,
                Some(toml::Value::Float(t)) => Some(*t),
                Some(_) => return Err(bad("header: `tolerance` must be a number".into())),
            },
        };
        grid.validate().map_err(|m| bad(format!("header: {m}")))?;
        let (max_stderr, mean_stderr) = (f("max_stderr")?, f("mean_stderr")?);
        if !(max_stderr >= 0.0
            && max_stderr.is_finite()
            && mean_stderr >= 0.0
            && mean_stderr <= max_stderr)
        {
            return Err(bad(format!(
                "header: max_stderr = {max_stderr}, mean_stderr = {mean_stderr} must be finite with 0 ≤ mean ≤ max"
            )));
        }
        let (n_theta, n_phi) = (grid.n_theta, grid.n_phi);
        let count = n_theta * n_theta * n_phi;
        let data_bytes = &payload[4 + hlen..];
        if data_bytes.len() != 8 * count {
            return Err(bad(format!(
                "expected {} bytes of data for a {n_theta}×{n_theta}×{n_phi} grid, found {}",
                8 * count,
                data_bytes.len()
            )));
        }
        let data: Vec<f64> = data_bytes
            .chunks_exact(8)
            .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
            .collect();
        if data.iter().any(|v| !v.is_finite() || *v < 0.0) {
            return Err(bad("table contains negative or non-finite values".into()));
        }
        Ok(BodyTable {
            ni: grid.ni,
            distribution: grid.distribution,
            masking: grid.masking,
            step_deg: grid.step_deg,
            n_theta,
            n_phi,
            samples: grid.samples,
            tolerance: grid.tolerance,
            max_stderr,
            mean_stderr,
            data,
        })
    }

    /// Reads a table file.
    pub fn load(path: &std::path::Path) -> Result<BodyTable, TableError> {
        let p = path.display().to_string();
        let bytes = std::fs::read(path).map_err(|e| TableError::Io {
            path: p.clone(),
            source: e,
        })?;
        Self::from_bytes(&bytes, &p)
    }

    /// Writes the table atomically (temporary file in the same directory, then rename).
    pub fn save(&self, path: &std::path::Path) -> Result<(), TableError> {
        let bytes = self.to_bytes();
        // Never write a file the loader would refuse (`facette merge` of corrupt parts).
        Self::from_bytes(&bytes, &path.display().to_string())?;
        write_atomically(path, &bytes).map_err(|e| TableError::Io {
            path: path.display().to_string(),
            source: e,
        })
    }
}

/// The grid and provenance of a table (everything but its values).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct TableGrid {
    pub ni: f64,
    pub distribution: String,
    pub masking: String,
    pub step_deg: f64,
    pub n_theta: usize,
    pub n_phi: usize,
    /// Microfacets per entry actually used (0 for adaptive entries).
    pub samples: usize,
    /// The relative tolerance of adaptive entries (`None`: sampled entries).
    pub tolerance: Option<f64>,
}

/// The header line of an adaptive table's tolerance (empty for sampled entries).
pub(crate) fn tolerance_line(tolerance: Option<f64>) -> String {
    tolerance.map_or(String::new(), |t| format!("tolerance = {t:e}\n"))
}

impl TableGrid {
    /// Checks every field a file gives: `ni` a valid index, a finite step that divides 90°,
    /// the grid sizes that step implies (n_θ = 90/step + 1, n_φ = 2·90/step + 1) within
    /// [`limits::TABLE_ENTRIES`], and at least 8 samples — or, for adaptive entries, 0 samples
    /// and a tolerance in the range of `tolerance`. A loader accepts only what
    /// [`compute_rows`] could have made, so lookups never meet a NaN step or a grid that
    /// does not match it.
    pub(crate) fn validate(&self) -> Result<(), String> {
        crate::checks::check_ior(self.ni).map_err(|e| e.to_string().replace("`ior`", "`ni`"))?;
        let intervals = check_step(self.step_deg)?;
        let (n_theta, n_phi) = (intervals + 1, 2 * intervals + 1);
        if (self.n_theta, self.n_phi) != (n_theta, n_phi) {
            return Err(format!(
                "grid {} × {} does not match step_deg = {}: that step gives n_theta = {n_theta}, n_phi = {n_phi}",
                self.n_theta, self.n_phi, self.step_deg
            ));
        }
        match self.tolerance {
            Some(t) => {
                check_tolerance(t).map_err(|e| e.to_string())?;
                if self.samples != 0 {
                    return Err(format!(
                        "samples = {} with tolerance = {t}: adaptive entries have samples = 0",
                        self.samples
                    ));
                }
            }
            None if self.samples < 8 => {
                return Err(format!(
                    "samples = {} (a table uses at least 8)",
                    self.samples
                ));
            }
            None => {}
        }
        Ok(())
    }
}

/// The number of grid intervals over 90° for a step of `step_deg` degrees: the step must
/// be finite, divide 90°, and give a grid within [`limits::TABLE_ENTRIES`].
pub(crate) fn check_step(step_deg: f64) -> Result<usize, String> {
    let intervals = (90.0 / step_deg).round();
    if !(step_deg > 0.0 && step_deg <= 90.0 && step_deg.is_finite())
        || (intervals * step_deg - 90.0).abs() > 1e-9
        || intervals < 1.0
    {
        return Err(format!(
            "step = {step_deg}°: the grid step must divide 90° (e.g. 1, 2, 2.5, 5, 10)"
        ));
    }
    // Checked before the grid is allocated: a 0.01° step means 1.5·10^12 entries.
    let n_theta = intervals as u64 + 1;
    limits::TABLE_ENTRIES
        .check_product(&[n_theta, n_theta, 2 * intervals as u64 + 1])
        .map_err(|e| format!("step = {step_deg}°: {e}"))?;
    Ok(intervals as usize)
}

/// One θ_i row: entries (θ_o index ≥ θ_i index, φ index, value, standard error).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct TableRow {
    pub theta_i: usize,
    pub entries: Vec<(usize, usize, f64, f64)>,
}

/// Computes the rows θ_i for which `keep(θ_i index)` holds [TSBRM §4.3: the body integral
/// of IL18 eq. 13 without its K_d prefactor, on the (θ_i, θ_o, Δφ) grid]. Sampled entries
/// use the same shared microfacet set, adaptive entries are computed independently, so
/// any subset of rows is computed exactly as in the full table.
pub(crate) fn compute_rows(
    lobe: &SpecularLobe,
    ni: f64,
    step_deg: f64,
    entries: TableEntries,
    keep: &(dyn Fn(usize) -> bool + Sync),
    progress: &(dyn Fn(usize, usize) + Sync),
) -> ParamResult<(TableGrid, Vec<TableRow>)> {
    if lobe.ndf.is_anisotropic() {
        return Err(ParamError::Invalid(
            "tables store (θ_i, θ_o, φ_o − φ_i) and need an isotropic distribution; \
             anisotropic IL uses evaluation = \"stochastic\" or \"quadrature\""
                .into(),
        ));
    }
    let intervals = check_step(step_deg).map_err(ParamError::Invalid)? as f64;
    let (samples, tolerance) = match entries {
        TableEntries::Samples(n) => (n, None),
        TableEntries::Adaptive { tolerance } => (0, Some(check_tolerance(tolerance)?)),
    };
    if tolerance.is_none() && samples < 8 {
        return Err(ParamError::OutOfRange {
            name: "samples".into(),
            value: samples as f64,
            expected: "samples >= 8".into(),
        });
    }
    let integral = MicrofacetIntegral::new(lobe.ndf.clone(), lobe.masking)?;
    let n_theta = intervals as usize + 1;
    let n_phi = 2 * intervals as usize + 1;
    // The shared microfacet set: 8 rotations of a Hammersley set, with D cos / pdf.
    const ROT: usize = 8;
    let per = if tolerance.is_some() {
        0
    } else {
        (samples / ROT).max(1) as u32
    };
    let mut rng = Pcg32::new(mix_seed(0x7ab1e, samples as u64), 3);
    let normals: Vec<Vec<(Vec3, f64)>> = (0..if tolerance.is_some() { 0 } else { ROT })
        .map(|_| {
            let shift = rng.next_2d();
            (0..per)
                .map(|k| {
                    let m = integral.ndf.sample_normal(hammersley(k, per, shift));
                    let p = integral.ndf.pdf_normal(m);
                    let w = if p > 0.0 { integral.ndf.d(m) / p } else { 0.0 };
                    (m, w)
                })
                .collect()
        })
        .collect();
    let step = step_deg.to_radians();
    let dir = |t: usize, p: usize| {
        // Grazing nodes are evaluated just above the horizon, where the integral is
        // continuous.
        let th = (t as f64 * step).min(0.5 * PI - 1e-6);
        spherical_direction(th, p as f64 * step)
    };
    let wanted: Vec<usize> = (0..n_theta).filter(|&t| keep(t)).collect();
    let total_rows = wanted.len();
    let done = std::sync::atomic::AtomicUsize::new(0);
    // Row θ_i: entries (θ_o ≥ θ_i, φ) → (value, stderr).
    let rows: Vec<TableRow> = wanted
        .into_par_iter()
        .map(|ti| {
            let i = dir(ti, 0);
            let mut out = Vec::with_capacity((n_theta - ti) * n_phi);
            if let Some(tol) = tolerance {
                // [IL18 eq. 13] to the tolerance, with its error estimate: the adaptive
                // quadrature of `evaluation = "quadrature"`.
                let t = |c: f64| 1.0 - fresnel_dielectric(c.abs(), ni);
                for to in ti..n_theta {
                    for ph in 0..n_phi {
                        let o = dir(to, ph);
                        let q = integral.integrate(i, o, tol, |m| t(i.dot(m)) * t(o.dot(m)));
                        out.push((to, ph, q.value, q.error));
                    }
                }
                let d = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
                progress(d, total_rows);
                return TableRow {
                    theta_i: ti,
                    entries: out,
                };
            }
            // T(i·m) per normal, computed once for the row.
            let ti_vals: Vec<Vec<f64>> = normals
                .iter()
                .map(|g| {
                    g.iter()
                        .map(|(m, _)| 1.0 - fresnel_dielectric(i.dot(*m).abs(), ni))
                        .collect()
                })
                .collect();
            for to in ti..n_theta {
                for ph in 0..n_phi {
                    let o = dir(to, ph);
                    let mut means = [0.0; ROT];
                    for (r, group) in normals.iter().enumerate() {
                        let mut s = 0.0;
                        for (k, &(m, w)) in group.iter().enumerate() {
                            let im = i.dot(m);
                            let om = o.dot(m);
                            if im <= 0.0 || om <= 0.0 || w == 0.0 {
                                continue;
                            }
                            let g = integral.masking.g(&integral.ndf, i, o, m);
                            if g == 0.0 {
                                continue;
                            }
                            let t_o = 1.0 - fresnel_dielectric(om, ni);
                            s += ti_vals[r][k] * t_o * w * g * im * om;
                        }
                        means[r] = s / (per as f64 * i.z * o.z);
                    }
                    let mean = means.iter().sum::<f64>() / ROT as f64;
                    let var =
                        means.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (ROT as f64 - 1.0);
                    out.push((to, ph, mean, (var / ROT as f64).sqrt()));
                }
            }
            let d = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
            progress(d, total_rows);
            TableRow {
                theta_i: ti,
                entries: out,
            }
        })
        .collect();
    Ok((
        TableGrid {
            ni,
            distribution: lobe.ndf.describe(),
            masking: lobe.masking.name().to_string(),
            step_deg,
            n_theta,
            n_phi,
            samples: per as usize * ROT,
            tolerance,
        },
        rows,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::rng::Pcg32;
    use crate::microfacet::specular_lobe::NormalSampling;
    use crate::microfacet::{Beckmann, Ggx, Masking, Ndf};
    use crate::models::il::il_table_part::{merge_table_parts, TablePart};

    fn lobes() -> Vec<SpecularLobe> {
        vec![
            SpecularLobe::new(
                Ndf::Beckmann(Beckmann::isotropic(0.4).unwrap()),
                Masking::SmithCorrelated,
                NormalSampling::Visible,
            )
            .unwrap(),
            SpecularLobe::new(
                Ndf::Ggx(Ggx::isotropic(0.8).unwrap()),
                Masking::VCavity,
                NormalSampling::Visible,
            )
            .unwrap(),
        ]
    }

    #[test]
    fn adaptive_entries_meet_their_tolerance_against_independent_references() {
        // A 30° table (4 × 4 × 7 grid) at tolerance 1e-4: every entry against the same
        // quadrature at 1e-9 (within the tolerance and within its own estimate), and against
        // the independent randomized QMC estimate with 2^20 normals (within 4 standard
        // errors plus the tolerance).
        let ni = 1.5;
        let tol = 1e-4;
        for lobe in lobes() {
            let t = BodyTable::build_with(
                &lobe,
                ni,
                30.0,
                TableEntries::Adaptive { tolerance: tol },
                &|_, _| {},
            )
            .unwrap();
            assert_eq!((t.tolerance, t.samples), (Some(tol), 0));
            assert!(t.max_stderr <= tol, "{}", t.max_stderr);
            let integral = MicrofacetIntegral::new(lobe.ndf.clone(), lobe.masking).unwrap();
            let tr = |c: f64| 1.0 - fresnel_dielectric(c.abs(), ni);
            let (n_theta, n_phi) = (t.n_theta, t.n_phi);
            let step = 30f64.to_radians();
            let dir = |k: usize, p: usize| {
                spherical_direction((k as f64 * step).min(0.5 * PI - 1e-6), p as f64 * step)
            };
            let mut worst = 0.0f64;
            for ti in 0..n_theta - 1 {
                for to in ti..n_theta - 1 {
                    for ph in [0, 2, 4, 6] {
                        let (i, o) = (dir(ti, 0), dir(to, ph));
                        let v = t.values()[(ti * n_theta + to) * n_phi + ph];
                        let h = |m: Vec3| tr(i.dot(m)) * tr(o.dot(m));
                        let r = integral.integrate(i, o, 1e-9, h);
                        let q = integral.integrate(i, o, tol, h);
                        let what =
                            format!("{} θ {ti} {to} φ {ph}: {v} vs {r:?}", lobe.ndf.describe());
                        assert_eq!(v, q.value, "{what}");
                        let err = (v - r.value).abs();
                        assert!(err <= tol * r.value + r.error, "{what}");
                        assert!(err <= q.error + r.error, "{what}: estimate {q:?}");
                        worst = worst.max(err / r.value);
                        let (m, se) =
                            integral.estimate(i, o, 1 << 20, &mut Pcg32::new(3, ti as u64), h);
                        assert!(
                            (m - v).abs() <= 4.0 * se + tol * v,
                            "{what}: QMC {m} ± {se}"
                        );
                    }
                }
            }
            println!(
                "{}: largest relative error {worst:.1e}",
                lobe.ndf.describe()
            );
        }
    }

    #[test]
    fn adaptive_tables_round_trip_and_merge_from_parts() {
        let lobe = &lobes()[0];
        let entries = TableEntries::Adaptive { tolerance: 1e-3 };
        let t = BodyTable::build_with(lobe, 1.3, 30.0, entries, &|_, _| {}).unwrap();
        let back = BodyTable::from_bytes(&t.to_bytes(), "t").unwrap();
        assert_eq!(back.values(), t.values());
        assert_eq!((back.tolerance, back.samples), (Some(1e-3), 0));
        assert_eq!(back.max_stderr, t.max_stderr);
        let parts: Vec<TablePart> = (0..2)
            .map(|k| {
                let p = TablePart::build_with(lobe, 1.3, 30.0, entries, k, 2, &|_, _| {}).unwrap();
                TablePart::from_bytes(&p.to_bytes(), "part").unwrap()
            })
            .collect();
        assert_eq!(merge_table_parts(&parts).unwrap().to_bytes(), t.to_bytes());
        // A part of a sampled table does not merge with adaptive parts.
        let sampled = TablePart::build(lobe, 1.3, 30.0, 64, 1, 2, &|_, _| {}).unwrap();
        assert!(merge_table_parts(&[parts[0].clone(), sampled])
            .unwrap_err()
            .contains("another table"));
        // Tolerances outside the range are refused, naming it.
        for bad in [0.0, 0.5, f64::NAN] {
            let e = BodyTable::build_with(
                lobe,
                1.3,
                30.0,
                TableEntries::Adaptive { tolerance: bad },
                &|_, _| {},
            )
            .unwrap_err()
            .to_string();
            assert!(e.contains("tolerance"), "{e}");
        }
        // A header with a tolerance out of range, or with samples, is refused.
        let text = String::from_utf8_lossy(&t.to_bytes()).to_string();
        assert!(text.contains("tolerance = 1e-3"), "{text}");
        let mut g = TableGrid {
            ni: 1.3,
            distribution: t.distribution.clone(),
            masking: t.masking.clone(),
            step_deg: 30.0,
            n_theta: 4,
            n_phi: 7,
            samples: 0,
            tolerance: Some(0.5),
        };
        assert!(g.validate().unwrap_err().contains("tolerance"));
        g.tolerance = Some(1e-3);
        g.samples = 64;
        assert!(g.validate().unwrap_err().contains("samples = 0"));
    }
}
