//! What `sim slam` reports: on the terminal ([`SlamReport::table`]) and as JSON (`--summary`).

use serde::Serialize;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use systems::eval::LocalizerMetrics;

#[derive(Clone, Debug, Serialize)]
pub struct MapInfo {
    pub width: usize,
    pub height: usize,
    pub resolution: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct SlamReport {
    pub log: String,
    /// The robot's name in the recording (the log's file stem).
    pub robot: String,
    /// The SLAM system's name and type.
    pub slam: String,
    pub slam_type: String,
    /// Front scans fed to the SLAM system (all of the log's).
    pub scans: usize,
    /// Scans after which it published an estimate.
    pub estimates: usize,
    /// Rear scans in the log (not used).
    pub rear_scans: usize,
    pub odometry_records: usize,
    pub truth_records: usize,
    /// Lines not used, by message type: unknown types and superseded old laser lines.
    pub skipped: BTreeMap<String, usize>,
    /// From the first to the last record's timestamp (s).
    pub log_duration_s: f64,
    pub wall_time_s: f64,
    /// Log duration / wall time.
    pub real_time_factor: f64,
    /// The SLAM system's estimates, published scan by scan, against TRUEPOS, with its final
    /// trajectory's figures in `final_trajectory` (None without TRUEPOS lines).
    pub slam_metrics: Option<LocalizerMetrics>,
    /// The logged odometry at the scans against TRUEPOS.
    pub odometry_metrics: Option<LocalizerMetrics>,
    pub map: Option<MapInfo>,
    /// Files written.
    pub files: Vec<String>,
}

fn metric(v: Option<f64>, unit: &str) -> String {
    v.map_or("-".to_string(), |v| format!("{v:.4} {unit}"))
}

impl SlamReport {
    /// The terminal report.
    pub fn table(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(
            s,
            "{} ({}) on {}: {} scans used, {} estimates",
            self.slam, self.slam_type, self.log, self.scans, self.estimates
        );
        let mut skipped: Vec<String> = self
            .skipped
            .iter()
            .map(|(k, n)| format!("{k} {n}"))
            .collect();
        if self.rear_scans > 0 {
            skipped.push(format!("rear scans {} (not used)", self.rear_scans));
        }
        let _ = writeln!(
            s,
            "skipped lines: {}",
            if skipped.is_empty() {
                "none".to_string()
            } else {
                skipped.join(", ")
            }
        );
        let _ = writeln!(
            s,
            "log {:.1} s in {:.2} s wall time: {:.1}× real time",
            self.log_duration_s, self.wall_time_s, self.real_time_factor
        );
        for (what, m) in [
            (self.slam.as_str(), &self.slam_metrics),
            ("odometry", &self.odometry_metrics),
        ] {
            if let Some(m) = m {
                let _ = writeln!(
                    s,
                    "{what:<12} vs TRUEPOS: ATE {}  RPE {} / {}  ({} poses)",
                    metric(m.ate_rmse_m, "m"),
                    metric(m.rpe_trans_m, "m"),
                    metric(m.rpe_rot_rad, "rad"),
                    m.estimates
                );
                if let Some(f) = &m.final_trajectory {
                    let _ = writeln!(
                        s,
                        "{:<12} final trajectory: ATE {}  RPE {} / {}  ({} poses)",
                        "",
                        metric(f.ate_rmse_m, "m"),
                        metric(f.rpe_trans_m, "m"),
                        metric(f.rpe_rot_rad, "rad"),
                        f.poses
                    );
                }
            }
        }
        if self.truth_records == 0 {
            let _ = writeln!(s, "no TRUEPOS lines: no ATE/RPE");
        }
        if let Some(m) = &self.map {
            let _ = writeln!(
                s,
                "map {} × {} cells of {} m",
                m.width, m.height, m.resolution
            );
        }
        for f in &self.files {
            let _ = writeln!(s, "written: {f}");
        }
        s
    }
}
