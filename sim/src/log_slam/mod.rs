//! `sim slam --carmen LOG`: a SLAM system run on a recorded CARMEN log — a
//! classic dataset or a run exported by `sim run --carmen-out`.
//!
//! The log is read by [`crate::formats::carmen`] (FLASER, ROBOTLASER1, ODOM, TRUEPOS and PARAM lines;
//! other types skipped and counted; a malformed line of a known type is an error naming the
//! file, the line and what was expected). The SLAM system is resolved like a scenario's `slam`
//! key (`--slam TYPE`, `--slam-config FILE` with the keys of that table,
//! [`crate::scenario::slam_file`]) and built by the constructor `sim run` uses
//! ([`crate::build::new_scan_estimator`]), so every SLAM type of the scenario files runs here.
//!
//! The front scans are fed in time order, each with the robot's odometry pose logged with it
//! and the laser's mount; the SLAM starts at the first scan's odometry pose, so its map frame
//! is the odometry frame at the start. Rear scans are not used. With `TRUEPOS` lines, the SLAM
//! trajectory and the raw odometry are judged against them ([`eval`]).
use systems::core::input::{MAX_CONFIG_BYTES, read_text_bounded};

pub mod eval;
pub mod feed;
pub mod report;

use crate::build::new_scan_estimator;
use crate::formats::carmen::{CarmenReadOptions, OldLaserOverrides, read_carmen};
use crate::formats::maps::{MapToSave, save_maps};
use crate::formats::tum::tum_line;
#[cfg(feature = "rrd")]
use crate::record::rrd::log_slam::ReplayRecorder;
use crate::scenario::slam_file::resolve_slam_config;
use eval::TruthTrack;
use feed::feed_scans;
use indicatif::{ProgressBar, ProgressStyle};
use report::{MapInfo, SlamReport};
use std::path::{Path, PathBuf};
use systems::core::{KernelPool, Pose2, stream_rng};

// the field docs are the --help text: <placeholders> are not HTML
#[allow(rustdoc::invalid_html_tags)]
#[derive(clap::Args, Clone, Debug)]
pub struct SlamArgs {
    /// The CARMEN log (plain text).
    #[arg(long)]
    pub carmen: PathBuf,
    /// The SLAM system: a `type` of the scenario key `slam` (default: the config file's type,
    /// else scan_to_map).
    #[arg(long)]
    pub slam: Option<String>,
    /// A TOML file with the keys of the scenario's `slam` table (resolution, name, …).
    #[arg(long)]
    pub slam_config: Option<PathBuf>,
    /// Field of view of old FLASER lines (degrees; default: the log's PARAMs, else CARMEN's
    /// guess from the beam count). ROBOTLASER1 lines carry their own.
    #[arg(long, allow_negative_numbers = true)]
    pub fov: Option<f64>,
    /// Maximum range of old FLASER lines (m; default: the log's PARAMs, else 80 m).
    #[arg(long, allow_negative_numbers = true)]
    pub max_range: Option<f64>,
    /// Where to write the Rerun recording (default: <log stem>-slam.rrd here).
    #[arg(long, conflicts_with = "no_rrd")]
    pub rrd: Option<PathBuf>,
    /// Do not write a recording.
    #[arg(long)]
    pub no_rrd: bool,
    /// SLAM maps, trajectories and graphs recorded per second of log time (0: only the last).
    #[arg(long, default_value_t = 0.5, allow_negative_numbers = true)]
    pub slam_rate: f64,
    /// Save the final map as map_server YAML + PGM (`.yaml` added when missing).
    #[arg(long)]
    pub save_map: Option<PathBuf>,
    /// Write the SLAM trajectory in TUM format (and, with TRUEPOS lines, the truth at the same
    /// stamps next to it as `<stem>.truth.tum`).
    #[arg(long)]
    pub trajectory: Option<PathBuf>,
    /// Write the report as JSON to this file.
    #[arg(long)]
    pub summary: Option<PathBuf>,
    /// No progress bar and no report, only errors.
    #[arg(long)]
    pub quiet: bool,
    /// Seed of the SLAM system's random stream (for randomized SLAM types).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Worker threads for parallel kernels (0 = one per core; at most 1024). Results do not
    /// depend on it.
    #[arg(long, default_value_t = 0, value_parser = crate::options::parse_threads)]
    pub threads: usize,
}

/// The robot's name in the recording: the log's file stem (letters, digits, `_`, `-`; others
/// become `_`), or `robot`.
pub fn robot_name(log: &Path) -> String {
    let stem = log.file_stem().and_then(|s| s.to_str()).unwrap_or("");
    let name: String = stem
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect();
    if name.is_empty() {
        "robot".into()
    } else {
        name
    }
}

fn read_options(a: &SlamArgs) -> anyhow::Result<CarmenReadOptions> {
    if !(a.slam_rate.is_finite() && a.slam_rate >= 0.0) {
        anyhow::bail!(
            "--slam-rate: expected a number of logs per second ≥ 0, got {}",
            a.slam_rate
        );
    }
    if let Some(f) = a.fov
        && !(f.is_finite() && f > 0.0 && f <= 360.0)
    {
        anyhow::bail!("--fov: expected degrees in (0, 360], got {f}");
    }
    if let Some(m) = a.max_range
        && !(m.is_finite() && m > 0.0)
    {
        anyhow::bail!("--max-range: expected a positive number of metres, got {m}");
    }
    Ok(CarmenReadOptions {
        front: OldLaserOverrides {
            fov: a.fov.map(f64::to_radians),
            resolution: None,
            max_range: a.max_range,
        },
        ..CarmenReadOptions::default()
    })
}

fn progress(quiet: bool, n: usize) -> ProgressBar {
    if quiet {
        return ProgressBar::hidden();
    }
    let b = ProgressBar::new(n as u64);
    b.set_style(
        ProgressStyle::with_template("{bar:40.cyan/blue} {pos}/{len} scans  [{elapsed_precise}]")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    b
}

/// Writes `poses` as TUM lines.
fn write_tum(path: &Path, poses: impl Iterator<Item = (f64, Pose2)>) -> anyhow::Result<()> {
    let text: String = poses.map(|(t, p)| tum_line(t, &p) + "\n").collect();
    std::fs::write(path, text)
        .map_err(|e| anyhow::anyhow!("{}: cannot write the trajectory: {e}", path.display()))
}

/// `sim slam`: runs, prints the report (unless quiet), writes the files asked for. A quiet run
/// with no summary and no saved map returns a report without the map's size.
pub fn run_slam_command(a: &SlamArgs) -> anyhow::Result<SlamReport> {
    let log = read_carmen(&a.carmen, &read_options(a)?)?;
    let file = a.carmen.display().to_string();
    let scans = log.front_scans();
    let Some(first) = scans.first() else {
        anyhow::bail!("{file}: no front laser scans (FLASER or ROBOTLASER1 lines): nothing to map");
    };
    let robot = robot_name(&a.carmen);
    let config_text = match &a.slam_config {
        Some(p) => Some((
            p.display().to_string(),
            read_text_bounded(p, MAX_CONFIG_BYTES)
                .map_err(|e| anyhow::anyhow!("{}: cannot read: {e}", p.display()))?,
        )),
        None => None,
    };
    let config = resolve_slam_config(
        a.slam.as_deref(),
        config_text.as_ref().map(|(l, t)| (l.as_str(), t.as_str())),
        &first.robot_pose,
    )?;
    let rng = stream_rng(a.seed, &robot, &format!("localizer/{}", config.name));
    let mut est = new_scan_estimator(&config.kind, rng)?;
    let pool = KernelPool::new(a.threads)
        .map_err(|e| anyhow::anyhow!("cannot start {} kernel threads: {e}", a.threads))?;
    let stamps: Vec<f64> = log.events().map(|e| e.timestamp()).collect();
    let (t0, t1) = (stamps[0], stamps[stamps.len() - 1]);
    let truth = TruthTrack::new(&log.truth);
    let rrd = (!a.no_rrd).then(|| {
        a.rrd
            .clone()
            .unwrap_or_else(|| PathBuf::from(format!("{robot}-slam.rrd")))
    });
    #[cfg(feature = "rrd")]
    let mut rec = match &rrd {
        Some(p) => Some(ReplayRecorder::create(
            p,
            &robot,
            &config.name,
            (t0, a.slam_rate),
        )?),
        None => None,
    };
    #[cfg(not(feature = "rrd"))]
    if let Some(p) = &rrd {
        return Err(crate::record::without_rrd(p));
    }
    if !a.quiet {
        eprintln!(
            "running {} ({}) on {file}: {} scans over {:.1} s",
            config.name,
            est.kind(),
            scans.len(),
            t1 - t0
        );
    }
    let bar = progress(a.quiet, scans.len());
    let run = feed_scans(est.as_mut(), &scans, &pool, |k, s, scan, est| {
        #[cfg(not(feature = "rrd"))]
        let _ = (s, scan, est); // no recording in this build
        #[cfg(feature = "rrd")]
        if let Some(r) = rec.as_mut() {
            let at = (s.timestamp, &s.robot_pose, truth.at(s.timestamp), &s.mount);
            r.scan(est, scan, at);
        }
        if k % 50 == 0 {
            bar.set_position(k as u64 + 1);
        }
    });
    bar.finish_and_clear();
    let wall_time_s = run.wall_time_s;
    #[cfg(feature = "rrd")]
    if let Some(r) = rec {
        r.finish(est.as_ref(), t1)?;
    }
    let (online, trajectory) = (run.online, run.trajectory);
    let odometry: Vec<(f64, Pose2)> = scans.iter().map(|s| (s.timestamp, s.robot_pose)).collect();
    // the whole map is built only for what reads it: the printed report, the summary's map
    // size and the saved map (for graph SLAM, every node's scan inserted again)
    let map = (!a.quiet || a.summary.is_some() || a.save_map.is_some())
        .then(|| est.map())
        .flatten();
    let mut report = SlamReport {
        log: file.clone(),
        robot: robot.clone(),
        slam: config.name.clone(),
        slam_type: est.kind().to_string(),
        scans: scans.len(),
        estimates: online.len(),
        rear_scans: log.rear_scans.len(),
        odometry_records: log.odometry.len(),
        truth_records: log.truth.len(),
        skipped: log.skipped.clone(),
        log_duration_s: t1 - t0,
        wall_time_s,
        real_time_factor: (t1 - t0) / wall_time_s.max(1e-9),
        slam_metrics: truth.slam_metrics(est.kind(), &online, &trajectory),
        odometry_metrics: truth.metrics("odometry", &odometry),
        map: map.as_ref().map(|m| MapInfo {
            width: m.width,
            height: m.height,
            resolution: m.resolution,
        }),
        files: Vec::new(),
    };
    if let Some(p) = &a.save_map {
        let Some(m) = &map else {
            anyhow::bail!("--save-map: {} built no map", config.name);
        };
        let grid = m.to_occupancy();
        let to_save = [MapToSave {
            robot: robot.clone(),
            name: config.name.clone(),
            grid,
        }];
        for s in save_maps(p, &to_save, None)? {
            report.files.push(s.yaml.display().to_string());
        }
    }
    if let Some(p) = &a.trajectory {
        write_tum(p, trajectory.iter().copied())?;
        report.files.push(p.display().to_string());
        if !truth.is_empty() {
            let tp = p.with_extension("truth.tum");
            let paired = truth.samples(&trajectory);
            write_tum(&tp, paired.iter().map(|s| (s.t, s.truth)))?;
            report.files.push(tp.display().to_string());
        }
    }
    if let Some(p) = &rrd {
        report.files.push(p.display().to_string());
    }
    if let Some(p) = &a.summary {
        let json = serde_json::to_string_pretty(&report)? + "\n";
        std::fs::write(p, json)
            .map_err(|e| anyhow::anyhow!("{}: cannot write the summary: {e}", p.display()))?;
    }
    if !a.quiet {
        print!("{}", report.table());
    }
    Ok(report)
}
