//! The one guard against non-finite values.
//!
//! A NaN or an infinity must never reach a renderer's film, so a model's `eval` and `pdf`
//! pass their result through [`guard`], which turns a non-finite value into zero. That alone
//! would hide formula bugs from the tests (a NaN shows up as lost energy, and the NaN sweep
//! would test the guard rather than the formula), so in test builds — `cfg(test)` of this
//! crate, or the `strict-finite` feature that every workspace crate enables for its tests —
//! the guard panics instead, naming the model and its inputs.

use crate::math::spectrum::Spectrum;

/// A value the guard can check and replace by zero.
pub trait Finite: Copy + std::fmt::Debug {
    fn is_finite_value(&self) -> bool;
    fn zero() -> Self;
}

impl Finite for f64 {
    #[inline]
    fn is_finite_value(&self) -> bool {
        self.is_finite()
    }
    #[inline]
    fn zero() -> Self {
        0.0
    }
}

impl Finite for Spectrum {
    #[inline]
    fn is_finite_value(&self) -> bool {
        self.is_finite()
    }
    #[inline]
    fn zero() -> Self {
        Spectrum::ZERO
    }
}

/// True when non-finite values panic (test builds) instead of becoming zero.
pub const STRICT: bool = cfg!(any(test, feature = "strict-finite"));

/// `value` if finite; otherwise zero in normal builds, a panic naming `context()` (the
/// model and its inputs, formatted only on failure) in strict builds.
#[inline]
pub fn guard<T: Finite>(value: T, context: impl FnOnce() -> String) -> T {
    if value.is_finite_value() {
        value
    } else {
        non_finite(value, context)
    }
}

#[cold]
#[inline(never)]
fn non_finite<T: Finite>(value: T, context: impl FnOnce() -> String) -> T {
    if STRICT {
        panic!("non-finite value {value:?} in {}", context());
    }
    T::zero()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finite_values_pass_and_non_finite_ones_fail_loudly_in_tests() {
        assert_eq!(guard(0.5, || unreachable!()), 0.5);
        assert_eq!(guard(Spectrum::ONE, || unreachable!()), Spectrum::ONE);
        let e =
            std::panic::catch_unwind(|| guard(f64::NAN, || "model(x=1)".to_string())).unwrap_err();
        let msg = e.downcast_ref::<String>().unwrap();
        assert!(msg.contains("NaN") && msg.contains("model(x=1)"), "{msg}");
    }
}
