//! A minimal 3-vector for directions in the shading frame.
//!
//! Convention (as in `docs/physics.md`): the macro-surface normal is `n = (0, 0, 1)`, so `z` is
//! `mu = cos(theta)` of a unit direction; the view direction `o` lies in the xz-plane with `x >= 0`.

use std::ops::{Add, Mul, Sub};

/// A 3-vector of f64 in the shading frame (normal along +z).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Vec3 {
    pub x: f64,
    pub y: f64,
    pub z: f64,
}

impl Vec3 {
    #[must_use]
    pub const fn new(x: f64, y: f64, z: f64) -> Self {
        Self { x, y, z }
    }

    /// The unit view direction with `cos(theta) = mu`, in the xz-plane: `(sqrt(1 - mu^2), 0, mu)`.
    #[must_use]
    pub fn from_mu(mu: f64) -> Self {
        Self::new(((1.0 - mu) * (1.0 + mu)).max(0.0).sqrt(), 0.0, mu)
    }

    #[must_use]
    pub fn dot(self, other: Self) -> f64 {
        self.x * other.x + self.y * other.y + self.z * other.z
    }

    #[must_use]
    pub fn length_squared(self) -> f64 {
        self.dot(self)
    }

    /// `self / |self|`; the zero vector gives NaNs, callers keep away from it.
    #[must_use]
    pub fn normalize(self) -> Self {
        self * (1.0 / self.length_squared().sqrt())
    }

    /// `tan^2(theta)` of this direction from its components, `(x^2 + y^2) / z^2`, which keeps full
    /// relative precision near the normal (unlike `(1 - mu^2) / mu^2`). Infinite on the horizon.
    #[must_use]
    #[inline(always)]
    pub fn tan2_theta(self) -> f64 {
        (self.x * self.x + self.y * self.y) / (self.z * self.z)
    }

    /// Mirror reflection of `self` about the unit normal `m`: `2 (self.m) m - self`.
    #[must_use]
    pub fn reflect(self, m: Self) -> Self {
        m * (2.0 * self.dot(m)) - self
    }
}

impl Add for Vec3 {
    type Output = Self;
    fn add(self, rhs: Self) -> Self {
        Self::new(self.x + rhs.x, self.y + rhs.y, self.z + rhs.z)
    }
}

impl Sub for Vec3 {
    type Output = Self;
    fn sub(self, rhs: Self) -> Self {
        Self::new(self.x - rhs.x, self.y - rhs.y, self.z - rhs.z)
    }
}

impl Mul<f64> for Vec3 {
    type Output = Self;
    fn mul(self, s: f64) -> Self {
        Self::new(self.x * s, self.y * s, self.z * s)
    }
}

/// `sqrt(1 - mu^2)` computed as `sqrt((1 - mu)(1 + mu))`, accurate near `mu = 1`.
#[must_use]
pub fn sin_from_cos(mu: f64) -> f64 {
    ((1.0 - mu) * (1.0 + mu)).max(0.0).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each operation on vectors whose results are exact in binary (the 3-4-5 triangles), or
    /// within rounding of it.
    #[test]
    fn vector_operations_on_exact_values() {
        assert_eq!(Vec3::from_mu(0.6), Vec3::new(0.8, 0.0, 0.6));
        assert_eq!(Vec3::from_mu(1.0), Vec3::new(0.0, 0.0, 1.0));
        assert_eq!(Vec3::from_mu(0.0), Vec3::new(1.0, 0.0, 0.0));
        let (a, b) = (Vec3::new(1.0, 2.0, 3.0), Vec3::new(4.0, -5.0, 6.0));
        assert_eq!(a.dot(b), 12.0);
        assert_eq!(a.length_squared(), 14.0);
        assert_eq!(a + b, Vec3::new(5.0, -3.0, 9.0));
        assert_eq!(a - b, Vec3::new(-3.0, 7.0, -3.0));
        assert_eq!(a * 2.0, Vec3::new(2.0, 4.0, 6.0));
        let unit = Vec3::new(0.0, 3.0, 4.0).normalize();
        assert!(
            (unit - Vec3::new(0.0, 0.6, 0.8)).length_squared() < 1e-30,
            "{unit:?}"
        );
        assert_eq!(
            Vec3::new(0.0, 0.0, -4.0).normalize(),
            Vec3::new(0.0, 0.0, -1.0)
        );
        // tan^2 of a direction at 45 degrees, of one at tan = 2 towards y, and on the horizon.
        assert_eq!(Vec3::new(3.0, 4.0, 5.0).tan2_theta(), 1.0);
        assert_eq!(Vec3::new(0.0, 0.6, 0.3).tan2_theta(), 4.0);
        assert_eq!(Vec3::new(1.0, 0.0, 0.0).tan2_theta(), f64::INFINITY);
        // Reflected about the normal, and about a facet tilted 45 degrees towards x.
        let o = Vec3::new(0.6, 0.0, 0.8);
        assert_eq!(
            o.reflect(Vec3::new(0.0, 0.0, 1.0)),
            Vec3::new(-0.6, 0.0, 0.8)
        );
        let m = Vec3::new(1.0, 0.0, 1.0).normalize();
        let i = Vec3::new(0.0, 0.0, 1.0).reflect(m);
        assert!(
            (i - Vec3::new(1.0, 0.0, 0.0)).length_squared() < 1e-30,
            "{i:?}"
        );
    }
}
