//! The exact dielectric Fresnel reflectance of one fixed index, tabulated for an inner loop
//! that evaluates it millions of times (the V-cavity beam tracer: a square root and three
//! divisions per footprint were an eighth of IL_∞'s `eval`).
//!
//! For an index η > 1 seen from outside, F(cos θ) [WMLT07 eq. 22] is analytic on [0, 1];
//! its features are the branch points of √(η² − 1 + c²) at c = ±i√(η² − 1) and, for the
//! p-polarized half, Brewster's zero near c = 1/η. A cubic through four neighbouring nodes
//! of a uniform grid of `INTERVALS` cells is accurate to about h⁴ over the fourth power of
//! the smaller of those scales: measured (test below) 4e-12 at η 1.049, 4e-13 at 1.5,
//! 8e-12 at 4 and 3e-10 at 10. [`FresnelTable::with_accuracy`] measures the table's error
//! at every cell's midpoint when it is built and keeps the formula where that exceeds what
//! the caller can afford (and always for η < `MIN_INDEX`, where the branch points approach
//! the interval); |cos θ| is clamped to [0, 1] as the formula does.

use super::dielectric::fresnel_dielectric;

/// Cells of the table on [0, 1].
const INTERVALS: usize = 4096;

/// Smallest index tabulated (η² − 1 ≥ 0.1); below it [`FresnelTable::eval`] computes.
pub const MIN_INDEX: f64 = 1.049;

/// F(|cos θ|, η) for one η, by table where accurate enough (see the module notes).
#[derive(Clone, Debug)]
pub struct FresnelTable {
    eta: f64,
    /// F at the nodes k/INTERVALS, k = 0 … INTERVALS; empty when the formula is used.
    values: Vec<f64>,
    /// The largest difference from the formula at the cells' midpoints (0 when empty).
    max_error: f64,
}

impl FresnelTable {
    /// The table for η if its measured error is at most `max_error` (absolute), else the
    /// formula.
    pub fn with_accuracy(eta: f64, max_error: f64) -> Self {
        let mut table = FresnelTable {
            eta,
            values: Vec::new(),
            max_error: 0.0,
        };
        if !(eta >= MIN_INDEX) {
            return table;
        }
        table.values = (0..=INTERVALS)
            .map(|k| fresnel_dielectric(k as f64 / INTERVALS as f64, eta))
            .collect();
        let measured = (0..INTERVALS)
            .map(|k| {
                let c = (k as f64 + 0.5) / INTERVALS as f64;
                (table.eval(c) - fresnel_dielectric(c, eta)).abs()
            })
            .fold(0.0, f64::max);
        if measured <= max_error {
            table.max_error = measured;
        } else {
            table.values = Vec::new();
        }
        table
    }

    /// Whether F comes from the table (else from the formula).
    pub fn is_tabulated(&self) -> bool {
        !self.values.is_empty()
    }

    /// The largest difference from the formula measured at the cells' midpoints.
    pub fn max_error(&self) -> f64 {
        self.max_error
    }

    /// F(|cos θ|, η): cubic Lagrange interpolation through the four nodes around |cos θ|
    /// (the formula itself when η is not tabulated).
    #[inline]
    pub fn eval(&self, cos_theta: f64) -> f64 {
        if self.values.is_empty() {
            return fresnel_dielectric(cos_theta, self.eta);
        }
        // min(NaN, 1) is 1, as in the formula; at cos θ = 0 the cubic below is node 0 exactly.
        let x = cos_theta.abs().min(1.0) * INTERVALS as f64;
        let n = (x as usize).clamp(1, INTERVALS - 2);
        let t = x - n as f64;
        let p = &self.values[n - 1..n + 3];
        lagrange4(t, [p[0], p[1], p[2], p[3]])
    }
}

/// The cubic through (−1, p₀), (0, p₁), (1, p₂), (2, p₃) at t (multiplications only: a
/// division by 6 is not rewritten by the compiler; the stall after it held 16 % of the
/// table look-up's profile samples).
#[inline(always)]
pub(crate) fn lagrange4(t: f64, p: [f64; 4]) -> f64 {
    const SIXTH: f64 = 1.0 / 6.0;
    let (tp1, tm1, tm2) = (t + 1.0, t - 1.0, t - 2.0);
    let a = -t * tm1 * tm2 * SIXTH;
    let b = tp1 * tm1 * tm2 * 0.5;
    let c = -tp1 * t * tm2 * 0.5;
    let d = tp1 * t * tm1 * SIXTH;
    a * p[0] + b * p[1] + c * p[2] + d * p[3]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_table_matches_the_formula_and_knows_its_error() {
        // Indices from the smallest tabulated to 10 (IL's range), at 200,001 cosines and
        // their negatives, and clamped ones outside: the difference is within 1e-9 and
        // within twice the error measured at the midpoints when the table was built.
        for eta in [MIN_INDEX, 1.1, 1.33, 1.5, 2.0, 4.0, 10.0] {
            let table = FresnelTable::with_accuracy(eta, 1.0);
            assert!(table.is_tabulated());
            let mut worst: f64 = 0.0;
            for k in 0..=200_000 {
                let c = k as f64 / 200_000.0;
                for c in [c, -c] {
                    worst = worst.max((table.eval(c) - fresnel_dielectric(c, eta)).abs());
                }
            }
            for c in [1.5, -2.0, f64::MIN_POSITIVE] {
                worst = worst.max((table.eval(c) - fresnel_dielectric(c, eta)).abs());
            }
            println!(
                "η {eta}: largest difference {worst:.2e}, measured at build {:.2e}",
                table.max_error()
            );
            assert!(
                worst < 1e-9 && worst <= 2.0 * table.max_error() + 1e-15,
                "η {eta}: {worst:.2e}"
            );
        }
    }

    #[test]
    fn the_formula_where_the_table_is_not_accurate_enough() {
        // Indices near 1 always; η 10 when asked for 1e-11.
        for (eta, max_error) in [(1.0, 1.0), (1.001, 1.0), (1.03, 1.0), (10.0, 1e-11)] {
            let table = FresnelTable::with_accuracy(eta, max_error);
            assert!(!table.is_tabulated() && table.max_error() == 0.0);
            for c in [0.0, 0.01, 0.3, 1.0] {
                assert_eq!(table.eval(c), fresnel_dielectric(c, eta), "η {eta} cos {c}");
            }
        }
    }
}
