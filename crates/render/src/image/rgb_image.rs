//! An RGB image in linear Rec. 709 / sRGB primaries: the in-memory form of every picture
//! the renderer reads (textures, environment maps) or writes (films).
//!
//! Pixels are stored as `f32` (rendering precision; EXR's own float type), row-major with the
//! top row first — the order of PNG, EXR (increasing y) and Radiance HDR files — so a file
//! maps to memory without reordering.

use facette_bsdf::{ParamError, ParamResult, Spectrum};

#[derive(Clone, Debug, PartialEq)]
pub struct RgbImage {
    width: usize,
    height: usize,
    data: Vec<[f32; 3]>,
}

impl RgbImage {
    /// An image from its pixels (row-major, top row first). Both sizes must be ≥ 1 and
    /// `data.len()` must equal `width · height`.
    pub fn new(width: usize, height: usize, data: Vec<[f32; 3]>) -> ParamResult<Self> {
        if width == 0 || height == 0 {
            return Err(ParamError::Invalid(format!(
                "an image needs at least one pixel, got {width}×{height}"
            )));
        }
        if width.checked_mul(height) != Some(data.len()) {
            return Err(ParamError::Invalid(format!(
                "a {width}×{height} image needs {} pixels, got {}",
                width.saturating_mul(height),
                data.len()
            )));
        }
        Ok(RgbImage {
            width,
            height,
            data,
        })
    }

    /// An image of one colour.
    pub fn filled(width: usize, height: usize, value: [f32; 3]) -> ParamResult<Self> {
        Self::new(width, height, vec![value; width.saturating_mul(height)])
    }

    /// An image whose pixel (x, y) is `f(x, y)`.
    pub fn from_fn(
        width: usize,
        height: usize,
        mut f: impl FnMut(usize, usize) -> [f32; 3],
    ) -> ParamResult<Self> {
        let mut data = Vec::with_capacity(width.saturating_mul(height));
        for y in 0..height {
            for x in 0..width {
                data.push(f(x, y));
            }
        }
        Self::new(width, height, data)
    }

    #[inline]
    pub fn width(&self) -> usize {
        self.width
    }

    #[inline]
    pub fn height(&self) -> usize {
        self.height
    }

    /// All pixels, row-major, top row first.
    #[inline]
    pub fn data(&self) -> &[[f32; 3]] {
        &self.data
    }

    #[inline]
    pub fn data_mut(&mut self) -> &mut [[f32; 3]] {
        &mut self.data
    }

    pub fn into_data(self) -> Vec<[f32; 3]> {
        self.data
    }

    /// Pixel (x, y); x < width, y < height (panics otherwise, like slice indexing).
    #[inline]
    pub fn get(&self, x: usize, y: usize) -> [f32; 3] {
        assert!(
            x < self.width && y < self.height,
            "pixel ({x}, {y}) outside image"
        );
        self.data[y * self.width + x]
    }

    #[inline]
    pub fn set(&mut self, x: usize, y: usize, value: [f32; 3]) {
        assert!(
            x < self.width && y < self.height,
            "pixel ({x}, {y}) outside image"
        );
        self.data[y * self.width + x] = value;
    }

    /// Pixel (x, y) as a [`Spectrum`].
    #[inline]
    pub fn spectrum(&self, x: usize, y: usize) -> Spectrum {
        to_spectrum(self.get(x, y))
    }

    /// One row of pixels.
    #[inline]
    pub fn row(&self, y: usize) -> &[[f32; 3]] {
        &self.data[y * self.width..(y + 1) * self.width]
    }

    /// Unweighted mean of all pixels, accumulated in f64.
    pub fn mean(&self) -> Spectrum {
        let mut s = Spectrum::ZERO;
        for &p in &self.data {
            s += to_spectrum(p);
        }
        s / self.data.len() as f64
    }

    /// True when every channel of every pixel is finite.
    pub fn is_finite(&self) -> bool {
        self.data.iter().all(|p| p.iter().all(|v| v.is_finite()))
    }
}

/// `[f32; 3]` → [`Spectrum`].
#[inline]
pub fn to_spectrum(p: [f32; 3]) -> Spectrum {
    Spectrum::rgb(p[0] as f64, p[1] as f64, p[2] as f64)
}

/// [`Spectrum`] → `[f32; 3]` (rounded to the nearest f32).
#[inline]
pub fn from_spectrum(s: Spectrum) -> [f32; 3] {
    [s[0] as f32, s[1] as f32, s[2] as f32]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_are_checked() {
        assert!(RgbImage::new(0, 3, vec![]).is_err());
        assert!(RgbImage::new(2, 2, vec![[0.0; 3]; 3]).is_err());
        assert!(RgbImage::new(usize::MAX, 2, vec![[0.0; 3]; 3]).is_err());
        let img = RgbImage::new(2, 1, vec![[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]]).unwrap();
        assert_eq!(img.get(1, 0), [4.0, 5.0, 6.0]);
        assert_eq!(img.spectrum(0, 0), Spectrum::rgb(1.0, 2.0, 3.0));
        assert_eq!(img.mean(), Spectrum::rgb(2.5, 3.5, 4.5));
    }

    #[test]
    fn from_fn_is_row_major_top_first() {
        let img = RgbImage::from_fn(3, 2, |x, y| [x as f32, y as f32, 0.0]).unwrap();
        assert_eq!(img.data()[4], [1.0, 1.0, 0.0]);
        assert_eq!(img.row(1)[2], [2.0, 1.0, 0.0]);
    }
}
