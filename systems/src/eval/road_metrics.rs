//! Outdoor runs judged against ground truth (the park experiments of [Park thesis §7.3]:
//! did the robot reach its goal, did it take a wrong turn and recover by re-localizing and
//! re-planning, how far off was each road localizer along the way).
//!
//! The true edge is the nearest edge to the true position when the robot is on the road and at
//! least [`MID_EDGE`] m from both of the edge's ends (near a node every edge meeting there is
//! about as near, so the edge is only judged once the robot has left the node). A wrong turn
//! is the true edge changing to one off the navigator's current route; a recovery is a re-plan
//! made while the robot is off the route.

use crate::body::TruePose;
use crate::core::SimClock;
use crate::localization::road_wiring::RoadLocalization;
use crate::navigation::road_drive::{RoadNavigator, RoadPhase};
use crate::world::roads::{EdgeId, RoadMap};
use bevy_ecs::prelude::*;

/// Distance (m) from an edge's ends within which the true edge is not judged.
pub const MID_EDGE: f64 = 2.5;

/// A run reached its goal when the navigator stopped with the robot truly this close to the
/// goal node (m): the scale of the GPS error the road localization works with (most fixes
/// 0.5–4 m off, [Park thesis §5.3.3]).
pub const REACHED_RADIUS: f64 = 5.0;

/// Position error of one road localizer, at its updates.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RoadErrorStats {
    pub n: u32,
    pub sum: f64,
    pub max: f64,
    /// Updates whose estimate was on another edge than the true one (judged mid-edge only).
    pub wrong_edge: u32,
    pub judged: u32,
    /// First time it gave an estimate.
    pub first_estimate: Option<f64>,
}

impl RoadErrorStats {
    pub fn mean(&self) -> f64 {
        if self.n == 0 {
            f64::NAN
        } else {
            self.sum / self.n as f64
        }
    }
}

#[derive(Component, Clone, Debug, Default)]
pub struct RoadRunMetrics {
    /// The edge the robot is truly on, when judged.
    pub truth_edge: Option<EdgeId>,
    pub wrong_turns: u32,
    pub recoveries: u32,
    /// The robot is on an edge off the route.
    pub off_route: bool,
    /// Seconds with the robot's centre off every road surface.
    pub off_road_time: f64,
    /// One per road localizer, in slot order.
    pub errors: Vec<RoadErrorStats>,
    /// The navigator stopped at the goal and the robot is truly within [`REACHED_RADIUS`] of it.
    pub reached: bool,
    /// Distance from the goal node when the navigator stopped (m).
    pub final_distance: Option<f64>,
    replans_seen: u32,
    route_snapshot: Vec<EdgeId>,
}

/// Evaluate: wrong turns, recoveries, off-road time, localization errors, arrival.
pub fn evaluate_road_runs(
    clock: Res<SimClock>,
    roads: Option<Res<RoadMap>>,
    mut robots: Query<(
        &TruePose,
        &RoadNavigator,
        &RoadLocalization,
        &mut RoadRunMetrics,
    )>,
) {
    let Some(roads) = roads else { return };
    let g = &*roads.0;
    for (truth, nav, loc, mut m) in robots.iter_mut() {
        let p = [truth.pose.x, truth.pose.y];
        let on_road = g.surface_at(p).is_some();
        if !on_road {
            m.off_road_time += clock.dt;
        }
        let judged = g
            .nearest_edge(p)
            .filter(|ep| {
                on_road && ep.along >= MID_EDGE && g.edges[ep.edge].length - ep.along >= MID_EDGE
            })
            .map(|ep| ep.edge);
        if let Some(e) = judged
            && m.truth_edge != Some(e)
        {
            m.truth_edge = Some(e);
            // judged against the route the robot was following when it was last on it (a
            // belief that notices the turn first re-plans before the truth is judged)
            let planned = if m.route_snapshot.is_empty() {
                nav.route_edges()
            } else {
                m.route_snapshot.clone()
            };
            let on_route = planned.contains(&e);
            if !on_route && !m.off_route && nav.route.is_some() {
                m.wrong_turns += 1;
            }
            m.off_route = !on_route;
        }
        if let Some(e) = m.truth_edge
            && !m.off_route
        {
            let now = nav.route_edges();
            if now.contains(&e) {
                m.route_snapshot = now;
            }
        }
        if nav.stats.replans > m.replans_seen {
            if m.off_route {
                m.recoveries += 1;
            }
            m.replans_seen = nav.stats.replans;
            // the new route may include the edge the robot is on
            m.off_route = m
                .truth_edge
                .is_some_and(|e| !nav.route_edges().contains(&e));
            if !m.off_route {
                m.route_snapshot = nav.route_edges();
            }
        }
        if m.errors.len() < loc.slots.len() {
            m.errors.resize(loc.slots.len(), RoadErrorStats::default());
        }
        for (s, stats) in loc.slots.iter().zip(m.errors.iter_mut()) {
            let Some(est) = s.estimate.filter(|_| s.updated) else {
                continue;
            };
            stats.first_estimate.get_or_insert(clock.start());
            let err = (est.xy[0] - p[0]).hypot(est.xy[1] - p[1]);
            stats.n += 1;
            stats.sum += err;
            stats.max = stats.max.max(err);
            if let Some(e) = judged {
                stats.judged += 1;
                if est.edge != e {
                    stats.wrong_edge += 1;
                }
            }
        }
        if nav.phase == RoadPhase::Arrived && m.final_distance.is_none() {
            let goal = g.nodes[nav.goal].pos;
            let d = (goal[0] - p[0]).hypot(goal[1] - p[1]);
            m.final_distance = Some(d);
            m.reached = d <= REACHED_RADIUS;
        }
    }
}
