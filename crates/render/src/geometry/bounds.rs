//! Axis-aligned bounding boxes.

use super::Vec3;

/// An axis-aligned box `[min, max]`. The empty box has `min = +∞`, `max = −∞`, so that
/// the union with any point or box is that point or box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds3 {
    pub min: Vec3,
    pub max: Vec3,
}

impl Default for Bounds3 {
    fn default() -> Self {
        Self::EMPTY
    }
}

impl Bounds3 {
    pub const EMPTY: Bounds3 = Bounds3 {
        min: Vec3::splat(f64::INFINITY),
        max: Vec3::splat(f64::NEG_INFINITY),
    };

    /// The box spanned by two corners (in any order).
    #[inline]
    pub fn new(a: Vec3, b: Vec3) -> Self {
        Bounds3 {
            min: a.min(b),
            max: a.max(b),
        }
    }

    #[inline]
    pub fn from_point(p: Vec3) -> Self {
        Bounds3 { min: p, max: p }
    }

    /// The smallest box holding all `points`.
    pub fn from_points(points: impl IntoIterator<Item = Vec3>) -> Self {
        points
            .into_iter()
            .fold(Self::EMPTY, |b, p| b.union_point(p))
    }

    #[inline]
    pub fn is_empty(&self) -> bool {
        !(self.min.x <= self.max.x && self.min.y <= self.max.y && self.min.z <= self.max.z)
    }

    #[inline]
    pub fn union(&self, o: &Bounds3) -> Bounds3 {
        Bounds3 {
            min: self.min.min(o.min),
            max: self.max.max(o.max),
        }
    }

    #[inline]
    pub fn union_point(&self, p: Vec3) -> Bounds3 {
        Bounds3 {
            min: self.min.min(p),
            max: self.max.max(p),
        }
    }

    /// `max − min`, or zero for the empty box.
    #[inline]
    pub fn extent(&self) -> Vec3 {
        if self.is_empty() {
            Vec3::ZERO
        } else {
            self.max - self.min
        }
    }

    #[inline]
    pub fn centroid(&self) -> Vec3 {
        0.5 * (self.min + self.max)
    }

    /// Surface area (zero for the empty box): the SAH weight of a box.
    #[inline]
    pub fn surface_area(&self) -> f64 {
        let d = self.extent();
        2.0 * (d.x * d.y + d.y * d.z + d.z * d.x)
    }

    /// Index of the longest axis.
    #[inline]
    pub fn max_axis(&self) -> usize {
        let d = self.extent();
        if d.x >= d.y && d.x >= d.z {
            0
        } else if d.y >= d.z {
            1
        } else {
            2
        }
    }

    /// Whether `p` is inside the box, boundary included.
    #[inline]
    pub fn contains(&self, p: Vec3) -> bool {
        p.cmpge(self.min).all() && p.cmple(self.max).all()
    }

    /// Whether `p` is inside the box grown by `tol` on every side.
    #[inline]
    pub fn contains_with_tolerance(&self, p: Vec3, tol: f64) -> bool {
        p.cmpge(self.min - Vec3::splat(tol)).all() && p.cmple(self.max + Vec3::splat(tol)).all()
    }

    /// Position of `p` relative to the box: 0 at `min`, 1 at `max` on each axis (0 on flat
    /// axes).
    #[inline]
    pub fn offset(&self, p: Vec3) -> Vec3 {
        let d = self.extent();
        let o = p - self.min;
        Vec3::new(
            if d.x > 0.0 { o.x / d.x } else { 0.0 },
            if d.y > 0.0 { o.y / d.y } else { 0.0 },
            if d.z > 0.0 { o.z / d.z } else { 0.0 },
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn empty_box_is_identity_of_union() {
        let b = Bounds3::new(Vec3::new(1.0, 2.0, 3.0), Vec3::new(-1.0, 0.0, 5.0));
        assert_eq!(Bounds3::EMPTY.union(&b), b);
        assert!(Bounds3::EMPTY.is_empty());
        assert_eq!(Bounds3::EMPTY.surface_area(), 0.0);
        assert_eq!(b.min, Vec3::new(-1.0, 0.0, 3.0));
        assert_eq!(b.surface_area(), 2.0 * (2.0 * 2.0 + 2.0 * 2.0 + 2.0 * 2.0));
        assert_eq!(b.max_axis(), 0);
        assert!(b.contains(Vec3::new(0.0, 1.0, 4.0)));
        assert!(!b.contains(Vec3::new(0.0, 1.0, 5.5)));
    }
}
