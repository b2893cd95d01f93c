//! Table axes: where each texel's value was computed, and how a lookup finds it.
//!
//! An axis of `N` samples maps an index `i` to a texture coordinate `t_i` in [0, 1] by its grid
//! convention, then `t` to the physical coordinate (`mu` or roughness) by its mapping:
//!
//! - grid `centers` (the default): `t_i = (i + 0.5) / N`, the centre of texel `i` when the table is
//!   a texture over [0, 1] sampled with bilinear filtering and clamp-to-edge (what a GPU does);
//!   the axis ends `t = 0` and `t = 1` lie half a texel outside the first and last sample;
//! - grid `nodes`: `t_i = i / (N - 1)`, the first and last samples sit exactly on the axis ends
//!   (Cycles, appleseed); a GPU lookup must then remap `t' = (t (N - 1) + 0.5) / N`.
//!
//! Mappings from `t` to the physical coordinate:
//!
//! - `mu`, `linear`: `mu = t`; `sqrt`: `mu = t^2`, i.e. the texture coordinate is `sqrt(mu)`
//!   (Unity HDRP), which puts more samples near grazing;
//! - roughness `r` (perceptual): `r = t`, `alpha = r^2`; roughness `alpha`: `alpha = t`.

use crate::model::RoughnessConvention;
use serde::{Deserialize, Serialize};

/// Where the samples of an axis sit.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum Grid {
    /// `t_i = (i + 0.5) / N`: texel centres.
    Centers,
    /// `t_i = i / (N - 1)`: nodes on the axis ends.
    Nodes,
}

impl Grid {
    /// The name used on the command line and in files.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Grid::Centers => "centers",
            Grid::Nodes => "nodes",
        }
    }

    /// The texture coordinate `t_i` of sample `i` of `n`.
    #[must_use]
    pub fn coordinate(self, i: usize, n: usize) -> f64 {
        match self {
            Grid::Centers => (i as f64 + 0.5) / n as f64,
            Grid::Nodes if n == 1 => 0.0,
            Grid::Nodes => i as f64 / (n - 1) as f64,
        }
    }

    /// The formula of [`Grid::coordinate`], for metadata.
    #[must_use]
    pub fn formula(self) -> &'static str {
        match self {
            Grid::Centers => "t_i = (i + 0.5) / N",
            Grid::Nodes => "t_i = i / (N - 1)",
        }
    }
}

/// How the `mu` axis is spaced.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum MuMapping {
    /// `mu = t`.
    Linear,
    /// `mu = t^2` (texture coordinate `sqrt(mu)`).
    Sqrt,
}

impl MuMapping {
    /// The name used on the command line and in files.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            MuMapping::Linear => "linear",
            MuMapping::Sqrt => "sqrt",
        }
    }

    /// `mu` at texture coordinate `t`.
    #[must_use]
    pub fn mu(self, t: f64) -> f64 {
        match self {
            MuMapping::Linear => t,
            MuMapping::Sqrt => t * t,
        }
    }

    /// The texture coordinate of `mu` (the inverse of [`MuMapping::mu`]).
    #[must_use]
    pub fn coordinate(self, mu: f64) -> f64 {
        match self {
            MuMapping::Linear => mu,
            MuMapping::Sqrt => mu.sqrt(),
        }
    }

    /// The formula, for metadata.
    #[must_use]
    pub fn formula(self) -> &'static str {
        match self {
            MuMapping::Linear => "mu = t",
            MuMapping::Sqrt => "mu = t^2 (lookup coordinate t = sqrt(mu))",
        }
    }
}

/// One axis of a table.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(tag = "quantity", rename_all = "kebab-case")]
pub enum Axis {
    /// `mu = cos(theta_o)` of the view direction.
    Mu {
        size: usize,
        mapping: MuMapping,
        grid: Grid,
    },
    /// Roughness, in the given convention (`r` with `alpha = r^2`, or `alpha`).
    Roughness {
        size: usize,
        convention: RoughnessConvention,
        grid: Grid,
    },
}

impl Axis {
    /// The number of samples along the axis.
    #[must_use]
    pub fn size(&self) -> usize {
        match *self {
            Axis::Mu { size, .. } | Axis::Roughness { size, .. } => size,
        }
    }

    /// The grid convention.
    #[must_use]
    pub fn grid(&self) -> Grid {
        match *self {
            Axis::Mu { grid, .. } | Axis::Roughness { grid, .. } => grid,
        }
    }

    /// The axis name: `mu`, `r` or `alpha`.
    #[must_use]
    pub fn name(&self) -> &'static str {
        match *self {
            Axis::Mu { .. } => "mu",
            Axis::Roughness { convention, .. } => convention.name(),
        }
    }

    /// The physical coordinate (`mu`, `r` or `alpha`, as [`Axis::name`] says) of sample `i`.
    #[must_use]
    pub fn value(&self, i: usize) -> f64 {
        match *self {
            Axis::Mu {
                size,
                mapping,
                grid,
            } => mapping.mu(grid.coordinate(i, size)),
            Axis::Roughness { size, grid, .. } => grid.coordinate(i, size),
        }
    }

    /// The values of every sample.
    #[must_use]
    pub fn values(&self) -> Vec<f64> {
        (0..self.size()).map(|i| self.value(i)).collect()
    }

    /// `alpha` at sample `i` of a roughness axis. Panics on a `mu` axis.
    #[must_use]
    pub fn alpha(&self, i: usize) -> f64 {
        match *self {
            Axis::Roughness { convention, .. } => convention.to_alpha(self.value(i)),
            Axis::Mu { .. } => panic!("alpha asked of a mu axis"),
        }
    }

    /// The formula from index to value, for metadata and generated docs.
    #[must_use]
    pub fn formula(&self) -> String {
        match *self {
            Axis::Mu { mapping, grid, .. } => format!("{}, {}", grid.formula(), mapping.formula()),
            Axis::Roughness {
                convention: RoughnessConvention::Perceptual,
                grid,
                ..
            } => {
                format!("{}, r = t_i, alpha = r^2", grid.formula())
            }
            Axis::Roughness {
                convention: RoughnessConvention::Alpha,
                grid,
                ..
            } => {
                format!("{}, alpha = t_i", grid.formula())
            }
        }
    }

    /// The continuous sample position (in units of samples, clamped to `[0, N - 1]`) of the
    /// physical coordinate `x`: what a bilinear lookup of this axis interpolates at.
    #[must_use]
    pub fn position(&self, x: f64) -> f64 {
        let t = match *self {
            Axis::Mu { mapping, .. } => mapping.coordinate(x),
            Axis::Roughness { .. } => x,
        };
        let n = self.size() as f64;
        let p = match self.grid() {
            Grid::Centers => t * n - 0.5,
            Grid::Nodes => t * (n - 1.0),
        };
        p.clamp(0.0, n - 1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_conventions() {
        assert_eq!(Grid::Centers.coordinate(0, 32), 0.5 / 32.0);
        assert_eq!(Grid::Centers.coordinate(31, 32), 31.5 / 32.0);
        assert_eq!(Grid::Nodes.coordinate(0, 32), 0.0);
        assert_eq!(Grid::Nodes.coordinate(31, 32), 1.0);
        let mu = Axis::Mu {
            size: 4,
            mapping: MuMapping::Sqrt,
            grid: Grid::Nodes,
        };
        assert_eq!(mu.values(), [0.0, 1.0 / 9.0, 4.0 / 9.0, 1.0]);
        let r = Axis::Roughness {
            size: 2,
            convention: RoughnessConvention::Perceptual,
            grid: Grid::Centers,
        };
        assert_eq!(r.values(), [0.25, 0.75]);
        assert_eq!(r.alpha(1), 0.5625);
    }

    #[test]
    fn position_inverts_value() {
        for grid in [Grid::Centers, Grid::Nodes] {
            for mapping in [MuMapping::Linear, MuMapping::Sqrt] {
                let axis = Axis::Mu {
                    size: 16,
                    mapping,
                    grid,
                };
                for i in 0..16 {
                    assert!((axis.position(axis.value(i)) - i as f64).abs() < 1e-12);
                }
            }
        }
    }
}
