//! An environment map: radiance arriving from infinitely far away, stored as a latitude-
//! longitude image, with importance sampling proportional to its luminance.
//!
//! **Mapping** — Mitsuba 3's `envmap` emitter (`src/emitters/envmap.cpp`,
//! `direction_to_uv` / `uv_to_direction`). A world direction d (pointing from the scene
//! towards the sky) is taken to the map's frame, v = to_world⁻¹ d, and
//!
//! u = atan2(v.x, −v.z) / 2π  (wrapped into [0, 1)),   v_tex = acos(v.y) / π,
//!
//! (v_tex computed as atan2(√(v.x² + v.z²), v.y) / π, the same angle without acos's loss of
//! precision near the poles),
//!
//! inversely v = (sin φ sin θ, cos θ, −cos φ sin θ) with φ = 2π u, θ = π v_tex. So +y is up
//! (the top row), −z is the centre of the left edge (u = 0), +x is a quarter across
//! (u = ¼), +z the middle (u = ½) and −x three quarters (u = ¾).
//!
//! **Texels** — pixel (x, y) of a W×H image covers u ∈ [x/W, (x+1)/W], θ ∈ [πy/H, π(y+1)/H],
//! centre at ((x+½)/W, (y+½)/H), and radiance is interpolated bilinearly between pixel
//! centres (wrapping in u, clamping at the poles). Mitsuba agrees horizontally (its
//! half-texel shift) but places its first and last rows *on* the poles (θ = πy/(H−1)); we
//! keep the pixel-centre convention of ordinary equirectangular images (pbrt's and most HDRI
//! tools'), so a map is not stretched by half a row.
//!
//! **Sampling** — exactly proportional to the luminance of what `eval` returns:
//! pdf(ω) = Y(ω) / ∫Y dω, Y the bilinear interpolation of the pixels' luminances (`eval`'s
//! own interpolation, wrap and clamp included). Then `eval / pdf` is ∫Y dω times the
//! chromaticity of the direction — the same number for every direction of a grey map — and
//! the direct lighting of a small sun keeps only the variance of the cosine and of the
//! visibility. A density constant per pixel (filtered luminance × solid angle, uniform inside
//! the pixel, as this map had before) lets radiance/pdf swing inside every pixel of a sun a
//! few pixels wide: sun lighting measured 1.7–1.8× noisier (relMSE at equal spp) than
//! Mitsuba 3's, whose `envmap` samples the bilinear interpolant.
//!
//! The construction is Mitsuba 3's (`envmap.cpp`: a 2-D warp over the bilinear interpolant)
//! with pbrt-v4's closed-form linear inversions (`SampleBilinear` / `SampleLinear` in
//! `util/sampling.h`). Y is bilinear on the *patches* between pixel centres: W columns of
//! patches, patch x spanning u ∈ [(x+½)/W, (x+1½)/W] between pixels x and x+1 (the last
//! wraps across u = 1), and H + 1 rows: a half-row v ∈ [0, ½/H] and another [1 − ½/H, 1] at
//! the poles, where the clamped radiance is constant in v, and H − 1 full rows between
//! centre rows. A patch is chosen with [`Distribution2D`] by its exact mass
//! ∫∫ Y sin(πv) du dv (dω = 2π² sin θ du dv); inside it v is drawn from its marginal —
//! linear in v, times sin(πv) — by safeguarded Newton inversion of its closed-form CDF, and
//! u from the linear conditional at that v in closed form. The one departure from Mitsuba:
//! it folds sin θ *at the pixel rows* into the interpolated weights, which leaves
//! L/pdf ∝ sin θ / lerp(sin θ_rows) varying inside each row (by (π/H)²/8 on a uniform map,
//! by ~(π/H) cot θ where luminance changes from row to row); using the exact sin(πv) costs
//! about two Newton steps per sample and makes the ratio constant,
//! with no 1/sin θ anywhere — the density is bounded and continuous over the whole sphere,
//! poles included. (In noise the two agree: on a 1° sun with sky they gave the same
//! per-sample variance to 4 digits; the gain is exactness, not variance.) `sample` returns
//! `eval` and `pdf` of the very direction it produces.
//!
//! **Lanes** — `eval`, `pdf` and `sample` are written once over the lane trait
//! ([`Real`]): the f64 methods are its one-lane instantiation, and the render kernel runs
//! it on eight f32 lanes (`eval_pdf_lanes` for rays leaving the scene, `sample_lanes` for
//! light samples). A sample's patch is drawn lane by lane from the f64 CDFs (the guided
//! search is a table look-up, and an f32 CDF would lose patches of mass below 2⁻²⁴); the
//! point inside the patch, its direction and the bilinear look-ups of its radiance and
//! density run in the lanes. The f32 Newton inversion stops at its precision's tolerances
//! (residual 1e-6 of the row's mass, step 1e-5, bracket 1e-6; f64 keeps 1e-14, 1e-10 and
//! 1e-15). Against the f64 `pdf` of the directions they draw, the f32 lanes' densities and
//! radiance are within 5.1e-4 relative on the default 1° sun (steep edges, where an f32
//! direction moves the bilinear look-up by 1e-4 pixel), and their draws pass the
//! chi-square test against the f64 density, on the sphere and zoomed on the sun (tested).
//! A map of more than 2²⁴ pixels (an f32 lane indexes a texel exactly only up to that), or
//! whose largest value, radiance or density scale lies outside [1e-15, 1e15] (where f32
//! squares and products would leave the normal range), is sampled lane by lane in f64
//! ([`EnvironmentMap::serves_lanes`]).
//!
//! Negative and non-finite pixel values are stored as 0 (radiance is non-negative).

use std::f64::consts::{FRAC_1_PI, PI};

use facette_bsdf::lanes::{CellTable, LVec3, Mask, Real};
use facette_bsdf::{ParamError, ParamResult, Spectrum};
use glam::{DMat3, DVec2, DVec3};

use super::distribution_2d::Distribution2D;
use super::rgb_image::{to_spectrum, RgbImage};
use facette_bsdf::math::sin_cos::sin_cos;

const TWO_PI: f64 = 2.0 * PI;
const INV_TWO_PI: f64 = 0.5 * FRAC_1_PI;

/// A direction drawn from an environment, its radiance and its density.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EnvSample {
    /// Unit world direction from the scene towards the environment.
    pub direction: DVec3,
    /// `eval(direction)`.
    pub radiance: Spectrum,
    /// `pdf(direction)`, per unit solid angle.
    pub pdf: f64,
}

/// [`EnvSample`]s in lanes: the lanes `drawn`, their directions, radiance and densities
/// (the other lanes hold what they may).
#[derive(Clone, Copy, Debug)]
pub struct EnvSampleLanes<R: Real> {
    pub drawn: R::Mask,
    pub direction: LVec3<R>,
    pub radiance: [R; 3],
    pub pdf: R,
}

/// The most lanes [`EnvironmentMap::sample_lanes`] draws at once, and the per-lane numbers
/// it gathers from the patches before the lane arithmetic.
const MAX_LANES: usize = 16;
const PATCH_FIELDS: usize = 12;

/// Checks that `to_world` is a rotation (or a rotation with a mirror): the map's frame
/// must stay orthonormal for directions and solid angles to carry over.
pub(crate) fn check_rotation(to_world: DMat3) -> ParamResult<()> {
    let gram = to_world.transpose() * to_world;
    let err = (gram - DMat3::IDENTITY)
        .to_cols_array()
        .iter()
        .fold(0.0f64, |m, v| m.max(v.abs()));
    if !(err < 1e-6) {
        return Err(ParamError::Invalid(format!(
            "`to_world` of an environment must be a rotation (orthonormal); its columns \
             deviate from orthonormal by {err:.3e}"
        )));
    }
    Ok(())
}

pub(crate) fn check_scale(scale: f64) -> ParamResult<()> {
    if !(scale >= 0.0) || !scale.is_finite() {
        return Err(ParamError::OutOfRange {
            name: "scale".into(),
            value: scale,
            expected: "a finite number ≥ 0".into(),
        });
    }
    Ok(())
}

/// Mitsuba 3's `direction_to_uv` for a local unit direction, u wrapped into [0, 1).
#[inline]
pub fn direction_to_uv(v: DVec3) -> DVec2 {
    let (u, w) = direction_to_uv_lanes(LVec3::<f64>::from(v));
    DVec2::new(u, w)
}

/// [`direction_to_uv`] in lanes: u = atan2(x, −z)/2π wrapped into [0, 1), v = θ/π with
/// θ = atan2(√(x² + z²), y) (Mitsuba's acos(y), see the module's notes).
#[inline(always)]
pub fn direction_to_uv_lanes<R: Real>(v: LVec3<R>) -> (R, R) {
    let mut u = v.x.atan2(-v.z) * R::splat(INV_TWO_PI);
    u = R::select(u.lt(R::zero()), u + R::one(), u);
    // After the line above: −tiny + 1 rounds to 1.
    u = R::select(u.ge(R::one()), u - R::one(), u);
    let across = (v.x * v.x + v.z * v.z).sqrt();
    (u, across.atan2(v.y) * R::splat(FRAC_1_PI))
}

/// Mitsuba 3's `uv_to_direction`: the local unit direction of texture coordinates `uv`.
#[inline]
pub fn uv_to_direction(uv: DVec2) -> DVec3 {
    uv_to_direction_lanes(uv.x, uv.y).into()
}

/// [`uv_to_direction`] in lanes.
#[inline(always)]
fn uv_to_direction_lanes<R: Real>(u: R, v: R) -> LVec3<R> {
    let (sin_theta, cos_theta) = (R::splat(PI) * v).sin_cos();
    let (sin_phi, cos_phi) = (R::splat(TWO_PI) * u).sin_cos();
    LVec3::new(sin_phi * sin_theta, cos_theta, -cos_phi * sin_theta)
}

/// The largest lane value below 1: 1 − 2⁻⁵³ in f64, 1 − 2⁻²⁴ in f32.
#[inline(always)]
fn one_minus_eps<R: Real>() -> R {
    R::splat(1.0 - 0.5f64.powi(R::DIGITS as i32))
}

/// Draws x ∈ [0, 1) with density ∝ (1 − x) a + x b (a, b ≥ 0, not both 0) by the closed-form
/// inverse of its CDF, x = ξ(a + b) / (a + √((1 − ξ) a² + ξ b²)): no cancellation when
/// a ≈ b, and a = 0 or b = 0 need no special case (only ξ = 0 with a = 0, which is 0).
#[inline(always)]
fn sample_linear<R: Real>(xi: R, a: R, b: R) -> R {
    let den = a + ((R::one() - xi) * a * a + xi * b * b).sqrt();
    let x = (xi * (a + b) / den).max(R::zero()).min(one_minus_eps());
    R::select(den.gt(R::zero()), x, R::zero())
}

/// ∫ τ sin(cτ) dτ over τ ∈ [−½, ½], by its Taylor series
/// Σₖ (−1)ᵏ c^(2k+1) / ((2k+1)! (2k+3) 4^(k+1)) — the closed form cancels catastrophically
/// for small c. For c ≤ π/2 (every patch: c = π Δv ≤ π/2) nine terms reach 1e-17 relative;
/// the coefficients are the series' own, in Horner form.
#[inline(always)]
fn odd_sin_moment<R: Real>(c: R) -> R {
    const A: [f64; 9] = [
        0.083_333_333_333_333_33,
        -0.002_083_333_333_333_333_3,
        1.860_119_047_619_047_8e-5,
        -8.611_662_257_495_591e-8,
        2.446_494_959_515_792_7e-10,
        -4.704_797_999_068_832e-13,
        6.534_441_665_373_378e-16,
        -6.863_909_312_366_994e-19,
        5.644_662_263_459_699e-22,
    ];
    let c2 = c * c;
    let mut p = R::splat(A[8]);
    for &a in A[..8].iter().rev() {
        p = p * c2 + R::splat(a);
    }
    c * p
}

/// sin h and cos h for h ∈ [0, π/4] (half a patch row's angle, c t₁/2): for h ≤ 1/32 (rows
/// of maps 64 or more pixels high) by their Taylor series to h⁷ and h⁸, whose remainders,
/// below h⁹/9! and h¹⁰/10!, are under 3e-18 relative — a few multiplications where
/// `sin_cos` reduces the argument and runs two polynomials (the row inversion's Newton
/// steps call this once each, the largest cost of the environment map's sampler).
#[inline(always)]
fn small_sin_cos<R: Real>(h: R) -> (R, R) {
    let z = h * h;
    let s = h + h
        * z
        * (R::splat(-1.0 / 6.0) + z * (R::splat(1.0 / 120.0) - z * R::splat(1.0 / 5040.0)));
    let c = (R::one() - R::splat(0.5) * z)
        + z * z
            * (R::splat(1.0 / 24.0) + z * (R::splat(-1.0 / 720.0) + z * R::splat(1.0 / 40320.0)));
    let wide = !h.le(R::splat(1.0 / 32.0));
    if wide.any() {
        let (sw, cw) = h.sin_cos();
        return (R::select(wide, sw, s), R::select(wide, cw, c));
    }
    (s, c)
}

/// A patch row's density in t ∈ [0, 1]: ((1 − t) top + t bottom) sin(a + c t)
/// (a, a + c ∈ [0, π]), with its closed-form CDF; a row per lane.
#[derive(Clone, Copy, Debug)]
struct PatchRow<R> {
    angles: RowAngles<R>,
    c: R,
    top: R,
    bottom: R,
}

/// What a patch row's points share, kept by the map per row: sin a and cos a, so that a
/// point costs one `sin_cos` (of h, see [`PatchRow::at`]) instead of two, and the row's end
/// (t₁ = 1, which every draw reads) none: sin and cos of c/2 and ∫ τ sin(cτ) dτ.
#[derive(Clone, Copy, Debug)]
struct RowAngles<R> {
    sin_a: R,
    cos_a: R,
    sin_half_c: R,
    cos_half_c: R,
    odd_c: R,
}

impl RowAngles<f64> {
    fn new(a: f64, c: f64) -> RowAngles<f64> {
        let (sin_a, cos_a) = sin_cos(a);
        // As `PatchRow::at(1)` computes them, so that the kept end is that point to the bit.
        let (sin_half_c, cos_half_c) = small_sin_cos(0.5 * c);
        RowAngles {
            sin_a,
            cos_a,
            sin_half_c,
            cos_half_c,
            odd_c: odd_sin_moment(c),
        }
    }
}

/// What [`PatchRow::at`] gives: the CDF at t₁, the density at t₁, and sin a (the density's
/// sine at t = 0).
struct RowPoint<R> {
    cdf: R,
    density: R,
    sin_start: R,
}

impl PatchRow<f64> {
    /// The row from a = π v₀ and c = π Δv (the map makes its rows from the angles it keeps).
    #[cfg(test)]
    fn new(a: f64, c: f64, top: f64, bottom: f64) -> PatchRow<f64> {
        PatchRow {
            angles: RowAngles::new(a, c),
            c,
            top,
            bottom,
        }
    }
}

impl<R: Real> PatchRow<R> {
    /// The mass on [0, t₁] and the density at t₁, from the moments about the midpoint
    /// m = a + h, h = c t₁ / 2, so that neither cancels for small c:
    /// ∫₀¹ sin(a + c t₁ r) dr = sin m · sinc h and ∫₀¹ r sin(a + c t₁ r) dr = half of it +
    /// cos m · ∫ τ sin(c t₁ τ) dτ; top ∫₀^t₁ (1 − t) sin + bottom ∫₀^t₁ t sin are two
    /// non-negative terms. The `sin_cos` of h and the row's sin a, cos a give these (m's by
    /// the angle-sum formulas) and the sines at both ends, sin(m ± h).
    #[inline(always)]
    fn at(&self, t1: R) -> RowPoint<R> {
        let h = R::splat(0.5) * self.c * t1;
        let (sh, ch) = small_sin_cos(h);
        self.point(t1, h, sh, ch, odd_sin_moment(self.c * t1))
    }

    /// [`at`](Self::at)`(1)` from the row's kept angles.
    #[inline(always)]
    fn end(&self) -> RowPoint<R> {
        let g = &self.angles;
        let h = R::splat(0.5) * self.c;
        self.point(R::one(), h, g.sin_half_c, g.cos_half_c, g.odd_c)
    }

    /// [`at`](Self::at)`(t1)` given h = c t₁/2, sin h, cos h and ∫ τ sin(c t₁ τ) dτ.
    #[inline(always)]
    fn point(&self, t1: R, h: R, sh: R, ch: R, odd: R) -> RowPoint<R> {
        let (sa, ca) = (self.angles.sin_a, self.angles.cos_a);
        let (sm, cm) = (sa * ch + ca * sh, ca * ch - sa * sh);
        let sinc = R::select(h.eq(R::zero()), R::one(), sh / h);
        let p0 = sm * sinc;
        let p1 = R::splat(0.5) * p0 + cm * odd;
        let lo = (t1 * (p0 - t1 * p1)).max(R::zero());
        let hi = (t1 * t1 * p1).max(R::zero());
        let sin_end = (sm * ch + cm * sh).max(R::zero());
        RowPoint {
            cdf: self.top * lo + self.bottom * hi,
            density: ((R::one() - t1) * self.top + t1 * self.bottom) * sin_end,
            sin_start: sa.max(R::zero()),
        }
    }

    /// Draws t ∈ [0, 1) with the row's density: Newton's method on the closed-form CDF, kept
    /// inside a shrinking bracket by bisection, started from the linear density through the
    /// end values. Newton converges quadratically from there, so a step below 1e-10 leaves
    /// an error far below f64's resolution of t and ends the iteration (usually after two
    /// evaluations; one more would only confirm it). f32 lanes stop at their own
    /// resolution: a residual of 1e-6 of the row's mass, a step of 1e-5 or a bracket of 1e-6.
    /// Each lane stops on its own; the others go on.
    #[inline(always)]
    fn sample(&self, xi: R) -> R {
        let (residual, step_end, bracket_end) = if R::DIGITS > 24 {
            (1e-14, 1e-10, 1e-15)
        } else {
            (1e-6, 1e-5, 1e-6)
        };
        let end = self.end();
        let total = end.cdf;
        let has_mass = total.gt(R::zero());
        let target = xi * total;
        let (mut lo, mut hi) = (R::zero(), R::one());
        let mut t = sample_linear(xi, self.top * end.sin_start, end.density);
        let mut active = has_mass;
        for _ in 0..64 {
            let point = self.at(t);
            let f = point.cdf - target;
            // At the CDF's rounding: the bracket's end there may be a hair past the root,
            // where a Newton step would fall outside and only bisect.
            active = active & !f.abs().le(R::splat(residual) * total);
            if active.none() {
                break;
            }
            let above = f.gt(R::zero());
            hi = R::select(active & above, t, hi);
            lo = R::select(active & !above, t, lo);
            let newton = t - f / point.density;
            let inside = newton.gt(lo) & newton.lt(hi);
            let next = R::select(inside, newton, R::splat(0.5) * (lo + hi));
            let step = (next - t).abs();
            t = R::select(active, next, t);
            let converged = inside & step.le(R::splat(step_end));
            active = active & !(converged | (hi - lo).le(R::splat(bracket_end)));
            if active.none() {
                break;
            }
        }
        R::select(has_mass, t.max(R::zero()).min(one_minus_eps()), xi)
    }
}

/// The mass on t ∈ [0, t₁] of (1 − t) top + t bottom, times sin(a + c t).
#[cfg(test)]
fn patch_row_cdf(a: f64, c: f64, top: f64, bottom: f64, t1: f64) -> f64 {
    PatchRow::new(a, c, top, bottom).at(t1).cdf
}

#[derive(Clone, Debug)]
pub struct EnvironmentMap {
    image: RgbImage,
    to_world: DMat3,
    to_local: DMat3,
    scale: f64,
    /// Each pixel's red, green, blue and luminance (unscaled), the cells that `eval` and
    /// `pdf` interpolate, in both precisions for the lanes.
    texels: CellTable,
    /// Over the W × (H + 1) patches between pixel centres, weights ∫∫ Y sin(πv) du dv.
    distribution: Distribution2D,
    /// 1 / (2π² Σ weights) = 1 / ∫Y dω (unscaled); 0 for a black map.
    inv_integral: f64,
    /// The largest pixel luminance or channel (unscaled).
    brightest: f64,
    /// What the points of each patch row share ([`PatchRow`]).
    row_angles: Vec<RowAngles<f64>>,
    mean: Spectrum,
}

/// The pixel rows at the top and bottom corners of patch row `j` ∈ [0, H], and the patch
/// row's extent [v₀, v₀ + Δv].
#[inline]
fn patch_row(j: usize, h: usize) -> (usize, usize, f64, f64) {
    let hf = h as f64;
    let v0 = if j == 0 { 0.0 } else { (j as f64 - 0.5) / hf };
    let v1 = if j == h { 1.0 } else { (j as f64 + 0.5) / hf };
    (j.saturating_sub(1), j.min(h - 1), v0, v1 - v0)
}

/// `m v` in lanes, with glam's order of the product's sums (so that f64 lanes give glam's
/// `DMat3 * DVec3` to the bit).
#[inline(always)]
fn rotate_lanes<R: Real>(m: &DMat3, v: LVec3<R>) -> LVec3<R> {
    // A function, not a closure, so that it inlines into the AVX2 build's code.
    #[inline(always)]
    fn column<R: Real>(c: DVec3) -> LVec3<R> {
        LVec3::new(R::splat(c.x), R::splat(c.y), R::splat(c.z))
    }
    column::<R>(m.x_axis).scale(v.x)
        + column::<R>(m.y_axis).scale(v.y)
        + column::<R>(m.z_axis).scale(v.z)
}

/// Luminance of a stored (non-negative) pixel.
#[inline]
fn luminance(p: [f32; 3]) -> f64 {
    to_spectrum(p).luminance().max(0.0)
}

impl EnvironmentMap {
    /// An environment from a latitude-longitude image of radiance, rotated by `to_world`
    /// (a rotation) and multiplied by `scale` (≥ 0).
    pub fn new(image: RgbImage, to_world: DMat3, scale: f64) -> ParamResult<Self> {
        check_rotation(to_world)?;
        check_scale(scale)?;
        let mut image = image;
        for p in image.data_mut() {
            for c in p.iter_mut() {
                if !(c.is_finite() && *c > 0.0) {
                    *c = 0.0;
                }
            }
        }
        // The radiance bound of every light (`limits::MAX_RADIANCE`) holds for the map's
        // brightest value as it is rendered, so that no film sum can overflow.
        let brightest = image
            .data()
            .iter()
            .flatten()
            .fold(0.0f64, |m, &c| m.max(c as f64));
        if brightest * scale > facette_bsdf::limits::MAX_RADIANCE {
            return Err(ParamError::OutOfRange {
                name: "scale".into(),
                value: scale,
                expected: format!(
                    "the brightest pixel ({brightest:e}) × scale at most {:e} (larger values overflow the film's sums; scale the exposure instead)",
                    facette_bsdf::limits::MAX_RADIANCE
                ),
            });
        }
        let (w, h) = (image.width(), image.height());

        // Patch weights: Δu Δv ∫₀¹ ((1 − t) top + t bottom) sin(π (v₀ + t Δv)) dt, top and
        // bottom the means of the patch's two upper and two lower corners.
        let du = 1.0 / w as f64;
        let mut weights = vec![0.0; w * (h + 1)];
        let mut row_angles = Vec::with_capacity(h + 1);
        for j in 0..=h {
            let (ra, rb, v0, dv) = patch_row(j, h);
            let (a, c) = (PI * v0, PI * dv);
            let angles = RowAngles::new(a, c);
            row_angles.push(angles);
            let (upper, lower) = (image.row(ra), image.row(rb));
            for x in 0..w {
                let xb = if x + 1 == w { 0 } else { x + 1 };
                let top = 0.5 * (luminance(upper[x]) + luminance(upper[xb]));
                let bottom = 0.5 * (luminance(lower[x]) + luminance(lower[xb]));
                let row = PatchRow {
                    angles,
                    c,
                    top,
                    bottom,
                };
                weights[j * w + x] = du * dv * row.end().cdf;
            }
        }
        let distribution = Distribution2D::new(w, h + 1, &weights);
        let integral = 2.0 * PI * PI * distribution.total();
        let inv_integral = if integral > 0.0 && integral.is_finite() {
            1.0 / integral
        } else {
            0.0
        };

        let cos_edge = |y: usize| {
            if y == 0 {
                1.0
            } else if y == h {
                -1.0
            } else {
                (PI * y as f64 / h as f64).cos()
            }
        };
        let mut sum = Spectrum::ZERO;
        for y in 0..h {
            let omega = TWO_PI / w as f64 * (cos_edge(y) - cos_edge(y + 1));
            let mut row = Spectrum::ZERO;
            for &p in image.row(y) {
                row += to_spectrum(p);
            }
            sum += row * omega;
        }
        let mean = sum * (scale / (4.0 * PI));

        let texels = CellTable::new(
            image
                .data()
                .iter()
                .map(|&p| {
                    let c = to_spectrum(p);
                    [c.0[0], c.0[1], c.0[2], luminance(p)]
                })
                .collect(),
        );
        let brightest = texels
            .f64_cells()
            .iter()
            .flatten()
            .fold(0.0f64, |m, &v| m.max(v));
        Ok(EnvironmentMap {
            brightest,
            texels,
            image,
            to_world,
            to_local: to_world.transpose(),
            scale,
            distribution,
            inv_integral,
            row_angles,
            mean,
        })
    }

    pub fn width(&self) -> usize {
        self.image.width()
    }

    pub fn height(&self) -> usize {
        self.image.height()
    }

    pub fn to_world(&self) -> DMat3 {
        self.to_world
    }

    pub fn scale(&self) -> f64 {
        self.scale
    }

    /// The stored radiance image (unscaled, negative values zeroed).
    pub fn image(&self) -> &RgbImage {
        &self.image
    }

    /// Texture coordinates of a world direction (need not be normalized); `None` for a zero
    /// or non-finite vector.
    #[inline]
    pub fn uv(&self, d: DVec3) -> Option<DVec2> {
        let (ok, u, v) = self.uv_lanes(LVec3::<f64>::from(d));
        ok.then(|| DVec2::new(u, v))
    }

    /// [`uv`](Self::uv) in lanes, with the lanes where `d` is neither zero nor non-finite
    /// (the others hold the coordinates of the map's +y).
    #[inline(always)]
    pub fn uv_lanes<R: Real>(&self, d: LVec3<R>) -> (R::Mask, R, R) {
        // glam's product, `length` and division.
        let v = rotate_lanes(&self.to_local, d);
        let len = v.length_squared().sqrt();
        let ok = len.gt(R::zero()) & len.is_finite();
        let unit = LVec3::new(v.x / len, v.y / len, v.z / len);
        let unit = LVec3::select(ok, unit, LVec3::new(R::zero(), R::one(), R::zero()));
        let (u, w) = direction_to_uv_lanes(unit);
        (ok, u, w)
    }

    /// The world direction of texture coordinates `uv`.
    #[inline]
    pub fn direction(&self, uv: DVec2) -> DVec3 {
        self.to_world * uv_to_direction(uv)
    }

    /// Whether [`eval_pdf_lanes`](Self::eval_pdf_lanes) and
    /// [`sample_lanes`](Self::sample_lanes) serve lanes of type `R`: a cell is indexed by a
    /// lane, exact for indices up to 2^digits, and in f32 lanes the luminances, their
    /// squares (the linear inversion), the radiance and the density's scale must be normal
    /// f32 numbers — true of any map in ordinary units; the others are sampled in f64 lane
    /// by lane.
    pub fn serves_lanes<R: Real>(&self) -> bool {
        let indexed = self.texels.len() as f64 <= 2f64.powi(R::DIGITS as i32);
        let in_range = |v: f64| v == 0.0 || (1e-15..=1e15).contains(&v);
        indexed
            && (R::DIGITS > 24
                || (in_range(self.brightest)
                    && in_range(self.brightest * self.scale)
                    && in_range(self.inv_integral)))
    }

    /// Radiance (times `scale`) and density at texture coordinates (u, v) ∈ [0, 1)² in
    /// lanes: the red, green, blue and luminance of the four pixels around (u, v),
    /// interpolated bilinearly between pixel centres, wrapping in u and clamping at the
    /// poles — the one interpolation behind `eval`, `pdf` and `sample`.
    #[inline(always)]
    fn lookup_lanes<R: Real>(&self, u: R, v: R) -> ([R; 3], R) {
        let (w, h) = (self.image.width() as f64, self.image.height() as f64);
        let x = u * R::splat(w) - R::splat(0.5);
        let y = v * R::splat(h) - R::splat(0.5);
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        // x0 ∈ [−1, W − 1] and y0 ∈ [−1, H − 1] for (u, v) ∈ [0, 1)²: the left neighbour
        // of column 0 is column W − 1; the clamps keep rounding inside the table.
        let xa = R::select(x0.lt(R::zero()), x0 + R::splat(w), x0).clamp(0.0, w - 1.0);
        let next = xa + R::one();
        let xb = R::select(next.ge(R::splat(w)), R::zero(), next);
        let ya = y0.clamp(0.0, h - 1.0) * R::splat(w);
        let yb = (y0 + R::one()).clamp(0.0, h - 1.0) * R::splat(w);
        let a = R::gather4(&self.texels, ya + xa);
        let b = R::gather4(&self.texels, ya + xb);
        let c = R::gather4(&self.texels, yb + xa);
        let d = R::gather4(&self.texels, yb + xb);
        let (gx, gy) = (R::one() - fx, R::one() - fy);
        let mut out = [R::zero(); 4];
        for k in 0..4 {
            let top = a[k] * gx + b[k] * fx;
            let bottom = c[k] * gx + d[k] * fx;
            out[k] = top * gy + bottom * fy;
        }
        let scale = R::splat(self.scale);
        (
            [out[0] * scale, out[1] * scale, out[2] * scale],
            out[3] * R::splat(self.inv_integral),
        )
    }

    /// Radiance arriving along world direction `d` (bilinear, times `scale`); black for a
    /// degenerate `d`.
    pub fn eval(&self, d: DVec3) -> Spectrum {
        self.eval_pdf(d).0
    }

    /// [`eval`](Self::eval) and [`pdf`](Self::pdf) of `d` together, from one look-up of its
    /// texture coordinates (what a ray leaving the scene needs for its MIS weight).
    pub fn eval_pdf(&self, d: DVec3) -> (Spectrum, f64) {
        let (radiance, pdf) = self.eval_pdf_lanes(LVec3::<f64>::from(d));
        (Spectrum(radiance), pdf)
    }

    /// [`eval_pdf`](Self::eval_pdf) in lanes (zero where `d` is zero or not finite), for
    /// lane types the map [serves](Self::serves_lanes).
    #[inline(always)]
    pub fn eval_pdf_lanes<R: Real>(&self, d: LVec3<R>) -> ([R; 3], R) {
        let (ok, u, v) = self.uv_lanes(d);
        let (radiance, pdf) = self.lookup_lanes(u, v);
        (radiance.map(|c| R::masked(ok, c)), R::masked(ok, pdf))
    }

    /// Density (per unit solid angle) with which [`EnvironmentMap::sample`] produces `d`:
    /// Y(uv) / ∫Y dω, the sampler's density in uv, Y sin(πv) / ∫∫ Y sin(πv) du dv, over the
    /// Jacobian dω / du dv = 2π² sin θ (the sin θ cancels).
    pub fn pdf(&self, d: DVec3) -> f64 {
        self.eval_pdf(d).1
    }

    /// Draws a direction with density proportional to the luminance of `eval`. `None` when
    /// the map is black.
    pub fn sample(&self, u: DVec2) -> Option<EnvSample> {
        let s = self.sample_lanes(u.x, u.y, true);
        s.drawn.then(|| EnvSample {
            direction: s.direction.into(),
            radiance: Spectrum(s.radiance),
            pdf: s.pdf,
        })
    }

    /// [`sample`](Self::sample) in lanes, for the lanes of `set` (the lanes a map
    /// [serves](Self::serves_lanes)): the patch of each lane is drawn from the f64 CDFs lane
    /// by lane, the point inside it and its radiance and density for every lane at once.
    #[inline(always)]
    pub fn sample_lanes<R: Real>(&self, u0: R, u1: R, set: R::Mask) -> EnvSampleLanes<R> {
        let mut drawn = R::Mask::splat(false);
        let none = EnvSampleLanes {
            drawn,
            direction: LVec3::zero(),
            radiance: [R::zero(); 3],
            pdf: R::zero(),
        };
        if self.inv_integral == 0.0 {
            return none;
        }
        let (w, h) = (self.image.width(), self.image.height());
        // Per lane: the patch's column x, its corner pixel rows, v₀, Δv, the row's angles
        // and the position ξ inside the patch.
        let mut patch = [[0.0f64; PATCH_FIELDS]; MAX_LANES];
        debug_assert!(R::LANES <= MAX_LANES);
        let mut us = [DVec2::ZERO; MAX_LANES];
        let mut chosen = [false; MAX_LANES];
        for i in 0..R::LANES {
            us[i] = DVec2::new(u0.lane(i), u1.lane(i));
            chosen[i] = set.lane(i);
        }
        let cells = self.distribution.sample_batch(&us, chosen);
        for (i, lane) in patch.iter_mut().enumerate().take(R::LANES) {
            let Some((x, j, _, f)) = cells[i] else {
                continue;
            };
            let (ra, rb, v0, dv) = patch_row(j, h);
            let g = &self.row_angles[j];
            *lane = [
                x as f64,
                (ra * w) as f64,
                (rb * w) as f64,
                v0,
                dv,
                g.sin_a,
                g.cos_a,
                g.sin_half_c,
                g.cos_half_c,
                g.odd_c,
                f.x,
                f.y,
            ];
            drawn = drawn | R::Mask::from_fn(|k| k == i);
        }
        if drawn.none() {
            return none;
        }
        // Functions, not closures, so that they inline into the render kernel's AVX2 code.
        #[inline(always)]
        fn field<R: Real>(patch: &[[f64; PATCH_FIELDS]; MAX_LANES], k: usize) -> R {
            R::from_fn(|i| patch[i][k])
        }
        #[inline(always)]
        fn nudge<R: Real>(v: R) -> R {
            const NUDGE: f64 = 1e-6;
            v + R::splat(NUDGE) * (R::splat(0.5) - v)
        }
        let luminance_at = |cell: R| R::gather4(&self.texels, cell)[3];
        let x: R = field(&patch, 0);
        let (row_a, row_b): (R, R) = (field(&patch, 1), field(&patch, 2));
        let (v0, dv): (R, R) = (field(&patch, 3), field(&patch, 4));
        let next = x + R::one();
        let xb = R::select(next.eq(R::splat(w as f64)), R::zero(), next);
        let (l00, l10) = (luminance_at(row_a + x), luminance_at(row_a + xb));
        let (l01, l11) = (luminance_at(row_b + x), luminance_at(row_b + xb));
        // v from the marginal, linear in v (the means of the upper and lower corners) times
        // sin(πv); then u from the linear conditional at that v.
        let half = R::splat(0.5);
        let row = PatchRow {
            angles: RowAngles {
                sin_a: field(&patch, 5),
                cos_a: field(&patch, 6),
                sin_half_c: field(&patch, 7),
                cos_half_c: field(&patch, 8),
                odd_c: field(&patch, 9),
            },
            c: R::splat(PI) * dv,
            top: half * (l00 + l10),
            bottom: half * (l01 + l11),
        };
        let t = row.sample(field(&patch, 11));
        let left = (R::one() - t) * l00 + t * l01;
        let right = (R::one() - t) * l10 + t * l11;
        let s = sample_linear(field(&patch, 10), left, right);
        let mut out = self.place(x, v0, dv, s, t);
        // The inversion maps the (null) set where the density vanishes — ξ = 0 on a patch
        // edge with black corners — onto points of zero density; such a draw is moved a
        // hair towards the patch centre, where the density is positive (the patch has
        // mass), so a non-black map always yields a sample.
        let empty = drawn & !out.pdf.gt(R::zero());
        if empty.any() {
            let again = self.place(x, v0, dv, nudge(s), nudge(t));
            out.direction = LVec3::select(empty, again.direction, out.direction);
            for c in 0..3 {
                out.radiance[c] = R::select(empty, again.radiance[c], out.radiance[c]);
            }
            out.pdf = R::select(empty, again.pdf, out.pdf);
        }
        out.drawn = drawn & out.pdf.gt(R::zero());
        out
    }

    /// The direction at (s, t) of patch column `x` of the row [v₀, v₀ + Δv], with `eval` and
    /// `pdf` of that direction: its uv re-derived from it, so that they equal
    /// `eval(direction)` and `pdf(direction)` to the bit.
    #[inline(always)]
    fn place<R: Real>(&self, x: R, v0: R, dv: R, s: R, t: R) -> EnvSampleLanes<R> {
        let mut uu = (x + R::splat(0.5) + s) / R::splat(self.image.width() as f64);
        uu = R::select(uu.ge(R::one()), uu - R::one(), uu);
        let vv = (v0 + dv * t).min(R::one());
        let local = uv_to_direction_lanes(uu, vv);
        let direction = rotate_lanes(&self.to_world, local).normalize();
        let (radiance, pdf) = self.eval_pdf_lanes(direction);
        EnvSampleLanes {
            drawn: R::Mask::splat(true),
            direction,
            radiance,
            pdf,
        }
    }

    /// Mean radiance over the sphere, (1/4π) ∫ L dω, from the pixel values weighted by
    /// their solid angle (times `scale`).
    pub fn mean_radiance(&self) -> Spectrum {
        self.mean
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: DVec2, b: DVec2) -> bool {
        (a - b).length() < 1e-12
    }

    #[test]
    fn uv_convention_is_mitsubas() {
        assert!(close(direction_to_uv(-DVec3::Z), DVec2::new(0.0, 0.5)));
        assert!(close(direction_to_uv(DVec3::X), DVec2::new(0.25, 0.5)));
        assert!(close(direction_to_uv(DVec3::Z), DVec2::new(0.5, 0.5)));
        assert!(close(direction_to_uv(-DVec3::X), DVec2::new(0.75, 0.5)));
        assert_eq!(direction_to_uv(DVec3::Y).y, 0.0);
        assert_eq!(direction_to_uv(-DVec3::Y).y, 1.0);
        // Round trips, including the u wrap.
        for k in 0..100 {
            let uv = DVec2::new(
                (k as f64 * 0.618).fract(),
                (k as f64 * 0.377).fract() * 0.98 + 0.01,
            );
            let back = direction_to_uv(uv_to_direction(uv));
            let du = (back.x - uv.x).abs();
            assert!(
                du.min(1.0 - du) < 1e-12 && (back.y - uv.y).abs() < 1e-12,
                "{uv} {back}"
            );
        }
    }

    #[test]
    fn parameters_are_validated() {
        let img = RgbImage::filled(4, 2, [1.0; 3]).unwrap();
        assert!(
            EnvironmentMap::new(img.clone(), DMat3::from_diagonal(DVec3::splat(2.0)), 1.0).is_err()
        );
        assert!(EnvironmentMap::new(img.clone(), DMat3::IDENTITY, -1.0).is_err());
        assert!(EnvironmentMap::new(img.clone(), DMat3::IDENTITY, f64::NAN).is_err());
        assert!(EnvironmentMap::new(img, DMat3::from_rotation_y(0.3), 1.0).is_ok());
    }

    #[test]
    fn top_row_is_up_and_rotation_applies() {
        // Top half red, bottom half blue.
        let img = RgbImage::from_fn(8, 4, |_, y| {
            if y < 2 {
                [1.0, 0.0, 0.0]
            } else {
                [0.0, 0.0, 1.0]
            }
        })
        .unwrap();
        let env = EnvironmentMap::new(img.clone(), DMat3::IDENTITY, 2.0).unwrap();
        assert_eq!(env.eval(DVec3::Y), Spectrum::rgb(2.0, 0.0, 0.0));
        assert_eq!(env.eval(-DVec3::Y * 3.0), Spectrum::rgb(0.0, 0.0, 2.0));
        assert_eq!(env.eval(DVec3::ZERO), Spectrum::ZERO);
        // Rotating the map by 90° about x sends its up (+y) to world +z.
        let rot = DMat3::from_rotation_x(std::f64::consts::FRAC_PI_2);
        let env = EnvironmentMap::new(img, rot, 1.0).unwrap();
        assert_eq!(env.eval(DVec3::Z), Spectrum::rgb(1.0, 0.0, 0.0));
        assert!((env.direction(DVec2::ZERO) - DVec3::Z).length() < 1e-12);
        assert!(
            (env.mean_radiance() - Spectrum::rgb(0.5, 0.0, 0.5))
                .max_component()
                .abs()
                < 1e-12
        );
    }

    #[test]
    fn a_single_bright_pixel_is_where_the_samples_go() {
        let mut img = RgbImage::filled(16, 8, [0.0; 3]).unwrap();
        img.set(5, 2, [100.0, 100.0, 100.0]);
        let env = EnvironmentMap::new(img, DMat3::IDENTITY, 1.0).unwrap();
        let centre = uv_to_direction(DVec2::new(5.5 / 16.0, 2.5 / 8.0));
        assert!(
            (env.eval(centre) - Spectrum::splat(100.0))
                .max_component()
                .abs()
                < 1e-9
        );
        for k in 0..64 {
            let u = DVec2::new(
                (k as f64 * 0.618_034).fract(),
                (k as f64 * 0.414_214).fract(),
            );
            let s = env.sample(u).unwrap();
            assert_eq!(s.radiance, env.eval(s.direction));
            assert_eq!(s.pdf, env.pdf(s.direction));
            assert_eq!(env.eval_pdf(s.direction), (env.eval(s.direction), s.pdf));
            // Within the 3×3 neighbourhood the bilinear radiance can reach.
            let uv = env.uv(s.direction).unwrap();
            let (px, py) = ((uv.x * 16.0) as i64, (uv.y * 8.0) as i64);
            assert!((px - 5).abs() <= 1 && (py - 2).abs() <= 1, "{px} {py}");
        }
        // Black maps cannot be sampled.
        let black = EnvironmentMap::new(
            RgbImage::filled(4, 2, [0.0; 3]).unwrap(),
            DMat3::IDENTITY,
            1.0,
        )
        .unwrap();
        assert!(black.sample(DVec2::splat(0.5)).is_none());
        assert_eq!(black.pdf(DVec3::Y), 0.0);
    }

    /// ∫₀¹ f by composite Simpson with `n` (even) intervals.
    fn simpson(f: impl Fn(f64) -> f64, n: usize) -> f64 {
        let h = 1.0 / n as f64;
        let mut s = f(0.0) + f(1.0);
        for k in 1..n {
            s += f(k as f64 * h) * if k % 2 == 1 { 4.0 } else { 2.0 };
        }
        s * h / 3.0
    }

    #[test]
    fn sin_moments_match_quadrature() {
        // Pole half-rows, full rows of coarse and fine maps, and the 1-row map's c = π/2.
        for (a, c) in [
            (0.0, PI / 2.0),
            (PI / 2.0, PI / 2.0),
            (0.0, PI / 16.0),
            (PI - PI / 16.0, PI / 16.0),
            (1.0, PI / 8.0),
            (2.0, PI / 8192.0),
            (0.0, PI / 16384.0),
            (PI - PI / 16384.0, PI / 16384.0),
        ] {
            let (p0, p1) = (
                patch_row_cdf(a, c, 1.0, 1.0, 1.0),
                patch_row_cdf(a, c, 0.0, 1.0, 1.0),
            );
            let q0 = simpson(|r| (a + c * r).sin(), 2000);
            let q1 = simpson(|r| r * (a + c * r).sin(), 2000);
            // Absolute 1e-15: sin near θ = π is only known to the rounding of π (1.2e-16).
            assert!(
                (p0 - q0).abs() <= 1e-13 * q0 + 1e-15,
                "{a} {c}: {p0} vs {q0}"
            );
            assert!(
                (p1 - q1).abs() <= 1e-13 * q1 + 1e-15,
                "{a} {c}: {p1} vs {q1}"
            );
            // The (1 − r) moment stays accurate too (no cancellation at the poles).
            let r0 = simpson(|r| (1.0 - r) * (a + c * r).sin(), 2000);
            let m0 = patch_row_cdf(a, c, 1.0, 0.0, 1.0);
            assert!(
                (m0 - r0).abs() <= 1e-13 * r0 + 1e-15,
                "{a} {c}: {m0} vs {r0}"
            );
        }
    }

    /// f32 lanes serve maps whose luminances, their squares and the density's scale are
    /// normal f32 numbers; the others (and every map, in f64 lanes) are served in f64.
    #[test]
    fn f32_lanes_serve_maps_in_ordinary_units() {
        use facette_bsdf::lanes::F32x8;
        let map = |v: f32, scale: f64| {
            let img = RgbImage::from_fn(8, 4, |x, _| [v * (x + 1) as f32; 3]).unwrap();
            EnvironmentMap::new(img, DMat3::IDENTITY, scale).unwrap()
        };
        assert!(map(1.0, 1.0).serves_lanes::<F32x8>());
        assert!(map(1e-3, 1e3).serves_lanes::<F32x8>());
        assert!(!map(1e20, 1e-6).serves_lanes::<F32x8>());
        assert!(!map(1e-20, 1.0).serves_lanes::<F32x8>());
        assert!(map(1e20, 1e-6).serves_lanes::<f64>() && map(1e-20, 1.0).serves_lanes::<f64>());
    }

    #[test]
    fn small_sin_cos_is_libms_within_rounding() {
        let n = 100_000;
        for k in 0..=n {
            // Up to the switch to `sin_cos` (1/32) and beyond it.
            let h = 0.04 * k as f64 / n as f64;
            let (s, c) = small_sin_cos(h);
            let (es, ec) = h.sin_cos();
            assert!(
                (s - es).abs() <= 2.5e-16 * es.max(1e-300),
                "sin {h}: {s} {es}"
            );
            assert!((c - ec).abs() <= 1.2e-16, "cos {h}: {c} {ec}");
        }
    }

    #[test]
    fn row_inversion_hits_its_cdf() {
        for (a, c) in [
            (0.0, PI / 2.0),
            (PI / 2.0, PI / 2.0),
            (0.0, 1e-3),
            (1.0, PI / 256.0),
            (3.0, 0.1),
        ] {
            for (top, bottom) in [(1.0, 1.0), (0.0, 1.0), (1.0, 0.0), (1e-9, 5.0), (3.0, 2.0)] {
                let total = patch_row_cdf(a, c, top, bottom, 1.0);
                for k in 0..=64 {
                    let xi = (k as f64 / 64.0).min(one_minus_eps::<f64>());
                    let row = PatchRow::new(a, c, top, bottom);
                    // The kept end is the computed one, to the bit.
                    let (end, at_one) = (row.end(), row.at(1.0));
                    assert_eq!(
                        (end.cdf, end.density, end.sin_start),
                        (at_one.cdf, at_one.density, at_one.sin_start)
                    );
                    let t = row.sample(xi);
                    assert!((0.0..1.0).contains(&t));
                    let f = patch_row_cdf(a, c, top, bottom, t) / total;
                    assert!((f - xi).abs() < 1e-13, "{a} {c} {top} {bottom} {xi}: {f}");
                    // The density beside the CDF, and the sine at the start.
                    let p = row.at(t);
                    let d = ((1.0 - t) * top + t * bottom) * (a + c * t).sin().max(0.0);
                    assert!(
                        (p.density - d).abs() <= 1e-14 * (1.0 + d),
                        "{t}: {}",
                        p.density
                    );
                    assert!((p.sin_start - a.sin().max(0.0)).abs() <= 1e-15);
                }
            }
        }
        // The linear inversion, including a = 0, b = 0 and a = b.
        for (a, b) in [
            (0.0, 1.0),
            (1.0, 0.0),
            (2.0, 2.0),
            (1.0, 1.0 + 1e-12),
            (0.0, 0.0),
        ] {
            for k in 0..=16 {
                let xi = (k as f64 / 16.0).min(one_minus_eps::<f64>());
                let x = sample_linear(xi, a, b);
                assert!((0.0..1.0).contains(&x));
                if a + b > 0.0 {
                    let cdf = (a * x + 0.5 * (b - a) * x * x) / (0.5 * (a + b));
                    assert!((cdf - xi).abs() < 1e-14, "{a} {b} {xi}: {cdf}");
                }
            }
        }
    }

    #[test]
    fn non_finite_and_negative_pixels_are_zero() {
        let img = RgbImage::new(2, 1, vec![[f32::NAN, -1.0, f32::INFINITY], [1.0; 3]]).unwrap();
        let env = EnvironmentMap::new(img, DMat3::IDENTITY, 1.0).unwrap();
        assert_eq!(env.image().get(0, 0), [0.0; 3]);
        for k in 0..50 {
            let d = uv_to_direction(DVec2::new(k as f64 / 50.0, 0.3));
            assert!(env.eval(d).is_finite() && env.pdf(d).is_finite());
        }
    }
}
