//! A 3-vector of lanes (structure of arrays: x, y and z each hold every lane).

use super::real::Real;
use crate::math::Vec3;
use std::ops::{Add, Neg, Sub};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LVec3<R> {
    pub x: R,
    pub y: R,
    pub z: R,
}

impl<R: Real> LVec3<R> {
    #[inline(always)]
    pub fn new(x: R, y: R, z: R) -> Self {
        LVec3 { x, y, z }
    }
    #[inline(always)]
    pub fn splat(v: Vec3) -> Self {
        LVec3::new(R::splat(v.x), R::splat(v.y), R::splat(v.z))
    }
    #[inline(always)]
    pub fn zero() -> Self {
        LVec3::new(R::zero(), R::zero(), R::zero())
    }
    /// Lane `i` as an f64 vector.
    #[inline(always)]
    pub fn lane(self, i: usize) -> Vec3 {
        Vec3::new(self.x.lane(i), self.y.lane(i), self.z.lane(i))
    }
    /// Sets lane `i` to `v` (each coordinate rounded to the lanes' precision).
    #[inline(always)]
    pub fn set_lane(&mut self, i: usize, v: Vec3) {
        self.x.set_lane(i, v.x);
        self.y.set_lane(i, v.y);
        self.z.set_lane(i, v.z);
    }
    #[inline(always)]
    pub fn from_fn(mut f: impl FnMut(usize) -> Vec3) -> Self {
        let v: [Vec3; 16] = std::array::from_fn(|i| if i < R::LANES { f(i) } else { Vec3::ZERO });
        LVec3::new(
            R::from_fn(|i| v[i].x),
            R::from_fn(|i| v[i].y),
            R::from_fn(|i| v[i].z),
        )
    }
    #[inline(always)]
    pub fn dot(self, o: Self) -> R {
        self.x * o.x + self.y * o.y + self.z * o.z
    }
    #[inline(always)]
    pub fn cross(self, o: Self) -> Self {
        LVec3::new(
            self.y * o.z - self.z * o.y,
            self.z * o.x - self.x * o.z,
            self.x * o.y - self.y * o.x,
        )
    }
    #[inline(always)]
    pub fn scale(self, s: R) -> Self {
        LVec3::new(self.x * s, self.y * s, self.z * s)
    }
    #[inline(always)]
    pub fn length_squared(self) -> R {
        self.dot(self)
    }
    /// `self / |self|` (glam's `normalize`: a zero vector gives NaN lanes).
    #[inline(always)]
    pub fn normalize(self) -> Self {
        self.scale(R::one() / self.length_squared().sqrt())
    }
    #[inline(always)]
    pub fn select(m: R::Mask, a: Self, b: Self) -> Self {
        LVec3::new(
            R::select(m, a.x, b.x),
            R::select(m, a.y, b.y),
            R::select(m, a.z, b.z),
        )
    }
    /// Lane `i` takes lane `from[i]` ([`Real::permute`]).
    #[inline(always)]
    pub fn permute(self, from: &[u8; 8]) -> Self {
        LVec3::new(
            self.x.permute(from),
            self.y.permute(from),
            self.z.permute(from),
        )
    }
}

impl<R: Real> Add for LVec3<R> {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        LVec3::new(self.x + o.x, self.y + o.y, self.z + o.z)
    }
}

impl<R: Real> Sub for LVec3<R> {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        LVec3::new(self.x - o.x, self.y - o.y, self.z - o.z)
    }
}

impl<R: Real> Neg for LVec3<R> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        LVec3::new(-self.x, -self.y, -self.z)
    }
}

impl From<Vec3> for LVec3<f64> {
    #[inline(always)]
    fn from(v: Vec3) -> Self {
        LVec3::new(v.x, v.y, v.z)
    }
}

impl From<LVec3<f64>> for Vec3 {
    #[inline(always)]
    fn from(v: LVec3<f64>) -> Self {
        Vec3::new(v.x, v.y, v.z)
    }
}
