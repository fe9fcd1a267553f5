//! Recording: the Rerun .rrd file (always, unless disabled) and, on request, TUM trajectories of
//! every localizer. MCAP replays come later.

pub mod belief;
pub mod rrd;
pub mod tum;

pub use rrd::{RrdRecorder, record_rrd};
pub use tum::write_trajectories;
