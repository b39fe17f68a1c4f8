//! Vectors of lanes in structure-of-arrays form: `x`, `y` and `z` each hold one
//! coordinate of every lane's point. Each method is glam's `Vec3` (or `Vec2`) method
//! written out in glam's order of operations, so that `LaneVec3<f32>` computes what glam
//! computes, bit for bit.

use std::ops::{Add, Div, Mul, Neg, Sub};

use glam::{Vec2, Vec3};

use super::Lane;

/// Points or directions, one per lane: the three coordinates as three lanes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LaneVec3<L> {
    /// The x coordinate of every lane.
    pub x: L,
    /// The y coordinate of every lane.
    pub y: L,
    /// The z coordinate of every lane.
    pub z: L,
}

impl<L: Lane> LaneVec3<L> {
    /// From its coordinates.
    #[inline(always)]
    pub fn new(x: L, y: L, z: L) -> Self {
        Self { x, y, z }
    }

    /// The same `v` in every lane.
    #[inline(always)]
    pub fn splat(v: Vec3) -> Self {
        Self::new(L::splat(v.x), L::splat(v.y), L::splat(v.z))
    }

    /// glam's `dot`: `x * x' + y * y' + z * z'`, left to right.
    #[inline(always)]
    pub fn dot(self, rhs: Self) -> L {
        self.x * rhs.x + self.y * rhs.y + self.z * rhs.z
    }

    /// `dot(self, self)`.
    #[inline(always)]
    pub fn length_squared(self) -> L {
        self.dot(self)
    }

    /// `dot(self, self).sqrt()`.
    #[inline(always)]
    pub fn length(self) -> L {
        self.dot(self).sqrt()
    }

    /// Per coordinate.
    #[inline(always)]
    pub fn abs(self) -> Self {
        Self::new(self.x.abs(), self.y.abs(), self.z.abs())
    }

    /// glam's `min`, per coordinate ([`Lane::min_cmp`]).
    #[inline(always)]
    pub fn min(self, rhs: Self) -> Self {
        Self::new(
            self.x.min_cmp(rhs.x),
            self.y.min_cmp(rhs.y),
            self.z.min_cmp(rhs.z),
        )
    }

    /// glam's `max`, per coordinate ([`Lane::max_cmp`]).
    #[inline(always)]
    pub fn max(self, rhs: Self) -> Self {
        Self::new(
            self.x.max_cmp(rhs.x),
            self.y.max_cmp(rhs.y),
            self.z.max_cmp(rhs.z),
        )
    }

    /// glam's `min_element`: `min(x, min(y, z))` by comparison.
    #[inline(always)]
    pub fn min_element(self) -> L {
        self.x.min_cmp(self.y.min_cmp(self.z))
    }

    /// glam's `max_element`: `max(x, max(y, z))` by comparison.
    #[inline(always)]
    pub fn max_element(self) -> L {
        self.x.max_cmp(self.y.max_cmp(self.z))
    }

    /// Where every coordinate is finite ([`Lane::finite`]).
    #[inline(always)]
    pub fn finite(self) -> L::Mask {
        L::and(self.x.finite(), L::and(self.y.finite(), self.z.finite()))
    }

    /// glam's `cross`.
    #[inline(always)]
    pub fn cross(self, rhs: Self) -> Self {
        Self::new(
            self.y * rhs.z - rhs.y * self.z,
            self.z * rhs.x - rhs.z * self.x,
            self.x * rhs.y - rhs.x * self.y,
        )
    }
}

impl From<Vec3> for LaneVec3<f32> {
    #[inline(always)]
    fn from(v: Vec3) -> Self {
        Self::new(v.x, v.y, v.z)
    }
}

impl From<LaneVec3<f32>> for Vec3 {
    #[inline(always)]
    fn from(v: LaneVec3<f32>) -> Self {
        Vec3::new(v.x, v.y, v.z)
    }
}

impl<L: Lane> Add for LaneVec3<L> {
    type Output = Self;
    #[inline(always)]
    fn add(self, rhs: Self) -> Self {
        Self::new(self.x + rhs.x, self.y + rhs.y, self.z + rhs.z)
    }
}

impl<L: Lane> Sub for LaneVec3<L> {
    type Output = Self;
    #[inline(always)]
    fn sub(self, rhs: Self) -> Self {
        Self::new(self.x - rhs.x, self.y - rhs.y, self.z - rhs.z)
    }
}

impl<L: Lane> Neg for LaneVec3<L> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        Self::new(-self.x, -self.y, -self.z)
    }
}

/// glam's `Vec3 * f32`: every coordinate times the lane's factor.
impl<L: Lane> Mul<L> for LaneVec3<L> {
    type Output = Self;
    #[inline(always)]
    fn mul(self, rhs: L) -> Self {
        Self::new(self.x * rhs, self.y * rhs, self.z * rhs)
    }
}

/// glam's `Vec3 / f32`: a division per coordinate (not a multiplication by the inverse).
impl<L: Lane> Div<L> for LaneVec3<L> {
    type Output = Self;
    #[inline(always)]
    fn div(self, rhs: L) -> Self {
        Self::new(self.x / rhs, self.y / rhs, self.z / rhs)
    }
}

/// The 2D profiles of the shapes of revolution, as [`LaneVec3`] is for points.
#[derive(Clone, Copy, Debug)]
pub(crate) struct LaneVec2<L> {
    pub x: L,
    pub y: L,
}

impl<L: Lane> LaneVec2<L> {
    #[inline(always)]
    pub fn new(x: L, y: L) -> Self {
        Self { x, y }
    }

    #[inline(always)]
    pub fn splat(v: Vec2) -> Self {
        Self::new(L::splat(v.x), L::splat(v.y))
    }

    /// glam's `length`: `(x * x + y * y).sqrt()`.
    #[inline(always)]
    pub fn length(self) -> L {
        (self.x * self.x + self.y * self.y).sqrt()
    }

    #[inline(always)]
    pub fn abs(self) -> Self {
        Self::new(self.x.abs(), self.y.abs())
    }

    /// glam's `max`, per coordinate.
    #[inline(always)]
    pub fn max(self, rhs: Self) -> Self {
        Self::new(self.x.max_cmp(rhs.x), self.y.max_cmp(rhs.y))
    }

    /// glam's `max_element`: `x > y ? x : y`.
    #[inline(always)]
    pub fn max_element(self) -> L {
        self.x.max_cmp(self.y)
    }
}

impl<L: Lane> Sub for LaneVec2<L> {
    type Output = Self;
    #[inline(always)]
    fn sub(self, rhs: Self) -> Self {
        Self::new(self.x - rhs.x, self.y - rhs.y)
    }
}
