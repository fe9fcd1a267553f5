//! Recording: the Rerun .rrd file (`rrd`, always unless disabled; the crate's `rrd` feature,
//! on by default), the MCAP layer of ROS 2 replays ([`mcap`]: messages, schemas, CDR, writer
//! and reader) and the run's topics in it ([`topics`]), the camera frames both share
//! ([`frames`]). The recording and the HTML report share the robots' colours ([`colours`]),
//! the simplified paths ([`path_trace`]) and the plots' axis ranges ([`axis_scale`]). The
//! recording's threads run at background priority ([`priority`]).

pub mod axis_scale;
pub mod colours;
pub mod frames;
pub mod mcap;
pub mod path_trace;
pub mod priority;
#[cfg(feature = "rrd")]
pub mod rrd;
pub mod topics;

#[cfg(feature = "rrd")]
pub use rrd::navigation::record_navigation;
#[cfg(feature = "rrd")]
pub use rrd::{RrdRecorder, record_rrd};

/// The error for a .rrd asked of a `sim` built without the `rrd` feature.
#[cfg(not(feature = "rrd"))]
pub fn without_rrd(path: &std::path::Path) -> anyhow::Error {
    anyhow::anyhow!(
        "{}: this sim was built without the .rrd recording (cargo feature `rrd`); \
         run with --no-rrd, or build sim with its default features",
        path.display()
    )
}
