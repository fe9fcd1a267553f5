//! `[robots.navigation]` and `[[robots.tasks]]`: the settings of a task-driven robot and its
//! task queue. Places in tasks resolve through the map's places file; every value is checked
//! with the robot and key named in the error.

use super::check::PointOrPlace;
use super::check::{Checker, R};
use super::error::KeyPath;
use super::localizers::{LocalizerConfig, localizer_index};
use serde::Deserialize;
use systems::body::{Footprint, Kinematics};
use systems::core::Pose2;
use systems::navigation::{
    CostmapParams, FollowerParams, Goal, NavParams, PlannerParams, Steering, Task, TaskKind,
};

/// `[robots.navigation]`: planner, follower and stop-and-wait settings of a robot with tasks.
#[derive(Deserialize, Debug, Clone, Default)]
#[serde(deny_unknown_fields)]
pub struct NavigationFile {
    /// Name of the localizer to navigate by (default: wheel odometry).
    pub localizer: Option<String>,
    pub speed: Option<f64>,
    pub max_accel: Option<f64>,
    pub max_yaw_rate: Option<f64>,
    pub tolerance: Option<f64>,
    pub lookahead: Option<f64>,
    /// Added to the robot radius for the costmap's impassable band (m).
    pub safety_margin: Option<f64>,
    pub inflation_radius: Option<f64>,
    pub cost_weight: Option<f64>,
    pub stop_distance: Option<f64>,
    pub wait_time: Option<f64>,
    pub priority: Option<u32>,
}

/// A task's `type`. Required in a file; the `Default` (delivery) only lets a table be written
/// with `..Default::default()`.
#[derive(Deserialize, Debug, Clone, Copy, PartialEq, Default)]
#[serde(rename_all = "snake_case")]
pub enum TaskType {
    #[default]
    Delivery,
    Go,
    Wait,
}

/// One `[[robots.tasks]]` table.
#[derive(Deserialize, Debug, Clone, Default)]
#[serde(deny_unknown_fields)]
pub struct TaskFile {
    #[serde(rename = "type")]
    pub kind: TaskType,
    pub name: Option<String>,
    pub from: Option<PointOrPlace>,
    pub to: Option<PointOrPlace>,
    /// Loading time at `from` (s).
    pub load: Option<f64>,
    /// Unloading time at `to` (s).
    pub unload: Option<f64>,
    /// Waiting time of a `wait` task (s).
    pub time: Option<f64>,
}

/// Checks that a goal leaves room for a robot of radius `radius` (m).
pub(super) fn goal_clear(
    c: &Checker,
    path: &KeyPath,
    grid: &systems::world::OccupancyGrid,
    pose: &Pose2,
    radius: f64,
) -> R<()> {
    if !grid.disc_is_clear(pose.x, pose.y, radius) {
        return c.err(
            path,
            format!(
                "the goal ({:.2}, {:.2}) is too close to an obstacle for the robot (radius {radius:.2} m)",
                pose.x, pose.y
            ),
        );
    }
    Ok(())
}

/// A robot's navigation, resolved.
#[derive(Clone, Debug, PartialEq)]
pub struct NavConfig {
    pub params: NavParams,
    pub costmap: CostmapParams,
    pub tasks: Vec<Task>,
    /// Index of the localizer the robot navigates by (None: wheel odometry).
    pub localizer: Option<usize>,
}

/// Everything `resolve_navigation` needs from the robot.
pub(super) struct RobotParts<'a> {
    pub kinematics: &'a Kinematics,
    pub footprint: &'a Footprint,
    pub localizers: &'a [LocalizerConfig],
    pub index: usize,
}

#[allow(clippy::too_many_arguments)]
pub(super) fn resolve_navigation(
    c: &Checker,
    robot_path: &KeyPath,
    nav: Option<&NavigationFile>,
    tasks: &[TaskFile],
    robot: RobotParts,
    goal_of: &dyn Fn(&KeyPath, &PointOrPlace) -> R<Pose2>,
) -> R<Option<NavConfig>> {
    let np = robot_path.key("navigation");
    if tasks.is_empty() {
        if nav.is_some() {
            return c.err(
                &np,
                "`[robots.navigation]` configures a robot with tasks: add `[[robots.tasks]]`",
            );
        }
        return Ok(None);
    }
    let d = NavigationFile::default();
    let n = nav.unwrap_or(&d);
    let fd = FollowerParams::default();
    let top = robot.kinematics.max_speed();
    let speed = c.opt_positive(&np.key("speed"), n.speed, fd.speed.min(top))?;
    if speed > top + 1e-9 {
        return c.err(
            &np.key("speed"),
            format!("{speed} m/s exceeds the drive's top speed of {top:.3} m/s"),
        );
    }
    let radius = robot.footprint.bounding_radius();
    let follower = FollowerParams {
        speed,
        max_accel: c.opt_positive(&np.key("max_accel"), n.max_accel, fd.max_accel)?,
        max_yaw_rate: c.opt_positive(&np.key("max_yaw_rate"), n.max_yaw_rate, fd.max_yaw_rate)?,
        tolerance: c.opt_positive(&np.key("tolerance"), n.tolerance, fd.tolerance)?,
        lookahead: c.opt_positive(&np.key("lookahead"), n.lookahead, fd.lookahead)?,
        ..fd
    };
    let margin = match n.safety_margin {
        Some(v) => c.range(&np.key("safety_margin"), v, Some(0.0), Some(2.0), false)?,
        None => 0.05,
    };
    let inflation = c.opt_positive(&np.key("inflation_radius"), n.inflation_radius, 1.0)?;
    if inflation < radius + margin {
        return c.err(
            &np.key("inflation_radius"),
            format!(
                "expected at least the robot radius plus the safety margin ({:.3} m), got {inflation}",
                radius + margin
            ),
        );
    }
    let cost_weight = match n.cost_weight {
        Some(v) => c.range(&np.key("cost_weight"), v, Some(0.0), Some(100.0), false)?,
        None => PlannerParams::default().cost_weight as f64,
    };
    let stop_distance = match n.stop_distance {
        Some(v) => c.range(&np.key("stop_distance"), v, Some(0.05), Some(5.0), false)?,
        None => 0.35,
    };
    let wait_time = match n.wait_time {
        Some(v) => c.range(&np.key("wait_time"), v, Some(0.0), Some(600.0), false)?,
        None => 3.0,
    };
    let steering = match robot.kinematics {
        Kinematics::DiffDrive(_) => Steering::DiffDrive,
        Kinematics::Ackermann(a) => Steering::Ackermann {
            wheelbase: a.wheelbase,
            max_steer: a.max_steer,
        },
    };
    let localizer = n
        .localizer
        .as_deref()
        .map(|name| localizer_index(c, &np.key("localizer"), name, robot.localizers))
        .transpose()?;
    let mut out = Vec::new();
    for (i, t) in tasks.iter().enumerate() {
        let tp = robot_path.key("tasks").index(i);
        out.push(resolve_task(c, &tp, t, i, goal_of)?);
    }
    for (i, t) in out.iter().enumerate() {
        if out[..i].iter().any(|o| o.name == t.name) {
            return c.err(
                &robot_path.key("tasks").index(i).key("name"),
                format!("duplicate task name `{}`", t.name),
            );
        }
    }
    Ok(Some(NavConfig {
        params: NavParams {
            follower,
            steering,
            radius,
            stop_distance,
            wait_time,
            priority: n.priority.unwrap_or(robot.index as u32),
            planner: PlannerParams {
                cost_weight: cost_weight as f32,
                ..PlannerParams::default()
            },
            costmap: 0,
        },
        costmap: CostmapParams {
            robot_radius: radius + margin,
            inflation_radius: inflation,
            ..CostmapParams::default()
        },
        tasks: out,
        localizer,
    }))
}

pub(super) fn resolve_task(
    c: &Checker,
    p: &KeyPath,
    t: &TaskFile,
    i: usize,
    goal_of: &dyn Fn(&KeyPath, &PointOrPlace) -> R<Pose2>,
) -> R<Task> {
    let kind_name = match t.kind {
        TaskType::Delivery => "delivery",
        TaskType::Go => "go",
        TaskType::Wait => "wait",
    };
    let only = |key: &str, present: bool| -> R<()> {
        if present {
            return c.err(
                &p.key(key),
                format!("`{key}` does not apply to a `{kind_name}` task"),
            );
        }
        Ok(())
    };
    let goal = |key: &str, v: &Option<PointOrPlace>| -> R<Goal> {
        let Some(v) = v else {
            return c.err(
                p,
                format!("a `{kind_name}` task needs `{key}` (a place name or [x, y])"),
            );
        };
        let kp = p.key(key);
        let pose = goal_of(&kp, v)?;
        let name = match v {
            PointOrPlace::Place(n) => n.clone(),
            PointOrPlace::Coords(_) => format!("({:.2}, {:.2})", pose.x, pose.y),
        };
        Ok(Goal { name, pose })
    };
    let secs = |key: &str, v: Option<f64>, default: f64| -> R<f64> {
        match v {
            Some(v) => c.range(&p.key(key), v, Some(0.0), Some(86_400.0), false),
            None => Ok(default),
        }
    };
    let kind = match t.kind {
        TaskType::Delivery => {
            only("time", t.time.is_some())?;
            TaskKind::Delivery {
                from: goal("from", &t.from)?,
                to: goal("to", &t.to)?,
                load: secs("load", t.load, 20.0)?,
                unload: secs("unload", t.unload, 30.0)?,
            }
        }
        TaskType::Go => {
            only("from", t.from.is_some())?;
            only("load", t.load.is_some())?;
            only("unload", t.unload.is_some())?;
            only("time", t.time.is_some())?;
            TaskKind::Go {
                to: goal("to", &t.to)?,
            }
        }
        TaskType::Wait => {
            only("from", t.from.is_some())?;
            only("to", t.to.is_some())?;
            only("load", t.load.is_some())?;
            only("unload", t.unload.is_some())?;
            let Some(time) = t.time else {
                return c.err(p, "a `wait` task needs `time` (seconds)");
            };
            TaskKind::Wait {
                time: secs("time", Some(time), 0.0)?,
            }
        }
    };
    let name = match &t.name {
        Some(n) if super::check::check_name(n) => n.clone(),
        Some(n) => {
            return c.err(
                &p.key("name"),
                format!("expected letters, digits, `_` or `-`, got `{n}`"),
            );
        }
        None => format!("{kind_name}_{}", i + 1),
    };
    Ok(Task { name, kind })
}
