//! `sim experiment …`: experiments that reproduce the seed documents' protocols on scenarios
//! simulated in-process.
//!
//! * [`de_match`] — the DE scan-matching study of 000_9f0113837c153763.txt (§6.3, §7);
//! * [`scan_pairs`] — its scan capture and pair selection (shared with `sim bench de-match`).

pub mod de_match;
pub mod scan_pairs;
