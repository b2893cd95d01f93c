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
    pub fn check(&self) -> crate::Result<()> {
        let q = self.quantity;
        let slot = |name: &str, axis: Option<Axis>, wanted: bool, right: fn(&Axis) -> bool| match (
            axis, wanted,
        ) {
            (Some(a), true) if right(&a) => Ok(()),
            (Some(a), true) => Err(crate::Error::Malformed(format!(
                "its {name} axis is a {} axis (axes swapped?)",
                a.name()
            ))),
            (None, true) => Err(crate::Error::Malformed(format!(
                "{} needs a {name} axis",
                q.symbol()
            ))),
            (Some(_), false) => Err(crate::Error::Malformed(format!(
                "{} has no {name} axis",
                q.symbol()
            ))),
            (None, false) => Ok(()),
        };
        // A glass albedo at one IOR names its index in its Fresnel model instead of an axis.
        let one_ior = q.is_dielectric()
            && self.ior.is_none()
            && matches!(self.fresnel, Some(crate::model::Fresnel::Dielectric { .. }));
        slot("eta", self.ior, q.has_ior() && !one_ior, |a| {
            matches!(a, Axis::Ior { .. })
        })?;
        if let Some(ior) = self.fixed_ior() {
            check_fixed_ior(ior)?;
        }
        slot("roughness", self.roughness, q.has_roughness(), |a| {
            matches!(a, Axis::Roughness { .. })
        })?;
        slot("mu", self.mu, q.has_mu(), |a| matches!(a, Axis::Mu { .. }))?;
        let mut texels: usize = 1;
        for axis in self.axes() {
            let size = axis.size();
            if size == 0 || size > super::MAX_TEXELS {
                return Err(crate::Error::Malformed(format!(
                    "its {} axis has {size} samples",
                    axis.name()
                )));
            }
            if let Axis::Ior { max, .. } = axis
                && !(max.0.is_finite() && max.0 > 1.0 && max.0 <= crate::model::fresnel::MAX_INDEX)
            {
                return Err(crate::Error::Malformed(format!(
                    "its eta axis ends at {}, outside (1, {}]",
                    max.0,
                    crate::model::fresnel::MAX_INDEX
                )));
            }
            texels = texels.saturating_mul(size);
        }
        if texels > super::MAX_TEXELS {
            return Err(crate::Error::Malformed(format!(
                "shape {:?}: {texels} texels, more than the {} kiln reads",
                self.shape(),
                super::MAX_TEXELS
            )));
        }
        // kiln's glass layout: its mu coordinate needs the IOR, its IOR coordinate the roughness.
        let glass_mu =
            matches!(self.mu, Some(Axis::Mu { mapping, .. }) if mapping.depends_on_ior());
        let glass_ior =
            matches!(self.ior, Some(Axis::Ior { mapping, .. }) if mapping.depends_on_roughness());
        if glass_mu && !glass_ior {
            return Err(crate::Error::Malformed(
                "its mu axis is in kiln's glass layout, which needs a glass IOR axis".into(),
            ));
        }
        let one_ior_mu = matches!(self.mu, Some(Axis::Mu { mapping, .. }) if mapping == super::axis::MuMapping::OneIor);
        if one_ior_mu && self.fixed_ior().is_none() {
            return Err(crate::Error::Malformed(format!(
                "its mu axis is in kiln's layout of a glass table at one IOR, which {} is not \
                 (it needs a dielectric quantity and its Fresnel model's IOR, without an eta axis)",
                q.symbol()
            )));
        }
        if glass_ior && self.roughness.is_none() {
            return Err(crate::Error::Malformed(format!(
                "its eta axis is in kiln's glass layout, which needs a roughness axis ({} has none)",
                q.symbol()
            )));
        }
        let balanced_rows = matches!(
            self.roughness,
            Some(Axis::Roughness {
                spacing: super::axis::RoughnessSpacing::Balanced,
                ..
            })
        );
        if balanced_rows && self.ior.is_some() {
            return Err(crate::Error::Malformed(format!(
                "its roughness axis has the balanced spacing, which kiln lays out for the tables \
                 over roughness and mu only ({} has an eta axis)",
                q.symbol()
            )));
        }
        if !self.transmission.is_default() && !q.is_glass_albedo() {
            return Err(crate::Error::Malformed(format!(
                "a transmission convention belongs to the dielectric tables, not {}",
                q.symbol()
            )));
        }
        if (q == Quantity::EF || one_ior) != self.fresnel.is_some() {
            return Err(crate::Error::Malformed(
                "a Fresnel model belongs to E_F tables and to glass tables at one IOR (a \
                 dielectric without an eta axis), and only to them"
                    .into(),
            ));
        }
        match (&self.lookup_of, q) {
            (Some(e), Quantity::FMsNorm) => {
                if e.quantity != Quantity::E {
                    return Err(crate::Error::Malformed(format!(
                        "f_ms_norm is derived from an E table, not {}",
                        e.quantity.symbol()
                    )));
                }
                e.check()
                    .map_err(|m| crate::Error::Malformed(format!("its E table: {m}")))?;
                // kiln's layout of the normalisation of that E table, or the one of files
                // older than the refined start (the same without it).
                let kiln = super::normalisation::refined_start_for(e);
                if self.refined_start.is_some() && self.refined_start != kiln {
                    return Err(crate::Error::Malformed(format!(
                        "f_ms_norm's refined_start {:?} is not kiln's for its E table ({kiln:?})",
                        self.refined_start
                    )));
                }
                let size = super::normalisation::size_of(e, self.refined_start);
                let got = self.roughness.map_or(0, |axis| axis.size());
                if got != size {
                    return Err(crate::Error::Malformed(format!(
                        "f_ms_norm of a {}-row E table has {size} entries with this layout, not \
                         {got}",
                        e.roughness_axis().size()
                    )));
                }
                Ok(())
            }
            (None, Quantity::FMsNorm) => Err(crate::Error::Malformed(
                "f_ms_norm needs lookup_of, its E table".into(),
            )),
            (Some(_), _) => Err(crate::Error::Malformed(format!(
                "{} is not derived from another table",
                q.symbol()
            ))),
            (None, _) if self.refined_start.is_some() => Err(crate::Error::Malformed(format!(
                "{} has no refined start (f_ms_norm only)",
                q.symbol()
            ))),
            (None, _) => Ok(()),
        }
    }
}

impl Table {
    /// Checks a computed table before anything is written or claimed about it: every value and
    /// one-minus value finite, every error estimate finite and not negative (an infinite one marks
    /// a quadrature that did not converge, `crate::bake::estimate_texel`), and then everything a reader
    /// checks ([`Table::check`]: values in `[0, 1]`, value and one-minus value adding up to 1).
    /// The error names the first texel that fails, where it is and what to do.
    ///
    /// # Errors
    /// As above.
    pub fn check_computed(&self) -> crate::error::Result<()> {
        let table = self;
        let spec = &table.spec;
        let place = |k: usize| {
            let (alpha, mu, eta) = spec.texel_point(k);
            let mut at = format!("texel {k} (alpha {alpha:e}");
            if let Some(mu) = mu {
                at += &format!(", mu {mu:e}");
            }
            if let Some(eta) = eta {
                at += &format!(", eta {eta:e}");
            }
            at + ")"
        };
        let lengths = [
            table.value.len(),
            table.one_minus_value.len(),
            table.std_error.len(),
        ];
        if lengths.iter().any(|&n| n != spec.len()) {
            return Err(crate::error::Error::InvalidInput(format!(
                "{}: {lengths:?} values, one-minus values and errors for {} texels",
                spec.id(),
                spec.len()
            )));
        }
        for k in 0..spec.len() {
            let (v, w, e) = (table.value[k], table.one_minus_value[k], table.std_error[k]);
            if !v.is_finite() || !w.is_finite() {
                return Err(crate::error::Error::InvalidInput(format!(
                    "{}: the computed value at {} is {v} (1 - value {w}): the model gives no finite \
                     number there; nothing was written. Check the inputs (IOR, eta, k) for values \
                     outside what the physics allows",
                    spec.id(),
                    place(k)
                )));
            }
            if e == f64::INFINITY {
                return Err(crate::error::Error::InvalidInput(format!(
                    "{}: the quadrature did not converge at {} within its evaluation budget, so \
                     the value {v} has no error bound; nothing was written. Ask for fewer digits \
                     (a larger --max-error) or use --method qmc",
                    spec.id(),
                    place(k)
                )));
            }
            if !(e >= 0.0 && e.is_finite()) {
                return Err(crate::error::Error::InvalidInput(format!(
                    "{}: the error estimate at {} is {e}; nothing was written",
                    spec.id(),
                    place(k)
                )));
            }
        }
        // What every reader checks (spec, ranges, sums): a table no reader would take is never
        // written, whether baked here or merged from shards.
        table.check().map_err(|message| {
            crate::error::Error::InvalidInput(format!(
                "{}: {message}; nothing was written",
                spec.id()
            ))
        })
    }
    /// Checks the spec ([`TableSpec::check`]) and the channels: each as long as the spec's
    /// texels, every value and one-minus value finite and within [`RANGE_TOLERANCE`] of
    /// `[0, 1]`, value and one-minus value adding up to 1 within twice that, every error estimate
    /// finite and not negative. The message names the first texel that fails.
    ///
    /// # Errors
    /// As above.
    pub fn check(&self) -> crate::Result<()> {
        self.spec.check()?;
        let n = self.spec.len();
        let symbol = self.spec.quantity.symbol();
        for (name, channel) in [
            (symbol.to_string(), &self.value),
            (format!("one_minus_{symbol}"), &self.one_minus_value),
            ("std_error".to_string(), &self.std_error),
        ] {
            if channel.len() != n {
                return Err(crate::Error::Malformed(format!(
                    "{name} has {} values for shape {:?} ({n} texels)",
                    channel.len(),
                    self.spec.shape()
                )));
            }
        }
        let range = -RANGE_TOLERANCE..=1.0 + RANGE_TOLERANCE;
        for k in 0..n {
            let (v, w, e) = (self.value[k], self.one_minus_value[k], self.std_error[k]);
            if !range.contains(&v) {
                return Err(crate::Error::Malformed(format!(
                    "{symbol} at texel {k} is {}, outside [0, 1]",
                    crate::error::shown(v)
                )));
            }
            if !range.contains(&w) {
                return Err(crate::Error::Malformed(format!(
                    "one_minus_{symbol} at texel {k} is {}, outside [0, 1]",
                    crate::error::shown(w)
                )));
            }
            if (v + w - 1.0).abs() > 2.0 * RANGE_TOLERANCE {
                return Err(crate::Error::Malformed(format!(
                    "at texel {k}, {symbol} = {} and one_minus_{symbol} = {} do not add up \
                     to 1",
                    crate::error::shown(v),
                    crate::error::shown(w)
                )));
            }
            if !(e.is_finite() && e >= 0.0) {
                return Err(crate::Error::Malformed(format!(
                    "std_error at texel {k} is {}",
                    crate::error::shown(e)
                )));
            }
        }
        Ok(())
    }
}

/// The range of a dielectric table's one IOR ([`super::TableSpec::fixed_ior`]): finite, within
/// `[1 / MAX_INDEX, MAX_INDEX]` as every index kiln reads, and not 1, where there is no
/// interface (its albedo is the limit the tables over the IOR hold on their `eta = 1` slice).
///
/// # Errors
/// Naming the index and the range.
pub fn check_fixed_ior(ior: f64) -> crate::Result<()> {
    let max = crate::model::fresnel::MAX_INDEX;
    if !(ior.is_finite() && (1.0 / max..=max).contains(&ior)) || ior == 1.0 {
        return Err(crate::Error::InvalidInput(format!(
            "a dielectric table at one IOR needs an index in [{}, {max}] other than 1 (got \
             {ior}): at 1 there is no interface (the tables over the IOR hold its limit)",
            1.0 / max
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::dielectric::TransmissionConvention;
    use crate::model::{Fresnel, RoughnessConvention};
    use crate::table::axis::{Grid, IorBound, IorMapping, MuMapping};

    const ROUGHNESS: Axis = Axis::Roughness {
        size: 4,
        convention: RoughnessConvention::Perceptual,
        grid: Grid::Nodes,
        spacing: crate::table::axis::RoughnessSpacing::Linear,
    };
    const MU: Axis = Axis::Mu {
        size: 3,
        mapping: MuMapping::Adaptive,
        grid: Grid::Nodes,
    };

    fn ior(max: f64) -> Axis {
        Axis::Ior {
            size: 2,
            mapping: IorMapping::Cycles,
            max: IorBound(max),
            grid: Grid::Nodes,
        }
    }

    /// A 4 x 3 E table's spec.
    fn e_spec() -> TableSpec {
        crate::table::test_e_spec(4, 3, Grid::Nodes, MuMapping::Adaptive)
    }

    fn refused(spec: &TableSpec, words: &str) {
        match spec.check() {
            Err(message) => assert!(
                message.to_string().contains(words),
                "{message}: wanted {words:?}"
            ),
            Ok(()) => panic!("accepted, wanted {words:?}: {spec:?}"),
        }
    }

    /// kiln's glass layout is whole or refused: a glass mu axis without a glass IOR axis (an E
    /// table claiming it), a glass IOR axis without roughness (F_avg claiming it).
    #[test]
    fn the_glass_layout_comes_whole() {
        let glass_mu = Axis::Mu {
            size: 3,
            mapping: MuMapping::Glass,
            grid: Grid::Nodes,
        };
        let glass_ior = Axis::Ior {
            size: 2,
            mapping: IorMapping::Glass,
            max: IorBound(3.0),
            grid: Grid::Nodes,
        };
        refused(
            &TableSpec {
                mu: Some(glass_mu),
                ..e_spec()
            },
            "needs a glass IOR axis",
        );
        let dielectric = TableSpec {
            quantity: Quantity::EDielectric,
            ior: Some(ior(3.0)),
            ..e_spec()
        };
        assert!(dielectric.check().is_ok());
        refused(
            &TableSpec {
                mu: Some(glass_mu),
                ..dielectric.clone()
            },
            "needs a glass IOR axis",
        );
        let glass = TableSpec {
            ior: Some(glass_ior),
            mu: Some(glass_mu),
            ..dielectric
        };
        assert!(glass.check().is_ok());
        let f_avg = TableSpec {
            quantity: Quantity::FAvg,
            ior: Some(glass_ior),
            roughness: None,
            mu: None,
            ..e_spec()
        };
        refused(&f_avg, "needs a roughness axis (F_avg has none)");
    }

    /// Each axis in its place, of a size kiln reads; each rule both ways.
    #[test]
    fn a_spec_needs_its_quantitys_axes_in_their_places() {
        assert!(e_spec().check().is_ok());
        let swapped = TableSpec {
            roughness: Some(MU),
            mu: Some(ROUGHNESS),
            ..e_spec()
        };
        refused(&swapped, "its roughness axis is a mu axis (axes swapped?)");
        refused(
            &TableSpec {
                mu: None,
                ..e_spec()
            },
            "E needs a mu axis",
        );
        let e_avg = TableSpec {
            quantity: Quantity::EAvg,
            ..e_spec()
        };
        refused(&e_avg, "E_avg has no mu axis");
        assert!(TableSpec { mu: None, ..e_avg }.check().is_ok());
        refused(
            &TableSpec {
                ior: Some(ior(3.0)),
                ..e_spec()
            },
            "E has no eta axis",
        );
        let empty = Axis::Mu {
            size: 0,
            mapping: MuMapping::Linear,
            grid: Grid::Nodes,
        };
        refused(
            &TableSpec {
                mu: Some(empty),
                ..e_spec()
            },
            "its mu axis has 0 samples",
        );
        // One axis may hold every texel kiln reads, not one more.
        let long = |size| Axis::Mu {
            size,
            mapping: MuMapping::Linear,
            grid: Grid::Nodes,
        };
        let one_row = Axis::Roughness {
            size: 1,
            convention: RoughnessConvention::Perceptual,
            grid: Grid::Nodes,
            spacing: crate::table::axis::RoughnessSpacing::Linear,
        };
        let widest = TableSpec {
            roughness: Some(one_row),
            mu: Some(long(super::super::MAX_TEXELS)),
            ..e_spec()
        };
        assert!(widest.check().is_ok());
        refused(
            &TableSpec {
                mu: Some(long(super::super::MAX_TEXELS + 1)),
                ..widest
            },
            "its mu axis has 67108865 samples",
        );
    }

    /// The IOR axis ends in `(1, MAX_INDEX]`.
    #[test]
    fn an_ior_axis_ends_above_1_and_at_most_at_the_largest_index() {
        let glass = |max: f64| TableSpec {
            quantity: Quantity::EDielectric,
            ior: Some(ior(max)),
            ..e_spec()
        };
        for max in [1.0001, 3.0, crate::model::fresnel::MAX_INDEX] {
            assert!(glass(max).check().is_ok(), "{max}");
        }
        for max in [1.0, 0.5, 100.5, f64::NAN, f64::INFINITY] {
            refused(&glass(max), "its eta axis ends at");
        }
        refused(
            &TableSpec {
                ior: None,
                ..glass(3.0)
            },
            "needs a eta axis",
        );
    }

    /// Transmission conventions, Fresnel models and source tables belong to the quantities
    /// that use them, and only to those.
    #[test]
    fn conventions_belong_to_the_quantities_that_use_them() {
        let cycles = TransmissionConvention::Cycles;
        let glass = TableSpec {
            quantity: Quantity::EDielectric,
            ior: Some(ior(3.0)),
            transmission: cycles,
            ..e_spec()
        };
        assert!(glass.check().is_ok());
        refused(
            &TableSpec {
                transmission: cycles,
                ..e_spec()
            },
            "a transmission convention belongs to the dielectric tables, not E",
        );
        let f_avg = TableSpec {
            quantity: Quantity::FAvg,
            roughness: None,
            mu: None,
            ..glass
        };
        refused(&f_avg, "not F_avg");
        let schlick = Some(Fresnel::Dielectric { eta: 1.5 });
        refused(
            &TableSpec {
                fresnel: schlick,
                ..e_spec()
            },
            "a Fresnel model belongs to E_F tables",
        );
        let e_f = TableSpec {
            quantity: Quantity::EF,
            ..e_spec()
        };
        refused(&e_f, "a Fresnel model belongs to E_F tables");
        assert!(
            TableSpec {
                fresnel: schlick,
                ..e_f
            }
            .check()
            .is_ok()
        );
        let norm = TableSpec {
            quantity: Quantity::FMsNorm,
            mu: None,
            ..e_spec()
        };
        refused(&norm, "f_ms_norm needs lookup_of");
        // The normalisation of `source` as kiln lays it out.
        let of = |source: TableSpec| {
            let kiln = crate::table::normalisation::spec_for(&source);
            TableSpec {
                roughness: kiln.roughness,
                refined_start: kiln.refined_start,
                lookup_of: Some(Box::new(source)),
                ..norm.clone()
            }
        };
        assert!(of(e_spec()).check().is_ok());
        // Its size follows its E table and refined start; older files have none.
        let resized = |size: usize, refined_start| {
            let mut spec = of(e_spec());
            if let Some(Axis::Roughness { size: s, .. }) = &mut spec.roughness {
                *s = size;
            }
            TableSpec {
                refined_start,
                ..spec
            }
        };
        let kiln = of(e_spec());
        let rows = e_spec().roughness_axis().size();
        assert!(
            resized(
                (rows - 1) * crate::table::normalisation::SUBDIVISIONS + 1,
                None
            )
            .check()
            .is_ok()
        );
        refused(
            &resized(kiln.roughness_axis().size() + 1, kiln.refined_start),
            "entries with this layout, not",
        );
        refused(
            &resized((rows - 1) * 16 + 1, kiln.refined_start),
            "entries with this layout, not",
        );
        let foreign = crate::table::normalisation::RefinedStart {
            cells: 1,
            subdivisions: 0,
        };
        refused(
            &resized(kiln.roughness_axis().size(), Some(foreign)),
            "is not kiln's for its E table",
        );
        refused(
            &TableSpec {
                refined_start: kiln.refined_start,
                ..e_spec()
            },
            "E has no refined start (f_ms_norm only)",
        );
        refused(
            &of(TableSpec {
                quantity: Quantity::EAvg,
                mu: None,
                ..e_spec()
            }),
            "derived from an E table, not E_avg",
        );
        refused(
            &of(TableSpec {
                mu: None,
                ..e_spec()
            }),
            "its E table: E needs a mu axis",
        );
        refused(
            &TableSpec {
                lookup_of: Some(Box::new(e_spec())),
                ..e_spec()
            },
            "E is not derived from another table",
        );
    }

    /// A 4 x 3 table whose channels are `value`, `1 - value` and `error` at every texel.
    fn table(value: f64, error: f64) -> Table {
        Table {
            spec: e_spec(),
            value: vec![value; 12],
            one_minus_value: vec![1.0 - value; 12],
            std_error: vec![error; 12],
            command: String::new(),
            node_errors: None,
            requested_max_error: None,
            lookup_fit: None,
        }
    }

    /// Channels as long as the spec, values in `[0, 1]` to within `RANGE_TOLERANCE`, value and
    /// one-minus value adding up to 1, errors finite and not negative.
    #[test]
    fn a_tables_channels_hold_what_its_spec_promises() {
        assert!(table(0.5, 1e-6).check().is_ok());
        assert!(table(1.0 + 0.9e-3, 0.0).check().is_ok());
        assert!(table(-0.9e-3, 0.0).check().is_ok());
        let mut t = table(0.5, 0.0);
        t.value.pop();
        match t.check() {
            Err(m) => assert_eq!(
                m.to_string(),
                "E has 11 values for shape [4, 3] (12 texels)"
            ),
            Ok(()) => panic!("a short channel passed"),
        }
        let mut t = table(0.5, 0.0);
        t.std_error.push(0.0);
        assert!(
            t.check()
                .unwrap_err()
                .to_string()
                .starts_with("std_error has 13 values")
        );
        let mut t = table(0.5, 0.0);
        t.value[7] = 1.0 + 1.1e-3;
        assert_eq!(
            t.check().unwrap_err().to_string(),
            "E at texel 7 is 1.0011, outside [0, 1]"
        );
        let mut t = table(0.5, 0.0);
        t.one_minus_value[2] = -1.1e-3;
        assert_eq!(
            t.check().unwrap_err().to_string(),
            "one_minus_E at texel 2 is -0.0011, outside [0, 1]"
        );
        let mut t = table(0.5, 0.0);
        t.value[4] = f64::NAN;
        assert!(
            t.check()
                .unwrap_err()
                .to_string()
                .starts_with("E at texel 4 is NaN")
        );
        // Each in range, not adding up to 1 (0.4 + 0.6 = 1; 0.4 + 0.5 = 0.9).
        let mut t = table(0.5, 0.0);
        t.value[3] = 0.4;
        assert!(
            t.check()
                .unwrap_err()
                .to_string()
                .contains("at texel 3, E = 0.4")
        );
        // A difference from 1 of 1.9e-3, within twice the tolerance, passes.
        let mut t = table(0.5, 0.0);
        t.value[3] = 0.5 + 0.95e-3;
        t.one_minus_value[3] = 0.5 + 0.95e-3;
        assert!(t.check().is_ok());
        // Shown as a message shows numbers: -1e-300, not 300 digits (issue 64).
        for (bad, shown) in [
            (f64::NAN, "NaN"),
            (f64::INFINITY, "inf"),
            (-1e-300, "-1e-300"),
        ] {
            let mut t = table(0.5, 0.0);
            t.std_error[11] = bad;
            assert_eq!(
                t.check().unwrap_err().to_string(),
                format!("std_error at texel 11 is {shown}")
            );
        }
    }
}
