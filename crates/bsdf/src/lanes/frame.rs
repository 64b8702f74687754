//! An orthonormal frame over lanes: the shading frame of eight hits at once, and the one
//! source of [`Frame`](crate::math::Frame)'s constructions (which instantiates it with
//! `f64`).

use super::{LVec3, Real};

/// An orthonormal frame (s, t, n) per lane.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LFrame<R> {
    pub s: LVec3<R>,
    pub t: LVec3<R>,
    pub n: LVec3<R>,
}

impl<R: Real> LFrame<R> {
    /// The frame around a unit normal, tangents by Duff et al.'s branchless construction
    /// (JCGT 6(1), 2017), the sign taken as +1 for n.z = ±0.
    #[inline(always)]
    pub fn from_normal(n: LVec3<R>) -> Self {
        let sign = n.z.sign_or_one();
        let a = -R::one() / (sign + n.z);
        let b = n.x * n.y * a;
        let s = LVec3::new(R::one() + sign * n.x * n.x * a, sign * b, -sign * n.x);
        let t = LVec3::new(b, sign + n.y * n.y * a, -n.y);
        LFrame { s, t, n }
    }

    /// The frame with normal `n` whose first tangent is `tangent` made orthogonal to it
    /// (Gram–Schmidt); [`from_normal`](Self::from_normal) where the tangent is (nearly)
    /// parallel to n.
    #[inline(always)]
    pub fn from_normal_tangent(n: LVec3<R>, tangent: LVec3<R>) -> Self {
        let d = n.dot(tangent);
        let s = tangent - n.scale(d);
        let len = s.length_squared().sqrt();
        let ok = len.gt(R::splat(1e-12));
        let s = LVec3::new(s.x / len, s.y / len, s.z / len);
        let fallback = Self::from_normal(n);
        let s = LVec3::select(ok, s, fallback.s);
        let t = LVec3::select(ok, n.cross(s), fallback.t);
        LFrame { s, t, n }
    }

    #[inline(always)]
    pub fn to_local(&self, v: LVec3<R>) -> LVec3<R> {
        LVec3::new(v.dot(self.s), v.dot(self.t), v.dot(self.n))
    }

    #[inline(always)]
    pub fn to_world(&self, v: LVec3<R>) -> LVec3<R> {
        self.s.scale(v.x) + self.t.scale(v.y) + self.n.scale(v.z)
    }
}
