//! Tangent-space normal maps as slope fields  [CCM19 §3, "Slope representation"].
//!
//! A map is a grid of W×H texels, each holding the normal of the microsurface in the
//! tangent frame (x along ∂p/∂u, y along n × ∂p/∂u, z along the shading normal — Mitsuba
//! 3's `normalmap` frame). Texel (x, y) is row y counted from the top of the image, which
//! is uv's v = 0 (the renderer's texture convention); its centre is at (x + ½, y + ½) in
//! texel units. The map is stored as slopes x̃ = −n_x/n_z, ỹ = −n_y/n_z  [CCM19 §3].
//!
//! **The interpolated normal map** — the surface the glint model approximates and the
//! ground truth it is compared with — is the bilinear interpolation of the texel *slopes*
//! between texel centres, repeated periodically (the map tiles the surface). Interpolating
//! slopes rather than normals keeps the field bilinear inside each cell, which lets the
//! lobe moments of [`super::microsurface`] be computed in closed form.
//!
//! This crate does not read image files (it does not depend on the renderer): callers
//! decode the image and hand its pixels to [`NormalMap::from_pixels`], which validates them.

use crate::error::{ParamError, ParamResult};
use crate::math::{Vec2, Vec3};

/// Largest width or height accepted (a 8192² map holds 64 M lobes, 1.3 GB).
pub const MAX_MAP_SIZE: usize = 8192;

/// Tolerated deviation of a decoded normal's length from 1 before normalization: covers
/// 8-bit quantization (≤ 0.7 %) and mildly filtered maps; a map scaled or encoded
/// differently (a signed map read as unsigned, a height map) falls far outside.
pub const NORMAL_LENGTH_TOLERANCE: f64 = 0.15;

/// Smallest accepted n_z (slopes up to 20): steeper texels are almost in the tangent plane
/// and usually mean swapped channels.
pub const MIN_NORMAL_Z: f64 = 0.05;

/// How pixel values encode normal components.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NormalEncoding {
    /// n = 2c − 1: the usual encoding of 8/16-bit files (c in [0, 1]).
    Unsigned,
    /// n = c: float files (EXR) holding signed components.
    Signed,
}

impl NormalEncoding {
    pub const NAMES: &'static [&'static str] = &["unsigned", "signed"];

    pub fn parse(s: &str) -> ParamResult<Self> {
        match s {
            "unsigned" => Ok(NormalEncoding::Unsigned),
            "signed" => Ok(NormalEncoding::Signed),
            other => Err(ParamError::UnknownChoice {
                what: "normal encoding".into(),
                given: other.into(),
                valid: Self::NAMES.join(", "),
            }),
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            NormalEncoding::Unsigned => "unsigned",
            NormalEncoding::Signed => "signed",
        }
    }

    #[inline]
    fn decode(self, c: f32) -> f64 {
        match self {
            NormalEncoding::Unsigned => 2.0 * c as f64 - 1.0,
            NormalEncoding::Signed => c as f64,
        }
    }

    #[inline]
    fn encode(self, n: f64) -> f32 {
        match self {
            NormalEncoding::Unsigned => (0.5 * (n + 1.0)) as f32,
            NormalEncoding::Signed => n as f32,
        }
    }
}

/// A periodic slope field.
#[derive(Clone, Debug, PartialEq)]
pub struct NormalMap {
    width: usize,
    height: usize,
    slopes: Vec<[f32; 2]>,
}

impl NormalMap {
    /// A map from its texel slopes (row-major, top row first).
    pub fn from_slopes(width: usize, height: usize, slopes: Vec<[f32; 2]>) -> ParamResult<Self> {
        check_size(width, height)?;
        if slopes.len() != width * height {
            return Err(ParamError::Invalid(format!(
                "normal map: {} slopes for {width}×{height} texels",
                slopes.len()
            )));
        }
        if let Some(k) = slopes
            .iter()
            .position(|s| !(s[0].is_finite() && s[1].is_finite()))
        {
            return Err(ParamError::Invalid(format!(
                "normal map: texel ({}, {}) has a non-finite slope",
                k % width,
                k / width
            )));
        }
        Ok(NormalMap {
            width,
            height,
            slopes,
        })
    }

    /// A map from decoded RGB pixels (x in red, y in green, z in blue; row-major, top row
    /// first). `source` names the file in error messages. Rejects grey images (a height or
    /// roughness map given by mistake), pixels that do not decode to a unit normal within
    /// [`NORMAL_LENGTH_TOLERANCE`], and normals with n_z < [`MIN_NORMAL_Z`]; the rest is
    /// normalized.
    pub fn from_pixels(
        width: usize,
        height: usize,
        pixels: &[[f32; 3]],
        encoding: NormalEncoding,
        source: &str,
    ) -> ParamResult<Self> {
        check_size(width, height).map_err(|e| ParamError::Invalid(format!("{source}: {e}")))?;
        if pixels.len() != width * height {
            return Err(ParamError::Invalid(format!(
                "{source}: {} pixels for {width}×{height}",
                pixels.len()
            )));
        }
        if pixels.iter().all(|p| p[0] == p[1] && p[1] == p[2]) {
            return Err(ParamError::Invalid(format!(
                "{source}: red, green and blue are equal in every pixel — a greyscale (height \
                 or roughness) image, not a tangent-space normal map (x in red, y in green, z \
                 in blue)"
            )));
        }
        let mut slopes = Vec::with_capacity(pixels.len());
        let mut bad = 0usize;
        let mut first_bad = None;
        for (k, p) in pixels.iter().enumerate() {
            let n = Vec3::new(
                encoding.decode(p[0]),
                encoding.decode(p[1]),
                encoding.decode(p[2]),
            );
            let len = n.length();
            let ok = len.is_finite()
                && (len - 1.0).abs() <= NORMAL_LENGTH_TOLERANCE
                && n.z / len >= MIN_NORMAL_Z;
            if !ok {
                bad += 1;
                if first_bad.is_none() {
                    first_bad = Some((k, n, len));
                }
                slopes.push([0.0, 0.0]);
                continue;
            }
            let n = n / len;
            slopes.push([(-n.x / n.z) as f32, (-n.y / n.z) as f32]);
        }
        if let Some((k, n, len)) = first_bad {
            return Err(ParamError::Invalid(format!(
                "{source}: {bad} of {} pixels do not decode to a unit normal above the surface \
                 (encoding \"{}\": |n| within 1 ± {NORMAL_LENGTH_TOLERANCE}, n_z/|n| ≥ \
                 {MIN_NORMAL_Z}); first at pixel ({}, {}): n = ({:.3}, {:.3}, {:.3}), |n| = \
                 {:.3}. Check the channels (x red, y green, z blue) and the encoding (valid: \
                 {})",
                pixels.len(),
                encoding.name(),
                k % width,
                k / width,
                n.x,
                n.y,
                n.z,
                len,
                NormalEncoding::NAMES.join(", ")
            )));
        }
        Self::from_slopes(width, height, slopes)
    }

    pub fn width(&self) -> usize {
        self.width
    }

    pub fn height(&self) -> usize {
        self.height
    }

    pub fn texels(&self) -> usize {
        self.width * self.height
    }

    /// Slope of texel (x, y), wrapped periodically.
    #[inline]
    pub fn slope(&self, x: i64, y: i64) -> [f64; 2] {
        let xi = x.rem_euclid(self.width as i64) as usize;
        let yi = y.rem_euclid(self.height as i64) as usize;
        let s = self.slopes[yi * self.width + xi];
        [s[0] as f64, s[1] as f64]
    }

    /// The raw slopes (row-major).
    pub fn slopes(&self) -> &[[f32; 2]] {
        &self.slopes
    }

    /// The normal of texel (x, y).
    pub fn normal(&self, x: i64, y: i64) -> Vec3 {
        super::lobe::normal_of_slope(self.slope(x, y))
    }

    /// The interpolated normal map's slope at the continuous texel position `p` (texel
    /// units, texel centres at half-integers), bilinear between the four nearest centres.
    #[inline]
    pub fn interpolated_slope(&self, p: Vec2) -> [f64; 2] {
        let fx = p.x - 0.5;
        let fy = p.y - 0.5;
        let x0 = fx.floor();
        let y0 = fy.floor();
        let (tx, ty) = (fx - x0, fy - y0);
        let (x0, y0) = (x0 as i64, y0 as i64);
        let s00 = self.slope(x0, y0);
        let s10 = self.slope(x0 + 1, y0);
        let s01 = self.slope(x0, y0 + 1);
        let s11 = self.slope(x0 + 1, y0 + 1);
        let mut out = [0.0; 2];
        for c in 0..2 {
            out[c] = (s00[c] * (1.0 - tx) + s10[c] * tx) * (1.0 - ty)
                + (s01[c] * (1.0 - tx) + s11[c] * tx) * ty;
        }
        out
    }

    /// The map encoded as RGB pixels (for writing a file).
    pub fn to_pixels(&self, encoding: NormalEncoding) -> Vec<[f32; 3]> {
        self.slopes
            .iter()
            .map(|s| {
                let n = super::lobe::normal_of_slope([s[0] as f64, s[1] as f64]);
                [
                    encoding.encode(n.x),
                    encoding.encode(n.y),
                    encoding.encode(n.z),
                ]
            })
            .collect()
    }

    /// Root-mean-square slope (per axis) of the texels: a quick roughness figure.
    pub fn rms_slope(&self) -> [f64; 2] {
        let n = self.slopes.len() as f64;
        let mut acc = [0.0; 2];
        for s in &self.slopes {
            acc[0] += (s[0] as f64).powi(2);
            acc[1] += (s[1] as f64).powi(2);
        }
        [(acc[0] / n).sqrt(), (acc[1] / n).sqrt()]
    }
}

fn check_size(width: usize, height: usize) -> ParamResult<()> {
    if width == 0 || height == 0 || width > MAX_MAP_SIZE || height > MAX_MAP_SIZE {
        return Err(ParamError::Invalid(format!(
            "normal map size {width}×{height} is outside 1..={MAX_MAP_SIZE} per side"
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pixels_decode_to_slopes_and_round_trip() {
        let n = Vec3::new(0.3, -0.2, 1.0).normalize();
        let px = [
            (0.5 * (n.x + 1.0)) as f32,
            (0.5 * (n.y + 1.0)) as f32,
            (0.5 * (n.z + 1.0)) as f32,
        ];
        let flat = [0.5f32, 0.5, 1.0];
        let m = NormalMap::from_pixels(2, 1, &[px, flat], NormalEncoding::Unsigned, "t").unwrap();
        let s = m.slope(0, 0);
        assert!(
            (s[0] + 0.3).abs() < 1e-5 && (s[1] - 0.2).abs() < 1e-5,
            "{s:?}"
        );
        assert_eq!(m.slope(1, 0), [0.0, 0.0]);
        assert_eq!(m.slope(-1, 5), m.slope(1, 0), "periodic");
        let back = m.to_pixels(NormalEncoding::Unsigned);
        assert!((back[0][0] - px[0]).abs() < 1e-6);
    }

    #[test]
    fn bad_maps_are_rejected_with_reasons() {
        let grey = vec![[0.4f32; 3]; 4];
        let e = NormalMap::from_pixels(2, 2, &grey, NormalEncoding::Unsigned, "h.png")
            .unwrap_err()
            .to_string();
        assert!(e.contains("greyscale"), "{e}");
        // Not normalized: (1, 1, 1) decodes to (1, 1, 1), |n| = 1.73.
        let px = vec![[1.0f32, 1.0, 1.0], [0.5, 0.5, 1.0]];
        let e = NormalMap::from_pixels(2, 1, &px, NormalEncoding::Unsigned, "n.png")
            .unwrap_err()
            .to_string();
        assert!(e.contains("1 of 2 pixels") && e.contains("(0, 0)"), "{e}");
        // Swapped channels: z in red.
        let px = vec![[1.0f32, 0.5, 0.5], [0.5, 0.5, 1.0]];
        let e = NormalMap::from_pixels(2, 1, &px, NormalEncoding::Unsigned, "s.png")
            .unwrap_err()
            .to_string();
        assert!(e.contains("Check the channels"), "{e}");
        assert!(NormalMap::from_slopes(0, 3, vec![]).is_err());
        assert!(NormalMap::from_slopes(1, 1, vec![[f32::NAN, 0.0]]).is_err());
    }

    #[test]
    fn interpolation_is_bilinear_between_texel_centres() {
        let m = NormalMap::from_slopes(2, 2, vec![[0.0, 0.0], [1.0, 0.0], [0.0, 2.0], [1.0, 2.0]])
            .unwrap();
        assert_eq!(m.interpolated_slope(Vec2::new(0.5, 0.5)), [0.0, 0.0]);
        let s = m.interpolated_slope(Vec2::new(1.0, 1.0));
        assert!((s[0] - 0.5).abs() < 1e-12 && (s[1] - 1.0).abs() < 1e-12);
        // Periodic: halfway between texel 1 and texel 0 of the next tile.
        let s = m.interpolated_slope(Vec2::new(2.0, 0.5));
        assert!((s[0] - 0.5).abs() < 1e-12);
    }
}
