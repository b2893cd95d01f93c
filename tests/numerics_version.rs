//! The cache key carries `kiln::cache::NUMERICS_VERSION`, the version of kiln's numbers, so that
//! no scene cache or build script reuses a table the current code would not make. This test
//! holds digests of small tables of every kind for that version: when a change alters any
//! stored number, it fails until the version is bumped and the digests are renewed.
//!
//! Values are digested at 9 significant digits, so that a machine whose last bits differ (FMA,
//! SIMD width) does not fail, while any change of substance does.

use kiln::cache::{NUMERICS_VERSION, fnv1a};
use kiln::{BakeOptions, IorMapping, Method, Ndf, Quantity, Table};

/// The digests of [`NUMERICS_VERSION`]: (version, table, FNV-1a of its values at 9 digits).
const GOLDEN: &[(u32, &str, &str)] = &[
    (15, "ggx-height-correlated-E Reference", "e78434a9206f69c9"),
    (
        15,
        "ggx-height-correlated-E_avg Reference",
        "2ecda5e9db154255",
    ),
    (
        15,
        "ggx-height-correlated-f_ms_norm Reference",
        "43730417e530a426",
    ),
    (15, "ggx-height-correlated-E Reference", "04365182607f6052"),
    (
        15,
        "beckmann-height-correlated-E Reference",
        "814d770d235263bc",
    ),
    (
        15,
        "beckmann-height-correlated-E_avg Reference",
        "1183534138a94430",
    ),
    (
        15,
        "ggx-height-correlated-E_scale-mu-linear Reference",
        "5855b395dd37186c",
    ),
    (
        15,
        "ggx-height-correlated-E_bias-mu-linear Reference",
        "149f2472c7115111",
    ),
    (
        15,
        "ggx-height-correlated-E_dielectric-ior-cycles Reference",
        "8be1bdf15cfb3879",
    ),
    (
        15,
        "ggx-height-correlated-E_dielectric_inside-ior-cycles Reference",
        "e356d879e557929f",
    ),
    (
        15,
        "ggx-height-correlated-E_avg_dielectric-ior-cycles Reference",
        "0ac0e7f33eecbccc",
    ),
    (
        15,
        "ggx-height-correlated-E_avg_dielectric_inside-ior-cycles Reference",
        "ab14230185748a72",
    ),
    (15, "dielectric-F_avg Reference", "6721c906b37a9454"),
    (
        15,
        "ggx-height-correlated-E_dielectric Reference",
        "beba823abc752931",
    ),
    (
        15,
        "ggx-height-correlated-E_dielectric_inside Reference",
        "f8533964b20161c1",
    ),
    (
        15,
        "ggx-height-correlated-E_avg_dielectric Reference",
        "f185cd27d01bb1bd",
    ),
    (
        15,
        "ggx-height-correlated-E_avg_dielectric_inside Reference",
        "0ac9db63dbeb8ccf",
    ),
    (15, "ggx-height-correlated-E Qmc", "0ab19d73f47d236b"),
    (15, "ggx-height-correlated-E_avg Qmc", "8687df7937745f15"),
    (15, "beckmann-height-correlated-E Qmc", "857b2cc0cdc45723"),
    (
        15,
        "beckmann-height-correlated-E_avg Qmc",
        "c70c33c6940ff7d3",
    ),
    (
        15,
        "ggx-height-correlated-E_dielectric-ior-cycles Qmc",
        "499cd44787ed1757",
    ),
];

fn digest(table: &Table) -> String {
    let text: String = table
        .value
        .iter()
        .chain(&table.one_minus_value)
        .map(|v| format!("{v:.8e};"))
        .collect();
    format!("{:016x}", fnv1a(text.as_bytes()))
}

fn tables() -> Vec<Table> {
    let base = BakeOptions {
        size: 5,
        ior_size: 3,
        max_error: Some(1e-6),
        ..BakeOptions::default()
    };
    let bake = |options: BakeOptions| options.bake(&|_| {}).unwrap();
    let mut all = bake(base.clone());
    // The default `E` at its default size: the lookup fit's points thin out from 32 cells up
    // (`LookupFitSettings::for_cells`), which a 5 x 5 table never reaches.
    all.extend(bake(BakeOptions {
        size: 32,
        quantities: vec![Quantity::E],
        ..base.clone()
    }));
    all.extend(bake(BakeOptions {
        ndfs: vec![Ndf::Beckmann],
        quantities: vec![Quantity::E, Quantity::EAvg],
        ..base.clone()
    }));
    all.extend(bake(BakeOptions {
        quantities: vec![Quantity::EScale, Quantity::EBias],
        mu_mapping: Some(kiln::MuMapping::Linear),
        ..base.clone()
    }));
    let glass = [
        Quantity::EDielectric,
        Quantity::EDielectricInside,
        Quantity::EAvgDielectric,
        Quantity::EAvgDielectricInside,
    ];
    all.extend(bake(BakeOptions {
        quantities: [&glass[..], &[Quantity::FAvg]].concat(),
        ior_mapping: IorMapping::Cycles,
        ..base.clone()
    }));
    // kiln's glass layout (the default for the dielectric albedos).
    all.extend(bake(BakeOptions {
        quantities: glass.to_vec(),
        ..base.clone()
    }));
    let qmc = BakeOptions {
        quantities: vec![Quantity::E, Quantity::EAvg],
        method: Method::Qmc,
        max_error: None,
        samples: 1 << 10,
        average_samples: 1 << 10,
        check_against_reference: false,
        ..base
    };
    all.extend(bake(qmc.clone()));
    // Each way the Beckmann sum places its points (the ladder, the lost circle, the reflected
    // directions) and the dielectric's strata.
    all.extend(bake(BakeOptions {
        ndfs: vec![Ndf::Beckmann],
        ..qmc.clone()
    }));
    all.extend(bake(BakeOptions {
        quantities: vec![Quantity::EDielectric],
        ior_mapping: IorMapping::Cycles,
        ..qmc
    }));
    all
}

#[test]
fn the_numbers_are_those_of_the_numerics_version() {
    let found: Vec<(String, String)> = tables()
        .iter()
        .map(|t| (format!("{} {:?}", t.spec.id(), t.spec.method), digest(t)))
        .collect();
    let listing: String = found
        .iter()
        .map(|(id, d)| format!("    ({NUMERICS_VERSION}, \"{id}\", \"{d}\"),\n"))
        .collect();
    let renew = format!(
        "if the change of numbers is intended, bump NUMERICS_VERSION in src/cache.rs (so that \
         caches rebake) and set GOLDEN in tests/numerics_version.rs to:\n{listing}"
    );
    assert!(
        GOLDEN.iter().all(|g| g.0 == NUMERICS_VERSION),
        "NUMERICS_VERSION is {NUMERICS_VERSION} but the digests are of another version; {renew}"
    );
    assert_eq!(GOLDEN.len(), found.len(), "{renew}");
    for ((_, id, want), (found_id, got)) in GOLDEN.iter().zip(&found) {
        assert_eq!(id, found_id, "{renew}");
        assert_eq!(
            want, got,
            "the numbers of {id} changed under NUMERICS_VERSION {NUMERICS_VERSION}; {renew}"
        );
    }
}
