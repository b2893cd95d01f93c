//! Whether a table read from a file (or a cache) is one kiln can use: a spec whose axes fit its
//! quantity and whose size is within [`super::MAX_TEXELS`], and channels of that length
//! holding finite numbers in the quantity's range. Every reader runs these before a table is
//! audited, looked up or written, so that a hostile or damaged file is an error naming the
//! value, never a panic, a huge allocation or a NaN audit that passes.

use super::axis::Axis;
use super::{Quantity, Table, TableSpec};

/// How far a stored value may lie outside `[0, 1]` (every quantity kiln tabulates is an albedo,
/// a Fresnel average or a normalisation in that range): the rounding of a half float near 1
/// (2.4e-4) and an estimate's noise, with room.
pub const RANGE_TOLERANCE: f64 = 1e-3;

impl TableSpec {
    /// Checks that the axes are those of the quantity, each in its place, that every axis has
    /// between 1 and [`super::MAX_TEXELS`] samples and the table at most that many
    /// texels, and that `fresnel` and `lookup_of` are set exactly where they belong.
    ///
    /// # Errors
    /// A sentence naming what does not fit.
    pub fn check(&self) -> Result<(), String> {
        let q = self.quantity;
        let slot = |name: &str, axis: Option<Axis>, wanted: bool, right: fn(&Axis) -> bool| match (
            axis, wanted,
        ) {
            (Some(a), true) if right(&a) => Ok(()),
            (Some(a), true) => Err(format!(
                "its {name} axis is a {} axis (axes swapped?)",
                a.name()
            )),
            (None, true) => Err(format!("{} needs a {name} axis", q.symbol())),
            (Some(_), false) => Err(format!("{} has no {name} axis", q.symbol())),
            (None, false) => Ok(()),
        };
        slot("eta", self.ior, q.has_ior(), |a| {
            matches!(a, Axis::Ior { .. })
        })?;
        slot("roughness", self.roughness, q.has_roughness(), |a| {
            matches!(a, Axis::Roughness { .. })
        })?;
        slot("mu", self.mu, q.has_mu(), |a| matches!(a, Axis::Mu { .. }))?;
        let mut texels: usize = 1;
        for axis in self.axes() {
            let size = axis.size();
            if size == 0 || size > super::MAX_TEXELS {
                return Err(format!("its {} axis has {size} samples", axis.name()));
            }
            if let Axis::Ior { max, .. } = axis
                && !(max.0.is_finite() && max.0 > 1.0 && max.0 <= crate::model::fresnel::MAX_INDEX)
            {
                return Err(format!(
                    "its eta axis ends at {}, outside (1, {}]",
                    max.0,
                    crate::model::fresnel::MAX_INDEX
                ));
            }
            texels = texels.saturating_mul(size);
        }
        if texels > super::MAX_TEXELS {
            return Err(format!(
                "shape {:?}: {texels} texels, more than the {} kiln reads",
                self.shape(),
                super::MAX_TEXELS
            ));
        }
        if !self.transmission.is_default() && (!q.has_ior() || q == Quantity::FAvg) {
            return Err(format!(
                "a transmission convention belongs to the dielectric tables, not {}",
                q.symbol()
            ));
        }
        if (q == Quantity::EF) != self.fresnel.is_some() {
            return Err("a Fresnel model belongs to E_F tables, and only to them".into());
        }
        match (&self.lookup_of, q) {
            (Some(e), Quantity::FMsNorm) => {
                if e.quantity != Quantity::E {
                    return Err(format!(
                        "f_ms_norm is derived from an E table, not {}",
                        e.quantity.symbol()
                    ));
                }
                e.check().map_err(|m| format!("its E table: {m}"))
            }
            (None, Quantity::FMsNorm) => Err("f_ms_norm needs lookup_of, its E table".into()),
            (Some(_), _) => Err(format!("{} is not derived from another table", q.symbol())),
            (None, _) => Ok(()),
        }
    }
}

impl Table {
    /// Checks the spec ([`TableSpec::check`]) and the channels: each as long as the spec's
    /// texels, every value and one-minus value finite and within [`RANGE_TOLERANCE`] of
    /// `[0, 1]`, value and one-minus value adding up to 1 within twice that, every error estimate
    /// finite and not negative. The message names the first texel that fails.
    ///
    /// # Errors
    /// As above.
    pub fn check(&self) -> Result<(), String> {
        self.spec.check()?;
        let n = self.spec.len();
        let symbol = self.spec.quantity.symbol();
        for (name, channel) in [
            (symbol.to_string(), &self.value),
            (format!("one_minus_{symbol}"), &self.one_minus_value),
            ("std_error".to_string(), &self.std_error),
        ] {
            if channel.len() != n {
                return Err(format!(
                    "{name} has {} values for shape {:?} ({n} texels)",
                    channel.len(),
                    self.spec.shape()
                ));
            }
        }
        let range = -RANGE_TOLERANCE..=1.0 + RANGE_TOLERANCE;
        for k in 0..n {
            let (v, w, e) = (self.value[k], self.one_minus_value[k], self.std_error[k]);
            if !range.contains(&v) {
                return Err(format!("{symbol} at texel {k} is {v}, outside [0, 1]"));
            }
            if !range.contains(&w) {
                return Err(format!(
                    "one_minus_{symbol} at texel {k} is {w}, outside [0, 1]"
                ));
            }
            if (v + w - 1.0).abs() > 2.0 * RANGE_TOLERANCE {
                return Err(format!(
                    "at texel {k}, {symbol} = {v} and one_minus_{symbol} = {w} do not add up \
                     to 1"
                ));
            }
            if !(e.is_finite() && e >= 0.0) {
                return Err(format!("std_error at texel {k} is {e}"));
            }
        }
        Ok(())
    }
}
