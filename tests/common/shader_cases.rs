//! What the shader tests run and what they expect: the default tables (kiln's balanced layout
//! with fitted texels: both of its coordinates computed in the shader) and a second layout
//! (the split-sum `E_bias` on its own mu axis, on texel centres, 8 x 8) baked with the
//! generated shaders, the points the
//! shaders are called at, and the library's value at each with the tolerance f32 allows.
//! `tests/shader_execution.rs` runs the points as C++, `tests/gpu_shaders.rs` on Vulkan.

use kiln::model::kulla_conty::{fresnel_colour, multiple_scattering};
use kiln::table::normalisation::normalisation_lookup;
use kiln::verify::input::read_kiln;
use kiln::verify::{AuditSettings, lookup_coordinates};
use kiln::{Quantity, Table};
use std::path::{Path, PathBuf};

use crate::command;

/// The generated files every test loads, by stem.
pub const TABLE_FILES: [&str; 4] = [
    "ggx-height-correlated-E",
    "ggx-height-correlated-E_bias-centers",
    "ggx-height-correlated-E_avg",
    "ggx-height-correlated-f_ms_norm",
];

/// The point sets, in the order the tests call them, with the inputs that make one point.
pub const POINT_SETS: [(&str, usize); 5] = [
    ("E lookups", 2),
    ("centres lookups", 2),
    ("1-D lookups", 1),
    ("lobes", 3),
    ("colours", 2),
];

pub struct Cases {
    dir: tempfile::TempDir,
    pub e: Table,
    pub avg: Table,
    pub norm: Table,
    pub centres: Table,
    /// (mu, r) pairs: every point `verify` audits on E, then on the centres layout.
    pub e_points: Vec<f64>,
    pub c_points: Vec<f64>,
    /// r on a dense ladder, for E_avg and f_ms_norm.
    pub ladder: Vec<f64>,
    /// (1 - E_o, 1 - E_i, r) triples for the lobe.
    pub lobes: Vec<f64>,
    /// (F_avg, E_avg) pairs for the lobe's colour and Turquin's factor.
    pub fresnels: Vec<f64>,
}

fn bake(formats: &str, extra: &[&str], out: &Path) {
    let mut args = vec![
        "bake",
        "--format",
        formats,
        "-q",
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    let baked = command::kiln(&args);
    assert!(
        baked.status.success(),
        "{}",
        String::from_utf8_lossy(&baked.stderr)
    );
}

fn read(dir: &Path, name: &str) -> Table {
    read_kiln(&dir.join(format!("{name}.json")))
        .unwrap()
        .unwrap()
}

fn f32_of(v: f64) -> f64 {
    f64::from(v as f32)
}

impl Cases {
    /// Bakes both layouts with the given shader `languages` (their file extensions).
    pub fn bake(languages: &[&str]) -> Cases {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path().to_path_buf();
        let formats = format!("{},json", languages.join(","));
        bake(&formats, &[], &d);
        let other = d.join("centres");
        bake(
            &formats,
            &["--grid", "centers", "--size", "8", "--quantity", "e-bias"],
            &other,
        );
        for language in languages {
            let name = format!("ggx-height-correlated-E_bias-centers.{language}");
            std::fs::copy(other.join(&name), d.join(&name)).unwrap();
        }
        let centres = read(&other, "ggx-height-correlated-E_bias-centers");
        assert_eq!(centres.spec.quantity, Quantity::EBias);
        let e = read(&d, "ggx-height-correlated-E");
        let points = |t: &Table| -> Vec<f64> {
            lookup_coordinates(&t.spec, &AuditSettings::default())
                .into_iter()
                .flat_map(|c| [c.mu.unwrap(), c.alpha.sqrt()])
                .collect()
        };
        let (e_points, c_points) = (points(&e), points(&centres));
        assert!(e_points.len() > 2000 && c_points.len() > 200);
        let ladder = (0..=1500)
            .map(|k| (f64::from(k) / 1500.0).powi(2))
            .collect();
        let lobes = (0..1200)
            .flat_map(|k| {
                let k = f64::from(k);
                let r = ((k * 0.618_034) % 1.0).powi(2);
                [(k * 0.754_877) % 1.0 * 0.6, (k * 0.569_840) % 1.0 * 0.6, r]
            })
            .collect();
        let fresnels = (0..1200)
            .flat_map(|k| {
                let k = f64::from(k);
                [(k * 0.618_034) % 1.0, 0.05 + 0.95 * ((k * 0.754_877) % 1.0)]
            })
            .collect();
        Cases {
            avg: read(&d, "ggx-height-correlated-E_avg"),
            norm: read(&d, "ggx-height-correlated-f_ms_norm"),
            e,
            centres,
            e_points,
            c_points,
            ladder,
            lobes,
            fresnels,
            dir,
        }
    }

    /// Where the generated files are.
    #[allow(dead_code)] // the Vulkan test reads them through `source`
    pub fn dir(&self) -> PathBuf {
        self.dir.path().to_path_buf()
    }

    /// The generated file `name.extension`.
    #[allow(dead_code)] // the C++ test reads the files itself
    pub fn source(&self, name: &str, extension: &str) -> String {
        std::fs::read_to_string(self.dir.path().join(format!("{name}.{extension}"))).unwrap()
    }

    /// The points of each of [`POINT_SETS`], in its order.
    pub fn point_sets(&self) -> [&[f64]; 5] {
        [
            &self.e_points,
            &self.c_points,
            &self.ladder,
            &self.lobes,
            &self.fresnels,
        ]
    }

    /// The library's values at `point` for the set named `set` (of [`POINT_SETS`], in the
    /// order a shader writes them), each with its tolerance. The point is rounded to f32 first,
    /// as the shader receives it.
    pub fn expected(&self, set: &str, point: &[f64]) -> Vec<(f64, f64)> {
        let p: Vec<f64> = point.iter().map(|&v| f32_of(v)).collect();
        match set {
            // f32 positions err by ~31 * 6e-8 of a texel (texel steps below 0.1): 2e-6 at most.
            "E lookups" | "centres lookups" => {
                let table = if set == "E lookups" {
                    &self.e
                } else {
                    &self.centres
                };
                vec![
                    (table.lookup(p[0], p[1]), 2e-6),
                    (table.lookup_one_minus(p[0], p[1]), 2e-6),
                ]
            }
            "1-D lookups" => {
                let want = normalisation_lookup(&self.norm, p[0]);
                vec![
                    (self.avg.lookup(1.0, p[0]), 1e-6),
                    (want, 1e-6 * want.max(1e-3)),
                ]
            }
            "lobes" => {
                let want = multiple_scattering(p[0], p[1], normalisation_lookup(&self.norm, p[2]));
                vec![(want, 1e-5 * want.max(1.0))]
            }
            "colours" => {
                let turquin = 1.0 + p[0] * (1.0 / p[1] - 1.0);
                vec![
                    (fresnel_colour(p[0], p[1]), 1e-6),
                    (turquin, 1e-6 * turquin),
                ]
            }
            _ => panic!("no point set {set}"),
        }
    }
}
