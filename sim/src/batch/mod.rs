//! `sim batch`: many seeded runs of a scenario, with parameter sets made of `--set`, `--sweep`
//! and `--zip` overrides, in parallel on a pool of `--jobs` workers. Each run is isolated and
//! deterministic (same set and seed ⇒ same summary, whatever `--jobs` and `--threads`); a set
//! that fails to load or a run that fails is reported and counted, and the others go on. Writes
//! `runs.csv`, `runs.jsonl` (one row per run, every summary metric), `aggregate.csv`
//! (mean, std, median, p95 per set and metric) and `batch.json` ([`manifest`]), and prints the
//! table of the main metrics.
//! `sim batch-merge` ([`merge`]) joins the outputs of the shards of one batch.

pub mod aggregate;
pub mod args;
pub mod journal;
pub mod manifest;
pub mod merge;
pub mod output;
pub mod runner;
pub mod sets;
pub mod sweep;

pub use args::BatchArgs;
pub use sweep::Sweep;

use crate::options::check_duration;
use crate::run::summary::Summary;
use crate::run::{RunOptions, run_scenario};
use crate::scenario::Scenario;
use crate::scenario::scenario_path;
use journal::Journal;
use output::Row;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// What a batch did.
#[derive(Debug)]
pub struct BatchReport {
    pub out_dir: PathBuf,
    /// Runs of this shard (or of the whole batch).
    pub runs: usize,
    pub failed: usize,
    /// One row per run, in job order (as in runs.csv).
    pub rows: Vec<Row>,
    /// The printed aggregate table.
    pub table: String,
    pub wall_s: f64,
}

/// The error of a batch whose files were written but some of whose runs failed (exit code 2).
#[derive(Debug)]
pub struct RunsFailed {
    pub failed: usize,
    pub runs: usize,
    pub out_dir: PathBuf,
}

impl std::fmt::Display for RunsFailed {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} of {} runs failed (the files in {} hold every run, with its status)",
            self.failed,
            self.runs,
            self.out_dir.display()
        )
    }
}

impl std::error::Error for RunsFailed {}

impl BatchReport {
    /// Ok if every run succeeded, else [`RunsFailed`].
    pub fn into_result(self) -> anyhow::Result<BatchReport> {
        if self.failed > 0 {
            return Err(RunsFailed {
                failed: self.failed,
                runs: self.runs,
                out_dir: self.out_dir,
            }
            .into());
        }
        Ok(self)
    }
}

/// What to run, parsed and loaded: parameter sets with their scenarios, and this shard's jobs.
pub struct Batch {
    pub name: String,
    pub keys: Vec<String>,
    pub sets: Vec<Vec<crate::scenario::overrides::Override>>,
    /// Per set, its scenario (None: no job of this shard uses it).
    pub scenarios: Vec<Option<Result<Scenario, String>>>,
    pub jobs: Vec<runner::Job>,
    /// The batch and shard, as `batch.json` records them.
    pub manifest: manifest::Manifest,
}

/// Parses the arguments and loads every parameter set a job of the shard uses; fails if the
/// arguments are bad or no set loads.
pub fn prepare(a: &BatchArgs) -> anyhow::Result<Batch> {
    let seeds = args::parse_seeds(&a.seeds)?;
    let shard = a.shard.as_deref().map(args::parse_shard).transpose()?;
    let plan = sets::plan_sets(&a.sets, &a.sweeps, &a.zips)?;
    let total = runner::total_runs(plan.sets.len(), &seeds)?;
    let source = crate::scenario::source::Source::load(&scenario_path(Some(&a.scenario))?)?;
    let duration = a.duration.map(check_duration).transpose()?;
    let (shard_k, shards) = shard.unwrap_or((0, 1));
    let manifest = manifest::Manifest {
        scenario: source.plain.name.clone(),
        seeds: format!("{}..{}", seeds.start, seeds.end),
        duration,
        set: a.sets.clone(),
        sweep: a.sweeps.clone(),
        zip: a.zips.clone(),
        jobs: total,
        shard: shard_k,
        shards,
    };
    let jobs = runner::plan_jobs(plan.sets.len(), seeds, shard)?;
    let scenarios: Vec<Option<Result<Scenario, String>>> = (0..plan.sets.len())
        .map(|i| {
            jobs.iter().any(|j| j.set == i).then(|| {
                source.scenario(&plan.sets[i]).map(|mut s| {
                    if let Some(d) = duration {
                        s.duration = d;
                    }
                    s
                })
            })
        })
        .collect();
    let errors: Vec<(usize, &String)> = scenarios
        .iter()
        .enumerate()
        .filter_map(|(i, s)| Some((i, s.as_ref()?.as_ref().err()?)))
        .collect();
    let loaded = scenarios.iter().flatten().count();
    if loaded > 0 && errors.len() == loaded {
        if let [(_, e)] = errors.as_slice() {
            anyhow::bail!("{e}");
        }
        let list: Vec<String> = errors
            .iter()
            .map(|(i, e)| format!("  set {i}: {e}"))
            .collect();
        anyhow::bail!("no parameter set loads:\n{}", list.join("\n"));
    }
    Ok(Batch {
        name: source.plain.name.clone(),
        keys: plan.keys,
        sets: plan.sets,
        scenarios,
        jobs,
        manifest,
    })
}

fn default_out(a: &BatchArgs, name: &str) -> PathBuf {
    let seeds = a.seeds.replace("..", "-");
    let shard = match a.shard.as_deref().and_then(|s| args::parse_shard(s).ok()) {
        Some((k, n)) => format!("-shard{k}of{n}"),
        None => String::new(),
    };
    PathBuf::from(format!("batch-{name}-{seeds}{shard}"))
}

fn describe_set(b: &Batch, set: usize) -> String {
    let p: Vec<String> = b.sets[set]
        .iter()
        .filter(|o| o.flag != "--set")
        .map(|o| format!("{}={}", o.key, o.text))
        .collect();
    if p.is_empty() {
        format!("set {set}")
    } else {
        format!("set {set} ({})", p.join(" "))
    }
}

/// Runs the batch's jobs but those in `kept` (already run, by a batch now resumed): the
/// summaries (or errors) in job order, with wall times. `journal` gets each one's row as it
/// ends.
pub fn run_batch(
    b: &Batch,
    workers: usize,
    threads: usize,
    rrd_dir: Option<&Path>,
    show_progress: bool,
    (journal, kept): (Option<&Journal>, &BTreeMap<usize, Row>),
) -> anyhow::Result<Vec<runner::Finished<Summary>>> {
    let bar = runner::progress_bar(b.jobs.len() - kept.len(), show_progress);
    let mut failed = Vec::new();
    let mut runnable = Vec::new();
    for (set, s) in b.scenarios.iter().enumerate() {
        if let Some(Err(e)) = s {
            let n = b.jobs.iter().filter(|j| j.set == set).count();
            eprintln!(
                "{} does not load; its {n} run{} count as failed: {e}",
                describe_set(b, set),
                if n == 1 { "" } else { "s" }
            );
        }
    }
    for j in b.jobs.iter().filter(|j| !kept.contains_key(&j.index)) {
        match &b.scenarios[j.set] {
            Some(Ok(_)) => runnable.push(*j),
            Some(Err(e)) => failed.push(runner::Finished {
                job: *j,
                result: Err(e.clone()),
                wall_s: 0.0,
            }),
            None => {}
        }
    }
    bar.inc(failed.len() as u64);
    bar.set_message(format!("{} failed", failed.len()));
    if let Some(j) = journal {
        j.append(&rows(b, &failed));
    }
    let done = runner::run_jobs(
        &runnable,
        workers,
        &bar,
        failed.len(),
        |j| {
            format!(
                "run {} ({}, seed {})",
                j.index,
                describe_set(b, j.set),
                j.seed
            )
        },
        |j| {
            let Some(Ok(sc)) = &b.scenarios[j.set] else {
                anyhow::bail!("set {} has no scenario", j.set);
            };
            let mut sc = sc.clone();
            sc.seed = j.seed;
            let opts = RunOptions {
                rrd: rrd_dir.map(|d| d.join(format!("set{}-seed{}.rrd", j.set, j.seed))),
                threads,
                progress: false,
                ..Default::default()
            };
            Ok(run_scenario(&sc, &opts)?.summary)
        },
        |f| {
            if let Some(j) = journal {
                j.append(&rows(b, std::slice::from_ref(f)));
            }
        },
    )?;
    bar.finish_and_clear();
    let mut all = failed;
    all.extend(done);
    all.sort_by_key(|f| f.job.index);
    Ok(all)
}

/// The rows of finished runs.
pub fn rows(b: &Batch, done: &[runner::Finished<Summary>]) -> Vec<Row> {
    done.iter()
        .map(|f| {
            let err = f.result.as_ref().err().map(String::as_str);
            let mut row = output::run_columns(&f.job, &b.keys, &b.sets[f.job.set], err, f.wall_s);
            if let Ok(s) = &f.result {
                row.extend(output::metrics(s));
            }
            row
        })
        .collect()
}

/// A batch's runs and their statistics, before any file is written: what `sim batch` writes and
/// prints, and what [`Sweep::run`] returns.
pub struct BatchResults {
    /// Every run's summary (or error), in job order.
    pub runs: Vec<runner::Finished<Summary>>,
    /// One row per run, in job order (as in runs.csv).
    pub rows: Vec<Row>,
    /// The runs.csv header.
    pub columns: Vec<String>,
    /// Per parameter set, the statistics of every metric (as in aggregate.csv).
    pub stats: Vec<aggregate::SetStats>,
    /// The aggregate table `sim batch` prints.
    pub table: String,
    /// Runs that failed.
    pub failed: usize,
}

impl Batch {
    /// Runs the jobs on `workers` parallel runs of `threads` kernel threads each (recordings
    /// into `rrd_dir` if given) and computes the rows and statistics: the engine of `sim batch`
    /// and of [`Sweep`].
    pub fn execute(
        &self,
        workers: usize,
        threads: usize,
        rrd_dir: Option<&Path>,
        show_progress: bool,
    ) -> anyhow::Result<BatchResults> {
        let none = BTreeMap::new();
        self.execute_with(workers, threads, rrd_dir, show_progress, (None, &none))
    }

    /// [`Batch::execute`], with each row appended to `journal` as its run ends, and the jobs
    /// of `kept` not run again: their rows (of a batch now resumed) join the results.
    pub fn execute_with(
        &self,
        workers: usize,
        threads: usize,
        rrd_dir: Option<&Path>,
        show_progress: bool,
        (journal, kept): (Option<&Journal>, &BTreeMap<usize, Row>),
    ) -> anyhow::Result<BatchResults> {
        let runs = run_batch(
            self,
            workers,
            threads,
            rrd_dir,
            show_progress,
            (journal, kept),
        )?;
        let mut rows = rows(self, &runs);
        if !kept.is_empty() {
            rows.extend(kept.values().cloned());
            rows.sort_by_key(|r| journal::number(r, "job"));
        }
        let columns = if rows.is_empty() {
            // a shard without jobs: the header of the run columns alone
            let none = runner::Job {
                index: 0,
                set: 0,
                seed: 0,
            };
            output::columns(&[output::run_columns(&none, &self.keys, &[], None, 0.0)])
        } else {
            output::columns(&rows)
        };
        let stats = aggregate::aggregate(self.sets.len(), &columns, &rows);
        let table = aggregate::table(&stats);
        let failed = rows.iter().filter(|r| !journal::succeeded(r)).count();
        Ok(BatchResults {
            runs,
            rows,
            columns,
            stats,
            table,
            failed,
        })
    }
}

/// `sim batch`.
pub fn batch_command(a: &BatchArgs) -> anyhow::Result<BatchReport> {
    let started = Instant::now();
    let b = prepare(a)?;
    let out_dir = a.out.clone().unwrap_or_else(|| default_out(a, &b.name));
    std::fs::create_dir_all(&out_dir).map_err(|e| {
        anyhow::anyhow!(
            "{}: cannot create the output folder: {e}",
            out_dir.display()
        )
    })?;
    if a.report {
        let page = out_dir.join(crate::report::PAGE);
        if page.exists() {
            anyhow::bail!(
                "{}: a report is already there; choose another --out or remove it",
                page.display()
            );
        }
    }
    if !a.quiet {
        let shard = a
            .shard
            .as_deref()
            .map_or(String::new(), |s| format!(", shard {s}"));
        eprintln!(
            "batch {}: {} parameter set{} × seeds {}{shard}: {} runs, {} at a time",
            b.name,
            b.sets.len(),
            if b.sets.len() == 1 { "" } else { "s" },
            a.seeds,
            b.jobs.len(),
            runner::worker_count(a.jobs, b.jobs.len())
        );
    }
    let kept = if a.resume {
        journal::finished_rows(&out_dir, &b.manifest, &b.jobs)?
    } else {
        BTreeMap::new()
    };
    // From the start the folder says which batch it holds, and its rows grow as runs end: a
    // batch that is killed can be resumed.
    for stale in ["runs.csv", "aggregate.csv"] {
        match std::fs::remove_file(out_dir.join(stale)) {
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => {
                anyhow::bail!("{}: cannot replace: {e}", out_dir.join(stale).display())
            }
            _ => {}
        }
    }
    b.manifest.write(&out_dir)?;
    let journal = Journal::start(&out_dir, &kept.values().cloned().collect::<Vec<_>>())?;
    if a.resume && !a.quiet {
        eprintln!(
            "resuming: {} of {} runs are done, {} to run",
            kept.len(),
            b.jobs.len(),
            b.jobs.len() - kept.len()
        );
    }
    let rrd_dir = a.rrd.then_some(out_dir.as_path());
    let r = b.execute_with(
        a.jobs,
        a.threads,
        rrd_dir,
        !a.quiet,
        (Some(&journal), &kept),
    )?;
    if let Err(e) = journal.finish() {
        eprintln!("warning: {e:#} (the rows are written again below)");
    }
    if r.rows.is_empty() {
        eprintln!("warning: this shard has no jobs (the batch has fewer than its number)");
    }
    output::write_csv(&out_dir.join("runs.csv"), &r.columns, &r.rows)?;
    output::write_jsonl(&out_dir.join(journal::RUNS), &r.rows)?;
    aggregate::write_aggregate(&out_dir.join("aggregate.csv"), &r.stats)?;
    let page = if a.report {
        Some(crate::report::write_batch(
            &out_dir, &b.name, &r.rows, &r.stats,
        )?)
    } else {
        None
    };
    let wall_s = started.elapsed().as_secs_f64();
    if !a.quiet {
        print!("{}", r.table);
        println!(
            "{} runs, {} failed, in {wall_s:.1} s; runs.csv, runs.jsonl, aggregate.csv and \
             batch.json written to {}",
            r.rows.len(),
            r.failed,
            out_dir.display()
        );
        if let Some(p) = &page {
            println!("report written to {}", p.display());
        }
    }
    Ok(BatchReport {
        out_dir,
        runs: r.rows.len(),
        failed: r.failed,
        rows: r.rows,
        table: r.table,
        wall_s,
    })
}
