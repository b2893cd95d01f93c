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
