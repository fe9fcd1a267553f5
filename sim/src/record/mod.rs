//! Recording: the Rerun .rrd file (always, unless disabled). MCAP replays come later.

pub mod rrd;

pub use rrd::{RrdRecorder, record_rrd};
