//! The sRGB transfer functions of IEC 61966-2-1: the piecewise EOTF (encoded → linear) used
//! to decode 8/16-bit colour textures and the OETF (linear → encoded) used to write PNGs.
//! Both are the exact standard curves, not a 2.2 gamma, so decode(encode(x)) = x.

use std::sync::OnceLock;

/// Encoded sRGB value in [0, 1] → linear value: c/12.92 below 0.04045, else
/// ((c + 0.055)/1.055)^2.4.
#[inline]
pub fn srgb_to_linear(c: f64) -> f64 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Linear value → encoded sRGB: 12.92·l below 0.0031308, else 1.055·l^(1/2.4) − 0.055.
/// Negative inputs map to negative outputs through the linear segment; callers clamp.
#[inline]
pub fn linear_to_srgb(l: f64) -> f64 {
    if l <= 0.003_130_8 {
        12.92 * l
    } else {
        1.055 * l.powf(1.0 / 2.4) - 0.055
    }
}

/// The 256 linear values of 8-bit sRGB codes: decoding a texture costs a table read.
pub fn srgb8_to_linear_table() -> &'static [f32; 256] {
    static TABLE: OnceLock<[f32; 256]> = OnceLock::new();
    TABLE.get_or_init(|| std::array::from_fn(|i| srgb_to_linear(i as f64 / 255.0) as f32))
}

/// Linear value → 8-bit sRGB code: OETF, clamp to [0, 1], round to nearest. NaN gives 0.
#[inline]
pub fn linear_to_srgb8(l: f64) -> u8 {
    let e = linear_to_srgb(l);
    if e > 0.0 {
        (e.min(1.0) * 255.0).round() as u8
    } else {
        0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transfer_functions_are_inverse_and_continuous() {
        for k in 0..=1000 {
            let x = k as f64 / 1000.0;
            assert!((srgb_to_linear(linear_to_srgb(x)) - x).abs() < 1e-12);
            assert!((linear_to_srgb(srgb_to_linear(x)) - x).abs() < 1e-12);
        }
        // The two pieces meet at the breakpoints (the standard's constants are rounded, so
        // to ~1e-7 rather than exactly).
        let below = 0.04045 / 12.92;
        let above = ((0.04045f64 + 0.055) / 1.055).powf(2.4);
        assert!((below - above).abs() < 1e-7);
        let below = 12.92 * 0.003_130_8;
        let above = 1.055 * 0.003_130_8f64.powf(1.0 / 2.4) - 0.055;
        assert!((below - above).abs() < 1e-6);
        assert_eq!(srgb_to_linear(1.0), 1.0);
        assert!((linear_to_srgb(0.18) - 0.461_356).abs() < 1e-5);
    }

    #[test]
    fn eight_bit_codes_round_trip() {
        let t = srgb8_to_linear_table();
        for c in 0..=255u8 {
            assert_eq!(linear_to_srgb8(t[c as usize] as f64), c);
        }
        assert_eq!(linear_to_srgb8(f64::NAN), 0);
        assert_eq!(linear_to_srgb8(-1.0), 0);
        assert_eq!(linear_to_srgb8(7.0), 255);
        assert_eq!(linear_to_srgb8(f64::INFINITY), 255);
    }
}
