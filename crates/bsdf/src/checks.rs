//! Parameter checks: the valid range of every parameter that more than one part accepts,
//! defined once. Models, distributions and recipes all validate through these functions,
//! so a range (and the wording of its error) cannot drift between the TOML layer and the
//! constructors it calls. Each value is checked once, where it enters: a recipe checks a
//! table's value and hands it on to a constructor that does not check it again.
//!
//! This module sits at the bottom of the crate: it depends on [`crate::error`] and
//! [`crate::math`] only.

use crate::error::{ParamError, ParamResult};
use crate::math::spectrum::{Spectrum, CHANNELS};

/// Which ends of an interval are included.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Bounds {
    /// (lo, hi)
    Open,
    /// [lo, hi]
    Closed,
    /// (lo, hi]
    OpenClosed,
    /// [lo, hi)
    ClosedOpen,
}

/// Checks that `value` is finite and inside the interval; the error names the parameter.
pub fn check_range(name: &str, value: f64, lo: f64, hi: f64, bounds: Bounds) -> ParamResult<f64> {
    if !value.is_finite() {
        return Err(ParamError::NotFinite {
            name: name.into(),
            value,
        });
    }
    let ok = match bounds {
        Bounds::Open => value > lo && value < hi,
        Bounds::Closed => value >= lo && value <= hi,
        Bounds::OpenClosed => value > lo && value <= hi,
        Bounds::ClosedOpen => value >= lo && value < hi,
    };
    if ok {
        return Ok(value);
    }
    // The message is formatted only on failure: materials are rebuilt per shading point
    // when textured.
    let (l, h) = (crate::math::fmt_num(lo), crate::math::fmt_num(hi));
    let expected = match bounds {
        Bounds::Open => format!("{l} < {name} < {h}"),
        Bounds::Closed => format!("{l} <= {name} <= {h}"),
        Bounds::OpenClosed => format!("{l} < {name} <= {h}"),
        Bounds::ClosedOpen => format!("{l} <= {name} < {h}"),
    };
    Err(ParamError::OutOfRange {
        name: name.into(),
        value,
        expected,
    })
}

/// Checks every component of a spectrum against a closed range.
pub fn check_spectrum(name: &str, s: Spectrum, lo: f64, hi: f64) -> ParamResult<Spectrum> {
    for k in 0..CHANNELS {
        check_range(name, s[k], lo, hi, Bounds::Closed)?;
    }
    Ok(s)
}

/// A reflectance or albedo (number or RGB): every channel in [0, 1].
pub fn check_reflectance(name: &str, s: Spectrum) -> ParamResult<Spectrum> {
    check_spectrum(name, s, 0.0, 1.0)
}

/// Largest microfacet width α (Beckmann, GGX, Ward): wider surfaces are no longer
/// meaningful as microfacet models and make the samplers' tails overflow.
pub const ALPHA_MAX: f64 = 10.0;

/// A rough microfacet width α (a distribution's constructor): 0 < α ≤ 10.
pub fn check_alpha(name: &str, alpha: f64) -> ParamResult<f64> {
    check_range(name, alpha, 0.0, ALPHA_MAX, Bounds::OpenClosed)
}

/// A width as a material table gives it, where 0 means a perfectly smooth surface:
/// 0 ≤ α ≤ 10.
pub fn check_alpha_or_smooth(name: &str, alpha: f64) -> ParamResult<f64> {
    check_range(name, alpha, 0.0, ALPHA_MAX, Bounds::Closed)
}

/// The index of refraction of a Fresnel term between air and a denser dielectric:
/// 1 < n ≤ 100.
pub fn check_ior(ior: f64) -> ParamResult<f64> {
    check_range("ior", ior, 1.0, 100.0, Bounds::OpenClosed)
}

/// A count with a lower bound (samples of a quadrature, of a table entry).
pub fn check_min_count(name: &str, n: usize, min: usize) -> ParamResult<usize> {
    if n < min {
        return Err(ParamError::OutOfRange {
            name: name.into(),
            value: n as f64,
            expected: format!("{name} >= {min}"),
        });
    }
    Ok(n)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn range_errors_name_the_parameter() {
        let e = check_range("alpha", -1.0, 0.0, 10.0, Bounds::OpenClosed).unwrap_err();
        assert_eq!(
            e.to_string(),
            "parameter `alpha` = -1 is out of range: expected 0 < alpha <= 10"
        );
        let e = check_range("ior", f64::NAN, 0.0, 10.0, Bounds::Open).unwrap_err();
        assert!(e.to_string().contains("`ior` must be a finite number"));
        assert_eq!(check_range("x", 0.0, 0.0, 1.0, Bounds::Closed), Ok(0.0));
    }

    #[test]
    fn shared_ranges_keep_their_wording() {
        assert_eq!(
            check_alpha("alpha_u", 0.0).unwrap_err().to_string(),
            "parameter `alpha_u` = 0 is out of range: expected 0 < alpha_u <= 10"
        );
        assert_eq!(check_alpha_or_smooth("alpha", 0.0), Ok(0.0));
        assert_eq!(
            check_min_count("samples", 4, 8).unwrap_err().to_string(),
            "parameter `samples` = 4 is out of range: expected samples >= 8"
        );
        let e = check_reflectance("kd", Spectrum::rgb(0.2, 1.5, 0.2)).unwrap_err();
        assert!(e.to_string().contains("`kd` = 1.5"), "{e}");
    }
}
