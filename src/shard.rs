//! Sharded bakes: one bake split over N processes (Slurm array tasks, Kubernetes indexed-job
//! pods, or plain processes), each integrating a share of every table's texels into a shard
//! file, and a merge that checks the shards and finishes the tables exactly as the unsharded
//! bake does ([`BakeOptions::confirm`], the derived `f_ms_norm`), so that the files it writes
//! are byte-identical.
//!
//! The partition: every integrated table's texels (row-major, slowest axis first) are cut into
//! N contiguous ranges of equal estimated cost ([`texel_cost`]); shard `i` takes range `i` of
//! every table. A texel's value depends only on its coordinates and the spec, so where and in
//! which order it is computed does not change a bit.
//!
//! A shard file (`kiln-shard-I-of-N.json`) holds: its kind and versions, the bake (the options,
//! output formats and precision), a digest of the bake (so a merge can tell shards of different
//! bakes apart), its index and count, and per table the spec, the texel range, the values,
//! one-minus values and error estimates, and a digest of those numbers.

use crate::bake::{BakeOptions, estimate_texel};
use crate::cache::fnv1a;
use crate::error::{Error, Result};
use crate::format::{Format, Precision};
use crate::table::{Quantity, Table, TableSpec};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The `kind` of a shard file.
pub const KIND: &str = "kiln-shard";

/// Which share of the work a process does: shard `index` of `count` (0-based, as Kubernetes
/// counts).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShardIndex {
    pub index: usize,
    pub count: usize,
}

impl ShardIndex {
    /// Parses `I/N`.
    ///
    /// # Errors
    /// Anything but two integers with `0 <= I < N`, `N` from 1 to 100,000.
    pub fn parse(text: &str) -> crate::Result<Self> {
        let (i, n) = text.split_once('/').ok_or_else(|| {
            crate::Error::InvalidInput(format!(
                "--shard takes I/N (e.g. 0/4) or auto, not '{text}'"
            ))
        })?;
        let number = |s: &str, what: &str| {
            s.trim().parse::<usize>().map_err(|_| {
                crate::Error::InvalidInput(format!(
                    "--shard {text}: {what} '{s}' is not a whole number"
                ))
            })
        };
        Self::new(number(i, "the index")?, number(n, "the count")?)
    }

    /// Shard `index` of `count`.
    ///
    /// # Errors
    /// Unless `index < count <= 100_000`.
    pub fn new(index: usize, count: usize) -> crate::Result<Self> {
        if count == 0 || count > 100_000 {
            return Err(crate::Error::InvalidInput(format!(
                "the shard count must be 1 to 100000 (got {count})"
            )));
        }
        if index >= count {
            return Err(crate::Error::InvalidInput(format!(
                "shard index {index} is not below the count {count} (indices run from 0 to {})",
                count - 1
            )));
        }
        Ok(Self { index, count })
    }

    /// The shard a scheduler's task is, from its environment (`get` reads a variable): Slurm's
    /// `SLURM_ARRAY_TASK_ID` with `SLURM_ARRAY_TASK_COUNT` (or `SLURM_ARRAY_TASK_MIN` and
    /// `_MAX`), or Kubernetes' `JOB_COMPLETION_INDEX` with the count from `count` (a
    /// caller's own setting) or `KILN_SHARD_COUNT`.
    ///
    /// # Errors
    /// Neither scheduler's variables, both, a missing count, or values that do not fit.
    pub fn from_environment(
        get: &dyn Fn(&str) -> Option<String>,
        count: Option<usize>,
    ) -> crate::Result<Self> {
        let number = |name: &str| -> crate::Result<Option<usize>> {
            get(name)
                .map(|v| {
                    v.trim().parse::<usize>().map_err(|_| {
                        crate::Error::InvalidInput(format!("{name}={v} is not a whole number"))
                    })
                })
                .transpose()
        };
        let slurm = number("SLURM_ARRAY_TASK_ID")?;
        let kubernetes = number("JOB_COMPLETION_INDEX")?;
        match (slurm, kubernetes) {
            (Some(_), Some(_)) => Err(crate::Error::InvalidInput(
                "--shard auto: both SLURM_ARRAY_TASK_ID and JOB_COMPLETION_INDEX are set; give \
                 --shard I/N"
                    .into(),
            )),
            (Some(id), None) => {
                let (min, max) = (
                    number("SLURM_ARRAY_TASK_MIN")?,
                    number("SLURM_ARRAY_TASK_MAX")?,
                );
                let min = min.unwrap_or(0);
                let total = match (number("SLURM_ARRAY_TASK_COUNT")?, max) {
                    (Some(n), _) => n,
                    (None, Some(max)) if max >= min => max - min + 1,
                    _ => {
                        return Err(crate::Error::InvalidInput(
                            "--shard auto under Slurm needs SLURM_ARRAY_TASK_COUNT or \
                             SLURM_ARRAY_TASK_MIN and _MAX (submit with --array=0-N)"
                                .into(),
                        ));
                    }
                };
                if id < min {
                    return Err(crate::Error::InvalidInput(format!(
                        "SLURM_ARRAY_TASK_ID={id} is below SLURM_ARRAY_TASK_MIN={min}"
                    )));
                }
                Self::new(id - min, total)
                    .map_err(|e| crate::Error::InvalidInput(format!("--shard auto (Slurm): {e}")))
            }
            (None, Some(index)) => {
                let total = match count {
                    Some(n) => n,
                    None => number("KILN_SHARD_COUNT")?.ok_or_else(|| {
                        crate::Error::InvalidInput(
                            "--shard auto under Kubernetes needs the completion count in \
                             KILN_SHARD_COUNT (JOB_COMPLETION_INDEX alone does not say it)"
                                .into(),
                        )
                    })?,
                };
                Self::new(index, total).map_err(|e| {
                    crate::Error::InvalidInput(format!("--shard auto (Kubernetes): {e}"))
                })
            }
            (None, None) => Err(crate::Error::InvalidInput(
                "--shard auto: neither SLURM_ARRAY_TASK_ID (a Slurm array task) nor \
                 JOB_COMPLETION_INDEX (a Kubernetes indexed job) is set; give --shard I/N"
                    .into(),
            )),
        }
    }

    /// The shard file's name: `kiln-shard-I-of-N.json`.
    #[must_use]
    pub fn file_name(self) -> String {
        format!("kiln-shard-{}-of-{}.json", self.index, self.count)
    }
}

/// The relative cost of integrating texel `k` of `spec`, for balancing shards: the glass
/// tables' quadrature work, measured as integrand evaluations per texel of the 16 x 16 x 16
/// tables at the default tolerance, follows their axes. From inside it grows with the index
/// (1/7 of the rest at `eta = 1`, where nothing refracts, then from 0.65 to 1 along the IOR
/// axis) and with roughness (0.5 to 1); from outside it is 0.65 at `eta = 1` and 2.6 times the
/// rest on the mirror row. Every other table: 1 per texel. A model of cost, which changes the
/// balance, never a value.
#[must_use]
pub fn texel_cost(spec: &TableSpec, k: usize) -> f64 {
    let shape = spec.shape();
    if shape.len() != 3 {
        return 1.0;
    }
    let (n_eta, n_r, n_mu) = (shape[0], shape[1], shape[2]);
    let (i_eta, i_r) = (k / (n_r * n_mu), (k / n_mu) % n_r);
    let t_eta = i_eta as f64 / (n_eta.max(2) - 1) as f64;
    let t_r = i_r as f64 / (n_r.max(2) - 1) as f64;
    match spec.quantity {
        Quantity::EDielectricInside => {
            let along_eta = if i_eta == 0 {
                0.15
            } else {
                0.65 + 0.35 * t_eta
            };
            along_eta * (0.5 + 0.5 * t_r)
        }
        Quantity::EDielectric => {
            let along_eta = if i_eta == 0 { 0.65 } else { 1.0 };
            along_eta * if i_r == 0 { 2.6 } else { 1.0 }
        }
        _ => 1.0,
    }
}

/// The texel ranges of `count` shards of `spec`: contiguous, in order, covering every texel
/// once, of equal estimated cost ([`texel_cost`]) as far as whole texels allow.
#[must_use]
pub fn partition(spec: &TableSpec, count: usize) -> Vec<(usize, usize)> {
    let n = spec.len();
    // The costs are summed twice rather than kept: a table of 2^26 texels would need 512 MiB.
    let total: f64 = (0..n).map(|k| texel_cost(spec, k)).sum();
    let mut bounds = vec![0];
    let mut running = 0.0;
    let mut next = 1;
    for k in 0..n {
        running += texel_cost(spec, k);
        while next < count && running >= total * next as f64 / count as f64 {
            bounds.push(k + 1);
            next += 1;
        }
    }
    while bounds.len() < count {
        bounds.push(n);
    }
    bounds.push(n);
    bounds.windows(2).map(|w| (w[0], w[1])).collect()
}

/// One table's share in a shard file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ShardTable {
    pub spec: TableSpec,
    /// The texels `[start, end)` of the table (row-major, slowest axis first).
    pub range: (usize, usize),
    pub value: Vec<f64>,
    pub one_minus_value: Vec<f64>,
    pub std_error: Vec<f64>,
    /// The check against the reference ([`BakeOptions::check_plan`]) at this shard's texels of
    /// it, in order: each texel's error and whether the reference converged.
    #[serde(default)]
    pub check: Vec<(f64, bool)>,
    /// FNV-1a of the JSON of the spec, range, the three channels and the check.
    pub digest: String,
}

impl ShardTable {
    /// The digest of the share's numbers, as [`ShardTable::digest`] should hold it (FNV-1a:
    /// a check against damage, not a signature; anyone can recompute it).
    #[must_use]
    pub fn compute_digest(&self) -> String {
        let json = serde_json::to_vec(&(
            &self.spec,
            self.range,
            &self.value,
            &self.one_minus_value,
            &self.std_error,
            &self.check,
        ))
        .expect("a shard serialises");
        format!("{:016x}", fnv1a(&json))
    }
}

/// What is baked and written: the same for every shard of one bake.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ShardedBake {
    pub options: BakeOptions,
    pub formats: Vec<Format>,
    pub precision: Precision,
}

impl ShardedBake {
    /// FNV-1a of the bake's JSON and kiln's versions: shards of one bake share it.
    #[must_use]
    pub fn digest(&self) -> String {
        let json = serde_json::to_vec(&(
            self,
            crate::format::metadata::KILN_VERSION,
            crate::cache::NUMERICS_VERSION,
        ))
        .expect("a bake serialises");
        format!("{:016x}", fnv1a(&json))
    }
}

/// A shard file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ShardFile {
    pub kind: String,
    pub kiln_version: String,
    pub numerics_version: u32,
    pub bake: ShardedBake,
    pub bake_digest: String,
    pub index: usize,
    pub count: usize,
    pub tables: Vec<ShardTable>,
}

/// The tables of `options` that are integrated texel by texel (all but the derived
/// `f_ms_norm`), in bake order.
fn integrated_specs(options: &BakeOptions) -> Vec<TableSpec> {
    options
        .resolved()
        .specs()
        .into_iter()
        .filter(|s| s.quantity != Quantity::FMsNorm)
        .collect()
}

/// Integrates shard `shard` of `bake`: its range of every table's texels, in parallel
/// (deterministic for any thread count). `progress` is called with the samples of each texel.
///
/// # Errors
/// Invalid options, or a texel that is not finite.
pub fn bake_shard(
    bake: &ShardedBake,
    shard: ShardIndex,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<ShardFile> {
    bake.options.validate()?;
    let resolved = bake.options.resolved();
    let mut tables = Vec::new();
    for spec in integrated_specs(&bake.options) {
        let range = partition(&spec, shard.count)[shard.index];
        let estimates: Vec<_> = (range.0..range.1)
            .into_par_iter()
            .map(|k| {
                let e = estimate_texel(&spec, k);
                progress(spec.qmc.samples);
                e
            })
            .collect();
        let mut piece = ShardTable {
            value: estimates.iter().map(|e| e.value).collect(),
            one_minus_value: estimates.iter().map(|e| e.one_minus_value).collect(),
            std_error: estimates.iter().map(|e| e.std_error).collect(),
            spec,
            range,
            check: Vec::new(),
            digest: String::new(),
        };
        if let Some(k) = (0..piece.value.len()).find(|&k| {
            !(piece.value[k].is_finite()
                && piece.one_minus_value[k].is_finite()
                && piece.std_error[k].is_finite())
        }) {
            return Err(Error::InvalidInput(format!(
                "{}: texel {} is not finite (value {}, error {}): nothing was written",
                piece.spec.id(),
                range.0 + k,
                piece.value[k],
                piece.std_error[k]
            )));
        }
        // This shard's part of the check against the reference, measured here in parallel with
        // the other shards (the merge only sums it up).
        if let Some((indices, settings)) = bake.options.check_plan(&resolved, &piece.spec) {
            let mine: Vec<usize> = indices
                .into_iter()
                .filter(|k| (range.0..range.1).contains(k))
                .collect();
            piece.check = crate::verify::node_error_terms(
                &piece.spec,
                &mine,
                &|k| (piece.value[k - range.0], piece.one_minus_value[k - range.0]),
                &settings,
            );
        }
        piece.digest = piece.compute_digest();
        tables.push(piece);
    }
    Ok(ShardFile {
        kind: KIND.to_string(),
        kiln_version: crate::format::metadata::KILN_VERSION.to_string(),
        numerics_version: crate::cache::NUMERICS_VERSION,
        bake_digest: bake.digest(),
        bake: bake.clone(),
        index: shard.index,
        count: shard.count,
        tables,
    })
}

/// Reads the shard files among `paths` (files, or directories whose `kiln-shard-*.json` files
/// are taken), each with the path it came from.
///
/// # Errors
/// An unreadable or damaged file, or a path with no shard file.
pub fn read_shards(paths: &[PathBuf]) -> Result<Vec<(PathBuf, ShardFile)>> {
    let mut files = Vec::new();
    for path in paths {
        if path.is_dir() {
            let mut found: Vec<PathBuf> = std::fs::read_dir(path)
                .map_err(|source| Error::Io {
                    path: path.clone(),
                    action: "list",
                    source,
                })?
                .flatten()
                .map(|e| e.path())
                .filter(|p| {
                    p.file_name()
                        .and_then(|n| n.to_str())
                        .is_some_and(|n| n.starts_with("kiln-shard-") && n.ends_with(".json"))
                })
                .collect();
            if found.is_empty() {
                return Err(Error::InvalidInput(format!(
                    "{}: no kiln-shard-*.json files in it",
                    path.display()
                )));
            }
            found.sort();
            files.extend(found);
        } else {
            files.push(path.clone());
        }
    }
    files
        .into_iter()
        .map(|path| {
            let bytes = crate::format::read_file(&path)?;
            let shard: ShardFile = serde_json::from_slice(&bytes).map_err(|e| {
                Error::InvalidInput(format!(
                    "{}: not a readable kiln shard file ({e}): damaged, or cut short",
                    path.display()
                ))
            })?;
            if shard.kind != KIND {
                return Err(Error::InvalidInput(format!(
                    "{}: not a kiln shard file (kind '{}')",
                    path.display(),
                    crate::error::quoted(&shard.kind)
                )));
            }
            Ok((path, shard))
        })
        .collect()
}

/// Checks that `shards` are all the shards of one bake, each whole, and merges them into the
/// bake's tables, finished exactly as the unsharded bake finishes them
/// ([`BakeOptions::confirm`]; `f_ms_norm` derived from the merged `E`).
///
/// # Errors
/// Shards of different bakes or kiln versions, a count that differs, a missing or duplicated
/// index, a table range that is not the partition's, a digest that does not hold (each naming
/// the shard file and the texel range), or the bake's own checks.
pub fn merge(shards: &[(PathBuf, ShardFile)]) -> Result<(ShardedBake, Vec<Table>)> {
    let Some((_, first)) = shards.first() else {
        return Err(Error::InvalidInput("no shard files to merge".into()));
    };
    let count = first.count;
    check_one_bake(shards)?;
    let specs = integrated_specs(&first.bake.options);
    let by_index = shards_by_index(shards, count, &specs)?;
    let options = first.bake.options.resolved();
    let mut tables: Vec<Table> = Vec::new();
    // The index of the next integrated table in each shard's list.
    let mut t = 0;
    for spec in options.specs() {
        let command = first.bake.options.command_for(spec.model);
        if spec.quantity == Quantity::FMsNorm {
            let table = crate::table::normalisation::derive_from(&spec, &tables, command)?;
            tables.push(table);
            continue;
        }
        let ranges = partition(&spec, count);
        // Grown from the shards' own numbers, each checked against its range first: nothing is
        // sized by what a shard claims.
        let (mut value, mut one_minus_value, mut std_error, mut check) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        let plan = first.bake.options.check_plan(&options, &spec);
        let mut shares = Vec::with_capacity(count);
        for (index, entry) in by_index.iter().enumerate() {
            let (path, shard) = entry;
            let range = ranges[index];
            let piece = share_of(path, shard, t, &spec, (index, count), range, plan.as_ref())?;
            value.extend(&piece.value);
            one_minus_value.extend(&piece.one_minus_value);
            std_error.extend(&piece.std_error);
            check.extend(&piece.check);
            shares.push(Share {
                path,
                index,
                range,
                piece,
            });
        }
        confirm_shares(&spec, &shares, plan.as_ref())?;
        let table = Table::unmeasured(spec, [value, one_minus_value, std_error], command);
        // The check's texels are in ascending order and the shards' ranges too: the
        // concatenation is the unsharded bake's sequence of terms, summed in the same order.
        let terms = plan.map(|_| check);
        tables.push(
            first
                .bake
                .options
                .confirm_with(table, terms.as_deref(), &|_| {})?,
        );
        t += 1;
    }
    Ok((first.bake.clone(), tables))
}

/// Checks that every shard is of one bake: its index and count valid, the same options (their
/// digest recomputed), this kiln's versions, one count, and options `kiln bake` would run.
fn check_one_bake(shards: &[(PathBuf, ShardFile)]) -> Result<()> {
    let name = |p: &Path| p.display().to_string();
    let (first_path, first) = &shards[0];
    let count = first.count;
    // Each shard's own index and count within what `--shard` accepts, before any is used to
    // size anything.
    for (path, shard) in shards {
        ShardIndex::new(shard.index, shard.count)
            .map_err(|e| Error::InvalidInput(format!("{}: index and count: {e}", name(path))))?;
    }
    for (path, shard) in shards {
        if shard.bake_digest != first.bake_digest
            || shard.bake != first.bake
            || shard.bake.digest() != shard.bake_digest
        {
            return Err(Error::InvalidInput(format!(
                "{} is a shard of another bake than {} (other options, formats or kiln version)",
                name(path),
                name(first_path)
            )));
        }
        if shard.kiln_version != crate::format::metadata::KILN_VERSION
            || shard.numerics_version != crate::cache::NUMERICS_VERSION
        {
            return Err(Error::InvalidInput(format!(
                "{} was baked by kiln {} (numerics {}); this is kiln {} (numerics {}): bake the \
                 shards again with this kiln",
                name(path),
                shard.kiln_version,
                shard.numerics_version,
                crate::format::metadata::KILN_VERSION,
                crate::cache::NUMERICS_VERSION
            )));
        }
        if shard.count != count {
            return Err(Error::InvalidInput(format!(
                "{} is shard {} of {}, but {} is of {count}",
                name(path),
                shard.index,
                shard.count,
                name(first_path)
            )));
        }
    }
    // The options are covered by the bake digest, which anyone can recompute: they get every
    // check `kiln bake` applies (each axis, their product, memory, time) before anything is
    // sized by them.
    first.bake.options.validate().map_err(|e| {
        Error::InvalidInput(format!(
            "{}: its bake options are not a bake kiln runs: {e}",
            name(first_path)
        ))
    })?;
    Ok(())
}

/// The shards in index order, each index below the count and given once, none missing (the
/// missing one's texel ranges of `specs` said).
fn shards_by_index<'a>(
    shards: &'a [(PathBuf, ShardFile)],
    count: usize,
    specs: &[TableSpec],
) -> Result<Vec<&'a (PathBuf, ShardFile)>> {
    let name = |p: &Path| p.display().to_string();
    let mut by_index: Vec<Option<&(PathBuf, ShardFile)>> = vec![None; count];
    for entry in shards {
        let (path, shard) = entry;
        if shard.index >= count {
            return Err(Error::InvalidInput(format!(
                "{}: shard index {} is not below its count {count}",
                name(path),
                shard.index
            )));
        }
        if let Some((other, _)) = by_index[shard.index] {
            return Err(Error::InvalidInput(format!(
                "{} and {} are both shard {} of {count}: give each shard once",
                name(other),
                name(path),
                shard.index
            )));
        }
        by_index[shard.index] = Some(entry);
    }
    if let Some(missing) = by_index.iter().position(Option::is_none) {
        let ranges: Vec<String> = specs
            .iter()
            .map(|s| {
                let r = partition(s, count)[missing];
                format!("{} texels {}..{}", s.id(), r.0, r.1)
            })
            .collect();
        return Err(Error::InvalidInput(format!(
            "shard {missing} of {count} is missing ({}): run it (kiln bake ... --shard \
             {missing}/{count}) and merge again",
            ranges.join(", ")
        )));
    }
    Ok(by_index
        .into_iter()
        .map(|e| e.expect("checked above"))
        .collect())
}

/// Shard `index` of `count`'s share of table `t` (`spec`), checked: its texel range, its lengths,
/// its digest, and the count of its checked texels (`plan`'s in its range).
fn share_of<'a>(
    path: &Path,
    shard: &'a ShardFile,
    t: usize,
    spec: &TableSpec,
    (index, count): (usize, usize),
    range: (usize, usize),
    plan: Option<&(Vec<usize>, crate::integrate::reference::ReferenceSettings)>,
) -> Result<&'a ShardTable> {
    let name = |p: &Path| p.display().to_string();
    let piece = shard
        .tables
        .get(t)
        .filter(|p| p.spec == *spec)
        .ok_or_else(|| {
            Error::InvalidInput(format!(
                "{}: has no share of {} (texels {}..{})",
                name(path),
                spec.id(),
                range.0,
                range.1
            ))
        })?;
    let n = range.1 - range.0;
    if piece.range != range
        || piece.value.len() != n
        || piece.one_minus_value.len() != n
        || piece.std_error.len() != n
    {
        return Err(Error::InvalidInput(format!(
            "{}: its share of {} is texels {}..{} with {} values, where shard {index} of \
             {count} takes texels {}..{}",
            name(path),
            spec.id(),
            piece.range.0,
            piece.range.1,
            piece.value.len(),
            range.0,
            range.1
        )));
    }
    if piece.compute_digest() != piece.digest {
        return Err(Error::InvalidInput(format!(
            "{}: the digest of {} texels {}..{} does not hold: the file was damaged or \
             edited; run shard {index} again",
            name(path),
            spec.id(),
            range.0,
            range.1
        )));
    }
    let checked = plan.map_or(0, |(indices, _)| {
        indices
            .iter()
            .filter(|k| (range.0..range.1).contains(*k))
            .count()
    });
    if piece.check.len() != checked {
        return Err(Error::InvalidInput(format!(
            "{}: {} checked texels of {} in texels {}..{}, where the check takes {checked}",
            name(path),
            piece.check.len(),
            spec.id(),
            range.0,
            range.1
        )));
    }
    Ok(piece)
}

/// One shard's share of a table, as the merge found it.
struct Share<'a> {
    path: &'a Path,
    index: usize,
    range: (usize, usize),
    piece: &'a ShardTable,
}

/// Texels and check terms the merge computes again per table, spread over the shards (at least
/// one of each per shard): `confirm_shares`.
pub const MERGE_CONFIRMATIONS: usize = 16;

/// `m` of the `n` positions `0..n`, evenly spread from an offset keyed by `key` (a shard's
/// digest: an edit moves them).
fn keyed_positions(n: usize, m: usize, key: &str) -> Vec<usize> {
    let m = m.min(n);
    let offset = (fnv1a(key.as_bytes()) % n.max(1) as u64) as usize;
    (0..m).map(|j| (offset + j * n / m) % n).collect()
}

/// Whether `a` and `b` differ by at most `tolerance` (false if either is NaN).
fn agrees(a: f64, b: f64, tolerance: f64) -> bool {
    (a - b).abs() <= tolerance
}

/// Confirms what the shards claim about `spec` by computing part of it again, since a digest
/// proves only that a file is as its writer left it, and anyone can recompute it: at
/// [`MERGE_CONFIRMATIONS`] texels spread over the shards (positions keyed by each share's
/// digest), the texel's estimate ([`estimate_texel`], deterministic) must be the stored value
/// and error estimate; at as many of the check's texels, the check's term (the node error
/// against the reference, [`crate::verify::node_error_terms`]) must be the one the shard
/// states. Both agree to within a thousandth of their own error estimate (a last-digit
/// difference of another machine's maths library passes; an edit does not). The error names
/// the shard file, the table and the texel.
fn confirm_shares(
    spec: &TableSpec,
    shares: &[Share<'_>],
    plan: Option<&(Vec<usize>, crate::integrate::reference::ReferenceSettings)>,
) -> Result<()> {
    let per_share = MERGE_CONFIRMATIONS.div_ceil(shares.len().max(1));
    let again = |share: &Share<'_>, what: &str, k: usize, stored: f64, computed: f64| {
        Error::InvalidInput(format!(
            "{}: {what} of {} at texel {k} is {stored:e}, but kiln computes {computed:e} there: \
             the shard was edited, or baked by another build of kiln; nothing was written. Run \
             shard {} of {} again",
            share.path.display(),
            spec.id(),
            share.index,
            shares.len()
        ))
    };
    let texels: Vec<(usize, usize)> = shares
        .iter()
        .enumerate()
        .flat_map(|(s, share)| {
            let n = share.range.1 - share.range.0;
            keyed_positions(n, per_share, &share.piece.digest)
                .into_iter()
                .map(move |j| (s, j))
        })
        .collect();
    let estimates: Vec<_> = texels
        .par_iter()
        .map(|&(s, j)| estimate_texel(spec, shares[s].range.0 + j))
        .collect();
    for (&(s, j), computed) in texels.iter().zip(&estimates) {
        let share = &shares[s];
        let k = share.range.0 + j;
        let tolerance = (1e-3 * computed.std_error).max(1e-13);
        for (what, stored, computed) in [
            ("the value", share.piece.value[j], computed.value),
            (
                "the one-minus value",
                share.piece.one_minus_value[j],
                computed.one_minus_value,
            ),
            (
                "the error estimate",
                share.piece.std_error[j],
                computed.std_error,
            ),
        ] {
            if !agrees(stored, computed, tolerance) {
                return Err(again(share, what, k, stored, computed));
            }
        }
    }
    let Some((indices, settings)) = plan else {
        return Ok(());
    };
    // The check's texels of each share, in order, and their terms in the share's list.
    let mut terms = Vec::new();
    for (s, share) in shares.iter().enumerate() {
        let mine: Vec<usize> = indices
            .iter()
            .copied()
            .filter(|k| (share.range.0..share.range.1).contains(k))
            .collect();
        for j in keyed_positions(mine.len(), per_share, &share.piece.digest) {
            terms.push((s, j, mine[j]));
        }
    }
    let at: Vec<usize> = terms.iter().map(|t| t.2).collect();
    let computed = crate::verify::node_error_terms(
        spec,
        &at,
        &|k| {
            let share = shares
                .iter()
                .find(|s| (s.range.0..s.range.1).contains(&k))
                .expect("a check texel lies in a share");
            let j = k - share.range.0;
            (share.piece.value[j], share.piece.one_minus_value[j])
        },
        settings,
    );
    let tolerance = (1e-3 * settings.tolerance).max(1e-13);
    for (&(s, j, k), &(error, converged)) in terms.iter().zip(&computed) {
        let share = &shares[s];
        let (stated, stated_converged) = share.piece.check[j];
        if !agrees(stated, error, tolerance) || stated_converged != converged {
            return Err(again(
                share,
                "the stated node error against the reference",
                k,
                stated,
                error,
            ));
        }
    }
    Ok(())
}
