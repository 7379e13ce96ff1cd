//! Axis-aligned bounding boxes in the SIMD-friendly `Vec3A` form used by the builders.

use glam::Vec3A;

/// An axis-aligned box. The empty box has `min = +inf`, `max = -inf`, so that growing it by any
/// point gives that point and its surface area is reported as zero.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    pub min: Vec3A,
    pub max: Vec3A,
}

impl Default for Aabb {
    fn default() -> Self {
        Self::EMPTY
    }
}

impl Aabb {
    pub const EMPTY: Aabb = Aabb {
        min: Vec3A::splat(f32::INFINITY),
        max: Vec3A::splat(f32::NEG_INFINITY),
    };

    pub fn new(min: Vec3A, max: Vec3A) -> Self {
        Self { min, max }
    }

    pub fn from_points(points: &[Vec3A]) -> Self {
        let mut b = Self::EMPTY;
        for &p in points {
            b.grow_point(p);
        }
        b
    }

    #[inline]
    pub fn grow_point(&mut self, p: Vec3A) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }

    #[inline]
    pub fn grow(&mut self, other: &Aabb) {
        self.min = self.min.min(other.min);
        self.max = self.max.max(other.max);
    }

    #[inline]
    pub fn union(&self, other: &Aabb) -> Aabb {
        Aabb::new(self.min.min(other.min), self.max.max(other.max))
    }

    #[inline]
    pub fn is_empty(&self) -> bool {
        self.min.cmpgt(self.max).any()
    }

    #[inline]
    pub fn extent(&self) -> Vec3A {
        (self.max - self.min).max(Vec3A::ZERO)
    }

    #[inline]
    pub fn center(&self) -> Vec3A {
        (self.min + self.max) * 0.5
    }

    /// Half the surface area: SAH only ever compares ratios, so the factor 2 is dropped.
    #[inline]
    pub fn half_area(&self) -> f32 {
        if self.is_empty() {
            return 0.0;
        }
        let e = self.max - self.min;
        e.x * e.y + e.y * e.z + e.z * e.x
    }

    pub fn contains(&self, other: &Aabb) -> bool {
        self.min.cmple(other.min).all() && self.max.cmpge(other.max).all()
    }

    /// The box of this box's 8 corners after an affine transform (row-major 3x4).
    pub fn transformed(&self, m: &glam::Affine3A) -> Aabb {
        if self.is_empty() {
            return Aabb::EMPTY;
        }
        // Arvo's method: each output axis is the translation plus, per input axis, the min or
        // max of the two products, which bounds all corners without enumerating them.
        let mut lo = m.translation;
        let mut hi = m.translation;
        let cols = [m.matrix3.x_axis, m.matrix3.y_axis, m.matrix3.z_axis];
        for (i, col) in cols.iter().enumerate() {
            let a = *col * self.min[i];
            let b = *col * self.max[i];
            lo += a.min(b);
            hi += a.max(b);
        }
        Aabb::new(lo, hi)
    }

    pub fn is_finite(&self) -> bool {
        self.min.is_finite() && self.max.is_finite()
    }
}
