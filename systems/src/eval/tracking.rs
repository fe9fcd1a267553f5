//! How well a localizer holds its robot once it has found it: the time tracked after
//! convergence, the untracked spans, and the episodes in which it lost the robot (untracked for
//! longer than [`LOST_AFTER_S`]), whether it noticed (its reported spread rose above the tracking
//! tolerance) and whether it recovered by itself. Tracking and convergence are those of
//! [`super::trajectory`]; every span is measured in simulated time, each sample standing for the
//! time until the next one (the last for the gap before it).

use super::trajectory::{self, Sample, TRACKED_POSITION_M};
use serde::Serialize;

/// An untracked span longer than this (s) counts as losing the robot.
pub const LOST_AFTER_S: f64 = 2.0;

/// One span in which a converged localizer lost its robot.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct LostEpisode {
    /// Time of its first untracked estimate (s).
    pub start_s: f64,
    /// Until the next tracked estimate, or the end of the run (s).
    pub duration_s: f64,
    /// Its largest position error (m).
    pub max_error_m: f64,
    /// Tracked again before the run ended.
    pub recovered: bool,
    /// The localizer's reported spread rose above the tracking tolerance (0.2 m) during it.
    pub noticed: bool,
}

/// The tracking figures of one localizer's run.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct TrackingRecord {
    /// Time of convergence (s; see [`trajectory::convergence_index`]).
    pub converged_after_s: Option<f64>,
    /// Share of the time from convergence to the end that was tracked.
    pub tracked_after_convergence: Option<f64>,
    /// The longest untracked span after convergence (s).
    pub longest_untracked_s: f64,
    /// Map-frame translation RMSE from convergence on (m).
    pub ate_after_convergence_m: Option<f64>,
    /// The untracked spans after convergence longer than [`LOST_AFTER_S`].
    pub lost: Vec<LostEpisode>,
}

/// The time each sample stands for: until the next one; the last one, the gap before it.
fn durations(samples: &[Sample]) -> Vec<f64> {
    let mut d: Vec<f64> = samples
        .windows(2)
        .map(|w| (w[1].t - w[0].t).max(0.0))
        .collect();
    if !samples.is_empty() {
        d.push(d.last().copied().unwrap_or(0.0));
    }
    d
}

/// The tracking record of one localizer's samples (in time order).
pub fn tracking_record(samples: &[Sample], hold_s: f64) -> TrackingRecord {
    let Some(c) = trajectory::convergence_index(samples, hold_s) else {
        return TrackingRecord::default();
    };
    let after = &samples[c..];
    let dt = durations(after);
    let total: f64 = dt.iter().sum();
    let tracked: f64 = after
        .iter()
        .zip(&dt)
        .filter(|(s, _)| s.tracked())
        .map(|(_, d)| d)
        .sum();
    let mut record = TrackingRecord {
        converged_after_s: Some(samples[c].t),
        tracked_after_convergence: Some(if total > 0.0 { tracked / total } else { 1.0 }),
        ate_after_convergence_m: trajectory::ate_unaligned(after),
        ..Default::default()
    };
    let mut i = 0;
    while i < after.len() {
        if after[i].tracked() {
            i += 1;
            continue;
        }
        let start = i;
        while i < after.len() && !after[i].tracked() {
            i += 1;
        }
        let span = &after[start..i];
        let recovered = i < after.len();
        let duration = if recovered {
            after[i].t - after[start].t
        } else {
            dt[start..].iter().sum()
        };
        record.longest_untracked_s = record.longest_untracked_s.max(duration);
        if duration > LOST_AFTER_S {
            record.lost.push(LostEpisode {
                start_s: after[start].t,
                duration_s: duration,
                max_error_m: span.iter().map(Sample::position_error).fold(0.0, f64::max),
                recovered,
                noticed: span.iter().any(|s| s.spread_m > TRACKED_POSITION_M),
            });
        }
    }
    record
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::core::Pose2;

    /// Samples every 0.5 s with the given (position error, reported spread).
    fn run(errors: &[(f64, f64)]) -> Vec<Sample> {
        errors
            .iter()
            .enumerate()
            .map(|(k, &(e, spread))| Sample {
                t: 0.5 * k as f64,
                estimate: Pose2::new(e, 0.0, 0.0),
                truth: Pose2::new(0.0, 0.0, 0.0),
                spread_m: spread,
            })
            .collect()
    }

    #[test]
    fn a_short_slip_is_untracked_time_but_not_a_lost_episode() {
        // 2 s searching, then tracked with one 1 s slip (2 samples at 0.3 m)
        let mut e = vec![(5.0, 3.0); 4];
        e.extend([(0.05, 0.1); 20]);
        e.extend([(0.3, 0.1); 2]);
        e.extend([(0.05, 0.1); 18]);
        let r = tracking_record(&run(&e), 5.0);
        assert_eq!(r.converged_after_s, Some(2.0));
        assert!((r.longest_untracked_s - 1.0).abs() < 1e-12, "{r:?}");
        assert!(r.lost.is_empty());
        // 40 samples after convergence, 2 of them untracked
        let f = r.tracked_after_convergence.unwrap();
        assert!((f - 38.0 / 40.0).abs() < 1e-12, "{f}");
    }

    #[test]
    fn a_lost_episode_says_whether_it_was_noticed_and_recovered() {
        // tracked 10 s, 4 s lost at 3 m without the spread rising (collapsed on a wrong pose),
        // tracked again, then lost to the end with a spread that grows
        let mut e = vec![(0.05, 0.05); 20];
        e.extend([(3.0, 0.05); 8]);
        e.extend([(0.05, 0.05); 20]);
        e.extend([(1.0, 0.5); 6]);
        let r = tracking_record(&run(&e), 5.0);
        assert_eq!(r.converged_after_s, Some(0.0));
        assert_eq!(r.lost.len(), 2, "{r:?}");
        let (a, b) = (r.lost[0], r.lost[1]);
        assert_eq!((a.start_s, a.duration_s), (10.0, 4.0));
        assert_eq!((a.max_error_m, a.recovered, a.noticed), (3.0, true, false));
        // to the end: 6 samples of 0.5 s
        assert_eq!((b.start_s, b.duration_s), (24.0, 3.0));
        assert_eq!((b.recovered, b.noticed), (false, true));
        assert_eq!(r.longest_untracked_s, 4.0);
    }

    #[test]
    fn never_converged_has_no_figures() {
        let r = tracking_record(&run(&[(2.0, 1.0); 30]), 5.0);
        assert_eq!(r, TrackingRecord::default());
        assert_eq!(tracking_record(&[], 5.0), TrackingRecord::default());
    }
}
