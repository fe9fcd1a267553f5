//! When a localizer converges and when it loses its robot, as lines of the recording's text log
//! (`robots/<name>/localization`), judged from the samples the summary's metrics use:
//! - converged: at the end of [`CONVERGENCE_HOLD_S`] of continuously tracked samples (the
//!   summary's convergence, `systems::eval::trajectory`), the line naming when tracking began;
//! - lost: a converged localizer whose position error stays above [`LOST_POSITION_M`] for
//!   [`LOST_HOLD_S`]; it may converge again later.
//!
//! The recorder reads ground truth for this; the localizers never do.

use systems::eval::Sample;
use systems::eval::localization_metrics::CONVERGENCE_HOLD_S;

/// A converged localizer this far off (m) ...
pub const LOST_POSITION_M: f64 = 1.0;
/// ... for this long (s) has lost its robot.
pub const LOST_HOLD_S: f64 = 2.0;

/// A change of a localizer's status.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Change {
    /// Tracked since `since` (s), for the hold.
    Converged { since: f64 },
    /// Off by more than the threshold since `since` (s); `error` (m) now.
    Lost { since: f64, error: f64 },
}

/// One localizer's status, fed its samples in time order.
#[derive(Clone, Debug, Default)]
pub struct Status {
    converged: bool,
    /// Start of the current run of tracked samples (not converged) or of samples beyond the
    /// lost threshold (converged).
    since: Option<f64>,
}

impl Status {
    /// Takes the next sample; the change it completes, if any.
    pub fn update(&mut self, s: &Sample) -> Option<Change> {
        let holding = if self.converged {
            s.position_error() > LOST_POSITION_M
        } else {
            s.tracked()
        };
        if !holding {
            self.since = None;
            return None;
        }
        let since = *self.since.get_or_insert(s.t);
        let hold = if self.converged {
            LOST_HOLD_S
        } else {
            CONVERGENCE_HOLD_S
        };
        if s.t - since < hold {
            return None;
        }
        self.since = None;
        self.converged = !self.converged;
        Some(if self.converged {
            Change::Converged { since }
        } else {
            Change::Lost {
                since,
                error: s.position_error(),
            }
        })
    }
}

impl Change {
    /// The text-log line for localizer `name` of robot `robot`.
    pub fn line(&self, robot: &str, name: &str) -> String {
        match *self {
            Change::Converged { since } => {
                format!("{robot} {name} converged (tracking since {since:.1} s)")
            }
            Change::Lost { since, error } => format!(
                "{robot} {name} lost its robot ({error:.1} m off, more than {LOST_POSITION_M} m since {since:.1} s)"
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use systems::core::Pose2;

    /// Samples every 0.5 s with the given position errors (heading exact).
    fn feed(errors: &[f64]) -> Vec<(f64, Change)> {
        let mut status = Status::default();
        let mut out = Vec::new();
        for (k, &e) in errors.iter().enumerate() {
            let t = 0.5 * k as f64;
            let s = Sample {
                t,
                estimate: Pose2::new(e, 0.0, 0.0),
                truth: Pose2::new(0.0, 0.0, 0.0),
                spread_m: 0.0,
            };
            if let Some(c) = status.update(&s) {
                out.push((t, c));
            }
        }
        out
    }

    #[test]
    fn converges_after_the_hold_loses_and_converges_again() {
        // 3 s searching, 10 s tracked, 4 s lost (5 m off), then tracked again
        let mut e = vec![8.0; 6];
        e.extend([0.05; 20]);
        e.extend([5.0; 8]);
        e.extend([0.05; 12]);
        let changes = feed(&e);
        assert_eq!(
            changes,
            vec![
                (8.0, Change::Converged { since: 3.0 }),
                (
                    15.0,
                    Change::Lost {
                        since: 13.0,
                        error: 5.0
                    }
                ),
                (22.0, Change::Converged { since: 17.0 }),
            ]
        );
        assert_eq!(
            changes[1].1.line("r1", "mcl"),
            "r1 mcl lost its robot (5.0 m off, more than 1 m since 13.0 s)"
        );
    }

    #[test]
    fn short_glitches_change_nothing() {
        // converged, then 1.5 s at 3 m (shorter than the hold), and a tracking gap before
        // convergence restarts the hold
        let mut e = vec![0.05; 8];
        e.push(0.5);
        e.extend([0.05; 12]);
        e.extend([3.0; 3]);
        e.extend([0.05; 4]);
        let changes = feed(&e);
        assert_eq!(changes, vec![(9.5, Change::Converged { since: 4.5 })]);
    }
}
