//! `sim replay`'s options (a leaf: the plan reads them, the command runs them).

use crate::run::report::OutputArgs;
use std::path::PathBuf;

// the field docs are the --help text: <placeholders> are not HTML
#[allow(rustdoc::invalid_html_tags)]
#[derive(clap::Args, Clone, Debug)]
pub struct ReplayArgs {
    /// An MCAP file: written by `sim run --mcap`, or by another ROS 2 system (then give
    /// --scenario).
    pub file: PathBuf,
    /// The scenario to replay in (a file or a bundled name); default: the one attached to the
    /// recording.
    #[arg(long)]
    pub scenario: Option<String>,
    /// Override the seed of the localizers' random numbers (default: the recorded run's).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Override a scenario key, as `sim batch --set` does
    /// (`robots.0.localization.0.max_particles=500`). Repeatable.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub sets: Vec<String>,
    /// Replay only this robot of the scenario (needed with topic flags when it has several).
    #[arg(long)]
    pub robot: Option<String>,
    /// sensor_msgs/LaserScan topic (default: /<robot>/scan in our files, /scan otherwise).
    #[arg(long)]
    pub scan_topic: Option<String>,
    /// nav_msgs/Odometry (or geometry_msgs/PoseStamped) topic whose poses replace wheel
    /// odometry (default for foreign files: /odom; our files replay the encoder ticks of
    /// /<robot>/joint_states).
    #[arg(long)]
    pub odom_topic: Option<String>,
    /// sensor_msgs/JointState topic of the wheel encoders (default: /<robot>/joint_states).
    #[arg(long)]
    pub joint_states_topic: Option<String>,
    /// Ground truth, geometry_msgs/PoseStamped or nav_msgs/Odometry in the map frame (default:
    /// /<robot>/ground_truth in our files, none otherwise).
    #[arg(long)]
    pub truth_topic: Option<String>,
    /// Replay a file cut short or damaged: the messages of every complete chunk before the
    /// damage, which is named on standard error (default: such a file is an error).
    #[arg(long)]
    pub recover: bool,
    #[command(flatten)]
    pub out: OutputArgs,
}
