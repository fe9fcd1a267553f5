//! `runs.jsonl` as the batch goes: each run's row is appended (and flushed) when the run ends,
//! so a batch that is killed (a cluster's time limit, a lost node) leaves the rows of the runs
//! it finished. `sim batch --resume` reads them back ([`finished_rows`]) and runs only the jobs
//! without a successful row; at the end the file is written again in job order.

use super::manifest::{self, Manifest};
use super::output::{Row, row_line};
use super::runner::Job;
use serde::de::{Deserializer, MapAccess, Visitor};
use serde_json::Value as Json;
use std::collections::BTreeMap;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use systems::core::input::{MAX_DATA_BYTES, read_bounded};

/// The rows' file in an output folder.
pub const RUNS: &str = "runs.jsonl";

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

/// One line of a runs.jsonl: a row, or what is wrong with it (the line number is the caller's).
pub fn parse_row(line: &str) -> Result<Row, String> {
    let Ordered(row) = serde_json::from_str(line).map_err(|e| format!("not a run row: {e}"))?;
    for k in ["job", "set"] {
        if !row.iter().any(|(c, v)| c == k && v.is_u64()) {
            return Err(format!("no `{k}` number: not a runs.jsonl of sim batch"));
        }
    }
    Ok(row)
}

/// The number `k` of a row (0 when absent).
pub fn number(row: &Row, k: &str) -> u64 {
    row.iter()
        .find(|(c, _)| c == k)
        .and_then(|(_, v)| v.as_u64())
        .unwrap_or(0)
}

/// Whether a row is of a successful run.
pub fn succeeded(row: &Row) -> bool {
    row.iter().any(|(c, v)| c == "status" && v == "ok")
}

/// The successful rows that the batch in `dir` already has for `jobs`, by job index, for
/// `--resume`: `dir`'s batch.json must describe the same batch and shard as `manifest`. A
/// last line cut short (the batch was killed while writing it) is left out; any other line
/// that is not a row is an error.
pub fn finished_rows(
    dir: &Path,
    manifest: &Manifest,
    jobs: &[Job],
) -> anyhow::Result<BTreeMap<usize, Row>> {
    if !dir.join(manifest::FILE).exists() {
        anyhow::bail!(
            "--resume: {} holds no batch ({} is missing): run it without --resume",
            dir.display(),
            manifest::FILE
        );
    }
    let there = Manifest::read(dir)?;
    if let Some((what, theirs, ours)) = there.difference(manifest) {
        anyhow::bail!(
            "--resume: {} holds another batch: {what} is {theirs} there, {ours} here (resume \
             with the arguments it was started with)",
            dir.display()
        );
    }
    if (there.shard, there.shards) != (manifest.shard, manifest.shards) {
        anyhow::bail!(
            "--resume: {} holds shard {}/{}, not {}/{}",
            dir.display(),
            there.shard,
            there.shards,
            manifest.shard,
            manifest.shards
        );
    }
    let path = dir.join(RUNS);
    let text = match read_bounded(&path, MAX_DATA_BYTES) {
        Ok(bytes) => String::from_utf8_lossy(&bytes).into_owned(),
        // killed before its first run ended
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => String::new(),
        Err(e) => anyhow::bail!("{}: cannot read: {e}", path.display()),
    };
    let by_index: BTreeMap<usize, &Job> = jobs.iter().map(|j| (j.index, j)).collect();
    let lines: Vec<&str> = text.lines().collect();
    let mut done = BTreeMap::new();
    for (i, line) in lines.iter().enumerate() {
        if line.trim().is_empty() {
            continue;
        }
        let row = match parse_row(line) {
            Ok(r) => r,
            Err(_) if i + 1 == lines.len() && !text.ends_with('\n') => break,
            Err(e) => anyhow::bail!("{}:{}: {e}", path.display(), i + 1),
        };
        let index = number(&row, "job") as usize;
        let Some(job) = by_index.get(&index) else {
            anyhow::bail!(
                "{}:{}: job {index} is not one of this shard's: the file is edited or from \
                 another batch",
                path.display(),
                i + 1
            );
        };
        if number(&row, "set") != job.set as u64 || number(&row, "seed") != job.seed {
            anyhow::bail!(
                "{}:{}: job {index} has another set or seed than this batch gives it: the file \
                 is edited or from another batch",
                path.display(),
                i + 1
            );
        }
        if succeeded(&row) {
            done.entry(index).or_insert(row);
        }
    }
    Ok(done)
}

/// The rows file of a batch being run: rows appended as runs end. A write error is kept and
/// returned by [`Journal::finish`]; the runs go on.
pub struct Journal {
    path: PathBuf,
    state: Mutex<(Option<BufWriter<File>>, Option<String>)>,
}

impl Journal {
    /// Starts `dir`'s rows file with `kept` (the rows a resumed batch keeps), in order.
    pub fn start(dir: &Path, kept: &[Row]) -> anyhow::Result<Journal> {
        let path = dir.join(RUNS);
        let io = |e: std::io::Error| anyhow::anyhow!("{}: cannot write: {e}", path.display());
        let mut w = BufWriter::new(File::create(&path).map_err(io)?);
        for r in kept {
            writeln!(w, "{}", row_line(r)).map_err(io)?;
        }
        w.flush().map_err(io)?;
        Ok(Journal {
            path: path.clone(),
            state: Mutex::new((Some(w), None)),
        })
    }

    /// Appends rows and hands them to the OS.
    pub fn append(&self, rows: &[Row]) {
        let mut s = self.state.lock().unwrap_or_else(|p| p.into_inner());
        let (writer, error) = &mut *s;
        let Some(w) = writer.as_mut() else { return };
        let written = rows
            .iter()
            .try_for_each(|r| writeln!(w, "{}", row_line(r)))
            .and_then(|()| w.flush());
        if let Err(e) = written {
            error.get_or_insert_with(|| format!("{}: cannot write: {e}", self.path.display()));
            *writer = None;
        }
    }

    /// Closes the file; the first write error, if any.
    pub fn finish(self) -> anyhow::Result<()> {
        let (_, error) = self.state.into_inner().unwrap_or_else(|p| p.into_inner());
        error.map_or(Ok(()), |e| Err(anyhow::anyhow!(e)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::batch::runner::plan_jobs;
    use serde_json::json;

    fn manifest(shard: usize, shards: usize) -> Manifest {
        Manifest {
            scenario: "maze_run".into(),
            seeds: "0..3".into(),
            duration: Some(5.0),
            set: Vec::new(),
            sweep: vec!["robots.0.behaviour.speed=0.4,0.5".into()],
            zip: Vec::new(),
            jobs: 6,
            shard,
            shards,
        }
    }

    fn row(job: usize, set: u64, seed: u64, ok: bool) -> Row {
        vec![
            ("job".into(), json!(job)),
            ("set".into(), json!(set)),
            ("seed".into(), json!(seed)),
            ("status".into(), json!(if ok { "ok" } else { "failed" })),
            ("sim_time_s".into(), json!(0.1 + job as f64)),
        ]
    }

    /// A folder of shard 0/2 (jobs 0, 2, 4) whose runs.jsonl is `text`.
    fn folder(text: &str) -> (tempfile::TempDir, Vec<Job>) {
        let dir = tempfile::tempdir().unwrap();
        manifest(0, 2).write(dir.path()).unwrap();
        std::fs::write(dir.path().join(RUNS), text).unwrap();
        (dir, plan_jobs(2, 0..3, Some((0, 2))).unwrap())
    }

    #[test]
    fn rows_written_as_runs_end_are_read_back_exactly() {
        let dir = tempfile::tempdir().unwrap();
        let kept = [row(0, 0, 0, true)];
        let j = Journal::start(dir.path(), &kept).unwrap();
        j.append(&[row(4, 1, 1, true), row(2, 0, 2, false)]);
        j.finish().unwrap();
        manifest(0, 2).write(dir.path()).unwrap();
        let jobs = plan_jobs(2, 0..3, Some((0, 2))).unwrap();
        let done = finished_rows(dir.path(), &manifest(0, 2), &jobs).unwrap();
        // the failed run is to be run again; the others keep their values bit for bit
        assert_eq!(done.keys().copied().collect::<Vec<_>>(), [0, 4]);
        assert_eq!(done[&4], row(4, 1, 1, true));
    }

    #[test]
    fn a_last_line_cut_short_is_left_out_and_any_other_bad_line_is_an_error() {
        let cut = format!("{}\n{{\"job\":2,\"se", row_line(&row(0, 0, 0, true)));
        let (dir, jobs) = folder(&cut);
        let done = finished_rows(dir.path(), &manifest(0, 2), &jobs).unwrap();
        assert_eq!(done.len(), 1);
        let bad = format!("{{\"job\":2,\"se\n{}\n", row_line(&row(0, 0, 0, true)));
        let (dir, jobs) = folder(&bad);
        let e = finished_rows(dir.path(), &manifest(0, 2), &jobs).unwrap_err();
        assert!(e.to_string().contains("runs.jsonl:1: not a run row"), "{e}");
    }

    #[test]
    fn another_batch_or_shard_or_a_foreign_row_is_refused() {
        let (dir, jobs) = folder("");
        let mut other = manifest(0, 2);
        other.duration = Some(9.0);
        let e = finished_rows(dir.path(), &other, &jobs).unwrap_err();
        assert!(
            e.to_string().contains("holds another batch: --duration"),
            "{e}"
        );
        let e = finished_rows(dir.path(), &manifest(1, 2), &jobs).unwrap_err();
        assert!(e.to_string().contains("holds shard 0/2, not 1/2"), "{e}");
        // job 1 belongs to shard 1/2; job 2 is set 0, seed 2
        for r in [row(1, 0, 1, true), row(2, 1, 0, true)] {
            let (dir, jobs) = folder(&(row_line(&r) + "\n"));
            let e = finished_rows(dir.path(), &manifest(0, 2), &jobs).unwrap_err();
            assert!(e.to_string().contains("runs.jsonl:1: job"), "{e}");
        }
        let empty = tempfile::tempdir().unwrap();
        let e = finished_rows(empty.path(), &manifest(0, 2), &jobs).unwrap_err();
        assert!(e.to_string().contains("holds no batch"), "{e}");
    }

    #[test]
    fn a_batch_killed_before_its_first_row_resumes_from_nothing() {
        let (dir, jobs) = folder("");
        std::fs::remove_file(dir.path().join(RUNS)).unwrap();
        assert!(
            finished_rows(dir.path(), &manifest(0, 2), &jobs)
                .unwrap()
                .is_empty()
        );
    }
}
