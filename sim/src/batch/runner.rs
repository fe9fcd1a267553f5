//! The jobs of a batch (parameter sets major, seeds minor, optionally one shard of them) and
//! their parallel execution: a rayon pool of `--jobs` workers, each taking the next job until
//! none is left. A job that errors or panics is recorded as failed; the others go on.
//!
//! Each worker runs its job from start to end on its own thread: it is a `broadcast` on the pool
//! pulling jobs from a shared counter, not one rayon task per job, because a run's kernels run
//! on the run's own pool (`--threads`) and a rayon worker waiting for another pool steals tasks
//! of its own pool meanwhile, which would stack a second run on top of the waiting one.

use indicatif::{ProgressBar, ProgressStyle};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

/// One run: a parameter set with a seed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Job {
    /// Position in the full batch (sets major, seeds minor), the same in every shard.
    pub index: usize,
    pub set: usize,
    pub seed: u64,
}

/// The most runs a batch may have (parameter sets × seeds, all shards together).
pub const MAX_RUNS: usize = 1_000_000;

/// The number of runs of `sets` parameter sets × `seeds`, or the error naming `--seeds` (and
/// `--sweep`/`--zip` when they make several sets) if it is above [`MAX_RUNS`].
pub fn total_runs(sets: usize, seeds: &std::ops::Range<u64>) -> anyhow::Result<usize> {
    let per_set = seeds.end.saturating_sub(seeds.start);
    let total = (sets as u128).checked_mul(u128::from(per_set));
    match total.and_then(|t| usize::try_from(t).ok()) {
        Some(t) if t <= MAX_RUNS => Ok(t),
        _ => {
            let runs = total.map_or("too many".to_string(), |t| t.to_string());
            let seeds = format!("--seeds {}..{}", seeds.start, seeds.end);
            let what = if sets == 1 {
                format!("{seeds} makes {runs} runs")
            } else {
                format!("{seeds} × {sets} parameter sets (--sweep/--zip) makes {runs} runs")
            };
            anyhow::bail!(
                "{what}, more than the {MAX_RUNS} a batch may have (split it into several batches)"
            )
        }
    }
}

/// The jobs of `sets` parameter sets × `seeds`, or of shard `k/n` of them: jobs k, k+n, …;
/// an error if the batch has more than [`MAX_RUNS`] runs.
pub fn plan_jobs(
    sets: usize,
    seeds: std::ops::Range<u64>,
    shard: Option<(usize, usize)>,
) -> anyhow::Result<Vec<Job>> {
    let total = total_runs(sets, &seeds)?;
    let per_set = (seeds.end - seeds.start) as usize;
    let (k, n) = shard.unwrap_or((0, 1));
    Ok((k..total)
        .step_by(n.max(1))
        .map(|index| Job {
            index,
            set: index / per_set,
            seed: seeds.start + (index % per_set) as u64,
        })
        .collect())
}

/// The workers that run `jobs` jobs when `--jobs` asks for `requested` (0 = one per core):
/// never more than the jobs, at least one.
pub fn worker_count(requested: usize, jobs: usize) -> usize {
    let wanted = if requested == 0 {
        std::thread::available_parallelism().map_or(1, |n| n.get())
    } else {
        requested
    };
    wanted.min(jobs).max(1)
}

/// What became of a job, with its wall time (s).
#[derive(Debug)]
pub struct Finished<T> {
    pub job: Job,
    pub result: Result<T, String>,
    pub wall_s: f64,
}

/// A progress bar with ETA and the count of failed runs (hidden when `show` is false).
pub fn progress_bar(total: usize, show: bool) -> ProgressBar {
    if !show {
        return ProgressBar::hidden();
    }
    let b = ProgressBar::new(total as u64);
    b.set_style(
        ProgressStyle::with_template(
            "{bar:40.cyan/blue} {pos}/{len} runs  {msg}  [{elapsed_precise} < {eta}]",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    b.set_message("0 failed");
    b
}

fn panic_text(p: &(dyn std::any::Any + Send)) -> String {
    let msg = p
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| p.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "(no message)".to_string());
    format!("panicked: {msg}")
}

/// `work(i, &items[i])` for every item, on `workers` threads (0 = one per core; never more
/// than the items), the results in item order. Each worker takes the next item from a shared
/// counter and runs it to its end: a run started on a worker keeps it to itself, whatever pools
/// its own kernels use (see the module's documentation). A panic in `work` reaches the caller
/// once the workers are done.
pub fn on_workers<I: Sync, T: Send>(
    items: &[I],
    workers: usize,
    work: impl Fn(usize, &I) -> T + Sync,
) -> anyhow::Result<Vec<T>> {
    if items.is_empty() {
        return Ok(Vec::new());
    }
    let workers = worker_count(workers, items.len());
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(workers)
        .thread_name(|i| format!("sim-worker-{i}"))
        .build()
        .map_err(|e| anyhow::anyhow!("cannot start {workers} worker threads: {e}"))?;
    let next = AtomicUsize::new(0);
    let done: Mutex<Vec<(usize, T)>> = Mutex::new(Vec::with_capacity(items.len()));
    pool.broadcast(|_| {
        loop {
            let i = next.fetch_add(1, Ordering::Relaxed);
            let Some(item) = items.get(i) else { break };
            let result = work(i, item);
            // a worker that panicked outside `work` cannot have poisoned this lock while holding it
            if let Ok(mut d) = done.lock() {
                d.push((i, result));
            }
        }
    });
    let mut done = done
        .into_inner()
        .map_err(|_| anyhow::anyhow!("a worker failed"))?;
    done.sort_by_key(|(i, _)| *i);
    Ok(done.into_iter().map(|(_, t)| t).collect())
}

/// Runs `work` on every job with `workers` threads (0 = one per core; never more than the jobs),
/// catching errors and panics; `done` sees each job as it ends, and the results come back in
/// job order. `failed_before` runs already counted as failed (shown on the bar).
pub fn run_jobs<T: Send>(
    jobs: &[Job],
    workers: usize,
    bar: &ProgressBar,
    failed_before: usize,
    describe: impl Fn(&Job) -> String + Sync,
    work: impl Fn(&Job) -> anyhow::Result<T> + Sync,
    ended: impl Fn(&Finished<T>) + Sync,
) -> anyhow::Result<Vec<Finished<T>>> {
    let failed = AtomicUsize::new(failed_before);
    on_workers(jobs, workers, |_, job| {
        let started = Instant::now();
        let result = match catch_unwind(AssertUnwindSafe(|| work(job))) {
            Ok(Ok(v)) => Ok(v),
            Ok(Err(e)) => Err(format!("{e:#}")),
            Err(p) => Err(panic_text(p.as_ref())),
        };
        if let Err(e) = &result {
            let n = failed.fetch_add(1, Ordering::Relaxed) + 1;
            bar.set_message(format!("{n} failed"));
            bar.suspend(|| eprintln!("{} failed: {e}", describe(job)));
        }
        bar.inc(1);
        let f = Finished {
            job: *job,
            result,
            wall_s: started.elapsed().as_secs_f64(),
        };
        ended(&f);
        f
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn jobs_and_shards() {
        let all = plan_jobs(2, 5..8, None).unwrap();
        assert_eq!(all.len(), 6);
        assert_eq!(
            all[0],
            Job {
                index: 0,
                set: 0,
                seed: 5
            }
        );
        assert_eq!(
            all[4],
            Job {
                index: 4,
                set: 1,
                seed: 6
            }
        );
        let a = plan_jobs(2, 5..8, Some((0, 4))).unwrap();
        let b = plan_jobs(2, 5..8, Some((1, 4))).unwrap();
        let idx: Vec<usize> = a.iter().chain(&b).map(|j| j.index).collect();
        assert_eq!(idx, [0, 4, 1, 5]);
        let mut union: Vec<Job> = (0..4)
            .flat_map(|k| plan_jobs(2, 5..8, Some((k, 4))).unwrap())
            .collect();
        union.sort_by_key(|j| j.index);
        assert_eq!(union, all);
    }

    #[test]
    fn too_many_runs_are_refused_before_planning() {
        assert_eq!(
            plan_jobs(1, 0..MAX_RUNS as u64, Some((3, 4)))
                .unwrap()
                .len(),
            MAX_RUNS / 4
        );
        for (sets, seeds, want) in [
            (
                1,
                0..u64::MAX,
                "--seeds 0..18446744073709551615 makes 18446744073709551615 runs",
            ),
            (
                1,
                0..MAX_RUNS as u64 + 1,
                "makes 1000001 runs, more than the 1000000",
            ),
            (
                3,
                0..6148914691236517206,
                "× 3 parameter sets (--sweep/--zip) makes 18446744073709551618 runs",
            ),
            (2, 0..9223372036854775808, "makes 18446744073709551616 runs"),
            (2, 0..500_001, "--seeds 0..500001 × 2 parameter sets"),
        ] {
            let e = plan_jobs(sets, seeds, None).unwrap_err().to_string();
            assert!(e.contains(want), "{e}");
        }
    }

    #[test]
    fn workers_never_outnumber_the_jobs() {
        assert_eq!(worker_count(5000, 1), 1);
        assert_eq!(worker_count(3, 10), 3);
        assert_eq!(worker_count(0, 1), 1);
        assert_eq!(worker_count(2, 0), 1);
    }

    #[test]
    fn errors_and_panics_do_not_stop_the_others() {
        let jobs = plan_jobs(1, 0..6, None).unwrap();
        let bar = ProgressBar::hidden();
        let seen = Mutex::new(Vec::new());
        let out = run_jobs(
            &jobs,
            2,
            &bar,
            0,
            |j| format!("seed {}", j.seed),
            |j| match j.seed {
                2 => anyhow::bail!("bad seed"),
                4 => panic!("seed four"),
                s => Ok(s * 10),
            },
            |f| seen.lock().unwrap().push(f.job.index),
        )
        .unwrap();
        // each job was seen as it ended, failed ones too
        let mut seen = seen.into_inner().unwrap();
        seen.sort();
        assert_eq!(seen, [0, 1, 2, 3, 4, 5]);
        let got: Vec<Result<u64, String>> = out.into_iter().map(|f| f.result).collect();
        assert_eq!(
            got,
            [
                Ok(0),
                Ok(10),
                Err("bad seed".to_string()),
                Ok(30),
                Err("panicked: seed four".to_string()),
                Ok(50)
            ]
        );
    }

    /// A run whose kernels wait on a pool of their own keeps its worker to itself: no second
    /// run is stacked on a worker while it waits (as a rayon `par_iter` over the runs does,
    /// its waiting worker stealing the next run), so at most `workers` runs are in progress
    /// at once; and the results come back in item order.
    #[test]
    fn a_worker_runs_one_item_at_a_time_however_its_kernels_wait() {
        let active = AtomicUsize::new(0);
        let most = AtomicUsize::new(0);
        let items: Vec<usize> = (0..12).collect();
        let out = on_workers(&items, 2, |i, &item| {
            let now = active.fetch_add(1, Ordering::SeqCst) + 1;
            most.fetch_max(now, Ordering::SeqCst);
            let kernels = rayon::ThreadPoolBuilder::new()
                .num_threads(1)
                .build()
                .unwrap();
            kernels.install(|| std::thread::sleep(std::time::Duration::from_millis(20)));
            active.fetch_sub(1, Ordering::SeqCst);
            (i, item * 10)
        })
        .unwrap();
        assert_eq!(out, (0..12).map(|i| (i, i * 10)).collect::<Vec<_>>());
        assert_eq!(most.load(Ordering::SeqCst), 2);
    }
}
