//! Numerical integration: Gauss–Legendre rules of any order and adaptive Gauss–Kronrod
//! (7–15 points). Used for normalizations, Smith Λ tables, hemispherical averages and the
//! validation harness's reference integrals.

use std::sync::OnceLock;

/// A Gauss–Legendre rule on [−1, 1].
#[derive(Clone, Debug)]
pub struct GaussLegendre {
    pub nodes: Vec<f64>,
    pub weights: Vec<f64>,
}

impl GaussLegendre {
    /// The n-point rule; nodes are roots of P_n found by Newton's method from Tricomi's
    /// initial guess, accurate to machine precision.
    pub fn new(n: usize) -> Self {
        assert!(n >= 1);
        let mut nodes = vec![0.0; n];
        let mut weights = vec![0.0; n];
        let m = n.div_ceil(2);
        for i in 0..m {
            let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut dp = 0.0;
            for _ in 0..100 {
                // Legendre recurrence for P_n(x) and its derivative.
                let (mut p0, mut p1) = (1.0, x);
                for k in 2..=n {
                    let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                    p0 = p1;
                    p1 = p2;
                }
                let pn = if n == 1 { x } else { p1 };
                let pn1 = if n == 1 { 1.0 } else { p0 };
                dp = n as f64 * (x * pn - pn1) / (x * x - 1.0);
                let dx = pn / dp;
                x -= dx;
                if dx.abs() < 1e-16 {
                    break;
                }
            }
            nodes[i] = -x;
            nodes[n - 1 - i] = x;
            let w = 2.0 / ((1.0 - x * x) * dp * dp);
            weights[i] = w;
            weights[n - 1 - i] = w;
        }
        if n % 2 == 1 {
            nodes[n / 2] = 0.0;
        }
        GaussLegendre { nodes, weights }
    }

    /// A shared 64-point rule (exact for polynomials up to degree 127).
    pub fn shared64() -> &'static GaussLegendre {
        static RULE: OnceLock<GaussLegendre> = OnceLock::new();
        RULE.get_or_init(|| GaussLegendre::new(64))
    }

    /// ∫_a^b f(x) dx.
    pub fn integrate(&self, a: f64, b: f64, mut f: impl FnMut(f64) -> f64) -> f64 {
        let h = 0.5 * (b - a);
        let c = 0.5 * (b + a);
        let mut s = 0.0;
        for (x, w) in self.nodes.iter().zip(&self.weights) {
            s += w * f(c + h * x);
        }
        s * h
    }

    /// ∫_a^b f(x) dx as a sum over `panels` equal sub-intervals.
    pub fn integrate_composite(
        &self,
        a: f64,
        b: f64,
        panels: usize,
        mut f: impl FnMut(f64) -> f64,
    ) -> f64 {
        let step = (b - a) / panels as f64;
        (0..panels)
            .map(|k| {
                let lo = a + step * k as f64;
                self.integrate(lo, lo + step, &mut f)
            })
            .sum()
    }
}

pub(crate) const XGK: [f64; 8] = [
    0.991_455_371_120_812_6,
    0.949_107_912_342_758_5,
    0.864_864_423_359_769_1,
    0.741_531_185_599_394_4,
    0.586_087_235_467_691_1,
    0.405_845_151_377_397_2,
    0.207_784_955_007_898_5,
    0.0,
];
pub(crate) const WGK: [f64; 8] = [
    0.022_935_322_010_529_22,
    0.063_092_092_629_978_55,
    0.104_790_010_322_250_2,
    0.140_653_259_715_525_9,
    0.169_004_726_639_267_9,
    0.190_350_578_064_785_4,
    0.204_432_940_075_298_9,
    0.209_482_141_084_727_8,
];
pub(crate) const WG: [f64; 4] = [
    0.129_484_966_168_869_7,
    0.279_705_391_489_276_7,
    0.381_830_050_505_118_9,
    0.417_959_183_673_469_4,
];

/// One Gauss–Kronrod 15-point estimate and its error estimate (|K15 − G7|).
fn gk15(a: f64, b: f64, f: &mut impl FnMut(f64) -> f64) -> (f64, f64) {
    let c = 0.5 * (a + b);
    let h = 0.5 * (b - a);
    let fc = f(c);
    let mut rk = fc * WGK[7];
    let mut rg = fc * WG[3];
    for j in 0..7 {
        let dx = h * XGK[j];
        let s = f(c - dx) + f(c + dx);
        rk += WGK[j] * s;
        if j % 2 == 1 {
            rg += WG[j / 2] * s;
        }
    }
    (rk * h, ((rk - rg) * h).abs())
}

/// Evaluations per [`gk15_weighted`] call.
pub(crate) const GK15_NODES: usize = 15;

/// K15 on [a, b] of an integrand that returns (value, its own error): (K15 value, the
/// error estimate of QUADPACK's QK15 — or, with `embedded`, |K15 − G7| itself — the
/// K15-weighted sum of the own errors).
///
/// QK15's estimate [Piessens et al. 1983] scales |K15 − G7| with the K15 integral
/// of |f − mean|, r: e = r·min(1, (200 |K15 − G7| / r)^1.5), at least 50 ε ∫|f|. Where
/// the two rules are far from agreeing (a kink or a peak they do not resolve, where they
/// err alike and their difference can be smaller than either error) it is close to r, a
/// large bound; where they agree it falls faster than |K15 − G7| (K15 is the far more
/// accurate of the two). At the moderate accuracies of a piecewise-smooth integrand
/// (|K15 − G7| between 1e-6 and 1e-2 of r) that scaling makes it 3 to 300 times |K15 − G7|;
/// `embedded` keeps |K15 − G7| — still an upper bound of K15's own error wherever the
/// segment is smooth (K15 is exact to degree 22, G7 to 13), and the adaptive driver's
/// bisection floor covers the kinks where the two rules err alike.
pub(crate) fn gk15_weighted(
    a: f64,
    b: f64,
    embedded: bool,
    f: &mut dyn FnMut(f64) -> (f64, f64),
) -> (f64, f64, f64) {
    let c = 0.5 * (a + b);
    let h = 0.5 * (b - a);
    let mut fv = [0.0; 15];
    let (fc, ec) = f(c);
    fv[14] = fc;
    let mut rk = fc * WGK[7];
    let mut rg = fc * WG[3];
    let mut re = ec * WGK[7];
    let mut rabs = fc.abs() * WGK[7];
    for j in 0..7 {
        let dx = h * XGK[j];
        let (f1, e1) = f(c - dx);
        let (f2, e2) = f(c + dx);
        fv[2 * j] = f1;
        fv[2 * j + 1] = f2;
        let s = f1 + f2;
        rk += WGK[j] * s;
        re += WGK[j] * (e1 + e2);
        rabs += WGK[j] * (f1.abs() + f2.abs());
        if j % 2 == 1 {
            rg += WG[j / 2] * s;
        }
    }
    let mean = 0.5 * rk;
    let mut rasc = WGK[7] * (fc - mean).abs();
    for j in 0..7 {
        rasc += WGK[j] * ((fv[2 * j] - mean).abs() + (fv[2 * j + 1] - mean).abs());
    }
    let hk = h.abs();
    let (rasc, rabs) = (rasc * hk, rabs * hk);
    let mut err = ((rk - rg) * h).abs();
    if !embedded && rasc > 0.0 && err > 0.0 {
        err = rasc * (200.0 * err / rasc).powf(1.5).min(1.0);
    }
    if rabs > f64::MIN_POSITIVE / (50.0 * f64::EPSILON) {
        err = err.max(50.0 * f64::EPSILON * rabs);
    }
    (rk * h, err, re * hk)
}

/// Globally adaptive Gauss–Kronrod integration of f over [a, b] (the strategy of
/// QUADPACK's QAG): the interval with the largest error estimate is bisected until the total
/// error is below max(`abs_tol`, `rel_tol`·|I|) or 2000 intervals are in use, so the cost is
/// bounded even for integrands that cancel to zero.
pub fn integrate_adaptive(
    a: f64,
    b: f64,
    abs_tol: f64,
    rel_tol: f64,
    mut f: impl FnMut(f64) -> f64,
) -> f64 {
    const MAX_INTERVALS: usize = 2000;
    if a == b {
        return 0.0;
    }
    let (v, e) = gk15(a, b, &mut f);
    let mut parts: Vec<(f64, f64, f64, f64)> = vec![(a, b, v, e)];
    let mut total = v;
    let mut err = e;
    while parts.len() < MAX_INTERVALS {
        let tol = abs_tol.max(rel_tol * total.abs());
        if err <= tol {
            break;
        }
        // Split the worst interval.
        let (k, _) = parts
            .iter()
            .enumerate()
            .max_by(|x, y| x.1 .3.total_cmp(&y.1 .3))
            .expect("non-empty");
        let (lo, hi, v0, e0) = parts.swap_remove(k);
        let mid = 0.5 * (lo + hi);
        if !(mid > lo && mid < hi) {
            // Interval at machine resolution: keep it and stop refining.
            parts.push((lo, hi, v0, 0.0));
            err -= e0;
            continue;
        }
        let (vl, el) = gk15(lo, mid, &mut f);
        let (vr, er) = gk15(mid, hi, &mut f);
        total += vl + vr - v0;
        err += el + er - e0;
        parts.push((lo, mid, vl, el));
        parts.push((mid, hi, vr, er));
    }
    // Re-sum to avoid drift from the incremental updates.
    parts.iter().map(|p| p.2).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_legendre_is_exact_for_polynomials() {
        for n in [1, 2, 3, 5, 8, 17, 64] {
            let gl = GaussLegendre::new(n);
            let deg = 2 * n - 1;
            let exact = 1.0 / (deg as f64 + 1.0); // ∫_0^1 x^deg
            let got = gl.integrate(0.0, 1.0, |x| x.powi(deg as i32));
            assert!((got - exact).abs() < 1e-13, "n={n}: {got} vs {exact}");
            let wsum: f64 = gl.weights.iter().sum();
            assert!((wsum - 2.0).abs() < 1e-13);
        }
    }

    #[test]
    fn kronrod_constants_are_right() {
        // K15 is exact to degree 22 and G7 to degree 13: both estimates must agree on x^12.
        let (k, e) = gk15(-1.0, 1.0, &mut |x: f64| x.powi(12));
        assert!((k - 2.0 / 13.0).abs() < 1e-15 && e < 1e-15);
        let (k, _) = gk15(0.0, 1.0, &mut |x: f64| x.powi(22));
        assert!((k - 1.0 / 23.0).abs() < 1e-15);
    }

    #[test]
    fn adaptive_handles_kinks_and_peaks() {
        let v = integrate_adaptive(-1.0, 2.0, 1e-13, 1e-13, |x: f64| x.abs());
        assert!((v - 2.5).abs() < 1e-12);
        let s = 1e-3;
        let v = integrate_adaptive(-1.0, 1.0, 1e-14, 1e-12, |x: f64| {
            (-x * x / (2.0 * s * s)).exp() / (s * (2.0 * std::f64::consts::PI).sqrt())
        });
        assert!((v - 1.0).abs() < 1e-10, "{v}");
    }
}
