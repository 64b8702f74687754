//! One albedo-table entry by adaptive quadrature over the microfacet normals, to a
//! tolerance and with an error estimate (issue 18; the tables are described in
//! [`super::albedo_tables`]).
//!
//! **The integral.** For light from o (cos θ_o = μ), the single-scattering lobe returns
//!
//!   E(μ) = (1/μ) ∫ D(m) ⟨o·m⟩ W(m) dω_m,   W = F G(o, r, m) + (1 − F) G(o, t, m),
//!
//! r = reflect(o, m) (counted while above the horizon), t = refract(o, m) (counted while
//! below it, and while it exists), F the dielectric Fresnel factor at o·m (F = 1 for the
//! conductor table). This is ∫ f cos θ_i dω_i with dω_i = 4 (o·m) dω_m for reflection and
//! the refraction Jacobian of WMLT07 eqs. 16–17 for transmission; the visible-normal
//! estimator weight G/G1(o) of WMLT07 eq. 41 integrated against D_o(m) is the same
//! integral.
//!
//! **Coordinates.** m = (sin θ cos φ, sin θ sin φ, cos θ), and θ is replaced by x with
//! tan θ = α tan x, x ∈ [0, π/2]. With u the cumulative of the distribution's own normal
//! sampler (D(m) cos θ dω = du dφ/2π) — u = sin²x for GGX, 1 − exp(−tan²x) for Beckmann —
//!
//!   E(μ) = (1/(π μ)) ∫₀^π ∫₀^{π/2} (μ + sin θ_o cos φ tan θ) W(m) (du/dx) dx dφ
//!
//! (o in the xz-plane: the integrand is even in φ). The peak of D (width α) and GGX's
//! heavy tail both become smooth and O(1) in x (for GGX the integrand is
//! 2 (μ sin x cos x + sin θ_o cos φ α sin²x) W), so no row of α needs break points of its
//! own; u itself as the variable left a (1 − u)^{-1/2} near-singularity at the tail that
//! cost 10× in error at α ≈ 0.01.
//!
//! **Kinks, located in closed form.** Along a line of constant φ, with
//! R = √(sin²θ_o cos²φ + μ²) and ψ = atan2(sin θ_o cos φ, μ):
//! - o·m = R cos(θ − ψ): the facet turns away from o at θ = ψ + π/2 (the end of the line);
//!   total internal reflection (η < 1) holds where o·m < √(1 − η²): breaks at
//!   θ = ψ ± acos(√(1 − η²)/R);
//! - r_z = 2 (o·m) m_z − μ = R cos(2θ − ψ): r crosses the horizon at θ = ψ/2 + π/4, where
//!   the reflected term ends with a kink; its masking falls from 1 to 0 within r_z ≲ α
//!   (Smith Λ grows like α/cot θ_r), so breaks also at r_z = α/2 and 2α, and at r_z = μ;
//! - where the refracted direction crosses the horizon (η < 1) and where the V-cavity or
//!   Kelemen masking changes branch: sign changes of those quantities on a 24-point scan
//!   of the line, bisected to machine precision (cheap: no D, no Λ).
//!
//! Each piece between breaks gets the graded Gauss–Kronrod rule of
//! [`integrate_2d_graded`] (the integrand behaves like a square root at total internal
//! reflection). The outer integral over φ is cut (`outer_cuts`) at φ = π/2, where the
//! lines change from tilting towards o to tilting away; where ψ = ±45° (at grazing
//! incidence ψ turns from −90° to 90° within a few μ of φ = 90°); where the line's end
//! comes within a few α of the normal (there the peak of D is cut off); where the TIR
//! band appears and where its edge leaves the line; and, when kinks are scanned, where
//! a line's count of them changes (a kink curve turning back in φ), located by bisection
//! over 48 lines. The error estimate is the embedded |K15 − G7| with
//! the bisection floor ([`ErrorEstimate::Embedded`]): all kinks are break points.

use super::albedo_tables::TableFresnel;
use crate::fresnel::fresnel_dielectric;
use crate::math::adaptive_quadrature::{integrate_2d_graded, ErrorEstimate, QuadResult, Tolerance};
use crate::math::special::beta;
use crate::math::{reflect, refract, Vec3, PI};
use crate::microfacet::{Distribution, Masking, Ndf};

/// Points of the scan that finds the kinks not located in closed form.
const SCAN: usize = 24;
/// Bisection steps refining a kink found by the scan: to 2⁻⁴⁰ of a scan interval.
const BISECTIONS: usize = 40;

/// The substitution of the polar angle: tan θ = α tan x, x ∈ [0, π/2], and the density
/// du/dx of the distribution's normal sampler in x (D(m) cos θ dω = du dφ/2π).
#[derive(Clone, Copy, Debug)]
enum SlopeMap {
    /// u = sin²x: du/dx = sin 2x.
    Ggx { alpha: f64 },
    /// u = 1 − exp(−tan²x): du/dx = 2 tan x (1 + tan²x) exp(−tan²x).
    Beckmann { alpha: f64 },
}

impl SlopeMap {
    fn of(ndf: &Ndf) -> Option<SlopeMap> {
        match ndf {
            Ndf::Ggx(g) => Some(SlopeMap::Ggx {
                alpha: (g.alpha_x() * g.alpha_y()).sqrt(),
            }),
            Ndf::Beckmann(b) => Some(SlopeMap::Beckmann {
                alpha: (b.alpha_x() * b.alpha_y()).sqrt(),
            }),
            _ => None,
        }
    }

    /// (tan θ, du/dx) at x ∈ [0, π/2).
    #[inline]
    fn at(self, x: f64) -> (f64, f64) {
        match self {
            SlopeMap::Ggx { alpha } => {
                let (sx, cx) = x.sin_cos();
                (alpha * sx / cx, 2.0 * sx * cx)
            }
            SlopeMap::Beckmann { alpha } => {
                let t = x.tan();
                let t2 = t * t;
                (alpha * t, 2.0 * t * (1.0 + t2) * (-t2).exp())
            }
        }
    }

    /// x at θ ∈ [0, π/2].
    #[inline]
    fn x(self, theta: f64) -> f64 {
        let (SlopeMap::Ggx { alpha } | SlopeMap::Beckmann { alpha }) = self;
        if theta >= 0.5 * PI {
            0.5 * PI
        } else {
            (theta.tan() / alpha).atan()
        }
    }
}

/// W(m) of the module notes for one view o: the estimator weight of
/// `albedo_tables::estimator_weight` with Λ(o) computed once (the Smith forms; the V-cavity and Kelemen
/// masking are cheap and use [`Masking::g`]).
struct EntryWeight<'a> {
    ndf: &'a Ndf,
    masking: Masking,
    fresnel: TableFresnel,
    o: Vec3,
    lambda_o: f64,
}

impl<'a> EntryWeight<'a> {
    fn new(ndf: &'a Ndf, masking: Masking, fresnel: TableFresnel, o: Vec3) -> Self {
        EntryWeight {
            ndf,
            masking,
            fresnel,
            o,
            lambda_o: ndf.lambda(o),
        }
    }

    /// G(o, v, m) for v on the side given by `reflection` (o·m > 0 and o above: the
    /// caller's checks), as [`Masking::g`] computes it.
    #[inline]
    fn g(&self, v: Vec3, m: Vec3, reflection: bool) -> f64 {
        if v.dot(m) * v.z <= 0.0 {
            return 0.0;
        }
        match self.masking {
            Masking::SmithSeparable => self.ndf.g1(v, m) / (1.0 + self.lambda_o),
            Masking::SmithCorrelated => {
                let lv = self.ndf.lambda(v);
                if reflection {
                    1.0 / (1.0 + lv + self.lambda_o)
                } else if lv.is_finite() && self.lambda_o.is_finite() {
                    beta(1.0 + lv, 1.0 + self.lambda_o)
                } else {
                    0.0
                }
            }
            Masking::VCavity | Masking::Kelemen => self.masking.g(self.ndf, v, self.o, m),
        }
    }

    /// F G(o, r, m) + (1 − F) G(o, t, m) (r counted above the horizon, t below it).
    #[inline]
    fn at(&self, m: Vec3) -> f64 {
        let o = self.o;
        let c = o.dot(m);
        if !(c > 0.0) {
            return 0.0;
        }
        let r = reflect(o, m);
        let gr = if r.z > 0.0 { self.g(r, m, true) } else { 0.0 };
        match self.fresnel {
            TableFresnel::One => gr,
            TableFresnel::Dielectric(eta) => {
                let f = fresnel_dielectric(c, eta);
                let gt = match refract(o, m, 1.0 / eta) {
                    Some(t) if t.z < 0.0 => self.g(t, m, false),
                    _ => 0.0,
                };
                f * gr + (1.0 - f) * gt
            }
        }
    }
}

/// The normal at polar angle θ (given by tan θ) and azimuth (cos φ, sin φ).
#[inline]
fn normal(tan: f64, cos_phi: f64, sin_phi: f64) -> Vec3 {
    let c = 1.0 / (1.0 + tan * tan).sqrt();
    let s = tan * c;
    Vec3::new(s * cos_phi, s * sin_phi, c)
}

/// The quantities whose sign changes are kinks of W that have no closed form at m: the
/// refracted direction's height (η < 1) and the branch switches of the V-cavity masking
/// (r_z = o_z, 2 m_z r_z = o·m, 2 m_z o_z = o·m) or of Kelemen's (2 r_z o_z = 1 + r·o).
#[inline]
fn scanned(masking: Masking, fresnel: TableFresnel, o: Vec3, m: Vec3, out: &mut [f64; 4]) {
    let om = o.dot(m);
    let r = reflect(o, m);
    *out = [1.0; 4];
    match masking {
        Masking::VCavity => {
            out[0] = r.z - o.z;
            out[1] = 2.0 * m.z * r.z - om;
            out[2] = 2.0 * m.z * o.z - om;
        }
        Masking::Kelemen => out[0] = 2.0 * r.z * o.z - (1.0 + r.dot(o)),
        Masking::SmithSeparable | Masking::SmithCorrelated => {}
    }
    if let TableFresnel::Dielectric(eta) = fresnel {
        if eta < 1.0 {
            // Outside the refraction band the sign is that of the band's edge (t_z < 0
            // there, t being nearly tangent to m): no spurious change.
            out[3] = refract(o, m, 1.0 / eta).map_or(-1.0, |t| t.z);
        }
    }
}

/// The break points (polar angles) of the line at azimuth φ in (0, `end`), pushed unsorted
/// to `out` (when given); returns how many sign changes of each scanned quantity
/// ([`scanned`]) the line has.
fn line_breaks(
    masking: Masking,
    fresnel: TableFresnel,
    alpha: f64,
    o: Vec3,
    (cos_phi, sin_phi): (f64, f64),
    end: f64,
    mut out: Option<&mut Vec<f64>>,
) -> [u8; 4] {
    let mut counts = [0u8; 4];
    let counting_only = out.is_none();
    let (s, c) = (o.x, o.z);
    let sc = s * cos_phi;
    let big_r = sc.hypot(c);
    let psi = sc.atan2(c);
    let mut push = |t: f64| {
        if let Some(out) = out.as_deref_mut() {
            if t > 0.0 && t < end {
                out.push(t);
            }
        }
    };
    // r_z = R cos(2θ − ψ) = z: 2θ = ψ ± acos(z/R).
    for z in [0.0, 0.5 * alpha, 2.0 * alpha, c] {
        if z <= big_r {
            let a = (z / big_r).acos();
            push(0.5 * (psi + a));
            push(0.5 * (psi - a));
        }
    }
    if let TableFresnel::Dielectric(eta) = fresnel {
        if eta < 1.0 {
            let k = (1.0 - eta * eta).sqrt();
            if k <= big_r {
                let a = (k / big_r).acos();
                push(psi + a);
                push(psi - a);
            }
        }
    }
    let scan_needed = matches!(masking, Masking::VCavity | Masking::Kelemen)
        || matches!(fresnel, TableFresnel::Dielectric(eta) if eta < 1.0);
    if scan_needed {
        let at = |t: f64, v: &mut [f64; 4]| {
            scanned(masking, fresnel, o, normal(t.tan(), cos_phi, sin_phi), v)
        };
        let (mut prev, mut cur) = ([0.0; 4], [0.0; 4]);
        let x = |k: usize| end * k as f64 / SCAN as f64;
        at(x(0), &mut prev);
        for k in 1..=SCAN {
            at(x(k), &mut cur);
            for q in 0..4 {
                if (prev[q] > 0.0) != (cur[q] > 0.0) {
                    counts[q] += 1;
                    if counting_only {
                        continue;
                    }
                    let (mut lo, mut hi) = (x(k - 1), x(k));
                    let mut v = [0.0; 4];
                    for _ in 0..BISECTIONS {
                        let mid = 0.5 * (lo + hi);
                        at(mid, &mut v);
                        if (v[q] > 0.0) == (prev[q] > 0.0) {
                            lo = mid;
                        } else {
                            hi = mid;
                        }
                    }
                    push(0.5 * (lo + hi));
                }
            }
            prev = cur;
        }
    }
    counts
}

/// The cuts of the outer integral over φ ∈ [0, π] for light from cos θ_o = μ: the ends;
/// π/2; where ψ = ±45° (s |cos φ| = μ); where the TIR band appears (R = √(1 − η²)) and
/// where its upper edge leaves the line (s cos φ = √(1 − η²)); where
/// the line's end θ_e (θ* = π/4 + ψ/2 when only reflection counts, ψ + π/2 otherwise) is
/// α/2, α, 2α or 4α — at grazing incidence it is below α, so that the peak of D is cut
/// off, for |cos φ| ≲ μ/α.
fn outer_cuts(mu: f64, alpha: f64, reflection_only: bool, fresnel: TableFresnel) -> Vec<f64> {
    let s = (1.0 - mu * mu).max(0.0).sqrt();
    let mut outer = vec![0.0, 0.5 * PI, PI];
    let mut at_cos = |k: f64| {
        if s > 0.0 && k.abs() < s {
            outer.push((k / s).acos());
        }
    };
    at_cos(mu);
    at_cos(-mu);
    if let TableFresnel::Dielectric(eta) = fresnel {
        if eta < 1.0 {
            let k2 = 1.0 - eta * eta - mu * mu;
            if k2 > 0.0 {
                at_cos(k2.sqrt());
                at_cos(-k2.sqrt());
            }
            // Where the band's upper edge reaches the end of the line, θ = π/2 (the
            // horizontal facet there has o·m = s cos φ = √(1 − η²)).
            at_cos((1.0 - eta * eta).sqrt());
        }
    }
    for k in [0.5, 1.0, 2.0, 4.0] {
        let theta_e = k * alpha;
        let psi = if reflection_only {
            2.0 * theta_e - 0.5 * PI
        } else {
            theta_e - 0.5 * PI
        };
        if psi > -0.5 * PI && psi < 0.0 {
            // s cos φ / μ = tan ψ.
            at_cos(mu * psi.tan());
        }
    }
    outer.sort_by(f64::total_cmp);
    outer.dedup_by(|a, b| (*a - *b).abs() < 1e-12);
    outer
}

/// The inner cuts of one line in its integration variable x = `x_of`(θ): the line's start
/// (x = 0), the kinks `breaks` (polar angles, from [`line_breaks`]) and its end θ = `end`,
/// sorted and without repeats.
fn line_cuts(breaks: &[f64], end: f64, x_of: impl Fn(f64) -> f64) -> Vec<f64> {
    let mut cuts: Vec<f64> = breaks.iter().map(|&t| x_of(t)).collect();
    cuts.push(0.0);
    cuts.push(x_of(end));
    cuts.sort_by(f64::total_cmp);
    cuts.dedup_by(|a, b| (*a - *b).abs() <= 1e-15);
    cuts
}

/// ∫ f(h, i) dω_h over the half-vectors h whose mirror direction i = reflect(o, h) is above
/// the horizon, for o at cos θ_o = `mu` in the xz-plane and f even in h_y (an isotropic
/// lobe), by adaptive quadrature to the relative tolerance `tolerance` — the reflection
/// part of [`directional_albedo_adaptive`] for lobes given by a half-vector density of
/// width `width` (KSK01's specular albedo). The polar angle of h is substituted by
/// tan θ = w tan x, which flattens a peak of width w at the normal; the cuts are those of
/// [`directional_albedo_adaptive`] (r_z = 0, w/2, 2w, μ along each line; the same outer
/// cuts).
pub(crate) fn reflection_integral_adaptive(
    mu: f64,
    width: f64,
    tolerance: f64,
    f: impl Fn(Vec3, Vec3) -> f64,
) -> QuadResult {
    let mu = mu.clamp(1e-6, 1.0);
    let s = (1.0 - mu * mu).max(0.0).sqrt();
    let o = Vec3::new(s, 0.0, mu);
    let w = width.max(1e-12);
    let outer = outer_cuts(mu, w, true, TableFresnel::One);
    let tol = Tolerance {
        rel: tolerance,
        abs: 1e-3 * tolerance * mu,
        max_segments: 400,
        estimate: ErrorEstimate::Embedded,
    };
    let line = std::cell::Cell::new((1.0, 0.0));
    let mut breaks = Vec::with_capacity(16);
    let q = integrate_2d_graded(
        &outer,
        tol,
        |phi| {
            let (sin_phi, cos_phi) = phi.sin_cos();
            line.set((cos_phi, sin_phi));
            let end = 0.25 * PI + 0.5 * (s * cos_phi).atan2(mu);
            breaks.clear();
            line_breaks(
                Masking::SmithSeparable,
                TableFresnel::One,
                w,
                o,
                (cos_phi, sin_phi),
                end,
                Some(&mut breaks),
            );
            line_cuts(&breaks, end, |theta| (theta.tan() / w).atan())
        },
        |_, x| {
            let (cos_phi, sin_phi) = line.get();
            let (sx, cx) = x.sin_cos();
            let tan = w * sx / cx;
            let h = normal(tan, cos_phi, sin_phi);
            let i = reflect(o, h);
            if !(i.z > 0.0) {
                return 0.0;
            }
            // dω = sin θ dθ dφ, dθ/dx = w sec²x / (1 + tan²θ) = w cos²θ / cos²x.
            let dtheta = w * h.z * h.z / (cx * cx);
            let sin_theta = tan * h.z;
            f(h, i) * sin_theta * dtheta
        },
    );
    // The integrand is even in φ: twice the half-plane.
    QuadResult {
        value: 2.0 * q.value,
        error: 2.0 * q.error,
        ..q
    }
}

/// Directional albedo E(μ) of the single-scattering lobe of `ndf` (isotropic Beckmann or
/// GGX) with `masking` and `fresnel`, by adaptive quadrature over the microfacet normals
/// (see the module notes) to the relative tolerance `tolerance`: the value (not clamped,
/// so that the estimate speaks of it), its estimated absolute error and the evaluations
/// spent. Other distributions have no tables: a NaN value, not converged.
pub fn directional_albedo_adaptive(
    ndf: &Ndf,
    masking: Masking,
    fresnel: TableFresnel,
    mu: f64,
    tolerance: f64,
) -> QuadResult {
    let Some(map) = SlopeMap::of(ndf) else {
        return QuadResult {
            value: f64::NAN,
            error: f64::INFINITY,
            evaluations: 0,
            converged: false,
        };
    };
    let mu = mu.clamp(1e-6, 1.0);
    let s = (1.0 - mu * mu).max(0.0).sqrt();
    let o = Vec3::new(s, 0.0, mu);
    let alpha = ndf.typical_width();
    let reflection_only = matches!(fresnel, TableFresnel::One);
    let mut outer = outer_cuts(mu, alpha, reflection_only, fresnel);
    let end_of = |cos_phi: f64| {
        let psi = (s * cos_phi).atan2(mu);
        if reflection_only {
            0.25 * PI + 0.5 * psi
        } else {
            (psi + 0.5 * PI).min(0.5 * PI)
        }
    };
    let scan_needed = matches!(masking, Masking::VCavity | Masking::Kelemen)
        || matches!(fresnel, TableFresnel::Dielectric(eta) if eta < 1.0);
    if scan_needed {
        // Where the scanned kinks appear or vanish along the lines (a kink curve turns
        // back in φ), the inner integral has a square-root singularity in φ: those φ are
        // outer cuts, found where the lines' counts of kinks change.
        let counts = |phi: f64| {
            let (sin_phi, cos_phi) = phi.sin_cos();
            line_breaks(
                masking,
                fresnel,
                alpha,
                o,
                (cos_phi, sin_phi),
                end_of(cos_phi),
                None,
            )
        };
        const LINES: usize = 48;
        let at = |k: usize| PI * k as f64 / LINES as f64;
        let mut prev = counts(at(0));
        for k in 1..=LINES {
            let cur = counts(at(k));
            if cur != prev {
                let (mut lo, mut hi) = (at(k - 1), at(k));
                for _ in 0..30 {
                    let mid = 0.5 * (lo + hi);
                    if counts(mid) == prev {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                outer.push(0.5 * (lo + hi));
            }
            prev = cur;
        }
        outer.sort_by(f64::total_cmp);
        outer.dedup_by(|a, b| (*a - *b).abs() < 1e-12);
    }
    let scale = 1.0 / (PI * mu);
    let tol = Tolerance {
        rel: tolerance,
        // E ≥ 0 and mostly near 1; the floor (on E, hence the scale) keeps entries with
        // E → 0 finite in cost.
        abs: 1e-3 * tolerance / scale,
        max_segments: 400,
        estimate: ErrorEstimate::Embedded,
    };
    let weight = EntryWeight::new(ndf, masking, fresnel, o);
    let mut breaks = Vec::with_capacity(16);
    // (cos φ, sin φ) of the line being integrated, set with its cuts.
    let line = std::cell::Cell::new((1.0, 0.0));
    let q = integrate_2d_graded(
        &outer,
        tol,
        |phi| {
            let (sin_phi, cos_phi) = phi.sin_cos();
            line.set((cos_phi, sin_phi));
            // The line ends where the facet turns away from o, or for the conductor where
            // r leaves the upper hemisphere.
            let end = end_of(cos_phi);
            breaks.clear();
            line_breaks(
                masking,
                fresnel,
                alpha,
                o,
                (cos_phi, sin_phi),
                end,
                Some(&mut breaks),
            );
            line_cuts(&breaks, end, |theta| map.x(theta))
        },
        |_, x| {
            let (cos_phi, sin_phi) = line.get();
            let (tan, du) = map.at(x);
            let m = normal(tan, cos_phi, sin_phi);
            let w = weight.at(m);
            if w == 0.0 {
                return 0.0;
            }
            (mu + s * cos_phi * tan) * w * du
        },
    );
    QuadResult {
        value: q.value * scale,
        error: q.error * scale,
        ..q
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::rng::{Pcg32, RandomSource};
    use crate::math::spherical_direction;
    use crate::microfacet::{Beckmann, Ggx};

    #[test]
    fn the_entry_weight_is_the_estimator_weight() {
        let mut rng = Pcg32::new(9, 4);
        for ndf in [
            Ndf::Ggx(Ggx::isotropic(0.4).unwrap()),
            Ndf::Beckmann(Beckmann::isotropic(0.7).unwrap()),
        ] {
            for masking in [
                Masking::SmithSeparable,
                Masking::SmithCorrelated,
                Masking::VCavity,
            ] {
                for fresnel in [
                    TableFresnel::One,
                    TableFresnel::Dielectric(1.5),
                    TableFresnel::Dielectric(1.0 / 1.5),
                ] {
                    for _ in 0..2000 {
                        let o = spherical_direction(1.5 * rng.next_f64(), 0.0);
                        let m = spherical_direction(1.5 * rng.next_f64(), 6.3 * rng.next_f64());
                        let a = EntryWeight::new(&ndf, masking, fresnel, o).at(m);
                        let b = super::super::albedo_tables::estimator_weight(
                            &ndf, masking, fresnel, o, m,
                        )
                        .0;
                        assert!((a - b).abs() <= 1e-12 * b.abs().max(1e-300), "{a} {b}");
                    }
                }
            }
        }
    }
}
