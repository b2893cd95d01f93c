//! kiln bakes the lookup tables energy-conserving microfacet materials need: the directional
//! albedo `E(mu, roughness)` and its average `E_avg(roughness)` of GGX and Beckmann BRDFs, for
//! Kulla and Conty's multiple-scattering compensation.
//!
//! The library is what the `kiln` command runs; a build script can use it with
//! `default-features = false` and pull none of the command line's dependencies.
//!
//! ```
//! use kiln::{BakeOptions, Format, Ndf, Precision};
//!
//! // A small, fast GGX table: 8 x 8 texels by QMC, 2^12 samples each (the default instead
//! // bakes to `max_error: Some(1e-7)` by the deterministic quadrature).
//! let options = BakeOptions {
//!     ndfs: vec![Ndf::Ggx],
//!     size: 8,
//!     samples: 1 << 12,
//!     average_samples: 1 << 14,
//!     max_error: None,
//!     ..BakeOptions::default()
//! };
//! let tables = options.bake(&|_samples_done| {})?;
//! let e = &tables[0];
//! assert_eq!(e.spec.id(), "ggx-height-correlated-E");
//! assert!(e.value.iter().all(|&v| (0.0..=1.0).contains(&v)));
//!
//! let dir = tempfile::tempdir().unwrap();
//! let written = kiln::format::write_tables(
//!     dir.path(),
//!     &tables,
//!     &[Format::Exr, Format::Json],
//!     Precision::F16,
//!     kiln::format::replace::Replace::Refuse,
//! )?;
//! assert_eq!(written.len(), 6); // E, E_avg and f_ms_norm, each as EXR and JSON
//! # Ok::<(), kiln::Error>(())
//! ```
//!
//! A build script (`build.rs`) of an engine crate that depends on kiln with
//! `default-features = false`, bakes what its scene needs into `OUT_DIR` (through kiln's cache
//! there, so an unchanged scene costs nothing) and `include!`s the Rust tables
//! (`examples/build-script` is such a crate, built and run by the tests):
//!
//! ```no_run
//! // build.rs
//! use std::path::{Path, PathBuf};
//!
//! fn main() -> Result<(), kiln::Error> {
//!     println!("cargo::rerun-if-changed=scene.toml");
//!     let out = PathBuf::from(std::env::var("OUT_DIR").expect("cargo sets OUT_DIR"));
//!     let scene = kiln::scene::Scene::read(Path::new("scene.toml"))?;
//!     // OUT_DIR is this build's own: a changed scene replaces what an earlier build wrote.
//!     let baked = scene.bake(&out, &|_samples| {}, kiln::format::replace::Replace::Force)?;
//!     for table in &baked.report.baked {
//!         println!("cargo::warning=kiln baked {table}");
//!     }
//!     Ok(())
//! }
//! // src/lib.rs then holds, for the scene's GGX tables:
//! // include!(concat!(env!("OUT_DIR"), "/ggx-height-correlated-E.rs"));
//! ```
//!
//! Conventions, everywhere: `mu = cos(theta)` of the view direction; roughness is either the
//! perceptual `r` with `alpha = r^2` or `alpha` itself, and every table says which; grids put
//! samples at nodes `i / (N - 1)` (the default) or at texel centres `(i + 0.5) / N`.

pub mod bake;
pub mod cache;
pub mod error;
pub mod fit;
pub mod format;
pub mod integrate;
pub mod model;
pub mod numerics;
pub mod preset;
pub mod scene;
pub mod shard;
pub mod stats;
pub mod study;
pub mod table;
pub mod verify;

pub use bake::{BakeOptions, bake_table};
pub use error::{Error, Result};
pub use format::{Format, Precision};
pub use integrate::{Estimate, QmcSettings, albedo, average_albedo};
pub use model::{Fresnel, Masking, Model, Ndf, RoughnessConvention};
pub use table::axis::{Axis, Grid, IorMapping, MuMapping, RoughnessSpacing};
pub use table::{Method, Quantity, Table, TableSpec};
