//! `sim batch-merge OUT DIR...`: joins the `runs.jsonl` of the shards of one batch (`--shard
//! k/n` runs, e.g. one per Slurm array task) into one folder with `runs.csv`, `runs.jsonl` and
//! `aggregate.csv` as a single `sim batch` would have written them, and prints the table.

use super::output::{self, Row};
use super::{BatchReport, aggregate};
use serde::de::{Deserializer, MapAccess, Visitor};
use serde_json::Value as Json;
use std::path::{Path, PathBuf};

#[derive(clap::Args, Clone, Debug)]
pub struct MergeArgs {
    /// The folder to write the merged files to.
    pub out: PathBuf,
    /// The shards' output folders (each with a runs.jsonl).
    #[arg(required = true)]
    pub shards: Vec<PathBuf>,
    /// No table, only errors.
    #[arg(long)]
    pub quiet: bool,
}

/// A JSON object with its keys in file order.
struct Ordered(Row);

impl<'de> serde::Deserialize<'de> for Ordered {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = Ordered;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a JSON object")
            }
            fn visit_map<A: MapAccess<'de>>(self, mut m: A) -> Result<Ordered, A::Error> {
                let mut row = Row::new();
                while let Some((k, v)) = m.next_entry::<String, Json>()? {
                    row.push((k, v));
                }
                Ok(Ordered(row))
            }
        }
        d.deserialize_map(V)
    }
}

fn read_rows(dir: &Path) -> anyhow::Result<Vec<Row>> {
    let path = dir.join("runs.jsonl");
    let text = std::fs::read_to_string(&path)
        .map_err(|e| anyhow::anyhow!("{}: cannot read: {e}", path.display()))?;
    text.lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty())
        .map(|(i, l)| {
            let Ordered(row) = serde_json::from_str(l)
                .map_err(|e| anyhow::anyhow!("{}:{}: not a run row: {e}", path.display(), i + 1))?;
            for k in ["job", "set"] {
                if !row.iter().any(|(c, v)| c == k && v.is_u64()) {
                    anyhow::bail!(
                        "{}:{}: no `{k}` number: not a runs.jsonl of sim batch",
                        path.display(),
                        i + 1
                    );
                }
            }
            Ok(row)
        })
        .collect()
}

fn get(row: &Row, k: &str) -> u64 {
    row.iter()
        .find(|(c, _)| c == k)
        .and_then(|(_, v)| v.as_u64())
        .unwrap_or(0)
}

/// `sim batch-merge`.
pub fn merge_command(a: &MergeArgs) -> anyhow::Result<BatchReport> {
    let started = std::time::Instant::now();
    let mut rows: Vec<(Row, &Path)> = Vec::new();
    for dir in &a.shards {
        rows.extend(read_rows(dir)?.into_iter().map(|r| (r, dir.as_path())));
    }
    rows.sort_by_key(|(r, _)| get(r, "job"));
    for w in rows.windows(2) {
        if get(&w[0].0, "job") == get(&w[1].0, "job") {
            anyhow::bail!(
                "job {} is in both {} and {}: merge each shard once",
                get(&w[0].0, "job"),
                w[0].1.display(),
                w[1].1.display()
            );
        }
    }
    let rows: Vec<Row> = rows.into_iter().map(|(r, _)| r).collect();
    let expected = rows.last().map_or(0, |r| get(r, "job") + 1) as usize;
    if rows.len() < expected {
        eprintln!(
            "warning: {} of jobs 0..{expected} are missing (a shard not merged, or still running?)",
            expected - rows.len()
        );
    }
    std::fs::create_dir_all(&a.out)
        .map_err(|e| anyhow::anyhow!("{}: cannot create the folder: {e}", a.out.display()))?;
    let cols = output::columns(&rows);
    output::write_csv(&a.out.join("runs.csv"), &cols, &rows)?;
    output::write_jsonl(&a.out.join("runs.jsonl"), &rows)?;
    let sets = rows.iter().map(|r| get(r, "set") + 1).max().unwrap_or(0) as usize;
    let stats = aggregate::aggregate(sets, &cols, &rows);
    aggregate::write_aggregate(&a.out.join("aggregate.csv"), &stats)?;
    let table = aggregate::table(&stats);
    let failed = rows
        .iter()
        .filter(|r| !r.iter().any(|(c, v)| c == "status" && v == "ok"))
        .count();
    if !a.quiet {
        print!("{table}");
        println!(
            "{} runs from {} shards, {failed} failed; merged into {}",
            rows.len(),
            a.shards.len(),
            a.out.display()
        );
    }
    Ok(BatchReport {
        out_dir: a.out.clone(),
        runs: rows.len(),
        failed,
        rows,
        table,
        wall_s: started.elapsed().as_secs_f64(),
    })
}
