//! `sim experiment …`: experiments that reproduce the seed documents' protocols on scenarios
//! simulated in-process.
//!
//! * [`de_match`] — the DE scan-matching study of 000_9f0113837c153763.txt (§6.3, §7);
//! * [`slam_compare`] — the maze SLAM experiment of 000_9f0113837c153763.txt and the hospital
//!   loop: every odometry and SLAM method of issue 5 on identical data (`maze-slam`);
//! * [`scan_pairs`] — its scan capture and pair selection (shared with `sim bench de-match`).

pub mod de_match;
pub mod park;
pub mod scan_pairs;
pub mod slam_compare;
