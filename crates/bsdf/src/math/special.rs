//! Special functions: error function and its inverse, log-gamma and the Beta function.

use crate::lanes::{Mask, Real};

/// Error function (libm's double-precision implementation, relative error ~1e-16).
#[inline]
pub fn erf(x: f64) -> f64 {
    libm::erf(x)
}

/// Complementary error function 1 − erf(x), accurate for large x.
#[inline]
pub fn erfc(x: f64) -> f64 {
    libm::erfc(x)
}

/// Inverse error function to about 1e-7 relative (Giles' single-precision rational,
/// "Approximating the erfinv function", GPU Computing Gems, 2011, evaluated in f64): an
/// initial guess for iterations that refine it.
#[inline]
pub fn erfinv_approx(y: f64) -> f64 {
    erfinv_approx_lanes(y)
}

/// [`erfinv_approx`] over lanes, its one source: each of Giles' two branches is evaluated
/// where some lane needs it, and selected per lane.
#[inline(always)]
pub fn erfinv_approx_lanes<R: Real>(y: R) -> R {
    erfinv_ratio_single_lanes(-((R::one() - y) * (R::one() + y)).ln()) * y
}

/// erfinv(y)/y as a function of w = −ln(1 − y²) ≥ 0, Giles' single-precision rational
/// (about 1e-7 relative; Giles 2011, §2).
#[inline(always)]
fn erfinv_ratio_single_lanes<R: Real>(w: R) -> R {
    // Functions, not closures, so that they inline into the renderer's AVX2 kernel (a
    // closure is compiled on its own for the baseline CPU).
    #[inline(always)]
    fn horner<R: Real>(w: R, c: &[f64]) -> R {
        let mut p = R::splat(c[0]);
        for &k in &c[1..] {
            p = R::splat(k) + p * w;
        }
        p
    }
    let central = w.lt(R::splat(5.0));
    let inner = if central.any() {
        horner(
            w - R::splat(2.5),
            &[
                2.810_226_36e-08,
                3.432_739_39e-07,
                -3.523_387_7e-06,
                -4.391_506_54e-06,
                0.000_218_580_87,
                -0.001_253_725_03,
                -0.004_177_681_64,
                0.246_640_727,
                1.501_409_41,
            ],
        )
    } else {
        R::zero()
    };
    let outer = if (!central).any() {
        horner(
            w.sqrt() - R::splat(3.0),
            &[
                -0.000_200_214_257,
                0.000_100_950_558,
                0.001_349_343_22,
                -0.003_673_428_44,
                0.005_739_507_73,
                -0.007_622_461_3,
                0.009_438_870_47,
                1.001_674_06,
                2.832_976_82,
            ],
        )
    } else {
        R::zero()
    };
    R::select(central, inner, outer)
}

/// [`erfinv_of_uniform`] over lanes: the f64 instantiation is that function lane by lane
/// (Giles' double-precision polynomials); f32 lanes take Giles' single-precision rational,
/// which vectorizes and keeps f32 precision (the tests measure it).
#[inline(always)]
pub fn erfinv_of_uniform_lanes<R: Real>(u: R) -> R {
    if R::DIGITS > f32::MANTISSA_DIGITS {
        return u.map(erfinv_of_uniform);
    }
    let w = -(R::splat(4.0) * u * (R::one() - u)).ln();
    let x = (R::splat(2.0) * u - R::one()) * erfinv_ratio_single_lanes(w);
    // Giles' single-precision rational covers w ≤ 16 (|2u − 1| down to f32's 1 − 2⁻²⁴); the
    // few lanes beyond it (u < 3e-8, when the sampler gives finer numbers near 0) take the
    // double-precision form.
    let far = w.gt(R::splat(16.0));
    if far.any() {
        R::select(far, u.map(erfinv_of_uniform), x)
    } else {
        x
    }
}

/// erfc over lanes: the f64 instantiation is libm's [`erfc`] lane by lane; f32 lanes take
/// the Chebyshev fit erfc(z) ≈ t exp(−z² + P(t)), t = 1/(1 + z/2), z = |x|, of Press et al.
/// (*Numerical Recipes in C*, 2nd ed., 1992, §6.2, `erfcc`: relative error below 1.2e-7
/// for every z ≥ 0, the lower tail included), and erfc(x) = 2 − erfc(−x) for x < 0 — one
/// division and one exponential, branch-free.
#[inline(always)]
pub fn erfc_lanes<R: Real>(x: R) -> R {
    if R::DIGITS > f32::MANTISSA_DIGITS {
        return x.map(erfc);
    }
    let z = x.abs();
    let t = R::one() / (R::one() + R::splat(0.5) * z);
    let mut p = R::splat(0.170_872_77);
    for c in [
        -0.822_152_23,
        1.488_515_87,
        -1.135_203_98,
        0.278_868_07,
        -0.186_288_06,
        0.096_784_18,
        0.374_091_96,
        1.000_023_68,
        -1.265_512_23,
    ] {
        p = p * t + R::splat(c);
    }
    let r = t * (p - z * z).exp();
    R::select(x.lt(R::zero()), R::splat(2.0) - r, r)
}

/// Giles' double-precision erfinv polynomials ("Approximating the erfinv function", GPU
/// Computing Gems Jade Edition, 2011, §3 and the code accompanying it): erfinv(y) = y p(w)
/// with w = −ln(1 − y²), p a polynomial in w − 3.125 for w < 6.25, in √w − 3.25 for
/// w < 16 and in √w − 5 beyond. Coefficients from the highest degree down (Horner).
const GILES_CENTRAL: [f64; 23] = [
    -3.64441206401782e-21,
    -1.6850591381820166e-19,
    1.28584807152564e-18,
    1.1157877678025181e-17,
    -1.333171662854621e-16,
    2.0972767875968562e-17,
    6.637638134358324e-15,
    -4.054566272975207e-14,
    -8.151934197605472e-14,
    2.6335093153082323e-12,
    -1.2975133253453532e-11,
    -5.415412054294628e-11,
    1.0512122733215323e-09,
    -4.112633980346984e-09,
    -2.9070369957882005e-08,
    4.2347877827932404e-07,
    -1.3654692000834679e-06,
    -1.3882523362786469e-05,
    0.00018673420803405714,
    -0.000740702534166267,
    -0.006033670871430149,
    0.24015818242558962,
    1.6536545626831027,
];
const GILES_MIDDLE: [f64; 19] = [
    2.2137376921775787e-09,
    9.075656193888539e-08,
    -2.7517406297064545e-07,
    1.8239629214389228e-08,
    1.5027403968909828e-06,
    -4.013867526981546e-06,
    2.9234449089955446e-06,
    1.2475304481671779e-05,
    -4.7318229009055734e-05,
    6.828485145957318e-05,
    2.4031110387097894e-05,
    -0.0003550375203628475,
    0.0009532893797373805,
    -0.0016882755560235047,
    0.002491442096107851,
    -0.003751208507569241,
    0.005370914553590064,
    1.0052589676941592,
    3.0838856104922208,
];
const GILES_TAIL: [f64; 17] = [
    -2.7109920616438573e-11,
    -2.555641816996525e-10,
    1.5076572693500548e-09,
    -3.789465440126737e-09,
    7.61570120807834e-09,
    -1.496002662714924e-08,
    2.914795345090108e-08,
    -6.771199775845234e-08,
    2.2900482228026655e-07,
    -9.9298272942317e-07,
    4.526062597223154e-06,
    -1.968177810553167e-05,
    7.599527703001776e-05,
    -0.00021503011930044477,
    -0.00013871931833623122,
    1.0103004648645344,
    4.849906401408584,
];

#[inline]
fn horner(coeffs: &[f64], x: f64) -> f64 {
    coeffs.iter().fold(0.0, |p, &c| p * x + c)
}

/// erfinv(y) / y as a function of w = −ln(1 − y²) ≥ 0 (Giles 2011, double precision).
#[inline]
fn erfinv_ratio(w: f64) -> f64 {
    if w < 6.25 {
        horner(&GILES_CENTRAL, w - 3.125)
    } else if w < 16.0 {
        horner(&GILES_MIDDLE, w.sqrt() - 3.25)
    } else {
        horner(&GILES_TAIL, w.sqrt() - 5.0)
    }
}

/// Inverse error function on (−1, 1) to double precision (Giles 2011's double-precision
/// polynomials, no erf evaluation; the tests measure it against erf). Returns ±∞ at ±1 and
/// NaN outside.
pub fn erfinv(y: f64) -> f64 {
    if !(-1.0..=1.0).contains(&y) {
        return f64::NAN;
    }
    if y == 1.0 {
        return f64::INFINITY;
    }
    if y == -1.0 {
        return f64::NEG_INFINITY;
    }
    y * erfinv_ratio(-((1.0 - y) * (1.0 + y)).ln())
}

/// erfinv(2u − 1) for u in (0, 1), with 1 − (2u − 1)² = 4u(1 − u) formed from u so that
/// no precision is lost to 2u − 1 near u = 0: the Gaussian quantile of a uniform number
/// (the slope e^{−y²}/√π has this inverse CDF). Accurate for u in [1e-16, 1 − 1e-16], the
/// range of Giles' polynomials (w ≤ 36.7); finite down to u = 1e-300.
#[inline]
pub fn erfinv_of_uniform(u: f64) -> f64 {
    (2.0 * u - 1.0) * erfinv_ratio(-(4.0 * u * (1.0 - u)).ln())
}

/// ln Γ(x) for x > 0.
#[inline]
pub fn ln_gamma(x: f64) -> f64 {
    libm::lgamma(x)
}

/// Beta function B(a, b) = Γ(a) Γ(b) / Γ(a + b) for a, b > 0.
#[inline]
pub fn beta(a: f64, b: f64) -> f64 {
    (ln_gamma(a) + ln_gamma(b) - ln_gamma(a + b)).exp()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn erfinv_inverts_erf_to_full_precision() {
        for i in -999..=999 {
            let y = i as f64 / 1000.0;
            let x = erfinv(y);
            assert!((erf(x) - y).abs() < 1e-14, "y={y} x={x}");
        }
        for &y in &[1e-300, 0.999_999_999, -0.999_999_999_999] {
            let x = erfinv(y);
            assert!(((erf(x) - y) / y).abs() < 1e-9, "y={y}");
        }
        assert_eq!(erfinv(1.0), f64::INFINITY);
        assert!(erfinv(1.5).is_nan());
    }

    /// The former erfinv: Giles' single-precision guess refined by one Halley step on erf.
    fn erfinv_halley(y: f64) -> f64 {
        let x = erfinv_approx(y);
        let f = erf(x) - y;
        let d = 2.0 / crate::math::SQRT_PI * (-x * x).exp();
        x - f / (d + x * f)
    }

    /// The relative error in x = erfinv(y) implied by the residual erf(x) − y.
    fn implied_error(x: f64, y: f64) -> f64 {
        (erf(x) - y).abs() / (2.0 / crate::math::SQRT_PI * (-x * x).exp() * x.abs())
    }

    #[test]
    fn erfinv_is_as_accurate_as_the_halley_refined_form() {
        let (mut new, mut old) = (0.0f64, 0.0f64);
        for i in 1..200_000 {
            let y = -0.999 + i as f64 * 0.999e-5;
            new = new.max(implied_error(erfinv(y), y));
            old = old.max(implied_error(erfinv_halley(y), y));
        }
        println!("erfinv on |y| ≤ 0.999: relative error {new:e} (Halley-refined form: {old:e})");
        assert!(new < 1e-15, "{new:e}");
    }

    #[test]
    fn erfinv_of_uniform_is_the_gaussian_quantile() {
        // P(X < x) = erfc(−x)/2 for the density e^{−x²}/√π; erfc keeps the tails' precision.
        let mut worst: f64 = 0.0;
        for k in 0..=400 {
            for u in [10f64.powf(-1.0 - k as f64 * 0.0375), 0.5 + k as f64 / 803.0] {
                let x = erfinv_of_uniform(u);
                assert!(x.is_finite(), "u={u}");
                worst = worst.max((0.5 * erfc(-x) - u).abs() / u.min(1.0 - u));
            }
        }
        // A relative CDF error ε is a relative error in x of about ε/(2x²) in the tails.
        println!("erfinv_of_uniform: largest relative CDF error {worst:e}");
        assert!(worst < 5e-14, "{worst:e}");
        assert_eq!(erfinv_of_uniform(0.5), 0.0);
    }

    /// The f32 lane forms against libm in f64, at f32 inputs: erfc's relative error grows
    /// like the rounding of the exponent −z² + P(t) (a few ulps of z² in relative terms);
    /// the Gaussian quantile's relative CDF error stays at f32 precision, tails included.
    #[test]
    fn f32_lane_erfc_and_gaussian_quantile_keep_f32_precision() {
        use crate::lanes::F32x8;
        let mut worst_erfc: f64 = 0.0;
        for k in 0..=12_000 {
            let x = (-4.0 + k as f64 * 1e-3) as f32 as f64; // −4 … 8
            let got = erfc_lanes(F32x8::splat(x)).lane(0);
            let scalar = erfc_lanes(x as f32) as f64;
            let want = erfc(x);
            for v in [got, scalar] {
                worst_erfc = worst_erfc.max((v - want).abs() / want / (1.0 + x * x));
            }
        }
        let mut worst_quantile: f64 = 0.0;
        for k in 0..=400 {
            for u in [10f64.powf(-1.0 - k as f64 * 0.0275), 0.5 + k as f64 / 803.0] {
                let u = u as f32 as f64;
                let x = erfinv_of_uniform_lanes(F32x8::splat(u)).lane(0);
                assert!(x.is_finite(), "u={u}");
                let cdf = 0.5 * erfc(-x);
                worst_quantile = worst_quantile.max((cdf - u).abs() / u.min(1.0 - u));
            }
        }
        println!(
            "f32 lanes: erfc relative error / (1 + x²) {worst_erfc:e}, \
             Gaussian quantile relative CDF error {worst_quantile:e}"
        );
        assert!(worst_erfc < 5e-7, "{worst_erfc:e}");
        assert!(worst_quantile < 1e-5, "{worst_quantile:e}");
        // The f64 instantiations are the scalar functions.
        assert_eq!(erfc_lanes(0.3f64), erfc(0.3));
        assert_eq!(erfinv_of_uniform_lanes(0.3f64), erfinv_of_uniform(0.3));
    }

    #[test]
    fn beta_matches_closed_forms() {
        // B(1, b) = 1/b ; B(2, 3) = 1/12 ; B(1/2, 1/2) = π
        assert!((beta(1.0, 4.0) - 0.25).abs() < 1e-14);
        assert!((beta(2.0, 3.0) - 1.0 / 12.0).abs() < 1e-14);
        assert!((beta(0.5, 0.5) - std::f64::consts::PI).abs() < 1e-13);
    }
}
