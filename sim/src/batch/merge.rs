//! `sim batch-merge OUT DIR...`: joins the `runs.jsonl` of the shards of one batch (`--shard
//! k/n` runs, e.g. one per Slurm array task) into one folder with `runs.csv`, `runs.jsonl`,
//! `aggregate.csv` and `batch.json` as a single `sim batch` would have written them, and prints
//! the table. Shards of different batches (by their `batch.json`), a shard given twice, a
//! missing shard and an output folder that is one of the shards are errors.

use super::output::{self, Row};
use super::{BatchReport, aggregate, journal, manifest};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use systems::core::input::{MAX_DATA_BYTES, read_text_bounded};

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

fn read_rows(dir: &Path) -> anyhow::Result<Vec<Row>> {
    let path = dir.join(journal::RUNS);
    let text = read_text_bounded(&path, MAX_DATA_BYTES)
        .map_err(|e| anyhow::anyhow!("{}: cannot read: {e}", path.display()))?;
    text.lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty())
        .map(|(i, l)| {
            journal::parse_row(l).map_err(|e| anyhow::anyhow!("{}:{}: {e}", path.display(), i + 1))
        })
        .collect()
}

fn get(row: &Row, k: &str) -> u64 {
    journal::number(row, k)
}

/// Refuses an output folder that is one of the shards (merging would overwrite its files).
fn check_out_is_no_shard(a: &MergeArgs) -> anyhow::Result<()> {
    let Ok(out) = a.out.canonicalize() else {
        return Ok(()); // not there yet, so no shard
    };
    for dir in &a.shards {
        if dir.canonicalize().is_ok_and(|d| d == out) {
            anyhow::bail!(
                "{}: the output folder is also given as a shard ({}); merging would overwrite \
                 that shard's files: write the merged files to another folder",
                a.out.display(),
                dir.display()
            );
        }
    }
    Ok(())
}

/// Refuses shards of different batches, naming the two folders and what differs.
fn check_same_batch(shards: &[(manifest::Manifest, &Path)]) -> anyhow::Result<()> {
    let Some((first, first_dir)) = shards.first() else {
        return Ok(());
    };
    for (m, dir) in &shards[1..] {
        if let Some((what, a, b)) = first.difference(m) {
            anyhow::bail!(
                "{} and {} are not shards of the same batch: {what} is {a} in {} but {b} in {}",
                first_dir.display(),
                dir.display(),
                first_dir.display(),
                dir.display()
            );
        }
    }
    Ok(())
}

/// Refuses a shard given twice and a batch with shards missing (naming them); the shards are
/// of one batch.
fn check_complete(shards: &[(manifest::Manifest, &Path)]) -> anyhow::Result<()> {
    let Some((first, _)) = shards.first() else {
        return Ok(());
    };
    let n = first.shards;
    let mut seen: BTreeMap<usize, &Path> = BTreeMap::new();
    for (m, dir) in shards {
        if let Some(before) = seen.insert(m.shard, dir) {
            anyhow::bail!(
                "shard {}/{n} is in both {} and {}: merge each shard once",
                m.shard,
                before.display(),
                dir.display()
            );
        }
    }
    let missing = n - seen.len();
    if missing > 0 {
        let first: Vec<String> = (0..n)
            .filter(|k| !seen.contains_key(k))
            .take(10)
            .map(|k| format!("{k}/{n}"))
            .collect();
        let listed = if missing > first.len() {
            format!("{}, … ({missing} in all)", first.join(", "))
        } else {
            first.join(", ")
        };
        anyhow::bail!(
            "shard{} {listed} of the batch {} missing: merge every shard (--shard K/{n} for K \
             from 0 to {})",
            if missing == 1 { "" } else { "s" },
            if missing == 1 { "is" } else { "are" },
            n - 1
        );
    }
    Ok(())
}

/// `sim batch-merge`.
pub fn merge_command(a: &MergeArgs) -> anyhow::Result<BatchReport> {
    let started = std::time::Instant::now();
    check_out_is_no_shard(a)?;
    let manifests = a
        .shards
        .iter()
        .map(|dir| Ok((manifest::Manifest::read(dir)?, dir.as_path())))
        .collect::<anyhow::Result<Vec<_>>>()?;
    check_same_batch(&manifests)?;
    let mut rows: Vec<(Row, &Path)> = Vec::new();
    for (m, dir) in &manifests {
        let shard_rows = read_rows(dir)?;
        if shard_rows.len() != m.shard_runs() {
            anyhow::bail!(
                "{}: {} runs, but shard {}/{} of a batch of {} jobs has {}: the file is \
                 incomplete (a shard that was stopped: run it again with the same arguments \
                 and --resume) or edited",
                dir.join("runs.jsonl").display(),
                shard_rows.len(),
                m.shard,
                m.shards,
                m.jobs,
                m.shard_runs()
            );
        }
        rows.extend(shard_rows.into_iter().map(|r| (r, *dir)));
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
    check_complete(&manifests)?;
    // every shard is here with its number of runs: jobs and sets are numbered below that
    let jobs = rows.len() as u64;
    if let Some((r, dir)) = rows
        .iter()
        .find(|(r, _)| get(r, "job") >= jobs || get(r, "set") >= jobs)
    {
        anyhow::bail!(
            "{}: job {} of parameter set {} is not in a batch of {jobs} runs: the file is \
             edited or from another batch",
            dir.join("runs.jsonl").display(),
            get(r, "job"),
            get(r, "set")
        );
    }
    let rows: Vec<Row> = rows.into_iter().map(|(r, _)| r).collect();
    std::fs::create_dir_all(&a.out)
        .map_err(|e| anyhow::anyhow!("{}: cannot create the folder: {e}", a.out.display()))?;
    let cols = output::columns(&rows);
    output::write_csv(&a.out.join("runs.csv"), &cols, &rows)?;
    output::write_jsonl(&a.out.join("runs.jsonl"), &rows)?;
    let sets = rows.iter().map(|r| get(r, "set") + 1).max().unwrap_or(0) as usize;
    let stats = aggregate::aggregate(sets, &cols, &rows);
    aggregate::write_aggregate(&a.out.join("aggregate.csv"), &stats)?;
    if let Some((m, _)) = manifests.first() {
        let whole = manifest::Manifest {
            shard: 0,
            shards: 1,
            ..m.clone()
        };
        whole.write(&a.out)?;
    }
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
