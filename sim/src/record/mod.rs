//! Recording: the Rerun .rrd file (always, unless disabled) and, on request, TUM trajectories of
//! every localizer. MCAP replays come later.

pub mod belief;
pub mod navigation;
pub mod outdoor;
pub mod replay;
pub mod rrd;
pub mod slam;
pub mod tum;

pub use navigation::record_navigation;
pub use rrd::{RrdRecorder, record_rrd};
pub use tum::write_trajectories;
