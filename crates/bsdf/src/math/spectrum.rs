//! The spectrum type: a small fixed-size array of channel values (linear RGB today), written
//! so that a spectral mode can replace the channel count without touching the models.

use std::ops::{Add, AddAssign, Div, DivAssign, Index, IndexMut, Mul, MulAssign, Sub};

/// Number of channels carried by [`Spectrum`].
pub const CHANNELS: usize = 3;

#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Spectrum(pub [f64; CHANNELS]);

impl Spectrum {
    pub const ZERO: Spectrum = Spectrum([0.0; CHANNELS]);
    pub const ONE: Spectrum = Spectrum([1.0; CHANNELS]);

    #[inline]
    pub const fn splat(v: f64) -> Self {
        Spectrum([v; CHANNELS])
    }

    #[inline]
    pub const fn rgb(r: f64, g: f64, b: f64) -> Self {
        Spectrum([r, g, b])
    }

    #[inline]
    pub fn map(self, f: impl Fn(f64) -> f64) -> Self {
        Spectrum(self.0.map(f))
    }

    #[inline]
    pub fn zip(self, o: Spectrum, f: impl Fn(f64, f64) -> f64) -> Self {
        let mut r = [0.0; CHANNELS];
        for (k, v) in r.iter_mut().enumerate() {
            *v = f(self.0[k], o.0[k]);
        }
        Spectrum(r)
    }

    /// Arithmetic mean of the channels (used for lobe-selection probabilities).
    #[inline]
    pub fn average(self) -> f64 {
        self.0.iter().sum::<f64>() / CHANNELS as f64
    }

    #[inline]
    pub fn max_component(self) -> f64 {
        self.0.iter().copied().fold(f64::NEG_INFINITY, f64::max)
    }

    #[inline]
    pub fn min_component(self) -> f64 {
        self.0.iter().copied().fold(f64::INFINITY, f64::min)
    }

    /// Rec. 709 / sRGB luminance.
    #[inline]
    pub fn luminance(self) -> f64 {
        0.2126 * self.0[0] + 0.7152 * self.0[1] + 0.0722 * self.0[2]
    }

    #[inline]
    pub fn is_black(self) -> bool {
        self.0.iter().all(|&v| v == 0.0)
    }

    #[inline]
    pub fn is_finite(self) -> bool {
        self.0.iter().all(|v| v.is_finite())
    }

    #[inline]
    pub fn has_negative(self) -> bool {
        self.0.iter().any(|&v| v < 0.0)
    }
}

impl From<f64> for Spectrum {
    fn from(v: f64) -> Self {
        Spectrum::splat(v)
    }
}

impl Index<usize> for Spectrum {
    type Output = f64;
    fn index(&self, i: usize) -> &f64 {
        &self.0[i]
    }
}

impl IndexMut<usize> for Spectrum {
    fn index_mut(&mut self, i: usize) -> &mut f64 {
        &mut self.0[i]
    }
}

macro_rules! binop {
    ($tr:ident, $f:ident, $op:tt, $tra:ident, $fa:ident) => {
        impl $tr for Spectrum {
            type Output = Spectrum;
            #[inline]
            fn $f(self, o: Spectrum) -> Spectrum {
                self.zip(o, |a, b| a $op b)
            }
        }
        impl $tr<f64> for Spectrum {
            type Output = Spectrum;
            #[inline]
            fn $f(self, o: f64) -> Spectrum {
                self.map(|a| a $op o)
            }
        }
        impl $tra for Spectrum {
            #[inline]
            fn $fa(&mut self, o: Spectrum) {
                *self = *self $op o;
            }
        }
        impl $tra<f64> for Spectrum {
            #[inline]
            fn $fa(&mut self, o: f64) {
                *self = *self $op o;
            }
        }
    };
}

binop!(Add, add, +, AddAssign, add_assign);
binop!(Mul, mul, *, MulAssign, mul_assign);
binop!(Div, div, /, DivAssign, div_assign);

impl Sub for Spectrum {
    type Output = Spectrum;
    #[inline]
    fn sub(self, o: Spectrum) -> Spectrum {
        self.zip(o, |a, b| a - b)
    }
}

impl Mul<Spectrum> for f64 {
    type Output = Spectrum;
    #[inline]
    fn mul(self, s: Spectrum) -> Spectrum {
        s * self
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arithmetic() {
        let a = Spectrum::rgb(1.0, 2.0, 3.0);
        let b = Spectrum::splat(2.0);
        assert_eq!(a * b, Spectrum::rgb(2.0, 4.0, 6.0));
        assert_eq!(a / 2.0, Spectrum::rgb(0.5, 1.0, 1.5));
        assert_eq!(2.0 * a - a, a);
        assert_eq!(a.average(), 2.0);
        assert_eq!(a.max_component(), 3.0);
        assert!((Spectrum::ONE.luminance() - 1.0).abs() < 1e-12);
    }
}
