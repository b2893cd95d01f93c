//! kiln's integration tests, one binary: each file beside this one is a module named after what
//! it checks (`cargo test --release --test suite NAME::` runs one file's tests). One binary
//! instead of one per file: the suite's build links once and instantiates the library's generic
//! code once (issue 63). The helpers under `common/` are declared once below and used by path.
//! `hostile_input.rs` and `hostile_shards.rs` stay binaries of their own: they install a counting
//! global allocator (`common/watching.rs`) whose largest request other tests would disturb.

// The helpers, once for every file (`use crate::NAME`).
#[path = "common/command.rs"]
mod command;
mod common;
#[path = "common/compensation_bake.rs"]
mod compensation_bake;
#[path = "common/cxx.rs"]
mod cxx;
#[path = "common/external.rs"]
mod external;
#[path = "common/f16_oracle.rs"]
mod f16_oracle;
#[path = "common/lookup_audit.rs"]
mod lookup_audit;
#[path = "common/rng.rs"]
mod rng;
#[path = "common/rustc.rs"]
mod rustc;
#[path = "common/shader_cases.rs"]
mod shader_cases;

// The tests, a file each.
mod accuracy;
mod anisotropic;
mod audit_tolerance;
mod balanced_layout;
mod build_script;
mod cli;
mod cli_promises;
mod coats;
mod containers;
mod cycles_glass;
mod default_tables;
mod dielectric;
mod dielectric_tables;
mod engine_files;
mod error_maps;
mod f16_rounding;
mod fits;
mod fresnel;
mod furnace;
mod generated_rust;
mod glass_layout;
mod glass_one_ior;
mod gpu_shaders;
mod hard_cases;
mod hard_grid;
mod hostile_code;
mod hostile_examples;
mod hostile_limits;
mod lookup_fit;
mod max_error;
mod microsurface_walk;
mod normalisation_accuracy;
mod numerics_version;
mod presets;
mod qmc_convergence;
mod readme;
mod reference;
mod scene;
mod schlick_ggx;
mod shader_execution;
mod shaders;
mod shard;
mod split_sum_layout;
mod stated_errors;
mod study;
mod verify;
