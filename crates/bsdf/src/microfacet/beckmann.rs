//! The Beckmann distribution, anisotropic  [WMLT07 eqs. 25–29; IL18 eqs. 16, 20, 29–30].
//!
//! | parameter | meaning | range |
//! |---|---|---|
//! | `alpha_x`, `alpha_y` | RMS slope along the tangent x / bitangent y axis (unitless) | (0, 10] |
//! | G1 form | exact erf-based Λ (default) or WMLT07's rational G1 (eq. 27) | — |
//!
//! IL18 eq. 16 calls the widths σ_x, σ_y; they are WMLT07's α_b (ERRATA 6).

use super::{normal_from_slopes_lanes, Distribution};
use crate::checks::check_alpha;
use crate::error::ParamResult;
use crate::lanes::{CellTable, LVec3, Mask, Real};
use crate::math::special::{erf, erfc, erfc_lanes, erfinv_approx, erfinv_of_uniform_lanes};
use crate::math::{fmt_num, Vec2, Vec3, PI, SQRT_PI, TWO_PI};

/// How G1 is evaluated.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BeckmannG1 {
    /// Λ = (erf(a) − 1)/2 + e^{−a²}/(2a√π)  [IL18 eq. 20; WMLT07 eq. 26].
    Exact,
    /// WMLT07's rational approximation of G1 (eq. 27), claimed relative error < 0.35 %.
    Rational,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Beckmann {
    ax: f64,
    ay: f64,
    g1_form: BeckmannG1,
    // Precomputed so that D costs one division and one exponential.
    ax2: f64,
    ay2: f64,
    inv_ax2: f64,
    inv_ay2: f64,
    norm: f64,
}

impl Beckmann {
    /// Anisotropic Beckmann; both widths in (0, 10].
    pub fn new(alpha_x: f64, alpha_y: f64) -> ParamResult<Self> {
        check_alpha("alpha_u", alpha_x)?;
        check_alpha("alpha_v", alpha_y)?;
        Ok(Self::from_checked(alpha_x, alpha_y))
    }

    /// Anisotropic Beckmann from widths the caller has already checked (a material recipe
    /// checks them once, with the smooth limit).
    pub(crate) fn from_checked(alpha_x: f64, alpha_y: f64) -> Self {
        Self::from_alphas(alpha_x, alpha_y, BeckmannG1::Exact)
    }

    fn from_alphas(ax: f64, ay: f64, g1_form: BeckmannG1) -> Self {
        Beckmann {
            ax,
            ay,
            g1_form,
            ax2: ax * ax,
            ay2: ay * ay,
            inv_ax2: 1.0 / (ax * ax),
            inv_ay2: 1.0 / (ay * ay),
            norm: 1.0 / (PI * ax * ay),
        }
    }

    pub fn isotropic(alpha: f64) -> ParamResult<Self> {
        check_alpha("alpha", alpha)?;
        Ok(Self::from_checked(alpha, alpha))
    }

    pub fn with_g1(mut self, form: BeckmannG1) -> Self {
        self.g1_form = form;
        self
    }

    pub fn alpha_x(&self) -> f64 {
        self.ax
    }

    pub fn alpha_y(&self) -> f64 {
        self.ay
    }

    pub fn g1_form(&self) -> BeckmannG1 {
        self.g1_form
    }

    /// Same distribution with both widths scaled by `s > 0` (WMLT07 §5.3's α†).
    pub fn scaled(&self, s: f64) -> Self {
        Self::from_alphas(self.ax * s, self.ay * s, self.g1_form)
    }

    /// a = 1 / (α_v tan θ_v) with α_v² = α_x² cos² φ_v + α_y² sin² φ_v  [IL18 eq. 20].
    #[inline]
    fn a_of(&self, v: Vec3) -> f64 {
        let s2 = self.ax2 * v.x * v.x + self.ay2 * v.y * v.y;
        if s2 <= 0.0 {
            return f64::INFINITY;
        }
        v.z.abs() / s2.sqrt()
    }

    /// Exact Smith Λ: −erfc(a)/2 + e^{−a²}/(2a√π), written with erfc so that it keeps
    /// its relative precision when Λ is small  [IL18 eq. 20].
    #[inline]
    pub fn lambda_exact(&self, v: Vec3) -> f64 {
        lambda_of_a(self.a_of(v))
    }

    /// WMLT07 eq. 27: G1 ≈ (3.535a + 2.181a²)/(1 + 2.276a + 2.577a²) for a < 1.6, else 1.
    /// As printed the rational overshoots 1 slightly just below a = 1.6 (by up to 6e-5);
    /// it is clamped so that G1 ≤ 1 (WMLT07 eq. 5).
    #[inline]
    pub fn g1_rational_of_a(a: f64) -> f64 {
        if a >= 1.6 {
            1.0
        } else {
            ((3.535 * a + 2.181 * a * a) / (1.0 + 2.276 * a + 2.577 * a * a)).min(1.0)
        }
    }

    /// Λ implied by the rational G1 (Λ = 1/G1 − 1).
    #[inline]
    pub fn lambda_rational(&self, v: Vec3) -> f64 {
        let g = Self::g1_rational_of_a(self.a_of(v));
        if g <= 0.0 {
            f64::INFINITY
        } else {
            1.0 / g - 1.0
        }
    }

    /// Exact G1 = 1/(1 + Λ) through [`g1_exact_table`]: y = a/(1 + a) = z/(z + √s²) costs
    /// one square root and one division.
    #[inline]
    pub fn g1_exact_fast(&self, v: Vec3) -> f64 {
        self.g1_exact_lanes::<f64>(v.into())
    }

    /// Exact G1 = 1/(1 + Λ) over lanes. In f64 the table lookup, per lane; in f32 lanes the
    /// closed form G1 = 2/(1 + erf(a) + e^{−a²}/(a√π)) [WMLT07 eq. 26] with a = z/r
    /// (r = α_v sin θ), multiplied through by a√π: G1 = 2z√π/(z√π(2 − erfc a) + r e^{−a²}).
    /// erfc(a) = t p(t) e^{−a²} with t = 1/(1 + 0.3275911 a) and p of degree 4
    /// [Abramowitz & Stegun 7.1.26, absolute error ≤ 1.5e-7] shares the one exponential:
    /// G1 = 2z√π/(2z√π + e^{−a²}(r − z√π t p(t))). ∂G1/∂erfc = G1²/2, so the fit moves G1
    /// by at most 7.5e-8; it is 1 at r = 0 (e^{−a²} = 0) and 0 at z = 0 (the tests measure
    /// it against the table).
    #[inline(always)]
    pub fn g1_exact_lanes<R: Real>(&self, v: LVec3<R>) -> R {
        let s2 = R::splat(self.ax2) * v.x * v.x + R::splat(self.ay2) * v.y * v.y;
        let z = v.z.abs();
        let r = s2.sqrt();
        let g = if R::DIGITS > f32::MANTISSA_DIGITS {
            let table = g1_exact_table();
            (z / (z + r)).map(|y| table.eval(y))
        } else {
            let a = z / r;
            let t = r / (r + R::splat(0.327_591_1) * z);
            let mut p = R::splat(1.061_405_429);
            for c in [-1.453_152_027, 1.421_413_741, -0.284_496_736, 0.254_829_592] {
                p = p * t + R::splat(c);
            }
            let zs = z * R::splat(SQRT_PI);
            let e = (-(a * a)).exp();
            R::splat(2.0) * zs / (R::splat(2.0) * zs + e * (r - zs * t * p))
        };
        R::select(s2.le(R::zero()), R::one(), g)
    }

    /// WMLT07 eq. 27 written with a = z/r (z = |cos θ|, r = α_v sin θ): one square root and
    /// one division; 1 from a = 1.6 on.
    #[inline(always)]
    fn g1_rational_lanes<R: Real>(&self, v: LVec3<R>) -> R {
        let r2 = R::splat(self.ax2) * v.x * v.x + R::splat(self.ay2) * v.y * v.y;
        let z = v.z.abs();
        let r = r2.sqrt();
        let g = ((R::splat(3.535) * z * r + R::splat(2.181) * z * z)
            / (r2 + R::splat(2.276) * z * r + R::splat(2.577) * z * z))
            .min(R::one());
        R::select((z * z).ge(R::splat(2.56) * r2), R::one(), g)
    }

    /// G1(v) in the model's form, without WMLT07 eq. 7's sidedness.
    #[inline(always)]
    pub fn g1_model_lanes<R: Real>(&self, v: LVec3<R>) -> R {
        match self.g1_form {
            BeckmannG1::Exact => self.g1_exact_lanes(v),
            BeckmannG1::Rational => self.g1_rational_lanes(v),
        }
    }

    /// G1(v) both ways a visible-normal sampler needs it, without the sidedness: the exact
    /// G1 (its density's, [Heitz 2014, eq. 2]) and the model's G1 divided by it (the ratio
    /// in the sample's weight). One exact evaluation where the model is exact (ratio 1).
    #[inline(always)]
    pub fn g1_visible_and_ratio_lanes<R: Real>(&self, v: LVec3<R>) -> (R, R) {
        let exact = self.g1_exact_lanes(v);
        match self.g1_form {
            BeckmannG1::Exact => (exact, R::one()),
            BeckmannG1::Rational => (exact, self.g1_rational_lanes(v) / exact),
        }
    }

    /// G1(v, m) in the model's form, 0 where v sees the back of m (WMLT07 eq. 7's χ⁺).
    #[inline(always)]
    pub fn g1_lanes<R: Real>(&self, v: LVec3<R>, m: LVec3<R>) -> R {
        super::sided_g1_lanes(v, m, self.g1_model_lanes(v))
    }

    /// D(m) = exp(−(x²/α_x² + y²/α_y²)/z²) / (π α_x α_y z⁴)  [IL18 eq. 16; WMLT07 eq. 25];
    /// 0 below the horizon and where z⁴ underflows.
    #[inline(always)]
    pub fn d_lanes<R: Real>(&self, m: LVec3<R>) -> R {
        let z2 = m.z * m.z;
        let inv_z2 = R::one() / z2;
        let e = (m.x * m.x * R::splat(self.inv_ax2) + m.y * m.y * R::splat(self.inv_ay2)) * inv_z2;
        let d = R::splat(self.norm) * (-e).exp() * inv_z2 * inv_z2;
        R::select(
            m.z.le(R::zero()) | (z2 * z2).lt(R::splat(R::TINY)),
            R::zero(),
            d,
        )
    }

    /// D(m)|m·n| sampling over lanes, the one source of [`Distribution::sample_normal`]:
    /// slopes r(cos 2πu₁, sin 2πu₁), r = √(−ln(1 − u₀)), stretched by (α_x, α_y)
    /// [IL18 eqs. 29–30 in slope space].
    #[inline(always)]
    pub fn sample_normal_lanes<R: Real>(&self, u0: R, u1: R) -> LVec3<R> {
        let r = (-(R::one() - u0).ln()).sqrt();
        let (s, c) = (R::splat(TWO_PI) * u1).sin_cos();
        normal_from_slopes_lanes(r * c * R::splat(self.ax), r * s * R::splat(self.ay))
    }

    /// Visible normals over lanes, the one source of [`Distribution::sample_visible`]: stretch
    /// the view to unit roughness, sample slopes (`visible_slopes_unit_lanes`), rotate and
    /// unstretch [Heitz & d'Eon 2014]. The stretched view (α_x v_x, α_y v_y, v_z) need not be
    /// normalized: the slope sampler only needs cos θ/(cos θ + sin θ) = z/(z + r).
    #[inline(always)]
    pub fn sample_visible_lanes<R: Real>(&self, v: LVec3<R>, u0: R, u1: R) -> LVec3<R> {
        let (px, py, pz) = (
            R::splat(self.ax) * v.x,
            R::splat(self.ay) * v.y,
            v.z.max(R::splat(1e-12)),
        );
        let r = (px * px + py * py).sqrt();
        let (sx, sy) = visible_slopes_unit_lanes(pz / (pz + r), u0, u1);
        let tilted = r.gt(R::zero());
        let inv = R::one() / r;
        let cp = R::select(tilted, px * inv, R::one());
        let sp = R::masked(tilted, py * inv);
        let rx = cp * sx - sp * sy;
        let ry = sp * sx + cp * sy;
        normal_from_slopes_lanes(rx * R::splat(self.ax), ry * R::splat(self.ay))
    }
}

/// The exact Beckmann G1(a) = 1/(1 + Λ(a)) tabulated once, at first use, from the erf form
/// of IL18 eq. 20, with its exact derivative, on a grid uniform in y = a/(1 + a) ∈ [0, 1]
/// (4096 intervals), evaluated by cubic Hermite interpolation. Λ depends on a alone, so one
/// table serves every roughness and anisotropy; the tests measure its largest deviation from
/// the closed form (below 1e-12).
pub struct G1Table {
    /// (G1, dG1/dy · h) at each node, interleaved so a lookup touches one cache line.
    nodes: Vec<[f64; 2]>,
}

impl G1Table {
    const INTERVALS: usize = 4096;

    fn build() -> Self {
        let n = Self::INTERVALS;
        let nodes = (0..=n)
            .map(|k| {
                let y = k as f64 / n as f64;
                let (g, dg_dy) = if k == 0 {
                    // G1 ≈ 2a√π near a = 0 and da/dy = 1 there.
                    (0.0, 2.0 * SQRT_PI)
                } else if k == n {
                    (1.0, 0.0)
                } else {
                    let a = y / (1.0 - y);
                    let l = lambda_of_a(a);
                    let g = 1.0 / (1.0 + l);
                    // dΛ/da = −e^{−a²}/(2a²√π); dG1/da = −Λ'/(1+Λ)²; da/dy = 1/(1−y)².
                    let dl = -(-a * a).exp() / (2.0 * a * a * SQRT_PI);
                    (g, -dl * g * g / ((1.0 - y) * (1.0 - y)))
                };
                [g, dg_dy / n as f64] // slope per unit of the cell coordinate
            })
            .collect();
        G1Table { nodes }
    }

    /// G1 at y = a/(1 + a).
    #[inline]
    pub fn eval(&self, y: f64) -> f64 {
        let n = Self::INTERVALS;
        let x = (y * n as f64).clamp(0.0, n as f64);
        let i = (x as usize).min(n - 1);
        let t = x - i as f64;
        let ([p0, m0], [p1, m1]) = (self.nodes[i], self.nodes[i + 1]);
        let t2 = t * t;
        let t3 = t2 * t;
        let v = (2.0 * t3 - 3.0 * t2 + 1.0) * p0
            + (t3 - 2.0 * t2 + t) * m0
            + (-2.0 * t3 + 3.0 * t2) * p1
            + (t3 - t2) * m1;
        v.clamp(0.0, 1.0)
    }
}

/// The shared exact-G1 table.
pub fn g1_exact_table() -> &'static G1Table {
    static TABLE: std::sync::OnceLock<G1Table> = std::sync::OnceLock::new();
    TABLE.get_or_init(G1Table::build)
}

/// Beckmann Λ as a function of a  [IL18 eq. 20].
#[inline]
pub fn lambda_of_a(a: f64) -> f64 {
    if a == f64::INFINITY || a > 26.0 {
        return 0.0;
    }
    if a <= 0.0 {
        return f64::INFINITY;
    }
    let l = (-a * a).exp() / (2.0 * a * SQRT_PI) - 0.5 * erfc(a);
    l.max(0.0)
}

/// Exact Beckmann G1 as a function of a: 2 / (1 + erf(a) + e^{−a²}/(a√π))  [WMLT07 eq. 26].
#[inline]
pub fn g1_exact_of_a(a: f64) -> f64 {
    1.0 / (1.0 + lambda_of_a(a))
}

// Visible-slope sampling [Heitz & d'Eon 2014, §4; Jakob 2014].
//
// Stretched to unit width, with the view at angle θ from the normal and its azimuth along +x,
// the slopes (x̃, ỹ) of visible normals have the density ∝ (cos θ − x̃ sin θ) e^{−x̃² − ỹ²}
// on x̃ < cot θ: ỹ is an independent Gaussian, e^{−ỹ²}/√π, and x̃ has the marginal CDF
// F(x̃)/Z with F(x̃) = c erfc(−x̃) + s e^{−x̃²}/√π and Z = F(c/s), for any (c, s) ∝ (cos θ, sin θ).
// Everything below takes (c, s) = (y, 1 − y) with y = cos θ/(cos θ + sin θ) ∈ [0, 1], which
// costs one division from the stretched view and is smooth at both ends (x̃ depends on
// tan θ = (1 − y)/y near the normal and on cot θ = y/(1 − y) near the horizon).

/// The x̃-marginal CDF numerator F(x̃) = y erfc(−x̃) + (1 − y) e^{−x̃²}/√π. erfc(−x̃) rather
/// than 1 + erf(x̃): the lower tail keeps its relative precision.
#[inline]
fn visible_slope_cdf(y: f64, x: f64) -> f64 {
    y * erfc(-x) + (1.0 - y) * (-x * x).exp() / SQRT_PI
}

/// Z(y) = F(cot θ) and dZ/dy = erfc(−cot θ) − e^{−cot² θ}/√π (the terms in dcot/dy cancel).
fn visible_slope_norm(y: f64) -> (f64, f64) {
    let s = 1.0 - y;
    if s <= 0.0 || y > 27.0 * s {
        // cot θ > 27: erfc(−cot θ) = 2 and e^{−cot² θ} = 0 in double precision.
        return (2.0 * y, 2.0);
    }
    let cot = y / s;
    let e = (-cot * cot).exp() / SQRT_PI;
    (y * erfc(-cot) + s * e, erfc(-cot) - e)
}

/// x̃ with F(x̃)/Z = u, to 1e-12, by Halley steps safeguarded by bisection from Jakob's
/// fitted initial guess [Jakob 2014, as in Mitsuba]: the former sampler, now the reference
/// of [`VisibleSlopeTable`] (it builds the table and the tests measure against it) and the
/// sampler of the top 1e-4 of u, which the table does not cover.
fn visible_slope_x_iterative(y: f64, u: f64) -> f64 {
    let (c, s) = (y, 1.0 - y);
    let cot = if s > 0.0 { c / s } else { f64::INFINITY };
    let inv_norm = 1.0 / visible_slope_norm(y).0;
    // Initial guess in the erf domain: b = erf(cot θ) − (1 + erf(cot θ)) (1 − u)^fit.
    let theta = s.atan2(c);
    let fit = 1.0 + theta * (-0.876 + theta * (0.4265 - 0.0594 * theta));
    let erf_cot = erf(cot);
    let b = (erf_cot - (1.0 + erf_cot) * (1.0 - u).powf(fit)).clamp(-1.0 + 1e-15, erf_cot);
    // Bracket: F(x̃)/Z ≤ e^{−x̃²} for x̃ ≤ −1 (erfc(z) ≤ e^{−z²}/(z√π) and Z ≥ F(0) ≥ c), and
    // 1 − F(x̃)/Z ≤ c erfc(x̃)/Z ≤ e^{−x̃²} for x̃ ≥ 0: the root lies in
    // [−1 − √(−ln u), √(−ln(1 − u))], and below cot θ.
    let (mut lo, mut hi) = (
        -1.0 - (-u.ln()).sqrt(),
        (-(1.0 - u).ln()).sqrt().min(cot) + 1e-9,
    );
    let mut x = erfinv_approx(b).clamp(lo, hi);
    for _ in 0..60 {
        let ex = (-x * x).exp();
        let value = visible_slope_cdf(y, x) * inv_norm - u;
        if value == 0.0 {
            break;
        }
        if value > 0.0 {
            hi = x;
        } else {
            lo = x;
        }
        // Halley's step (cubic convergence): V' = k e^{−x²}(c − s x),
        // V'' = k e^{−x²}(−2x(c − s x) − s), k = 2/(√π Z).
        let k = inv_norm * (2.0 / SQRT_PI) * ex;
        let d1 = k * (c - s * x);
        let d2 = k * (-2.0 * x * (c - s * x) - s);
        let next = x - 2.0 * value * d1 / (2.0 * d1 * d1 - value * d2);
        if (next - x).abs() <= 1e-12 * (1.0 + x.abs()) {
            x = next;
            break;
        }
        x = if next > lo && next < hi {
            next
        } else {
            0.5 * (lo + hi)
        };
        if hi - lo <= 1e-14 {
            break;
        }
    }
    x.min(cot)
}

/// t(u) = sign(u − ½) √(−ln 4u(1 − u)): the table's coordinate along u. It behaves like the
/// Gaussian quantile in both tails (x̃ is nearly linear in it where x̃ → −∞), and is
/// analytic through u = ½.
#[inline(always)]
fn visible_slope_t<R: Real>(u: R) -> R {
    let t = (-(R::splat(4.0) * u * (R::one() - u)).ln())
        .max(R::zero())
        .sqrt();
    R::select(u.lt(R::splat(0.5)), -t, t)
}

/// The inverse of [`visible_slope_t`], and du/dt.
fn visible_slope_u(t: f64) -> (f64, f64) {
    let e = (-t * t).exp();
    let r = (-(-t * t).exp_m1()).sqrt(); // √(1 − e^{−t²}) = |2u − 1|
    let u = if t < 0.0 {
        e / (2.0 * (1.0 + r)) // (1 − r)/2 without cancellation
    } else {
        0.5 * (1.0 + r)
    };
    let du_dt = if r < 1e-8 {
        0.5
    } else {
        t.abs() * e / (2.0 * r)
    };
    (u, du_dt)
}

/// Cubic Hermite interpolation on [0, 1] between (p0, m0) and (p1, m1), m the slopes per
/// unit of t.
#[inline(always)]
fn hermite<R: Real>(t: R, p0: R, m0: R, p1: R, m1: R) -> R {
    let t2 = t * t;
    let t3 = t2 * t;
    let h01 = R::splat(3.0) * t2 - R::splat(2.0) * t3;
    (R::one() - h01) * p0 + (t3 - R::splat(2.0) * t2 + t) * m0 + h01 * p1 + (t3 - t2) * m1
}

/// ⌊x⌋ of x ≥ 0 as a lane value, capped at `max`.
#[inline(always)]
fn cell_index<R: Real>(x: R, max: usize) -> R {
    x.floor().min(R::splat(max as f64))
}

/// The Hermite interpolant of cell `cell` of `table` at t ∈ [0, 1] in the cell.
#[inline(always)]
fn hermite_cell<R: Real>(table: &CellTable, cell: R, t: R) -> R {
    let [p0, m0, p1, m1] = R::gather4(table, cell);
    hermite(t, p0, m0, p1, m1)
}

/// The inverse CDF of the visible-slope marginal x̃(y, u), tabulated once at first use:
/// 65 × 65 nodes uniform in y ∈ [0, 1] and in t(u) for u ∈ [1e-12, 1 − 1e-4], each with
/// x̃ and its exact derivative dx̃/dt = Z (du/dt) / F'(x̃); cubic Hermite along t, cubic
/// Lagrange across four rows in y. The normalization Z(y) has its own 4096-interval Hermite
/// table. The interpolated x̃ is within 1e-4 of the root (the tests measure it), and one
/// Halley step on the exact CDF brings it to ~1e-12; see [`visible_slope_x`].
struct VisibleSlopeTable {
    /// Cells of (x̃, dx̃/dt · h_t) nodes, row-major: row i (y = i/NY) holds NT cells.
    x: CellTable,
    /// Cells of (Z, dZ/dy · h_z) nodes at y = k/NZ.
    z: CellTable,
    t_lo: f64,
    inv_ht: f64,
}

impl VisibleSlopeTable {
    const NY: usize = 64;
    const NT: usize = 64;
    const NZ: usize = 4096;
    /// The table covers u ≤ U_MAX; above it x̃ approaches the horizon slope cot θ like
    /// √(1 − u), which a table in t follows poorly, and the iteration takes over.
    const U_MAX: f64 = 1.0 - 1e-4;
    const U_MIN: f64 = 1e-12;

    fn build() -> Self {
        let (ny, nt, nz) = (Self::NY, Self::NT, Self::NZ);
        let t_lo = visible_slope_t(Self::U_MIN);
        let ht = (visible_slope_t(Self::U_MAX) - t_lo) / nt as f64;
        let mut x = Vec::with_capacity((ny + 1) * nt);
        for i in 0..=ny {
            let y = i as f64 / ny as f64;
            let norm = visible_slope_norm(y).0;
            let row: Vec<[f64; 2]> = (0..=nt)
                .map(|j| {
                    let (u, du_dt) = visible_slope_u(t_lo + j as f64 * ht);
                    let xi = visible_slope_x_iterative(y, u);
                    let dcdf = (2.0 / SQRT_PI) * (-xi * xi).exp() * (y - (1.0 - y) * xi);
                    [xi, norm * du_dt / dcdf * ht]
                })
                .collect();
            x.extend(row.windows(2).map(|w| [w[0][0], w[0][1], w[1][0], w[1][1]]));
        }
        let z: Vec<[f64; 2]> = (0..=nz)
            .map(|k| {
                let (v, d) = visible_slope_norm(k as f64 / nz as f64);
                [v, d / nz as f64]
            })
            .collect();
        VisibleSlopeTable {
            x: CellTable::new(x),
            z: CellTable::from_nodes(&z),
            t_lo,
            inv_ht: 1.0 / ht,
        }
    }

    /// Z(y) by Hermite interpolation.
    #[inline(always)]
    fn norm<R: Real>(&self, y: R) -> R {
        let n = Self::NZ;
        let f = (y * R::splat(n as f64)).clamp(0.0, n as f64);
        let i = cell_index(f, n - 1);
        hermite_cell(&self.z, i, f - i)
    }

    /// The interpolated x̃ at (y, t): cubic Lagrange across the four rows around y, cubic
    /// Hermite along t in each.
    #[inline(always)]
    fn guess<R: Real>(&self, y: R, t: R) -> R {
        let (ny, nt) = (Self::NY, Self::NT);
        let fy = (y * R::splat(ny as f64)).clamp(0.0, ny as f64);
        // Rows i0 … i0 + 3 with i0 = ⌊fy⌋ − 1 kept in [0, ny − 3].
        let i0 = (fy.floor() - R::one()).clamp(0.0, (ny - 3) as f64);
        let a = fy - i0; // in [0, 3]
        let (a1, a2, a3) = (a - R::one(), a - R::splat(2.0), a - R::splat(3.0));
        let sixth = R::splat(1.0 / 6.0);
        let half = R::splat(0.5);
        let w = [
            -a1 * a2 * a3 * sixth,
            a * a2 * a3 * half,
            -a * a1 * a3 * half,
            a * a1 * a2 * sixth,
        ];
        let ft = ((t - R::splat(self.t_lo)) * R::splat(self.inv_ht)).clamp(0.0, nt as f64);
        let j = cell_index(ft, nt - 1);
        let b = ft - j;
        if R::DIGITS <= f32::MANTISSA_DIGITS {
            // f32 lanes: linear across the two rows around y. The guess is then within
            // ~1e-3 rather than 1e-4, and the Halley step, cubic, still lands within f32's
            // resolution (the tests measure it) for half the gathers.
            let i = cell_index(fy, ny - 1);
            let a = fy - i;
            let first = i * R::splat(nt as f64) + j;
            let x0 = hermite_cell(&self.x, first, b);
            let x1 = hermite_cell(&self.x, first + R::splat(nt as f64), b);
            return x0 + a * (x1 - x0);
        }
        let first = i0 * R::splat(nt as f64) + j;
        let mut x = R::zero();
        for (k, wk) in w.into_iter().enumerate() {
            x = x + wk * hermite_cell(&self.x, first + R::splat((k * nt) as f64), b);
        }
        x
    }
}

fn visible_slope_table() -> &'static VisibleSlopeTable {
    static TABLE: std::sync::OnceLock<VisibleSlopeTable> = std::sync::OnceLock::new();
    TABLE.get_or_init(VisibleSlopeTable::build)
}

/// x̃ for u in [1e-12, 1 − 1e-12] over lanes: the tabulated inverse CDF and ONE Halley step
/// on the exact CDF (one erfc and one exp, [`erfc_lanes`]), or, for lanes with u above the
/// table's 1 − 1e-4, the iteration (in f64, lane by lane).
#[inline(always)]
fn visible_slope_x<R: Real>(y: R, u: R) -> R {
    let table = visible_slope_table();
    let (c, s) = (y, R::one() - y);
    let horizon = c / s; // x̃ never passes the horizon slope cot θ
    let x = table.guess(y, visible_slope_t(u));
    let x = R::select((s * x).gt(c), horizon, x);
    let ex = (-(x * x)).exp();
    let two_over_sqrt_pi = R::splat(2.0 / SQRT_PI);
    let f = c * erfc_lanes(-x) + s * ex * R::splat(1.0 / SQRT_PI) - u * table.norm(y);
    let d1 = two_over_sqrt_pi * ex * (c - s * x);
    let d2 = two_over_sqrt_pi * ex * (R::splat(-2.0) * x * (c - s * x) - s);
    let den = R::splat(2.0) * d1 * d1 - f * d2;
    let x = R::select(den.gt(R::zero()), x - R::splat(2.0) * f * d1 / den, x);
    let x = R::select((s * x).gt(c), horizon, x);
    let upper = u.gt(R::splat(VisibleSlopeTable::U_MAX));
    if upper.any() {
        let iterated = R::from_fn(|l| visible_slope_x_iterative(y.lane(l), u.lane(l)));
        R::select(upper, iterated, x)
    } else {
        x
    }
}

/// Samples the slopes (x̃, ỹ) of visible normals of the unit-width isotropic Beckmann
/// distribution seen at y = cos θ/(cos θ + sin θ) [Heitz & d'Eon 2014], over lanes: x̃ from
/// the tabulated inverse CDF refined by one Halley step ([`visible_slope_x`]), ỹ the
/// Gaussian quantile of u₁ ([`erfinv_of_uniform_lanes`], no erf evaluation). The uniform
/// numbers are kept inside the lane type's open interval (1e-12 … 1 − 1e-12 in f64,
/// 1 − 2⁻²⁴ in f32, where 1 − 1e-12 rounds to 1).
#[inline(always)]
fn visible_slopes_unit_lanes<R: Real>(y: R, u0: R, u1: R) -> (R, R) {
    let hi = if R::DIGITS > f32::MANTISSA_DIGITS {
        1.0 - 1e-12
    } else {
        1.0 - f32::EPSILON as f64 / 2.0
    };
    let ux = u0.clamp(1e-12, hi);
    let uy = u1.clamp(1e-12, hi);
    (visible_slope_x(y, ux), erfinv_of_uniform_lanes(uy))
}

impl Distribution for Beckmann {
    /// D(m) = exp(−(x²/α_x² + y²/α_y²)/z²) / (π α_x α_y z⁴)  [IL18 eq. 16; WMLT07 eq. 25].
    #[inline]
    fn d(&self, m: Vec3) -> f64 {
        self.d_lanes::<f64>(m.into())
    }

    #[inline]
    fn lambda(&self, v: Vec3) -> f64 {
        match self.g1_form {
            BeckmannG1::Exact => self.lambda_exact(v),
            BeckmannG1::Rational => self.lambda_rational(v),
        }
    }

    #[inline]
    fn g1(&self, v: Vec3, m: Vec3) -> f64 {
        self.g1_lanes::<f64>(v.into(), m.into())
    }

    /// Samples D(m)|m·n|: slopes r(cos 2πξ2, sin 2πξ2) with r = √(−ln(1−ξ1)), stretched by
    /// (α_x, α_y). This is IL18 eqs. 29–30 (and WMLT07 eqs. 28–29 when isotropic) written
    /// in slope space, which avoids the quadrant bookkeeping of the arctan in eq. 29.
    #[inline]
    fn sample_normal(&self, u: Vec2) -> Vec3 {
        self.sample_normal_lanes::<f64>(u.x, u.y).into()
    }

    /// p(m) = D(m) |m·n|  [WMLT07 eq. 24].
    #[inline]
    fn pdf_normal(&self, m: Vec3) -> f64 {
        self.d(m) * m.z.max(0.0)
    }

    fn has_visible_sampling(&self) -> bool {
        true
    }

    /// Visible normals [Heitz & d'Eon 2014]: [`Beckmann::sample_visible_lanes`] in f64.
    fn sample_visible(&self, v: Vec3, u: Vec2) -> Vec3 {
        self.sample_visible_lanes::<f64>(v.into(), u.x, u.y).into()
    }

    /// D_v(m) with the exact Λ, whatever G1 form the model evaluates.
    #[inline]
    fn pdf_visible(&self, v: Vec3, m: Vec3) -> f64 {
        let vm = v.dot(m);
        if vm <= 0.0 || v.z <= 0.0 {
            return 0.0;
        }
        self.g1_exact_fast(v) * vm * self.d(m) / v.z
    }

    fn typical_width(&self) -> f64 {
        (self.ax * self.ay).sqrt()
    }

    fn describe(&self) -> String {
        let g = match self.g1_form {
            BeckmannG1::Exact => "",
            BeckmannG1::Rational => ", rational G1",
        };
        if self.ax == self.ay {
            format!("beckmann(alpha={}{g})", fmt_num(self.ax))
        } else {
            format!(
                "beckmann(alpha_u={}, alpha_v={}{g})",
                fmt_num(self.ax),
                fmt_num(self.ay)
            )
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn g1_table_matches_the_closed_form() {
        let t = g1_exact_table();
        let mut worst: f64 = 0.0;
        for k in 0..200_000 {
            let a = 1e-4 * (1.0001f64).powi(k); // 1e-4 … ~5e4
            if a > 60.0 {
                break;
            }
            let exact = g1_exact_of_a(a);
            let tab = t.eval(a / (1.0 + a));
            worst = worst.max((tab - exact).abs() / exact);
        }
        assert!(worst < 1e-12, "max relative error {worst:e}");
    }

    /// The u of the comparison grid: log-spaced tails and a uniform middle.
    fn u_grid() -> Vec<f64> {
        let mut us: Vec<f64> = (0..240)
            .map(|k| 10f64.powf(-12.0 + k as f64 * 0.05))
            .collect();
        us.extend((1..1000).map(|k| k as f64 / 1000.0 + 3.7e-4));
        us.extend((0..240).map(|k| 1.0 - 10f64.powf(-12.0 + k as f64 * 0.05)));
        us
    }

    #[test]
    fn tabulated_visible_slopes_match_the_iteration() {
        // The sampler's x̃ (table + one Halley step) against the 1e-12 iteration, over a grid
        // of cos θ (through y = cos θ/(cos θ + sin θ), on and between the table's rows) and u.
        let us = u_grid();
        let (mut worst, mut worst_guess, mut at) = (0.0f64, 0.0f64, (0.0, 0.0));
        for i in 0..=400 {
            let y = i as f64 / 400.0 + if i < 400 { 1.3e-3 } else { 0.0 };
            for &u in &us {
                let exact = visible_slope_x_iterative(y, u);
                let fast = visible_slope_x(y, u);
                assert!(fast.is_finite(), "y={y} u={u}");
                let e = (fast - exact).abs();
                if e > worst {
                    (worst, at) = (e, (y, u));
                }
                if u <= VisibleSlopeTable::U_MAX {
                    let t = visible_slope_table().guess(y, visible_slope_t(u));
                    worst_guess = worst_guess.max((t - exact).abs());
                }
            }
        }
        println!(
            "visible slope x̃: table alone within {worst_guess:e}, \
             after one Halley step within {worst:e} (at y, u = {at:?})"
        );
        assert!(worst_guess < 1e-4, "{worst_guess:e}");
        assert!(worst < 1e-11, "{worst:e} at {at:?}");
    }

    /// The renderer's f32 lanes: x̃ (table, one Halley step in f32) against the f64
    /// iteration at the same (f32) inputs, and G1 by the f32 closed form against the table.
    #[test]
    fn f32_lanes_sample_slopes_and_evaluate_g1_to_f32_precision() {
        use crate::lanes::F32x8;
        let us: Vec<f64> = u_grid().into_iter().map(|u| u as f32 as f64).collect();
        let (mut worst, mut worst_x, mut at) = (0.0f64, 0.0f64, (0.0, 0.0));
        for i in 0..=200 {
            let y = (i as f64 / 200.0 + if i < 200 { 1.3e-3 } else { 0.0 }) as f32 as f64;
            for &u in &us {
                let (x, _) =
                    visible_slopes_unit_lanes(F32x8::splat(y), F32x8::splat(u), F32x8::splat(0.5));
                let x = x.lane(0);
                let u = u.clamp(1e-12, 1.0 - f32::EPSILON as f64 / 2.0);
                let exact = visible_slope_x_iterative(y, u);
                assert!(
                    x.is_finite() && x * (1.0 - y) <= y * (1.0 + 1e-6),
                    "y={y} u={u}: {x}"
                );
                // Backward error: the u whose exact inverse x̃ is, against the given u —
                // absolute, and relative in the lower tail (f32's own spacing of u is 6e-8
                // near 1, where x̃ is most sensitive to u).
                let cdf = visible_slope_cdf(y, x) / visible_slope_norm(y).0;
                let e = (cdf - u).abs() / u.clamp(1e-12, 0.5) * 0.5;
                worst_x = worst_x.max((x - exact).abs() / (1.0 + exact.abs()));
                if e > worst {
                    (worst, at) = (e, (y, u));
                }
            }
        }
        let b = Beckmann::new(0.3, 0.7).unwrap();
        let mut worst_g1: f64 = 0.0;
        for k in 0..=20_000 {
            let theta = k as f64 / 20_000.0 * 0.5 * PI;
            let phi = k as f64 * 0.618_034 * TWO_PI;
            let v = crate::math::spherical_direction(theta, phi);
            let lanes = LVec3::new(F32x8::splat(v.x), F32x8::splat(v.y), F32x8::splat(v.z));
            let g = b.g1_exact_lanes(lanes).lane(0);
            let vf = Vec3::new(v.x as f32 as f64, v.y as f32 as f64, v.z as f32 as f64);
            worst_g1 = worst_g1.max((g - b.g1_exact_fast(vf)).abs());
        }
        println!(
            "f32 lanes: x̃ within {worst_x:e} of the iteration (relative to 1 + |x̃|); \
             backward error in u {worst:e} (relative below ½, at y, u = {at:?}); \
             G1 within {worst_g1:e}"
        );
        assert!(worst < 1e-5, "{worst:e}");
        assert!(worst_x < 2e-4, "{worst_x:e}");
        assert!(worst_g1 < 1e-6, "{worst_g1:e}");
    }

    #[test]
    fn visible_slope_norm_table_matches_the_closed_form() {
        let t = visible_slope_table();
        let mut worst: f64 = 0.0;
        for k in 0..=100_000 {
            let y = k as f64 / 100_000.0;
            let exact = visible_slope_norm(y).0;
            worst = worst.max((t.norm(y) - exact).abs() / exact);
        }
        println!("visible slope Z(y): largest relative error {worst:e}");
        assert!(worst < 1e-14, "{worst:e}");
    }

    #[test]
    fn visible_sampling_is_finite_at_the_extremes() {
        let ys = [0.0, 1e-300, 1e-16, 1e-8, 0.5, 1.0 - 1e-12, 1.0 - 1e-16, 1.0];
        let us = [
            0.0,
            1e-300,
            1e-12,
            1e-4,
            0.5,
            1.0 - 1e-4,
            1.0 - 1e-12,
            1.0 - 1e-17,
            1.0,
        ];
        for &y in &ys {
            for &ux in &us {
                for &uy in &us {
                    let (sx, sy) = visible_slopes_unit_lanes(y, ux, uy);
                    assert!(sx.is_finite() && sy.is_finite(), "y={y} u=({ux}, {uy})");
                    // Never past the horizon slope cot θ = y/(1 − y).
                    assert!(sx * (1.0 - y) <= y, "y={y} u={ux}: x̃ = {sx}");
                }
            }
        }
        let views = [
            Vec3::Z,
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.6, -0.8, 1e-300),
            Vec3::new(1.0, 0.0, 1e-9).normalize(),
            Vec3::new(0.3, 0.4, 0.5).normalize(),
            Vec3::new(1e-300, 0.0, 1.0),
        ];
        for (ax, ay) in [(1e-4, 1e-4), (0.3, 0.5), (10.0, 0.01), (10.0, 10.0)] {
            let b = Beckmann::new(ax, ay).unwrap();
            for &v in &views {
                for &ux in &us {
                    for &uy in &us {
                        let m = b.sample_visible(v, Vec2::new(ux, uy));
                        assert!(
                            m.is_finite() && m.z >= 0.0 && (m.length() - 1.0).abs() < 1e-12,
                            "α=({ax}, {ay}) v={v:?} u=({ux}, {uy}): {m:?}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn rational_form_matches_eq_27() {
        let b = Beckmann::isotropic(0.4)
            .unwrap()
            .with_g1(BeckmannG1::Rational);
        for k in 1..89 {
            let v = crate::math::spherical_direction((k as f64).to_radians(), 0.3);
            let a = v.z / (0.4 * (1.0 - v.z * v.z).sqrt());
            let direct = Beckmann::g1_rational_of_a(a);
            assert!((b.g1(v, Vec3::Z) - direct).abs() < 1e-14, "{k}");
        }
    }
}
