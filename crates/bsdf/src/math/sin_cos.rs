//! sin and cos together in double precision, for the one-source lane code's `f64`
//! instantiation (the models' samplers pass angles 2πu ∈ [0, 2π)).
//!
//! x is reduced to r = x − k π/2 ∈ [−π/4, π/4] (Cody–Waite: π/2 in three parts of 33
//! bits, so k·part is exact for |k| < 2²⁰), then sin r and cos r are fdlibm's minimax
//! polynomials (`__kernel_sin`, `__kernel_cos`: degree 13 and 14, error below 1 ulp on the
//! interval) and the quadrant permutes and signs them. Beyond |x| = 2²⁰ π/2, and for
//! non-finite x, it is the C library's `sincos`. Against libm over [−8, 8] it is within
//! 2 ulp, or 2e-16 absolute near a zero (tested). It costs a third of glibc's `sincos` in
//! the visible-normal samplers (docs/performance.md), because it has no branch on the
//! argument's size for the usual angles and inlines into its caller.

/// π/2 in three parts (fdlibm's `pio2_1`, `pio2_2`, `pio2_3`).
const PIO2_1: f64 = 1.5707963267341256;
const PIO2_2: f64 = 6.077100506303966e-11;
const PIO2_3: f64 = 2.0222662487111665e-21;
/// Beyond this |x| the reduction's k·part products are no longer exact.
const REDUCTION_LIMIT: f64 = 1_647_099.0; // ≈ 2²⁰ π/2

/// (sin x, cos x).
#[inline(always)]
pub fn sin_cos(x: f64) -> (f64, f64) {
    if !(x.abs() < REDUCTION_LIMIT) {
        return x.sin_cos();
    }
    // k = x·2/π rounded to the nearest integer by adding and subtracting 1.5·2⁵², not by
    // `round`: that is a C library call in code built for the baseline x86-64 (no SSE4.1
    // `roundsd`), and one in the environment map's sampler cost as much as the polynomials.
    // Exact for |x·2/π| < 2⁵¹ (here below 2²⁰); a tie rounds to even, and either
    // neighbour leaves |r| ≤ π/4.
    const ROUNDER: f64 = 6_755_399_441_055_744.0; // 1.5 · 2⁵²
    let k = (x * std::f64::consts::FRAC_2_PI + ROUNDER) - ROUNDER;
    let r = ((x - k * PIO2_1) - k * PIO2_2) - k * PIO2_3;
    let (s, c) = (kernel_sin(r), kernel_cos(r));
    // Quadrant q = k mod 4: (sin, cos) of r + qπ/2, without a branch on q (random angles
    // would mispredict it): odd q swaps the two, and sin is negated for q = 2, 3, cos for
    // q = 1, 2.
    let q = k as i64;
    let odd = (q & 1) as u64;
    let swap = 0u64.wrapping_sub(odd);
    let (sb, cb) = (s.to_bits(), c.to_bits());
    let first = (sb & !swap) | (cb & swap);
    let second = (cb & !swap) | (sb & swap);
    let sin_sign = ((q & 2) as u64) << 62;
    let cos_sign = (((q + 1) & 2) as u64) << 62;
    (
        f64::from_bits(first ^ sin_sign),
        f64::from_bits(second ^ cos_sign),
    )
}

/// sin r for |r| ≤ π/4 [fdlibm `__kernel_sin`, without its tail term].
#[inline(always)]
fn kernel_sin(r: f64) -> f64 {
    const S1: f64 = -0.16666666666666632;
    const S2: f64 = 0.00833333333332249;
    const S3: f64 = -0.0001984126982985795;
    const S4: f64 = 2.7557313707070068e-06;
    const S5: f64 = -2.5050760253406863e-08;
    const S6: f64 = 1.58969099521155e-10;
    let z = r * r;
    let p = S2 + z * (S3 + z * (S4 + z * (S5 + z * S6)));
    r + r * z * (S1 + z * p)
}

/// cos r for |r| ≤ π/4 [fdlibm `__kernel_cos`]: 1 − z/2 + z² C(z), with 1 − z/2 split as
/// fdlibm does so that its rounding error is not amplified.
#[inline(always)]
fn kernel_cos(r: f64) -> f64 {
    const C1: f64 = 0.0416666666666666;
    const C2: f64 = -0.001388888888887411;
    const C3: f64 = 2.480158728947673e-05;
    const C4: f64 = -2.7557314351390663e-07;
    const C5: f64 = 2.087572321298175e-09;
    const C6: f64 = -1.1359647557788195e-11;
    let z = r * r;
    let p = z * (C1 + z * (C2 + z * (C3 + z * (C4 + z * (C5 + z * C6)))));
    let hz = 0.5 * z;
    let w = 1.0 - hz;
    w + (((1.0 - w) - hz) + z * p)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Distance in units in the last place of `b`.
    fn ulps(a: f64, b: f64) -> f64 {
        let ulp = (b.abs().max(f64::MIN_POSITIVE) * f64::EPSILON).max(f64::MIN_POSITIVE);
        (a - b).abs() / ulp
    }

    #[test]
    fn within_two_ulps_of_libm_or_tiny_absolute_error() {
        let n = 400_001;
        let (mut worst_s, mut worst_c) = (0.0f64, 0.0f64);
        for j in 0..n {
            let x = -8.0 + 16.0 * j as f64 / (n - 1) as f64;
            let (s, c) = sin_cos(x);
            let (es, ec) = x.sin_cos();
            // Near a zero of sin or cos, the absolute error is what matters.
            let ds = if es.abs() < 1e-3 {
                (s - es).abs() / 1.1e-16
            } else {
                ulps(s, es)
            };
            let dc = if ec.abs() < 1e-3 {
                (c - ec).abs() / 1.1e-16
            } else {
                ulps(c, ec)
            };
            worst_s = worst_s.max(ds);
            worst_c = worst_c.max(dc);
        }
        assert!(
            worst_s <= 2.0 && worst_c <= 2.0,
            "sin {worst_s}, cos {worst_c}"
        );
        // The samplers' angles 2πu, u ∈ [0, 1), including the ends.
        for u in [
            0.0,
            1e-300,
            1e-17,
            0.125,
            0.25,
            0.5,
            0.75,
            1.0 - f64::EPSILON / 2.0,
        ] {
            let x = std::f64::consts::TAU * u;
            let (s, c) = sin_cos(x);
            let (es, ec) = x.sin_cos();
            assert!(
                (s - es).abs() <= 2.5e-16 && (c - ec).abs() <= 2.5e-16,
                "{x}"
            );
        }
        assert_eq!(sin_cos(0.0), (0.0, 1.0));
    }

    #[test]
    fn large_and_non_finite_arguments_take_libm() {
        for x in [1e7, -3e9, 1e300, f64::INFINITY, f64::NAN] {
            let (s, c) = sin_cos(x);
            let (es, ec) = x.sin_cos();
            assert_eq!(s.to_bits(), es.to_bits());
            assert_eq!(c.to_bits(), ec.to_bits());
        }
        // Just inside the limit the reduction is still accurate.
        let x = 1.6e6;
        let (s, c) = sin_cos(x);
        let (es, ec) = x.sin_cos();
        assert!((s - es).abs() < 1e-15 && (c - ec).abs() < 1e-15);
    }
}
