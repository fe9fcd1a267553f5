//! Navigation outcomes the robot itself knows (ground-truth ones are in `eval`): counters, task
//! failures, the event log and the leg boundaries the evaluation measures.

/// One failed task.
#[derive(Clone, Debug, PartialEq)]
pub struct NavFailure {
    pub time: f64,
    pub task: String,
    pub reason: String,
}

/// Navigation outcomes the robot itself knows (ground-truth ones are in `eval`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct NavMetrics {
    pub tasks_completed: u32,
    pub tasks_failed: u32,
    pub deliveries_completed: u32,
    /// Duration of each completed delivery, from taking the task to the end of unloading (s).
    pub delivery_times_s: Vec<f64>,
    /// Stops for obstacles (each stop counted once, however long).
    pub stops: u32,
    /// Time spent stopped for obstacles or waiting aside for another robot (s).
    pub waiting_time_s: f64,
    pub replans: u32,
    /// Times the robot stepped aside for another robot.
    pub yields: u32,
    pub failures: Vec<NavFailure>,
}

/// A navigation event for logs and the recording.
#[derive(Clone, Debug, PartialEq)]
pub struct NavEvent {
    pub time: f64,
    pub text: String,
}

/// A leg (one `Go` step) starting or ending, for the ground-truth evaluation.
#[derive(Clone, Debug, PartialEq)]
pub enum LegEvent {
    Started { goal: [f64; 2] },
    Finished { goal: [f64; 2], reached: bool },
}
