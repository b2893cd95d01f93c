//! How the audits of files report: the `--max-error` verdict of a file, its JSON object, and
//! the picture `--plot` asks for.

use std::path::Path;

/// What a file's verdict names: the file, and the bound it is held to (`--max-error`).
pub struct FileGate<'a> {
    pub file: &'a Path,
    pub max_error: Option<f64>,
}

/// The `--max-error` line of the text report.
pub fn print_verdict(bound: Option<f64>, passed: bool, what: &str, value: f64) {
    if let Some(bound) = bound {
        let verdict = if passed { "passes" } else { "FAILS" };
        println!("  {verdict} --max-error {bound:e} ({what} {value:.2e})");
    }
}

/// With `--quiet`: one line on stderr when the check failed, nothing otherwise.
pub fn quiet_verdict(gate: &FileGate, passed: bool, what: &str, value: f64) {
    if let (false, Some(bound)) = (passed, gate.max_error) {
        eprintln!(
            "kiln: {}: {what} {value:.2e} exceeds --max-error {bound:e}",
            gate.file.display()
        );
    }
}

/// A report as one JSON object, with the file and the `--max-error` verdict.
pub fn json_report(
    report: &impl serde::Serialize,
    gate: &FileGate,
    passed: bool,
) -> serde_json::Value {
    let mut object = serde_json::to_value(report).expect("a report serialises");
    object["file"] = gate.file.display().to_string().into();
    if let Some(bound) = gate.max_error {
        object["max_error"] = bound.into();
        object["passed"] = passed.into();
    }
    object
}

/// Whether a `--plot` path asks for SVG (`Some(true)`) or PNG; an error for a folder that does
/// not exist or another extension.
pub fn plot_kind_of(plot: Option<&Path>) -> kiln::Result<Option<bool>> {
    // A picture goes into a folder that exists: a mistyped path is an error now, before the
    // audit, not a chain of new folders after it.
    if let Some(dir) = plot
        .and_then(Path::parent)
        .filter(|d| !d.as_os_str().is_empty() && !d.is_dir())
    {
        return Err(kiln::Error::InvalidInput(format!(
            "--plot {}: the folder {} does not exist; create it, or give a path in a folder \
             that does",
            plot.unwrap_or(dir).display(),
            dir.display()
        )));
    }
    match plot {
        Some(path) => match path.extension().and_then(|e| e.to_str()) {
            Some("svg") => Ok(Some(true)),
            Some("png") => Ok(Some(false)),
            _ => Err(kiln::Error::InvalidInput(format!(
                "--plot {}: give a .svg or .png file",
                path.display()
            ))),
        },
        None => Ok(None),
    }
}

/// Writes a plot drawn as `(SVG text, PNG bytes)` to `path`, the SVG if `svg`.
pub fn write_plot(
    path: &Path,
    svg: bool,
    drawn: Result<(String, Vec<u8>), String>,
) -> kiln::Result<()> {
    let (text, png) = drawn.map_err(|message| kiln::Error::Format {
        path: path.to_path_buf(),
        message,
    })?;
    let bytes = if svg { text.into_bytes() } else { png };
    let dir = path.parent().filter(|p| !p.as_os_str().is_empty());
    let name = path
        .file_name()
        .and_then(|n| n.to_str())
        .unwrap_or("plot.svg");
    kiln::format::write_files(dir.unwrap_or(Path::new(".")), &[(name.to_string(), bytes)])?;
    Ok(())
}

/// What a bake or a merge wrote, as one JSON object: each table (its id, shape, largest
/// standard error, the node errors measured against the reference and what its lookup fit
/// measured, where there are), the files and the folder, and the seconds taken.
pub fn tables_written_json(
    tables: &[kiln::Table],
    written: &[std::path::PathBuf],
    out: &Path,
    seconds: Option<f64>,
) -> serde_json::Value {
    let tables: Vec<serde_json::Value> = tables
        .iter()
        .map(|t| {
            serde_json::json!({
                "id": t.spec.id(),
                "quantity": t.spec.quantity.symbol(),
                "shape": t.spec.shape(),
                "max_std_error": t.max_std_error(),
                "node_errors": t.node_errors,
                "lookup_fit": t.lookup_fit,
            })
        })
        .collect();
    let files: Vec<String> = written.iter().map(|p| p.display().to_string()).collect();
    serde_json::json!({
        "tables": tables,
        "files": files,
        "out": out.display().to_string(),
        "seconds": seconds,
    })
}
