//! Recording: the Rerun .rrd file ([`rrd`], always unless disabled), the MCAP layer of ROS 2
//! replays ([`mcap`]: messages, schemas, CDR, writer and reader) and the run's topics in it
//! ([`topics`]), the camera frames both share ([`frames`]), the robots' colours the recording
//! and the HTML report share ([`colours`]). The recording's threads run at background priority
//! ([`priority`]).

pub mod colours;
pub mod frames;
pub mod mcap;
pub mod priority;
pub mod rrd;
pub mod topics;

pub use rrd::navigation::record_navigation;
pub use rrd::{RrdRecorder, record_rrd};
