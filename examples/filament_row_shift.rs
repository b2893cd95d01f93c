//! What Filament's own row convention costs: writes `dfg.inc` in the `filament` preset's layout
//! but with GL row `j` computed at `r = min(1, (j + 1.5) / 128)`, as Filament's `cmgen` does
//! (`CubemapIBL::DFG` evaluates image row `y` at `saturate((128 - y + 0.5) / 128)`, then the rows
//! are flipped), with kiln's deterministic reference values instead of Filament's 1024-sample
//! estimate, so that only the row shift is measured. Audit it with
//! `kiln verify --preset filament FILE` and compare with kiln's own `--preset filament` bake.
//!
//! Usage: `cargo run --release --example filament_row_shift -- OUT.inc`
use rayon::prelude::*;

fn main() -> kiln::Result<()> {
    let out = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "filament-row-shift.inc".to_string());
    let preset = kiln::preset::Preset::Filament;
    // Only the tables' specs and commands are kept; the values are replaced below.
    let mut tables = kiln::BakeOptions {
        max_error: Some(1e-3),
        ..preset.options()
    }
    .bake(&|_| {})?;
    let n = preset.options().size;
    let settings = kiln::integrate::reference::ReferenceSettings::default();
    for table in &mut tables {
        let spec = table.spec.clone();
        table.value = (0..n * n)
            .into_par_iter()
            .map(|k| {
                let r = (((k / n) as f64 + 1.5) / n as f64).min(1.0);
                let mu = ((k % n) as f64 + 0.5) / n as f64;
                let at = kiln::integrate::value::Point {
                    alpha: r * r,
                    mu: Some(mu),
                    eta: None,
                };
                spec.integral().reference(at, &settings).value
            })
            .collect();
    }
    // Staged and renamed into place: an interrupted run leaves no partial file.
    let out = std::path::Path::new(&out);
    let dir = out.parent().filter(|p| !p.as_os_str().is_empty());
    let name = out.file_name().expect("a file name").to_string_lossy();
    let files = [(name.to_string(), preset.encode(&tables)?)];
    let written = kiln::format::write_files(dir.unwrap_or(std::path::Path::new(".")), &files)?;
    println!("wrote {}", written[0].display());
    Ok(())
}
