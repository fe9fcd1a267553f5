//! What a replay re-runs: the scenario (our own file: its `scenario.toml` attachment with the
//! seed and length of the recorded run; otherwise `--scenario`), with `--set` overrides
//! applied as `sim batch` applies them, the robots to replay and each one's readings.

use super::args::ReplayArgs;
use super::source::{RobotFeed, TimeBase, TopicFlags, first_stamp, robot_feed};
use crate::batch::sets::plan_sets;
use crate::record::mcap::McapRecording;
use crate::record::topics::RunInfo;
use crate::scenario::scenario_path;
use crate::scenario::source::Source;
use crate::scenario::{OdometrySource, Scenario, assets_dir};
use anyhow::{anyhow, bail};
use std::path::{Path, PathBuf};

/// A replay ready to build.
pub struct ReplayPlan {
    pub scenario: Scenario,
    /// `run.json` of our own files.
    pub run: Option<RunInfo>,
    /// Each replayed robot's readings, in the order of `scenario.robots` (which keeps only them).
    pub feeds: Vec<RobotFeed>,
}

/// `run.json`, if the file has it (a file written by `sim run --mcap`).
fn run_info(rec: &McapRecording) -> anyhow::Result<Option<RunInfo>> {
    let Some(a) = rec.attachment("run.json") else {
        return Ok(None);
    };
    serde_json::from_slice(&a.data).map(Some).map_err(|e| {
        anyhow!(
            "{}: attachment run.json does not describe a run: {e}",
            rec.path.display()
        )
    })
}

/// Folders the relative paths of an attached scenario may be relative to: where the scenario
/// was when recorded, next to the recording, the bundled scenarios.
fn base_dirs(run: &RunInfo, file: &Path) -> Vec<PathBuf> {
    let mut dirs = Vec::new();
    if let Some(d) = Path::new(&run.scenario_file).parent() {
        dirs.push(d.to_path_buf());
    }
    dirs.push(file.parent().map(Path::to_path_buf).unwrap_or_default());
    dirs.push(assets_dir().join("scenarios"));
    dirs
}

/// The scenario attached to our own file, loaded against the first folder its paths resolve in.
fn attached_source(
    rec: &McapRecording,
    run: &RunInfo,
    odometry: OdometrySource,
) -> anyhow::Result<Source> {
    let Some(a) = rec.attachment("scenario.toml") else {
        bail!(
            "{}: no scenario.toml attachment; give the scenario with --scenario",
            rec.path.display()
        );
    };
    let text = std::str::from_utf8(&a.data).map_err(|_| {
        anyhow!(
            "{}: attachment scenario.toml is not UTF-8 text",
            rec.path.display()
        )
    })?;
    let label = format!("{} (attached scenario.toml)", rec.path.display());
    let mut first_error = None;
    for dir in base_dirs(run, &rec.path) {
        match Source::from_text_with(text, &label, &dir, &run.scenario, odometry) {
            Ok(s) => return Ok(s),
            Err(e) => {
                first_error.get_or_insert(e);
            }
        }
    }
    Err(first_error.unwrap_or_else(|| anyhow!("{label}: cannot load")))
}

/// Reads the plan of `sim replay` from the arguments and the opened recording.
pub fn plan(a: &ReplayArgs, rec: &McapRecording) -> anyhow::Result<ReplayPlan> {
    let run = run_info(rec)?;
    // foreign files replay an odometry topic (default /odom), our own the encoder ticks
    let odometry = if run.is_none() || a.odom_topic.is_some() {
        OdometrySource::Recorded
    } else {
        OdometrySource::Encoders
    };
    let source = match (&a.scenario, &run) {
        (Some(s), _) => Source::load_with(&scenario_path(Some(s))?, odometry)?,
        (None, Some(run)) => attached_source(rec, run, odometry)?,
        (None, None) => bail!(
            "{}: not written by `sim run --mcap` (no run.json attachment): give the map and robot \
             with --scenario, and the topics with --scan-topic and --odom-topic if they are not \
             /scan and /odom",
            rec.path.display()
        ),
    };
    if let Some(s) = a.sets.iter().find(|s| s.trim_start().starts_with("seed=")) {
        bail!("--set {s}: give the seed with --seed");
    }
    let sets = plan_sets(&a.sets, &[], &[])?;
    let mut scenario = source.scenario(&sets.sets[0]).map_err(|e| anyhow!("{e}"))?;
    if let Some(run) = &run {
        scenario.seed = run.seed;
        scenario.dt = run.dt;
    }
    if let Some(s) = a.seed {
        scenario.seed = s;
    }
    let robots = pick_robots(a, &scenario, run.is_some())?;
    let flags = TopicFlags {
        scan: a.scan_topic.clone(),
        odom: a.odom_topic.clone(),
        joint_states: a.joint_states_topic.clone(),
        truth: a.truth_topic.clone(),
    };
    let time = match &run {
        Some(run) => TimeBase::Own(run),
        None => {
            let topics = [
                flags.scan.as_deref().unwrap_or("/scan"),
                flags.odom.as_deref().unwrap_or("/odom"),
            ];
            TimeBase::Since(first_stamp(rec, &topics)?)
        }
    };
    let feeds = robots
        .iter()
        .map(|&i| robot_feed(rec, &scenario.robots[i], &flags, &time))
        .collect::<anyhow::Result<Vec<_>>>()?;
    // keep only the replayed robots, in their scenario order
    let keep: Vec<_> = robots.iter().map(|&i| scenario.robots[i].clone()).collect();
    scenario.robots = keep;
    scenario.people.clear();
    let (last, what) = last_reading(&feeds, &scenario)
        .ok_or_else(|| anyhow!("{}: no messages on the replayed topics", rec.path.display()))?;
    // up to the last reading, whole ticks
    scenario.duration = ((last / scenario.dt - 1e-6).ceil().max(1.0)) * scenario.dt;
    // a stamp years ahead of the others (a clock unset, or a damaged stamp) would make the
    // replay run for ever: refused before it starts, naming the reading
    if crate::scenario::model::too_many_ticks(scenario.duration, scenario.dt).is_some() {
        bail!(
            "{}: {what} is stamped {last:.4e} s ({:.1} days) after the replay's start; at dt = \
             {} s that is {:.3e} ticks, more than a run may have ({:.0e}): is its stamp wrong?",
            rec.path.display(),
            last / 86_400.0,
            scenario.dt,
            scenario.duration / scenario.dt,
            crate::scenario::model::MAX_TICKS
        );
    }
    Ok(ReplayPlan {
        scenario,
        run,
        feeds,
    })
}

/// The robots to replay (indices into the scenario): `--robot`, else every robot of our own
/// file, else the scenario's only robot.
fn pick_robots(a: &ReplayArgs, sc: &Scenario, own: bool) -> anyhow::Result<Vec<usize>> {
    let names = || {
        sc.robots
            .iter()
            .map(|r| r.name.as_str())
            .collect::<Vec<_>>()
            .join(", ")
    };
    if let Some(name) = &a.robot {
        return match sc.robots.iter().position(|r| &r.name == name) {
            Some(i) => Ok(vec![i]),
            None => bail!(
                "--robot {name}: {} has no robot of that name (robots: {})",
                sc.source,
                names()
            ),
        };
    }
    let topic_flags = a.scan_topic.is_some()
        || a.odom_topic.is_some()
        || a.joint_states_topic.is_some()
        || a.truth_topic.is_some();
    if (own && !topic_flags) || sc.robots.len() == 1 {
        return Ok((0..sc.robots.len()).collect());
    }
    bail!(
        "{} has {} robots ({}): say which one the topics belong to with --robot",
        sc.source,
        sc.robots.len(),
        names()
    )
}

/// The latest reading of the replayed robots: its time (s since the replay's start) and what
/// it is (`r1's laser scan`), for messages.
fn last_reading(feeds: &[RobotFeed], sc: &Scenario) -> Option<(f64, String)> {
    let mut last: Option<(f64, String)> = None;
    for (f, robot) in feeds.iter().zip(&sc.robots) {
        let kinds = [
            (f.scans.last().map(|s| s.stamp), "laser scan"),
            (f.encoder.last().map(|e| e.stamp), "encoder reading"),
            (f.odometry.last().map(|o| o.0), "odometry pose"),
            (f.truth.last().map(|t| t.0), "true pose"),
        ];
        for (t, kind) in kinds {
            if let Some(t) = t.filter(|&t| last.as_ref().is_none_or(|l| t > l.0)) {
                last = Some((t, format!("{}'s last {kind}", robot.name)));
            }
        }
    }
    last
}
