//! Affine (and projective) transforms of points, vectors and normals.
//!
//! A [`Transform`] stores a matrix and its inverse, as pbrt-v4 and Mitsuba 3 do: every
//! transform used to place a shape is inverted (rays go to object space, normals use the
//! inverse transpose), so the inverse is computed once, when the transform is built — and
//! that is where a singular or non-finite matrix is rejected, with an error instead of NaNs
//! later. Matrices are column-major (`glam`), applied to column vectors: `a * b` applies
//! `b` first, like Mitsuba's `Transform4f` product.

use super::error::{GeometryError, GeometryResult};
use super::{Mat4, Vec3};
use facette_bsdf::lanes::{LVec3, Real};
use glam::DVec4;

/// A transform with its precomputed inverse.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    m: Mat4,
    inv: Mat4,
}

impl Default for Transform {
    fn default() -> Self {
        Self::IDENTITY
    }
}

/// Largest accepted deviation of `m · m⁻¹` from the identity; beyond it the matrix is
/// treated as singular (its inverse would be dominated by rounding error).
const INVERSE_TOLERANCE: f64 = 1e-8;

impl Transform {
    pub const IDENTITY: Transform = Transform {
        m: Mat4::IDENTITY,
        inv: Mat4::IDENTITY,
    };

    /// The transform of matrix `m`; rejects non-finite entries and singular matrices.
    pub fn try_new(m: Mat4) -> GeometryResult<Transform> {
        for col in 0..4 {
            for row in 0..4 {
                let value = m.col(col)[row];
                if !value.is_finite() {
                    return Err(GeometryError::NonFiniteTransform { row, col, value });
                }
            }
        }
        let det = m.determinant();
        if det == 0.0 || !det.is_finite() {
            return Err(GeometryError::SingularTransform { det });
        }
        let inv = m.inverse();
        let residual = (m * inv - Mat4::IDENTITY)
            .to_cols_array()
            .iter()
            .fold(0.0f64, |acc, x| acc.max(x.abs()));
        if !(residual <= INVERSE_TOLERANCE) {
            return Err(GeometryError::SingularTransform { det });
        }
        Ok(Transform { m, inv })
    }

    #[inline]
    pub fn identity() -> Transform {
        Self::IDENTITY
    }

    /// Translation by `v`.
    pub fn translate(v: Vec3) -> GeometryResult<Transform> {
        check_finite("translate", v)?;
        Ok(Transform {
            m: Mat4::from_translation(v),
            inv: Mat4::from_translation(-v),
        })
    }

    /// Scale by `s` along the axes; every factor must be finite and non-zero (negative
    /// factors mirror).
    pub fn scale(s: Vec3) -> GeometryResult<Transform> {
        check_finite("scale", s)?;
        if s.x == 0.0 || s.y == 0.0 || s.z == 0.0 {
            return Err(GeometryError::InvalidTransformParameter {
                name: "scale",
                value: format!("{s}"),
                expected: "non-zero factors on every axis",
            });
        }
        Ok(Transform {
            m: Mat4::from_scale(s),
            inv: Mat4::from_scale(s.recip()),
        })
    }

    /// Rotation by `degrees` about `axis` (any non-zero length), counter-clockwise when
    /// looking down the axis towards the origin (right-handed, as Mitsuba's
    /// `Transform4f::rotate`).
    pub fn rotate(axis: Vec3, degrees: f64) -> GeometryResult<Transform> {
        check_finite("rotate axis", axis)?;
        if !degrees.is_finite() {
            return Err(GeometryError::InvalidTransformParameter {
                name: "rotate angle",
                value: format!("{degrees}"),
                expected: "a finite angle in degrees",
            });
        }
        let a = axis.normalize_or_zero();
        if a == Vec3::ZERO {
            return Err(GeometryError::InvalidTransformParameter {
                name: "rotate axis",
                value: format!("{axis}"),
                expected: "a non-zero axis",
            });
        }
        let m = Mat4::from_axis_angle(a, degrees.to_radians());
        Ok(Transform {
            m,
            inv: m.transpose(),
        })
    }

    /// Camera-to-world transform of a camera at `origin` looking at `target`, following
    /// Mitsuba 3's `Transform4f::look_at`: local +z is `dir = normalize(target − origin)`,
    /// local +x is `left = normalize(up × dir)`, local +y is `dir × left` (the up vector
    /// made orthogonal to `dir`), and the local origin maps to `origin`. Rejects
    /// `target == origin` and `up` parallel to the viewing direction.
    pub fn look_at(origin: Vec3, target: Vec3, up: Vec3) -> GeometryResult<Transform> {
        check_finite("look_at origin", origin)?;
        check_finite("look_at target", target)?;
        check_finite("look_at up", up)?;
        for (name, p) in [("look_at origin", origin), ("look_at target", target)] {
            if p.abs().max_element() > facette_bsdf::limits::MAX_COORDINATE {
                return Err(GeometryError::InvalidTransformParameter {
                    name,
                    value: format!("{p}"),
                    expected: "coordinates within ±1e30 (the scene coordinate limit)",
                });
            }
        }
        let dir = (target - origin).normalize_or_zero();
        if dir == Vec3::ZERO {
            return Err(GeometryError::InvalidTransformParameter {
                name: "look_at target",
                value: format!("{target}"),
                expected: "a point different from the camera's position",
            });
        }
        let left = up.cross(dir).normalize_or_zero();
        if left == Vec3::ZERO {
            return Err(GeometryError::InvalidTransformParameter {
                name: "look_at up",
                value: format!("{up}"),
                expected: "a non-zero vector not parallel to the viewing direction",
            });
        }
        let new_up = dir.cross(left);
        let m = Mat4::from_cols(
            left.extend(0.0),
            new_up.extend(0.0),
            dir.extend(0.0),
            origin.extend(1.0),
        );
        // Orthonormal rotation part: the inverse is its transpose, then the translation.
        let rot_t = Mat4::from_cols(
            DVec4::new(left.x, new_up.x, dir.x, 0.0),
            DVec4::new(left.y, new_up.y, dir.y, 0.0),
            DVec4::new(left.z, new_up.z, dir.z, 0.0),
            DVec4::W,
        );
        let inv = rot_t * Mat4::from_translation(-origin);
        Ok(Transform { m, inv })
    }

    /// The matrix.
    #[inline]
    pub fn matrix(&self) -> &Mat4 {
        &self.m
    }

    /// The inverse matrix.
    #[inline]
    pub fn inverse_matrix(&self) -> &Mat4 {
        &self.inv
    }

    /// The inverse transform (free: the inverse is stored).
    #[inline]
    pub fn inverse(&self) -> Transform {
        Transform {
            m: self.inv,
            inv: self.m,
        }
    }

    /// `self` followed by `next` (= `next * self`).
    #[inline]
    pub fn then(&self, next: &Transform) -> Transform {
        *next * *self
    }

    /// Applies the transform to a point; a projective matrix is divided by w.
    #[inline]
    pub fn point(&self, p: Vec3) -> Vec3 {
        apply_point(&self.m, p)
    }

    /// Applies the inverse transform to a point.
    #[inline]
    pub fn inverse_point(&self, p: Vec3) -> Vec3 {
        apply_point(&self.inv, p)
    }

    /// Applies the linear part to a vector (no translation).
    #[inline]
    pub fn vector(&self, v: Vec3) -> Vec3 {
        self.m.transform_vector3(v)
    }

    /// Applies the inverse's linear part to a vector.
    #[inline]
    pub fn inverse_vector(&self, v: Vec3) -> Vec3 {
        self.inv.transform_vector3(v)
    }

    /// [`vector`](Self::vector) over lanes, with glam's order of operations (the same bits
    /// in `f64` lanes).
    #[inline(always)]
    pub fn vector_lanes<R: Real>(&self, v: LVec3<R>) -> LVec3<R> {
        linear_lanes(&self.m, v)
    }

    /// [`point`](Self::point) over lanes, with glam's order of operations.
    #[inline(always)]
    pub fn point_lanes<R: Real>(&self, p: LVec3<R>) -> LVec3<R> {
        point_lanes_of(&self.m, p)
    }

    /// [`inverse_point`](Self::inverse_point) over lanes.
    #[inline(always)]
    pub fn inverse_point_lanes<R: Real>(&self, p: LVec3<R>) -> LVec3<R> {
        point_lanes_of(&self.inv, p)
    }

    /// [`inverse_vector`](Self::inverse_vector) over lanes.
    #[inline(always)]
    pub fn inverse_vector_lanes<R: Real>(&self, v: LVec3<R>) -> LVec3<R> {
        linear_lanes(&self.inv, v)
    }

    /// Applies the transform to a surface normal: the inverse transpose of the linear part,
    /// so that normals stay perpendicular to transformed tangents under non-uniform scale.
    /// The result is not normalized.
    #[inline]
    pub fn normal(&self, n: Vec3) -> Vec3 {
        let i = &self.inv;
        // (M⁻¹)ᵀ n: row j of the transpose is column j of M⁻¹.
        Vec3::new(
            i.x_axis.truncate().dot(n),
            i.y_axis.truncate().dot(n),
            i.z_axis.truncate().dot(n),
        )
    }

    /// Whether the bottom row is (0, 0, 0, 1): no perspective.
    pub fn is_affine(&self) -> bool {
        let r = self.m.row(3);
        r.x == 0.0 && r.y == 0.0 && r.z == 0.0 && r.w == 1.0
    }

    /// The linear part's determinant; negative for a mirroring transform.
    pub fn linear_determinant(&self) -> f64 {
        glam::DMat3::from_mat4(self.m).determinant()
    }

    /// If the transform is affine and its linear part is a rotation (or mirror) times a
    /// uniform scale — a similarity — the scale factor (positive); `None` for shear,
    /// non-uniform scale or perspective. Relative tolerance 1e-6, as Mitsuba's sphere
    /// checks its `to_world`.
    pub fn similarity_scale(&self) -> Option<f64> {
        if !self.is_affine() {
            return None;
        }
        let c = [
            self.m.x_axis.truncate(),
            self.m.y_axis.truncate(),
            self.m.z_axis.truncate(),
        ];
        let s2 = c[0].length_squared();
        let tol = 1e-6 * s2;
        let ok = (c[1].length_squared() - s2).abs() <= tol
            && (c[2].length_squared() - s2).abs() <= tol
            && c[0].dot(c[1]).abs() <= tol
            && c[0].dot(c[2]).abs() <= tol
            && c[1].dot(c[2]).abs() <= tol;
        ok.then(|| s2.sqrt())
    }
}

impl std::ops::Mul for Transform {
    type Output = Transform;
    /// Composition: `(a * b).point(p) == a.point(b.point(p))`.
    #[inline]
    fn mul(self, rhs: Transform) -> Transform {
        Transform {
            m: self.m * rhs.m,
            inv: rhs.inv * self.inv,
        }
    }
}

/// `m` applied to points in lanes, divided by w where it is not 1, with glam's order of
/// operations.
#[inline(always)]
fn point_lanes_of<R: Real>(m: &Mat4, p: LVec3<R>) -> LVec3<R> {
    // Functions, not closures or `array::from_fn`: those are compiled apart, with the
    // instruction set of this generic code rather than the AVX2 kernel's, and called
    // out of line where LLVM does not inline them (it had stopped doing so here).
    #[inline(always)]
    fn row<R: Real>(m: &Mat4, k: usize, p: LVec3<R>) -> R {
        let (x, y, z, w) = (m.x_axis[k], m.y_axis[k], m.z_axis[k], m.w_axis[k]);
        ((R::splat(x) * p.x + R::splat(y) * p.y) + R::splat(z) * p.z) + R::splat(w)
    }
    let h = [row(m, 0, p), row(m, 1, p), row(m, 2, p), row(m, 3, p)];
    let affine = h[3].eq(R::one());
    LVec3::new(
        R::select(affine, h[0], h[0] / h[3]),
        R::select(affine, h[1], h[1] / h[3]),
        R::select(affine, h[2], h[2] / h[3]),
    )
}

/// The linear part of `m` applied to lanes of vectors: x·v.x, then + y·v.y, then + z·v.z,
/// as `DMat4::transform_vector3` adds them.
#[inline(always)]
fn linear_lanes<R: Real>(m: &Mat4, v: LVec3<R>) -> LVec3<R> {
    let axis = |a: DVec4| LVec3::new(R::splat(a.x), R::splat(a.y), R::splat(a.z));
    let res = axis(m.x_axis).scale(v.x);
    let res = axis(m.y_axis).scale(v.y) + res;
    axis(m.z_axis).scale(v.z) + res
}

#[inline]
fn apply_point(m: &Mat4, p: Vec3) -> Vec3 {
    let h = *m * p.extend(1.0);
    if h.w == 1.0 {
        h.truncate()
    } else {
        h.truncate() / h.w
    }
}

fn check_finite(name: &'static str, v: Vec3) -> GeometryResult<()> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(GeometryError::InvalidTransformParameter {
            name,
            value: format!("{v}"),
            expected: "finite components",
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: Vec3, b: Vec3, tol: f64) -> bool {
        (a - b).abs().max_element() <= tol
    }

    fn max_dev_from_identity(m: Mat4) -> f64 {
        (m - Mat4::IDENTITY)
            .to_cols_array()
            .iter()
            .fold(0.0f64, |a, x| a.max(x.abs()))
    }

    fn some_transform() -> Transform {
        Transform::translate(Vec3::new(1.0, -2.0, 3.0)).unwrap()
            * Transform::rotate(Vec3::new(1.0, 1.0, 0.3), 37.0).unwrap()
            * Transform::scale(Vec3::new(2.0, 0.5, -3.0)).unwrap()
    }

    #[test]
    fn inverse_times_matrix_is_identity() {
        let t = some_transform();
        assert!(max_dev_from_identity(*t.inverse_matrix() * *t.matrix()) < 1e-14);
        assert!(max_dev_from_identity(*t.matrix() * *t.inverse_matrix()) < 1e-14);
        let la = Transform::look_at(Vec3::new(1.0, 2.0, 3.0), Vec3::new(-1.0, 0.5, 0.0), Vec3::Y)
            .unwrap();
        assert!(max_dev_from_identity(*la.inverse_matrix() * *la.matrix()) < 1e-14);
        let p = Vec3::new(0.3, -0.7, 2.0);
        assert!(close(t.inverse_point(t.point(p)), p, 1e-14));
        assert!(close(t.inverse().point(t.point(p)), p, 1e-14));
    }

    #[test]
    fn try_new_rejects_singular_and_non_finite() {
        let mut cols = Mat4::IDENTITY.to_cols_array();
        cols[5] = 0.0; // y scale 0
        let e = Transform::try_new(Mat4::from_cols_array(&cols)).unwrap_err();
        assert!(matches!(e, GeometryError::SingularTransform { .. }), "{e}");
        cols[5] = f64::NAN;
        let e = Transform::try_new(Mat4::from_cols_array(&cols)).unwrap_err();
        assert!(
            matches!(e, GeometryError::NonFiniteTransform { row: 1, col: 1, .. }),
            "{e}"
        );
        // Rank-deficient but with a tiny non-zero determinant from rounding.
        let a = Vec3::new(1.0, 2.0, 3.0);
        let b = Vec3::new(0.1, 0.7, -0.2);
        let m = Mat4::from_cols(
            a.extend(0.0),
            b.extend(0.0),
            (a * 0.3 + b * 0.7).extend(0.0),
            glam::DVec4::W,
        );
        assert!(Transform::try_new(m).is_err());
        assert!(Transform::try_new(*some_transform().matrix()).is_ok());
    }

    #[test]
    fn constructors_reject_bad_parameters() {
        assert!(Transform::scale(Vec3::new(1.0, 0.0, 1.0)).is_err());
        assert!(Transform::scale(Vec3::new(1.0, f64::INFINITY, 1.0)).is_err());
        assert!(Transform::rotate(Vec3::ZERO, 10.0).is_err());
        assert!(Transform::rotate(Vec3::X, f64::NAN).is_err());
        assert!(Transform::translate(Vec3::new(f64::NAN, 0.0, 0.0)).is_err());
        assert!(Transform::look_at(Vec3::ONE, Vec3::ONE, Vec3::Y).is_err());
        assert!(Transform::look_at(Vec3::ZERO, Vec3::Y * 2.0, Vec3::Y).is_err());
        let msg = Transform::scale(Vec3::ZERO).unwrap_err().to_string();
        assert!(msg.contains("scale") && msg.contains("non-zero"), "{msg}");
    }

    #[test]
    fn rotation_is_right_handed() {
        let r = Transform::rotate(Vec3::Z, 90.0).unwrap();
        assert!(close(r.vector(Vec3::X), Vec3::Y, 1e-15));
        let r = Transform::rotate(Vec3::X, 90.0).unwrap();
        assert!(close(r.vector(Vec3::Y), Vec3::Z, 1e-15));
    }

    #[test]
    fn look_at_follows_mitsuba() {
        let origin = Vec3::new(1.0, 2.0, 3.0);
        let target = Vec3::new(4.0, -1.0, 0.5);
        let up = Vec3::new(0.1, 1.0, 0.2);
        let t = Transform::look_at(origin, target, up).unwrap();
        let x = t.vector(Vec3::X);
        let y = t.vector(Vec3::Y);
        let z = t.vector(Vec3::Z);
        // Orthonormal, right-handed.
        for (a, b) in [(x, y), (y, z), (z, x)] {
            assert!(a.dot(b).abs() < 1e-15);
        }
        for v in [x, y, z] {
            assert!((v.length() - 1.0).abs() < 1e-15);
        }
        assert!(close(x.cross(y), z, 1e-15));
        // +z towards the target, origin at the camera, x = normalize(up × dir), y·up > 0.
        assert!(close(z, (target - origin).normalize(), 1e-15));
        assert!(close(t.point(Vec3::ZERO), origin, 1e-15));
        assert!(close(x, up.cross(z).normalize(), 1e-15));
        assert!(y.dot(up) > 0.0);
        // Standard case: camera on -z looking at the origin with +y up: left is +x... as
        // in Mitsuba, x = up × dir = Y × Z = X.
        let t = Transform::look_at(Vec3::new(0.0, 0.0, -5.0), Vec3::ZERO, Vec3::Y).unwrap();
        assert!(close(t.vector(Vec3::X), Vec3::X, 1e-15));
        assert!(close(t.vector(Vec3::Y), Vec3::Y, 1e-15));
    }

    #[test]
    fn normals_stay_perpendicular_under_nonuniform_scale() {
        let t = some_transform();
        // A plane spanned by two tangents with normal n.
        let s = Vec3::new(1.0, 0.2, -0.3);
        let u = Vec3::new(-0.4, 1.0, 0.5);
        let n = s.cross(u);
        let (ts, tu, tn) = (t.vector(s), t.vector(u), t.normal(n));
        assert!(tn.dot(ts).abs() < 1e-13 * tn.length() * ts.length());
        assert!(tn.dot(tu).abs() < 1e-13 * tn.length() * tu.length());
        // A plain vector transform would not be perpendicular.
        assert!(t.vector(n).dot(ts).abs() > 1e-3);
    }

    #[test]
    fn composition_applies_right_operand_first() {
        let a = Transform::translate(Vec3::X).unwrap();
        let b = Transform::scale(Vec3::splat(2.0)).unwrap();
        let p = Vec3::new(1.0, 1.0, 1.0);
        assert_eq!((a * b).point(p), Vec3::new(3.0, 2.0, 2.0));
        assert_eq!(b.then(&a).point(p), Vec3::new(3.0, 2.0, 2.0));
        assert_eq!((a * b).inverse().point(Vec3::new(3.0, 2.0, 2.0)), p);
    }

    #[test]
    fn similarity_scale_detects_shear_and_nonuniform_scale() {
        let sim = Transform::rotate(Vec3::new(1.0, 2.0, 3.0), 33.0).unwrap()
            * Transform::scale(Vec3::splat(-2.5)).unwrap();
        assert!((sim.similarity_scale().unwrap() - 2.5).abs() < 1e-12);
        assert!(sim.linear_determinant() < 0.0);
        assert!(some_transform().similarity_scale().is_none());
    }
}
