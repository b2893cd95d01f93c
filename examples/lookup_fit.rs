//! Fits a kiln table's texels for its lookup and audits both the node table and the fitted one
//! with `kiln verify`'s lookup audit: `cargo run --release --example lookup_fit -- FILE.json`.
use kiln::table::lookup_fit::{LookupFitSettings, fit_for_lookup};
use kiln::verify::{Against, AuditSettings, audit};

fn main() {
    let path = std::env::args().nth(1).expect("a kiln table file");
    let mut table = kiln::verify::input::read_kiln(std::path::Path::new(&path))
        .expect("readable")
        .expect("a kiln file");
    let against = Against::Reference(Default::default());
    let settings = AuditSettings {
        density: 4,
        ..AuditSettings::default()
    };
    let before = audit(&table, &against, &settings, &|_| {});
    let cells = table.spec.shape().into_iter().max().unwrap();
    let mut fit_settings = LookupFitSettings::for_cells(cells);
    if let Some(c) = std::env::args().nth(3) {
        fit_settings.weight_cap = c.parse().unwrap();
    }
    if let Some(n) = std::env::args().nth(2) {
        fit_settings.iterations = n.parse().unwrap();
    }
    let start = std::time::Instant::now();
    let report = fit_for_lookup(&mut table, &fit_settings, &[], &|| {});
    let seconds = start.elapsed().as_secs_f64();
    let after = audit(&table, &against, &settings, &|_| {});
    println!("fit: {report:?} in {seconds:.2} s");
    for (name, r) in [("nodes ", &before), ("fitted", &after)] {
        println!(
            "{name}: lookup max {:.3e} rms {:.3e} p99 {:.3e} worst {:?}; node max {:.3e}",
            r.lookup_max_error,
            r.lookup_rms_error,
            r.lookup_p99_error,
            r.worst_lookup,
            r.node_max_error
        );
    }
}
