//! Feeding a log's front scans to a SLAM system in time order, each with the odometry pose
//! logged with it and the laser's mount, timing every update: the loop `sim slam`,
//! `sim experiment maze-slam` and `sim bench slam` share.

use crate::formats::carmen::ScanRecord;
use std::time::Instant;
use systems::core::{KernelPool, Pose2};
use systems::localization::ScanEstimator;
use systems::sensors::LaserScan;

/// What a run of a SLAM system over the scans gave.
#[derive(Clone, Debug, Default)]
pub struct FedRun {
    /// The estimates it published scan by scan.
    pub online: Vec<(f64, Pose2)>,
    /// Its trajectory at the end (after [`ScanEstimator::finish`]).
    pub trajectory: Vec<(f64, Pose2)>,
    /// Time of each update (ms), in scan order; the final `finish` is in `finish_ms`.
    pub update_ms: Vec<f64>,
    pub finish_ms: f64,
    /// Wall time of the whole loop, callbacks included (s).
    pub wall_time_s: f64,
}

/// Runs `est` over `scans` on `pool`; `after(k, record, scan, est)` is called after each update
/// (recording, progress) and is not counted in the update times. The whole loop runs inside one
/// section of the pool, so the caller's thread hands over to the pool once, not once per scan.
pub fn feed_scans(
    est: &mut dyn ScanEstimator,
    scans: &[&ScanRecord],
    pool: &KernelPool,
    mut after: impl FnMut(usize, &ScanRecord, &LaserScan, &dyn ScanEstimator) + Send,
) -> FedRun {
    let started = Instant::now();
    let mut run = FedRun {
        online: Vec::with_capacity(scans.len()),
        update_ms: Vec::with_capacity(scans.len()),
        ..FedRun::default()
    };
    pool.install(|| {
        for (k, s) in scans.iter().enumerate() {
            let scan = s.to_laser_scan();
            let t = Instant::now();
            let published = est.update(&scan, &s.mount, &s.robot_pose);
            run.update_ms.push(t.elapsed().as_secs_f64() * 1e3);
            if published && let Some(e) = est.estimate() {
                run.online.push((s.timestamp, e.pose));
            }
            after(k, s, &scan, &*est);
        }
        // a smoother's final optimization is part of the run
        let t = Instant::now();
        est.finish();
        run.finish_ms = t.elapsed().as_secs_f64() * 1e3;
    });
    run.wall_time_s = started.elapsed().as_secs_f64();
    run.trajectory = est.trajectory();
    run
}
