//! `batch.json`: what an output folder of `sim batch` holds — the batch it belongs to (scenario,
//! seeds, duration, overrides, number of jobs) and which shard of it — so that `sim batch-merge`
//! can refuse shards of different batches and name the shards that are missing.

use serde::{Deserialize, Serialize};
use std::path::Path;
use systems::core::input::{MAX_CONFIG_BYTES, read_text_bounded};

/// The file's name in the output folder.
pub const FILE: &str = "batch.json";

/// The batch an output folder belongs to, and its shard.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    /// The scenario's name.
    pub scenario: String,
    /// `--seeds` as parsed, `A..B`.
    pub seeds: String,
    /// `--duration` (None: each set's scenario says).
    pub duration: Option<f64>,
    /// The `--set`, `--sweep` and `--zip` arguments, in order.
    pub set: Vec<String>,
    pub sweep: Vec<String>,
    pub zip: Vec<String>,
    /// Jobs of the whole batch (every shard).
    pub jobs: usize,
    /// This folder holds shard `shard` of `shards` (0 of 1 without `--shard`).
    pub shard: usize,
    pub shards: usize,
}

impl Manifest {
    /// Writes `batch.json` into `dir`.
    pub fn write(&self, dir: &Path) -> anyhow::Result<()> {
        let path = dir.join(FILE);
        let text = serde_json::to_string_pretty(self)?;
        std::fs::write(&path, text + "\n")
            .map_err(|e| anyhow::anyhow!("{}: cannot write: {e}", path.display()))
    }

    /// Reads the `batch.json` of `dir`, checking that its shard is one.
    pub fn read(dir: &Path) -> anyhow::Result<Manifest> {
        let path = dir.join(FILE);
        let text = read_text_bounded(&path, MAX_CONFIG_BYTES).map_err(|e| {
            anyhow::anyhow!(
                "{}: cannot read: {e} (every output folder of sim batch has one; a folder \
                 written by an older sim has not: run that shard again)",
                path.display()
            )
        })?;
        let m: Manifest = serde_json::from_str(&text)
            .map_err(|e| anyhow::anyhow!("{}: not a {FILE} of sim batch: {e}", path.display()))?;
        if m.shard >= m.shards {
            anyhow::bail!(
                "{}: shard {} of {} is not a shard (expected K below N)",
                path.display(),
                m.shard,
                m.shards
            );
        }
        Ok(m)
    }

    /// The runs of this shard: jobs K, K+N, … below the batch's number of jobs.
    pub fn shard_runs(&self) -> usize {
        self.jobs
            .saturating_sub(self.shard)
            .div_ceil(self.shards.max(1))
    }

    /// The first thing that two folders of one batch would share but these do not: what it is
    /// (the scenario, or the option), and its value in `self` and in `other`.
    pub fn difference(&self, other: &Manifest) -> Option<(&'static str, String, String)> {
        let list = |v: &[String]| {
            if v.is_empty() {
                "not given".to_string()
            } else {
                v.join(" ")
            }
        };
        let duration = |d: Option<f64>| d.map_or("not given".to_string(), |d| d.to_string());
        let fields = [
            (
                "the scenario",
                self.scenario.clone(),
                other.scenario.clone(),
            ),
            ("--seeds", self.seeds.clone(), other.seeds.clone()),
            (
                "--duration",
                duration(self.duration),
                duration(other.duration),
            ),
            ("--set", list(&self.set), list(&other.set)),
            ("--sweep", list(&self.sweep), list(&other.sweep)),
            ("--zip", list(&self.zip), list(&other.zip)),
            (
                "the number of shards N (--shard K/N)",
                self.shards.to_string(),
                other.shards.to_string(),
            ),
            (
                "the number of jobs",
                self.jobs.to_string(),
                other.jobs.to_string(),
            ),
        ];
        fields.into_iter().find(|(_, a, b)| a != b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn manifest(shard: usize, shards: usize, jobs: usize) -> Manifest {
        Manifest {
            scenario: "maze_run".into(),
            seeds: "0..3".into(),
            duration: None,
            set: Vec::new(),
            sweep: vec!["duration=1,2".into()],
            zip: Vec::new(),
            jobs,
            shard,
            shards,
        }
    }

    #[test]
    fn shard_runs_and_round_trip() {
        assert_eq!(manifest(0, 1, 6).shard_runs(), 6);
        assert_eq!(manifest(0, 4, 6).shard_runs(), 2);
        assert_eq!(manifest(1, 4, 6).shard_runs(), 2);
        assert_eq!(manifest(2, 4, 6).shard_runs(), 1);
        assert_eq!(manifest(5, 8, 3).shard_runs(), 0);
        let dir = tempfile::tempdir().unwrap();
        let m = manifest(1, 2, 6);
        m.write(dir.path()).unwrap();
        assert_eq!(Manifest::read(dir.path()).unwrap(), m);
        manifest(2, 2, 6).write(dir.path()).unwrap();
        let e = Manifest::read(dir.path()).unwrap_err().to_string();
        assert!(e.contains("shard 2 of 2 is not a shard"), "{e}");
    }

    #[test]
    fn differences_name_the_option() {
        let a = manifest(0, 2, 6);
        assert_eq!(a.difference(&manifest(1, 2, 6)), None);
        let mut b = manifest(1, 2, 6);
        b.duration = Some(5.0);
        assert_eq!(
            a.difference(&b),
            Some(("--duration", "not given".into(), "5".into()))
        );
        let d = a.difference(&manifest(1, 3, 6)).unwrap();
        assert_eq!((d.1.as_str(), d.2.as_str()), ("2", "3"));
    }
}
