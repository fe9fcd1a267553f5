//! The navigator: a robot's task queue executed on its own belief (the localization estimate it
//! navigates by), never ground truth. Per tick, in the Control set, it advances a small state
//! machine:
//!
//! - `Driving`: pure pursuit ([`super::follower`]) along the planned path, slowed by the free
//!   space the laser and sonars see ahead; an obstacle closer than `stop_distance` (gap from the
//!   robot's outline) stops it (`Blocked`).
//! - `Blocked`: stand still; go on as soon as the way is clear. Another robot coming the other
//!   way is settled by the yield rule ([`super::fleet`]). Otherwise, after `wait_time` seconds
//!   the robot asks for a plan around what it sees (laser points in free space marked on a copy
//!   of the costmap, [`mark_obstacles`]) and retries every `wait_time` while none exists. A robot
//!   parked at our goal is waited for.
//! - `Yielding`: driving to a spot off the other robot's path, then waiting there until it has
//!   passed; then re-plan to the goal.
//! - `Waiting` at a place (loading, unloading) for the task's time.
//!
//! Plans are computed in the Plan set from the requests the state machine leaves
//! ([`PlanRequest`]); a goal the static costmap cannot reach fails the task with the planner's
//! reason instead of retrying forever. A door closing across the current path (the shared
//! costmap changes) triggers a re-plan.

mod blocking;
mod clearance;

use super::astar::{PlanError, Planner, PlannerParams};
use super::avoid::SectorRanges;
use super::costmap::Costmap;
use super::fleet::{Fleet, FleetActivity, FleetEntry, comes_through};
use super::follower::{FollowerParams, FollowerState, Steering, follow};
use super::local_map::{mark_obstacles, nearest_free, path_blocked};
use super::outcomes::{LegEvent, NavEvent, NavFailure, NavMetrics};
use super::tasks::{Goal, Step, Task};
use crate::body::DriveCommand;
use crate::core::Pose2;
use bevy_ecs::prelude::*;

/// Navigation settings of one robot.
#[derive(Clone, Debug, PartialEq)]
pub struct NavParams {
    pub follower: FollowerParams,
    pub steering: Steering,
    /// Radius of the robot's bounding circle (m).
    pub radius: f64,
    /// Stop when something is this close (m) to the robot's outline, in the band it drives
    /// through.
    pub stop_distance: f64,
    /// Seconds to wait at an obstacle before planning around it.
    pub wait_time: f64,
    /// Yield priority: the robot with the higher number gives way (ties: the later robot).
    pub priority: u32,
    pub planner: PlannerParams,
    /// Which of the shared costmaps (one per inflation radius) the robot plans on.
    pub costmap: usize,
}

impl Default for NavParams {
    fn default() -> Self {
        NavParams {
            follower: FollowerParams::default(),
            steering: Steering::DiffDrive,
            radius: 0.3,
            stop_distance: 0.35,
            wait_time: 3.0,
            priority: 0,
            planner: PlannerParams::default(),
            costmap: 0,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Phase {
    /// Nothing (more) to do.
    Idle,
    /// A plan has been requested.
    Planning,
    Driving,
    Blocked {
        since: f64,
    },
    Yielding {
        for_robot: u32,
        since: f64,
        parked: bool,
    },
    Waiting {
        until: f64,
    },
}

/// What the Plan set should compute.
#[derive(Clone, Debug, PartialEq)]
pub struct PlanRequest {
    pub goal: [f64; 2],
    /// Obstacle points (world frame) to plan around; empty for a plan on the shared costmap.
    pub around: Vec<[f64; 2]>,
}

#[derive(Component, Clone, Debug)]
pub struct Navigator {
    pub params: NavParams,
    pub tasks: Vec<Task>,
    /// Index of the current task (== tasks.len() when all are done).
    pub task: usize,
    steps: Vec<Step>,
    step: usize,
    pub phase: Phase,
    pub goal: Option<Goal>,
    /// The path being followed (world points), and a counter bumped whenever it changes.
    pub path: Vec<[f64; 2]>,
    pub path_serial: u64,
    follower: FollowerState,
    pub request: Option<PlanRequest>,
    pub metrics: NavMetrics,
    /// Every event so far (the recorder logs the new ones).
    pub events: Vec<NavEvent>,
    /// Legs started or finished during this tick.
    pub legs: Vec<LegEvent>,
    pub(crate) planner: Planner,
    task_started: f64,
    cannot_yield: bool,
    costmap_version: u64,
    /// Obstacle points seen ahead (base frame), refreshed from the sensors.
    pub(crate) seen: Option<SectorRanges>,
    /// Extra obstacle points in the base frame (sonar echoes), refreshed every tick.
    pub(crate) extra: Vec<(f32, f32)>,
    /// While blocked: since when the way has looked clear.
    clear_since: Option<f64>,
    /// The last stop the robot went on from, to tell a flickering obstacle from a new one.
    resumed: Option<Resumed>,
    /// Long ways round refused in a row while blocked (see [`DETOUR_FACTOR`]).
    detours_refused: u32,
    /// Since when the robot has been held by an obstacle on its way aside.
    held_since: Option<f64>,
}

/// A stop the robot went on from: when it began, where, and when the robot went on.
#[derive(Clone, Copy, Debug)]
struct Resumed {
    since: f64,
    at: [f64; 2],
    time: f64,
}

/// The way must look clear this long (s) before a stopped robot goes on: one clear reading of a
/// noisy sensor is not enough.
const CLEAR_TIME: f64 = 0.5;

/// A plan around an obstacle longer than this many times the rest of the current path (plus
/// [`DETOUR_SLACK`] m) is refused up to [`MAX_DETOUR_REFUSALS`] times in a row, one `wait_time`
/// apart: a person standing in a cross corridor should not send the robot round the building.
const DETOUR_FACTOR: f64 = 1.5;
const DETOUR_SLACK: f64 = 10.0;
const MAX_DETOUR_REFUSALS: u32 = 3;

/// Length (m) of `path` from `from` (a point near segment `seg`) to its end.
fn remaining_length(path: &[[f64; 2]], seg: usize, from: &Pose2) -> f64 {
    let Some(next) = path.get(seg + 1) else {
        return 0.0;
    };
    let rest: f64 = path[seg + 1..]
        .windows(2)
        .map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]))
        .sum();
    (next[0] - from.x).hypot(next[1] - from.y) + rest
}

impl Navigator {
    pub fn new(params: NavParams, tasks: Vec<Task>) -> Self {
        let planner = Planner::new(params.planner);
        Navigator {
            params,
            tasks,
            task: 0,
            steps: Vec::new(),
            step: 0,
            phase: Phase::Idle,
            goal: None,
            path: Vec::new(),
            path_serial: 0,
            follower: FollowerState::default(),
            request: None,
            metrics: NavMetrics::default(),
            events: Vec::new(),
            legs: Vec::new(),
            planner,
            task_started: 0.0,
            cannot_yield: false,
            costmap_version: 0,
            seen: None,
            extra: Vec::new(),
            clear_since: None,
            resumed: None,
            detours_refused: 0,
            held_since: None,
        }
    }

    /// True when every task has been done (or has failed).
    pub fn finished(&self) -> bool {
        self.task >= self.tasks.len() && self.phase == Phase::Idle
    }

    /// The current task's description, for the recording.
    pub fn status_text(&self) -> String {
        let Some(task) = self.tasks.get(self.task) else {
            return format!(
                "all tasks done ({} completed, {} failed)",
                self.metrics.tasks_completed, self.metrics.tasks_failed
            );
        };
        let what = match (&self.phase, self.steps.get(self.step)) {
            (Phase::Waiting { .. }, Some(Step::Wait { label, .. })) => label.to_string(),
            (Phase::Blocked { .. }, _) => "stopped for an obstacle".into(),
            (Phase::Yielding { for_robot, .. }, _) => format!("giving way to robot #{for_robot}"),
            (Phase::Planning, _) => "planning".into(),
            (_, Some(Step::Go(g))) => format!("driving to {}", g.name),
            _ => "idle".into(),
        };
        format!("{} — {what}", task.describe())
    }

    fn log(&mut self, time: f64, text: impl Into<String>) {
        self.events.push(NavEvent {
            time,
            text: text.into(),
        });
    }

    fn set_path(&mut self, path: Vec<[f64; 2]>) {
        self.path = path;
        self.path_serial += 1;
        self.follower.segment = 0;
    }

    /// The board entry this robot publishes.
    pub fn fleet_entry(&self, index: u32, pose: &Pose2) -> FleetEntry {
        let activity = match self.phase {
            Phase::Driving | Phase::Blocked { .. } | Phase::Planning => FleetActivity::Driving,
            Phase::Yielding {
                for_robot, parked, ..
            } => FleetActivity::Yielding { for_robot, parked },
            Phase::Idle | Phase::Waiting { .. } => FleetActivity::Parked,
        };
        let mut path_ahead = vec![[pose.x, pose.y]];
        if matches!(activity, FleetActivity::Driving) && self.path.len() >= 2 {
            let mut left = 8.0;
            let mut prev = [pose.x, pose.y];
            for &p in &self.path[(self.follower.segment + 1).min(self.path.len() - 1)..] {
                path_ahead.push(p);
                left -= (p[0] - prev[0]).hypot(p[1] - prev[1]);
                prev = p;
                if left <= 0.0 {
                    break;
                }
            }
        }
        FleetEntry {
            index,
            pose: *pose,
            radius: self.params.radius,
            priority: self.params.priority,
            activity,
            path_ahead,
            cannot_yield: self.cannot_yield,
        }
    }

    /// Moves on to the next step (starting the next task when the current one is done).
    fn next_step(&mut self, now: f64) {
        self.step += 1;
        if self.step >= self.steps.len() {
            if let Some(t) = self.tasks.get(self.task)
                && !self.steps.is_empty()
            {
                self.metrics.tasks_completed += 1;
                if t.is_delivery() {
                    self.metrics.deliveries_completed += 1;
                    self.metrics.delivery_times_s.push(now - self.task_started);
                }
                let name = t.name.clone();
                self.log(now, format!("task {name} completed"));
                self.task += 1;
            }
            self.steps.clear();
            self.step = 0;
        }
        self.start_step(now);
    }

    /// Abandons the current task.
    fn fail_task(&mut self, now: f64, reason: String) {
        let name = self
            .tasks
            .get(self.task)
            .map(|t| t.name.clone())
            .unwrap_or_default();
        self.log(now, format!("task {name} FAILED: {reason}"));
        self.metrics.tasks_failed += 1;
        self.metrics.failures.push(NavFailure {
            time: now,
            task: name,
            reason,
        });
        self.task += 1;
        self.steps.clear();
        self.step = 0;
        self.start_step(now);
    }

    fn start_step(&mut self, now: f64) {
        if self.steps.is_empty() {
            let Some(task) = self.tasks.get(self.task) else {
                self.phase = Phase::Idle;
                self.goal = None;
                return;
            };
            self.steps = task.steps();
            self.step = 0;
            self.task_started = now;
            let d = task.describe();
            self.log(now, format!("task started: {d}"));
        }
        match self.steps[self.step].clone() {
            Step::Go(goal) => {
                self.request = Some(PlanRequest {
                    goal: [goal.pose.x, goal.pose.y],
                    around: Vec::new(),
                });
                self.legs.push(LegEvent::Started {
                    goal: [goal.pose.x, goal.pose.y],
                });
                self.goal = Some(goal);
                self.phase = Phase::Planning;
            }
            Step::Wait { seconds, label } => {
                self.phase = Phase::Waiting {
                    until: now + seconds,
                };
                self.log(now, format!("{label} for {seconds:.0} s"));
            }
        }
    }

    /// Plan set: answers the pending request on `map` (the shared costmap, or a copy with the
    /// request's obstacles marked).
    pub fn plan(&mut self, now: f64, map: &Costmap, from: &Pose2) {
        let Some(req) = self.request.take() else {
            return;
        };
        let around = !req.around.is_empty();
        let marked;
        let map = if around {
            // keep the stop band (radius + 5 cm) and a margin off what was seen, so the new
            // path does not stop the robot again at once, and a wider berth where there is room
            // (what was seen may be a person who moves)
            let r = self.params.radius;
            marked = mark_obstacles(map, &req.around, r + 0.15, r + 0.5, [from.x, from.y]);
            &marked
        } else {
            map
        };
        let mut result = self.planner.plan(map, [from.x, from.y], req.goal);
        if let Err(PlanError::StartBlocked { .. }) = result
            && let Some(free) = nearest_free(map, [from.x, from.y], 0.5)
        {
            // squeezed against something (a doorway, a passing bay): plan from the nearest cell
            // the robot may occupy, and get there first
            result = self.planner.plan(map, free, req.goal).map(|mut p| {
                p.waypoints.insert(0, [from.x, from.y]);
                p
            });
        }
        if around
            && let Ok(p) = &result
            && self.detours_refused < MAX_DETOUR_REFUSALS
        {
            let remaining = remaining_length(&self.path, self.follower.segment, from);
            if p.length > DETOUR_FACTOR * remaining + DETOUR_SLACK {
                // what blocks the way is probably a person who will walk on: wait a while
                // longer before taking a long way round
                self.detours_refused += 1;
                self.log(
                    now,
                    format!(
                        "the way around is {:.0} m against {remaining:.0} m: waiting",
                        p.length
                    ),
                );
                if let Phase::Blocked { since } = &mut self.phase {
                    *since = now;
                }
                return;
            }
        }
        match result {
            Ok(p) => {
                self.detours_refused = 0;
                self.set_path(p.waypoints);
                if matches!(self.phase, Phase::Planning | Phase::Blocked { .. }) {
                    self.phase = Phase::Driving;
                }
            }
            Err(e) if around => {
                // nothing around the obstacle: keep waiting, try again later
                self.log(now, format!("no way around the obstacle yet: {e}"));
                if let Phase::Blocked { since } = &mut self.phase {
                    *since = now;
                }
            }
            Err(e) => {
                let goal = req.goal;
                self.legs.push(LegEvent::Finished {
                    goal,
                    reached: false,
                });
                let reason = match &e {
                    PlanError::Unreachable { .. } => format!("goal unreachable: {e}"),
                    _ => e.to_string(),
                };
                self.fail_task(now, reason);
            }
        }
    }

    /// Control set: one tick of the state machine; returns the drive command.
    pub fn control(
        &mut self,
        ctx: &ControlContext,
        index: u32,
        pose: &Pose2,
        fleet: &Fleet,
    ) -> DriveCommand {
        let now = ctx.now;
        if self.phase == Phase::Idle && self.task < self.tasks.len() {
            self.start_step(now);
        }
        // the shared costmap changed (a door): re-plan if the path now crosses an obstacle
        if ctx.costmap_version != self.costmap_version {
            self.costmap_version = ctx.costmap_version;
            if matches!(self.phase, Phase::Driving | Phase::Blocked { .. })
                && path_blocked(ctx.costmap, &self.path, self.follower.segment)
            {
                self.replan_to_goal(now, "map changed across the path: re-planning");
            }
        }
        let p = self.params.clone();
        let gap = self.gap_ahead(pose, ctx.costmap);
        match self.phase {
            Phase::Idle | Phase::Planning => self.brake(ctx.dt),
            Phase::Waiting { until } => {
                if now + 1e-9 >= until {
                    self.next_step(now);
                }
                self.brake(ctx.dt)
            }
            Phase::Driving | Phase::Yielding { parked: false, .. } => {
                if self.path.is_empty() {
                    return self.brake(ctx.dt);
                }
                // slow down in front of obstacles: stop `stop_distance` short of them
                let room = gap - p.stop_distance;
                let cap = if room <= 0.0 {
                    0.0
                } else {
                    (2.0 * p.follower.max_accel * room).sqrt()
                };
                // stepping aside is a slow, tight manoeuvre (short look-ahead: no corner cutting
                // at the mouth of a bay)
                let mut fp = p.follower;
                if matches!(self.phase, Phase::Yielding { .. }) {
                    fp.speed = fp.speed.min(0.3);
                    fp.lookahead = 0.2;
                    fp.lookahead_time = 0.0;
                }
                let fp = self.safe_lookahead(pose, ctx.costmap, fp);
                let out = follow(
                    &self.path,
                    pose,
                    &mut self.follower,
                    &fp,
                    &p.steering,
                    cap,
                    ctx.dt,
                );
                if out.arrived {
                    if let Phase::Yielding { for_robot, .. } = self.phase {
                        self.phase = Phase::Yielding {
                            for_robot,
                            since: now,
                            parked: true,
                        };
                    } else {
                        if let Some(g) = &self.goal {
                            let goal = [g.pose.x, g.pose.y];
                            let name = g.name.clone();
                            self.legs.push(LegEvent::Finished {
                                goal,
                                reached: true,
                            });
                            self.log(now, format!("reached {name}"));
                        }
                        self.next_step(now);
                    }
                    return DriveCommand::new(out.v, out.w);
                }
                // held by the obstacle: not moving forward and not turning on the spot (or not
                // moving at all)
                let held = self.wants_forward(pose) || out.w.abs() < 1e-3;
                if room <= 0.0 && out.v <= 1e-3 && out.w.abs() < 0.3 && held {
                    if let Phase::Yielding { for_robot, .. } = self.phase {
                        self.held_on_the_way_aside(now, pose, gap, for_robot);
                    } else {
                        self.stopped(now, pose, gap);
                    }
                } else if out.v > 0.05 {
                    self.held_since = None;
                }
                if out.off_path > 1.5
                    && matches!(self.phase, Phase::Driving)
                    && let Some(g) = &self.goal
                {
                    self.metrics.replans += 1;
                    self.request = Some(PlanRequest {
                        goal: [g.pose.x, g.pose.y],
                        around: Vec::new(),
                    });
                    self.phase = Phase::Planning;
                    self.log(now, "off the path: re-planning");
                }
                DriveCommand::new(out.v, out.w)
            }
            Phase::Blocked { since } => {
                self.metrics.waiting_time_s += ctx.dt;
                if gap - p.stop_distance > 0.1 {
                    let clear = *self.clear_since.get_or_insert(now);
                    if now - clear >= CLEAR_TIME - 1e-9 {
                        self.phase = Phase::Driving;
                        self.clear_since = None;
                        self.resumed = Some(Resumed {
                            since,
                            at: [pose.x, pose.y],
                            time: now,
                        });
                        self.detours_refused = 0;
                        self.log(now, "way clear: going on");
                        return self.brake(ctx.dt);
                    }
                } else {
                    self.clear_since = None;
                }
                self.settle_block(ctx, index, pose, fleet, since);
                self.brake(ctx.dt)
            }
            Phase::Yielding {
                for_robot,
                since,
                parked: true,
            } => {
                self.metrics.waiting_time_s += ctx.dt;
                let me = self.fleet_entry(index, pose);
                let still_coming = fleet.get(for_robot).is_some_and(|o| {
                    comes_through(o, &me, o.radius + me.radius + 0.2)
                        || (o.pose.x - pose.x).hypot(o.pose.y - pose.y) < o.radius + me.radius + 0.3
                });
                if !still_coming || now - since > 60.0 {
                    self.replan_to_goal(now, "gave way: re-planning to the goal");
                }
                self.brake(ctx.dt)
            }
        }
    }

    fn brake(&mut self, dt: f64) -> DriveCommand {
        let a = self.params.follower.max_decel * dt;
        let aw = self.params.follower.max_yaw_accel * dt;
        self.follower.v -= self.follower.v.clamp(-a, a);
        self.follower.w -= self.follower.w.clamp(-aw, aw);
        DriveCommand::new(self.follower.v, self.follower.w)
    }
}

/// Shared inputs of one control tick.
pub struct ControlContext<'a> {
    pub now: f64,
    pub dt: f64,
    pub costmap: &'a Costmap,
    pub costmap_version: u64,
}
