//! The blocked robot's decisions: counting a stop once while an obstacle flickers, giving way
//! or waiting (the yield rule of [`crate::navigation::fleet`]), planning around after `wait_time`,
//! parking when held on the way aside.

use super::{ControlContext, Navigator, Phase, PlanRequest};
use crate::core::Pose2;
use crate::navigation::fleet::{Fleet, FleetActivity, comes_through, gives_way, yield_spot};

/// Stopping again within this time (s) and distance (m) of going on continues the same stop
/// (same start of waiting, not counted again).
const SAME_STOP_TIME: f64 = 3.0;
const SAME_STOP_DIST: f64 = 0.5;

impl Navigator {
    /// Driving and stopped by an obstacle: block (continuing the last stop if the robot went on
    /// from it only just now and nearby).
    pub(super) fn stopped(&mut self, now: f64, pose: &Pose2, gap: f64) {
        let same = self.resumed.take().filter(|r| {
            now - r.time < SAME_STOP_TIME
                && (pose.x - r.at[0]).hypot(pose.y - r.at[1]) < SAME_STOP_DIST
        });
        let since = match same {
            Some(r) => r.since,
            None => {
                self.metrics.stops += 1;
                self.log(
                    now,
                    format!(
                        "stop at ({:.2}, {:.2}): obstacle {gap:.2} m ahead",
                        pose.x, pose.y
                    ),
                );
                now
            }
        };
        self.phase = Phase::Blocked { since };
        self.clear_since = None;
    }

    /// On the way to a spot to give way and stopped by an obstacle: one stop, and after
    /// `wait_time` the robot waits where it is instead (the other robot plans around it).
    pub(super) fn held_on_the_way_aside(
        &mut self,
        now: f64,
        pose: &Pose2,
        gap: f64,
        for_robot: u32,
    ) {
        match self.held_since {
            None => {
                self.held_since = Some(now);
                self.metrics.stops += 1;
                self.log(
                    now,
                    format!(
                        "stop at ({:.2}, {:.2}) on the way aside: obstacle {gap:.2} m ahead",
                        pose.x, pose.y
                    ),
                );
            }
            Some(since) if now - since >= self.params.wait_time => {
                self.held_since = None;
                self.phase = Phase::Yielding {
                    for_robot,
                    since: now,
                    parked: true,
                };
                self.log(now, "cannot get aside: waiting here");
            }
            Some(_) => {}
        }
    }

    pub(super) fn replan_to_goal(&mut self, now: f64, why: &str) {
        if let Some(g) = &self.goal {
            self.request = Some(PlanRequest {
                goal: [g.pose.x, g.pose.y],
                around: Vec::new(),
            });
            self.metrics.replans += 1;
            self.phase = Phase::Planning;
            self.log(now, why);
        } else {
            self.phase = Phase::Idle;
        }
    }

    /// A blocked robot decides: give way, wait, or plan around.
    pub(super) fn settle_block(
        &mut self,
        ctx: &ControlContext,
        index: u32,
        pose: &Pose2,
        fleet: &Fleet,
        since: f64,
    ) {
        let now = ctx.now;
        let p = &self.params;
        let me = self.fleet_entry(index, pose);
        let reach = p.stop_distance + p.radius + 0.6;
        if let Some(other) = fleet.robot_ahead(&me, p.radius + 0.05, reach) {
            let clearance = me.radius + other.radius + 0.1;
            let oncoming = comes_through(other, &me, clearance);
            if matches!(other.activity, FleetActivity::Yielding { for_robot, parked: false } if for_robot == index)
            {
                return; // it is making room for us (once it is aside, plan around it if need be)
            }
            if oncoming {
                if gives_way(&me, other) && now - since >= 0.5 {
                    let keep_clear = other.path_ahead.clone();
                    // a spot well out of the way if there is one (deeper into a bay), else
                    // one just clear of the other robot's band
                    let spot = |extra: f64| {
                        yield_spot(
                            ctx.costmap,
                            [pose.x, pose.y],
                            [other.pose.x, other.pose.y],
                            me.radius + other.radius,
                            &keep_clear,
                            clearance + extra,
                            15.0,
                        )
                    };
                    match spot(0.35).or_else(|| spot(0.05)) {
                        Some(path) => {
                            let o = other.index;
                            self.set_path(path);
                            self.metrics.yields += 1;
                            self.cannot_yield = false;
                            self.held_since = None;
                            self.phase = Phase::Yielding {
                                for_robot: o,
                                since: now,
                                parked: false,
                            };
                            self.log(now, format!("giving way to robot #{o}"));
                        }
                        None => {
                            if !self.cannot_yield {
                                self.log(now, "nowhere to give way");
                            }
                            self.cannot_yield = true;
                        }
                    }
                }
                if !(self.cannot_yield && now - since >= self.params.wait_time) {
                    return; // wait for the other robot to give way
                }
            } else if let Some(g) = &self.goal {
                let at_goal = (other.pose.x - g.pose.x).hypot(other.pose.y - g.pose.y)
                    < other.radius + me.radius + 0.3;
                if at_goal && other.activity == FleetActivity::Parked {
                    return; // it is using our goal: wait until it leaves
                }
            }
        }
        if now - since >= self.params.wait_time
            && let Some(g) = &self.goal
        {
            let around = self.obstacles_world(pose);
            let goal = [g.pose.x, g.pose.y];
            self.request = Some(PlanRequest { goal, around });
            self.metrics.replans += 1;
            self.phase = Phase::Blocked { since: now };
            self.log(now, "still blocked: planning around the obstacle");
        }
    }
}
