//! Ground-truth navigation outcomes: for every leg a navigator drives (one `Go` step), the
//! distance the robot truly covered against the A* optimum from its TRUE start pose to the goal
//! on the costmap it plans on — the path-length ratio of navigation benchmarks (e.g. the
//! "path length / optimal path length" of Bench-MR, Heiden et al., RA-L 2021). The navigator's
//! own counters (tasks, stops, waits, re-plans, failures) are in
//! [`NavMetrics`](crate::navigation::NavMetrics).

use super::robot_metrics::RobotMetrics;
use crate::body::{Collisions, TruePose};
use crate::core::SimClock;
use crate::navigation::{LegEvent, NavCostmaps, Navigator, Planner, PlannerParams};
use bevy_ecs::prelude::*;

#[derive(Component, Clone, Debug, Default, PartialEq)]
pub struct NavOutcome {
    /// Legs that reached their goal.
    pub legs: u32,
    /// True distance driven on those legs (m).
    pub driven_m: f64,
    /// Sum of the A* optima of those legs from the true start poses (m).
    pub optimal_m: f64,
    /// Collision starts (time, what), for the event log.
    pub collision_log: Vec<(f64, String)>,
    current: Option<Leg>,
    seen_collisions: Collisions,
}

#[derive(Clone, Debug, PartialEq)]
struct Leg {
    /// The A* optimum from the true start when the leg began (None: no path then).
    optimal: Option<f64>,
    driven: f64,
}

impl NavOutcome {
    /// Driven / optimal length over the reached legs (≥ 1; NaN before any).
    pub fn path_ratio(&self) -> f64 {
        if self.optimal_m > 0.0 {
            self.driven_m / self.optimal_m
        } else {
            f64::NAN
        }
    }
}

/// Evaluate: accumulate every navigating robot's legs.
pub fn evaluate_navigation(
    clock: Res<SimClock>,
    costmaps: Option<Res<NavCostmaps>>,
    mut planner: Local<Option<Planner>>,
    mut robots: Query<(&mut Navigator, &TruePose, &RobotMetrics, &mut NavOutcome)>,
) {
    let Some(costmaps) = costmaps else {
        return;
    };
    for (mut nav, truth, metrics, mut out) in robots.iter_mut() {
        let c = metrics.collisions;
        if c != out.seen_collisions {
            let seen = out.seen_collisions;
            let what = if c.wall > seen.wall {
                "collision with a wall"
            } else if c.robot > seen.robot {
                "collision with another robot"
            } else if c.person > seen.person {
                "collision with a person"
            } else {
                "collision"
            };
            let p = truth.pose;
            out.collision_log
                .push((clock.start(), format!("{what} at ({:.2}, {:.2})", p.x, p.y)));
            out.seen_collisions = c;
        }
        if let Some(leg) = &mut out.current {
            leg.driven += truth.prev.distance(&truth.pose);
        }
        for ev in std::mem::take(&mut nav.legs) {
            match ev {
                LegEvent::Started { goal } => {
                    let p = planner.get_or_insert_with(|| Planner::new(PlannerParams::default()));
                    // the optimum is the shortest collision-free way (no wall-distance weight)
                    p.params.cost_weight = 0.0;
                    let map = costmaps.get(nav.params.costmap);
                    let optimal = p
                        .plan(map, [truth.pose.x, truth.pose.y], goal)
                        .ok()
                        .map(|b| b.length);
                    out.current = Some(Leg {
                        optimal,
                        driven: 0.0,
                    });
                }
                LegEvent::Finished { reached, .. } => {
                    let Some(leg) = out.current.take() else {
                        continue;
                    };
                    if let (true, Some(best)) = (reached, leg.optimal) {
                        out.legs += 1;
                        out.driven_m += leg.driven;
                        out.optimal_m += best;
                    }
                }
            }
        }
    }
}
