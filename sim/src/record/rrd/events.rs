//! The run's story as text-log lines, each at the simulated time it happened, for a text-log
//! view beside the map:
//! - `events`: every scenario event as it fires, and every command a program sent (commands
//!   fire the same way); a robot's lines start with its name;
//! - `robots/<name>/collisions`: the start of each collision of a navigating robot, with what
//!   it hit and where (level WARN).
//!
//! Navigation events and task states are `robots/<name>/task` ([`super::navigation`]).

use super::RrdRecorder;
use crate::build::script::EventQueue;
use bevy_ecs::prelude::*;
use systems::core::{RobotId, RobotIndex};
use systems::eval::NavOutcome;

/// Lines logged so far: of the fired events, and of each robot's collisions (by robot index).
#[derive(Default)]
pub struct EventsLogged {
    fired: usize,
    collisions: Vec<usize>,
}

/// Record: the lines added since the last tick.
pub fn record_events(
    mut r: ResMut<RrdRecorder>,
    mut logged: Local<EventsLogged>,
    queue: Option<Res<EventQueue>>,
    robots: Query<(&RobotIndex, &RobotId, &NavOutcome)>,
) {
    let (r, logged) = (&mut *r, &mut *logged);
    if let Some(q) = queue {
        for (t, robot, text) in q.fired.iter().skip(logged.fired) {
            let line = if robot.is_empty() {
                text.clone()
            } else {
                format!("{robot}: {text}")
            };
            r.rec.set_duration_secs("sim_time", *t);
            let res = r.rec.log(
                "events",
                &rerun::TextLog::new(line).with_level(rerun::TextLogLevel::INFO),
            );
            r.check(res);
        }
        logged.fired = q.fired.len();
    }
    for (idx, id, out) in &robots {
        let i = idx.0 as usize;
        if logged.collisions.len() <= i {
            logged.collisions.resize(i + 1, 0);
        }
        for (t, text) in out.collision_log.iter().skip(logged.collisions[i]) {
            r.rec.set_duration_secs("sim_time", *t);
            let res = r.rec.log(
                format!("robots/{}/collisions", id.0),
                &rerun::TextLog::new(text.as_str()).with_level(rerun::TextLogLevel::WARN),
            );
            r.check(res);
        }
        logged.collisions[i] = out.collision_log.len();
    }
}
