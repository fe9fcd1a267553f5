//! `sim experiment …`: experiments that reproduce the seed documents' protocols on scenarios
//! simulated in-process.
//!
//! * [`de_match`] — the DE scan-matching study of [Hospital thesis §6.3, §7];
//! * [`slam_compare`] — the maze SLAM experiment of [Hospital thesis] and the hospital
//!   loop: every odometry and SLAM method on identical data (`maze-slam`);
//! * [`localization`] — whether the localizers of a scenario find and hold their robots over
//!   many seeds, against the targets it prints (`localization`);
//! * [`scan_pairs`] — its scan capture and pair selection (shared with `sim bench de-match`).

pub mod de_match;
pub mod localization;
pub mod match_pair;
pub mod park;
pub mod scan_pairs;
pub mod slam_compare;
