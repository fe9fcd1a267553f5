//! Components and resources every system shares: poses, the simulation clock, per-entity random
//! streams, robot identity, the tick schedule and the kernel thread pool (and where the source
//! tree is, for its assets); the on-disk cache of map-derived structures.

pub mod cache;
pub mod clock;
pub mod cpu;
pub mod ids;
pub mod input;
pub mod jobs;
pub mod moments;
pub mod normal;
pub mod pool;
pub mod pose;
#[cfg(test)]
pub mod props;
pub mod rng;
pub mod schedule;
pub mod source;
pub mod spatial_order;
pub mod test_tools;

pub use cache::{CacheKey, Cached, MapCache};
pub use clock::SimClock;
pub use ids::{RobotId, RobotIndex};
pub use jobs::JobMemory;
pub use pool::KernelPool;
pub use pose::{Pose2, wrap_angle};
pub use rng::{SimRng, stream_rng, stream_seed};
pub use schedule::{
    Chained, SimPlugin, SimSet, TickSystem, any_with, deny_ambiguities, new_schedule, tick_order,
};
