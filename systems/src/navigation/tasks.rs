//! Robot tasks as a hospital logistics system hands them out ([Hospital thesis §1]: the
//! robot loads at the pharmacy, drives to a ward, waits to be unloaded and returns): a queue of
//! deliveries, trips and waits per robot, each expanded into steps the navigator executes in
//! order.

use crate::core::Pose2;

/// A named destination.
#[derive(Clone, Debug, PartialEq)]
pub struct Goal {
    /// The place name, or the coordinates as written when the goal was given as a point.
    pub name: String,
    pub pose: Pose2,
}

#[derive(Clone, Debug, PartialEq)]
pub enum TaskKind {
    /// Drive to `from`, wait `load` s, drive to `to`, wait `unload` s.
    Delivery {
        from: Goal,
        to: Goal,
        load: f64,
        unload: f64,
    },
    /// Drive to a place (e.g. back to the charger).
    Go { to: Goal },
    /// Stay put for a while.
    Wait { time: f64 },
}

#[derive(Clone, Debug, PartialEq)]
pub struct Task {
    pub name: String,
    pub kind: TaskKind,
}

/// One thing to do.
#[derive(Clone, Debug, PartialEq)]
pub enum Step {
    Go(Goal),
    /// Wait `seconds`; the label says why ("loading", "unloading", "waiting").
    Wait {
        seconds: f64,
        label: &'static str,
    },
}

impl Task {
    pub fn is_delivery(&self) -> bool {
        matches!(self.kind, TaskKind::Delivery { .. })
    }

    /// The places the task drives to, in order.
    pub fn goals(&self) -> Vec<&Goal> {
        match &self.kind {
            TaskKind::Delivery { from, to, .. } => vec![from, to],
            TaskKind::Go { to } => vec![to],
            TaskKind::Wait { .. } => Vec::new(),
        }
    }

    /// The task's steps, in order.
    pub fn steps(&self) -> Vec<Step> {
        match &self.kind {
            TaskKind::Delivery {
                from,
                to,
                load,
                unload,
            } => vec![
                Step::Go(from.clone()),
                Step::Wait {
                    seconds: *load,
                    label: "loading",
                },
                Step::Go(to.clone()),
                Step::Wait {
                    seconds: *unload,
                    label: "unloading",
                },
            ],
            TaskKind::Go { to } => vec![Step::Go(to.clone())],
            TaskKind::Wait { time } => vec![Step::Wait {
                seconds: *time,
                label: "waiting",
            }],
        }
    }

    /// One line for logs and the recording, e.g. "deliver pharmacy → ward_3".
    pub fn describe(&self) -> String {
        match &self.kind {
            TaskKind::Delivery { from, to, .. } => {
                format!("{}: deliver {} → {}", self.name, from.name, to.name)
            }
            TaskKind::Go { to } => format!("{}: go to {}", self.name, to.name),
            TaskKind::Wait { time } => format!("{}: wait {time:.0} s", self.name),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn goal(name: &str, x: f64) -> Goal {
        Goal {
            name: name.into(),
            pose: Pose2::new(x, 0.0, 0.0),
        }
    }

    #[test]
    fn a_delivery_is_load_drive_unload() {
        let t = Task {
            name: "d1".into(),
            kind: TaskKind::Delivery {
                from: goal("pharmacy", 1.0),
                to: goal("ward_3", 2.0),
                load: 20.0,
                unload: 30.0,
            },
        };
        let s = t.steps();
        assert_eq!(s.len(), 4);
        assert!(matches!(&s[0], Step::Go(g) if g.name == "pharmacy"));
        assert!(matches!(s[1], Step::Wait { seconds, label: "loading" } if seconds == 20.0));
        assert!(matches!(&s[2], Step::Go(g) if g.name == "ward_3"));
        assert!(matches!(s[3], Step::Wait { seconds, label: "unloading" } if seconds == 30.0));
        assert_eq!(t.describe(), "d1: deliver pharmacy → ward_3");
    }
}
