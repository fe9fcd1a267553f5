//! HTML reports for people without a viewer: `sim run --report DIR`, `sim batch --report` and
//! `sim report FILE`. A page is one self-contained HTML file (inline CSS and SVG figures drawn
//! with plotters; no script and no other file), beside the data it was drawn from:
//! - a run: `report.html` and `report.json` ([`data::RunReport`]: the summary, the simplified
//!   paths, the error series and the task spans), which `sim report` draws again;
//! - a batch: `report.html` in the batch's folder, drawn from its rows (`runs.jsonl`).
use systems::core::input::{MAX_DATA_BYTES, read_text_bounded};

pub mod batch;
pub mod data;
pub mod figures;
pub mod page;
#[cfg(test)]
mod tests;

use crate::batch::output::Row;
use data::RunReport;
use std::path::{Path, PathBuf};

/// The page a report folder gets.
pub const PAGE: &str = "report.html";
/// The data beside a run's page.
pub const DATA: &str = "report.json";

/// Makes `dir` ready for a report before a run starts: creates it if missing, and refuses a
/// folder that is not writable or already holds a report.
pub fn prepare_dir(dir: &Path) -> anyhow::Result<()> {
    std::fs::create_dir_all(dir)
        .map_err(|e| anyhow::anyhow!("{}: cannot create the report folder: {e}", dir.display()))?;
    for f in [PAGE, DATA] {
        let p = dir.join(f);
        if p.exists() {
            anyhow::bail!(
                "{}: a report is already there; choose another folder or remove it",
                p.display()
            );
        }
    }
    let probe = dir.join(".sim-report-probe");
    std::fs::write(&probe, b"")
        .map_err(|e| anyhow::anyhow!("{}: cannot write the report there: {e}", dir.display()))?;
    let _ = std::fs::remove_file(&probe);
    Ok(())
}

fn write(path: &Path, text: &str) -> anyhow::Result<()> {
    std::fs::write(path, text)
        .map_err(|e| anyhow::anyhow!("{}: cannot write the report: {e}", path.display()))
}

/// Writes a run's page and data into `dir` (made ready by [`prepare_dir`]); the page's path.
pub fn write_run(dir: &Path, report: &RunReport) -> anyhow::Result<PathBuf> {
    write(&dir.join(DATA), &serde_json::to_string(report)?)?;
    let page = dir.join(PAGE);
    write(&page, &page::run_page(report)?)?;
    Ok(page)
}

/// Writes a batch's page into its folder `dir`; the page's path.
pub fn write_batch(
    dir: &Path,
    name: &str,
    rows: &[Row],
    stats: &[crate::batch::aggregate::SetStats],
) -> anyhow::Result<PathBuf> {
    let page = dir.join(PAGE);
    write(&page, &batch::batch_page(name, rows, stats)?)?;
    Ok(page)
}

/// What `sim report` was given.
enum Input {
    Run(RunReport),
    Batch { name: String, rows: Vec<Row> },
}

/// Reads `path`: a report folder or its `report.json`, a `--summary` JSON, or a batch folder
/// or its `runs.jsonl`. Anything else is refused, naming the file.
fn read_input(path: &Path) -> anyhow::Result<(Input, PathBuf)> {
    let (file, dir) = if path.is_dir() {
        let data = path.join(DATA);
        let runs = path.join("runs.jsonl");
        if data.is_file() {
            (data, path.to_path_buf())
        } else if runs.is_file() {
            (runs, path.to_path_buf())
        } else {
            anyhow::bail!(
                "{}: holds neither a report ({DATA}) nor a batch (runs.jsonl)",
                path.display()
            );
        }
    } else {
        let dir = path.parent().map_or_else(PathBuf::new, Path::to_path_buf);
        (path.to_path_buf(), dir)
    };
    let text = read_text_bounded(&file, MAX_DATA_BYTES)
        .map_err(|e| anyhow::anyhow!("{}: cannot read: {e}", file.display()))?;
    let not_ours = |why: String| {
        anyhow::anyhow!(
            "{}: not a file written by sim ({why}); expected a report.json from --report, a \
             summary from --summary or a batch's runs.jsonl",
            file.display()
        )
    };
    if file.extension().is_some_and(|e| e == "jsonl") {
        let mut rows = Vec::new();
        for (k, line) in text
            .lines()
            .enumerate()
            .filter(|(_, l)| !l.trim().is_empty())
        {
            let v: serde_json::Map<String, serde_json::Value> =
                serde_json::from_str(line).map_err(|e| not_ours(format!("line {}: {e}", k + 1)))?;
            if !(v.contains_key("set") && v.contains_key("status")) {
                return Err(not_ours(format!("line {}: no `set` and `status`", k + 1)));
            }
            rows.push(v.into_iter().collect::<Row>());
        }
        let name = dir
            .file_name()
            .map_or_else(|| "batch".to_string(), |n| n.to_string_lossy().into_owned());
        return Ok((Input::Batch { name, rows }, dir));
    }
    let v: serde_json::Value =
        serde_json::from_str(&text).map_err(|e| not_ours(format!("not JSON: {e}")))?;
    if v.get("format").is_some() {
        let format = v["format"].as_str().unwrap_or("");
        if format != data::FORMAT {
            return Err(not_ours(format!(
                "format `{format}`, this sim reads `{}`",
                data::FORMAT
            )));
        }
        let r: RunReport = serde_json::from_value(v).map_err(|e| not_ours(e.to_string()))?;
        return Ok((Input::Run(r), dir));
    }
    let is_summary = v.get("scenario").is_some_and(|s| s.is_string())
        && v.get("seed").is_some_and(|s| s.is_u64())
        && v.get("robots").is_some_and(|r| r.is_array());
    if !is_summary {
        return Err(not_ours(
            "no `scenario`, `seed` and `robots` of a summary".into(),
        ));
    }
    Ok((Input::Run(RunReport::of_summary(v)), dir))
}

/// `sim report`: draws the page of `input` again, to `out` (default: `report.html` beside the
/// input); an existing page is replaced only with `force`.
pub fn redraw(input: &Path, out: Option<&Path>, force: bool) -> anyhow::Result<PathBuf> {
    let (what, dir) = read_input(input)?;
    let out = out.map_or_else(|| dir.join(PAGE), Path::to_path_buf);
    if out.exists() && !force {
        anyhow::bail!(
            "{}: exists; pass --force to replace it, or --out another file",
            out.display()
        );
    }
    let html = match what {
        Input::Run(r) => page::run_page(&r)?,
        Input::Batch { name, rows } => {
            let cols = crate::batch::output::columns(&rows);
            let sets = rows
                .iter()
                .filter_map(|r| {
                    r.iter()
                        .find(|(c, _)| c == "set")
                        .and_then(|(_, v)| v.as_u64())
                })
                .max()
                .map_or(0, |m| m as usize + 1);
            let stats = crate::batch::aggregate::aggregate(sets, &cols, &rows);
            batch::batch_page(&name, &rows, &stats)?
        }
    };
    write(&out, &html)?;
    Ok(out)
}

/// `sim report`'s arguments.
#[derive(clap::Args, Clone, Debug)]
pub struct ReportArgs {
    /// A report folder or its report.json (`sim run --report`), a summary (`--summary`), or a
    /// batch folder or its runs.jsonl.
    pub input: PathBuf,
    /// Where to write the page (default: report.html beside the input).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Replace an existing page.
    #[arg(long)]
    pub force: bool,
}

/// `sim report`.
pub fn report_command(a: &ReportArgs) -> anyhow::Result<()> {
    let page = redraw(&a.input, a.out.as_deref(), a.force)?;
    println!("report written to {}", page.display());
    Ok(())
}
