//! Recording: the Rerun .rrd file (always, unless disabled), on request TUM trajectories of
//! every localizer, and the MCAP layer of ROS 2 replays ([`mcap`]: messages, schemas, CDR,
//! writer and reader; the replay's topics are in `crate::mcap_out`). The recording's threads
//! run at background priority ([`priority`]).

pub mod belief;
pub mod frames;
pub mod mcap;
pub mod navigation;
pub mod outdoor;
pub mod path_trace;
pub mod priority;
pub mod replay;
pub mod rows;
pub mod rrd;
pub mod slam;
pub mod stream;
pub mod tum;

pub use navigation::record_navigation;
pub use rrd::{RrdRecorder, record_rrd};
pub use tum::write_trajectories;
