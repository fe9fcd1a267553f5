//! Driving to a goal on the road network ([Park thesis §5.4, §5.5]): the road localization's belief
//! (a directed edge and the distance left on it) is checked against the planned route; when it is
//! not on the route — at the start, or after a wrong turn the localization has noticed — the A*
//! road planner plans again from there, never with a U-turn. Between junctions the camera's road
//! follower steers; approaching a junction the robot keeps to the left or right road edge or steers
//! by the compass ([`junction`]); the front sonars stop it before obstacles. Everything here reads
//! the belief and the sensors only.

pub mod junction;
pub mod system;

pub use junction::{JunctionMove, junction_move};

use crate::core::wrap_angle;
use crate::navigation::road_planner::{RoadRoute, RoadStart, plan_route};
use crate::world::roads::geo::heading_of_azimuth;
use crate::world::roads::{EdgeId, NodeId, RoadGraph, Surface};
use bevy_ecs::prelude::Component;

/// A heading within this angle (rad) of the way back along the edge counts as turned round.
const TURNED_ROUND: f64 = 0.7;

/// Which part of the road the camera follower aims at.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FollowSide {
    Centre,
    Left,
    Right,
}

#[derive(Clone, Debug, PartialEq)]
pub struct RoadNavParams {
    /// Cruise speed (m/s).
    pub speed: f64,
    /// Speed through junctions and while not yet localized (fraction of `speed`).
    pub slow_factor: f64,
    /// The robot stops when the belief puts it this close to the goal node (m), before or
    /// just past it.
    pub tolerance: f64,
    /// A junction manoeuvre starts this far before the node (m)…
    pub junction_radius: f64,
    /// …and ends this far past it (m, by the encoder).
    pub exit_distance: f64,
    /// Stop when a front sonar hears something closer (m).
    pub stop_distance: f64,
    /// Yaw rate per radian of compass heading error (1/s).
    pub compass_gain: f64,
    /// Largest curvature the controller asks for (1/m).
    pub max_curvature: f64,
    /// Look-ahead of the map pursuit along the route (m).
    pub lookahead: f64,
    /// In a junction the camera's target is followed when it lies within this angle (rad) of
    /// the map's.
    pub junction_agreement: f64,
    /// Between junctions it is followed when it lies within this angle (rad) of the map's and
    /// within the road's half width plus this margin (m) of the map's line…
    pub road_agreement: f64,
    pub road_margin: f64,
    /// …plus this much (m per m ahead) for the heading error.
    pub heading_slack: f64,
}

impl Default for RoadNavParams {
    fn default() -> Self {
        RoadNavParams {
            speed: 1.0,
            slow_factor: 0.6,
            tolerance: 1.0,
            junction_radius: 4.0,
            exit_distance: 3.0,
            stop_distance: 0.8,
            compass_gain: 1.2,
            max_curvature: 1.2,
            lookahead: 2.5,
            junction_agreement: 0.4,
            road_agreement: 1.0,
            road_margin: 2.5,
            heading_slack: 0.2,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RoadPhase {
    /// No belief yet: creep along the road by camera so the localization sees motion.
    Localizing,
    Driving,
    /// Crossing `node` onto `next`, until the encoder reads `until`.
    Junction {
        node: NodeId,
        next: EdgeId,
        mv: JunctionMove,
        until: f64,
    },
    /// No route without a U-turn (a dead end): turn round on full lock until the compass
    /// shows this azimuth, then plan again.
    TurningRound {
        azimuth: f64,
    },
    Arrived,
}

/// What the navigator did, for metrics.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RoadNavStats {
    /// Routes planned (the first included).
    pub plans: u32,
    /// Re-plans because the belief left the route (a wrong turn noticed, or a re-localization).
    pub replans: u32,
    /// Junction manoeuvres by kind: keep left, keep right, compass.
    pub junctions: [u32; 3],
    /// Seconds stopped by the sonars.
    pub sonar_stop_time: f64,
    pub arrived_at: Option<f64>,
    /// Plan failures (no route without a U-turn from where the belief is).
    pub plan_failures: u32,
}

/// One tick's inputs, all from the robot's own sensors and estimators.
pub struct RoadDriveInput<'a> {
    pub now: f64,
    pub dt: f64,
    /// The navigating localizer's belief, moved on by the encoder to `now`.
    pub belief: Option<RoadStart>,
    /// Latest compass azimuth (rad clockwise from north).
    pub compass: Option<f64>,
    /// Distance driven so far (m, encoder).
    pub odometer: f64,
    /// Nearest echo of the front-facing sonars (m; infinite when none).
    pub front_range: f64,
    /// The camera road follower: the point (robot frame, m) it steers to on the given side.
    pub follow: &'a dyn Fn(FollowSide) -> Option<[f64; 2]>,
    /// Road surfaces whose colours the camera has learned.
    pub learned: &'a [Surface],
}

#[derive(Component, Clone, Debug)]
pub struct RoadNavigator {
    pub goal: NodeId,
    pub params: RoadNavParams,
    pub phase: RoadPhase,
    pub route: Option<RoadRoute>,
    /// Length of the first route planned (m).
    pub first_route_length: Option<f64>,
    /// The directed edge the route starts on.
    route_start: Option<(EdgeId, NodeId)>,
    /// The last directed edge a plan failed from (so a failure is not retried every tick).
    failed_from: Option<(EdgeId, NodeId)>,
    /// A belief has put the robot on an edge towards the goal.
    goal_ahead: bool,
    pub stats: RoadNavStats,
    /// Road surfaces the camera has learned the colours of.
    pub learned: Vec<Surface>,
    /// (time, message) of plans, re-plans, junction moves and arrival.
    pub events: Vec<(f64, String)>,
}

impl RoadNavigator {
    pub fn new(goal: NodeId, params: RoadNavParams) -> Self {
        RoadNavigator {
            goal,
            params,
            phase: RoadPhase::Localizing,
            route: None,
            first_route_length: None,
            route_start: None,
            failed_from: None,
            goal_ahead: false,
            stats: RoadNavStats::default(),
            learned: Vec::new(),
            events: Vec::new(),
        }
    }

    /// The route's directed edges (edge, head node) in order: the start edge, then the rest.
    fn route_steps(&self) -> Vec<(EdgeId, NodeId)> {
        let (Some(route), Some(start)) = (&self.route, self.route_start) else {
            return Vec::new();
        };
        let mut out = vec![start];
        out.extend(
            route
                .edges
                .iter()
                .zip(&route.nodes[1..])
                .map(|(&e, &n)| (e, n)),
        );
        out
    }

    /// The start edge of the current route (the first of [`RoadNavigator::route_edges`]),
    /// without gathering the rest.
    pub fn route_start_edge(&self) -> Option<EdgeId> {
        self.route.as_ref().and(self.route_start).map(|(e, _)| e)
    }

    /// The edges of the current route, the start edge first.
    pub fn route_edges(&self) -> Vec<EdgeId> {
        self.route_steps().into_iter().map(|(e, _)| e).collect()
    }

    /// Makes sure the route passes the belief; returns the index of the belief's step on it.
    fn check_route(&mut self, graph: &RoadGraph, now: f64, b: RoadStart) -> Option<usize> {
        let here = (b.edge, b.toward);
        if let Some(i) = self.route_steps().iter().position(|&s| s == here) {
            return Some(i);
        }
        if self.failed_from == Some(here) {
            return None;
        }
        match plan_route(graph, b, self.goal) {
            Ok(route) => {
                if self.route.is_some() {
                    self.stats.replans += 1;
                    self.events.push((
                        now,
                        format!(
                            "off the route on edge {}→{}: re-planned, {:.1} m",
                            graph.nodes[other_end(graph, b.edge, b.toward)].source,
                            graph.nodes[b.toward].source,
                            route.length
                        ),
                    ));
                } else {
                    self.events
                        .push((now, format!("route planned: {:.1} m", route.length)));
                }
                self.stats.plans += 1;
                self.first_route_length.get_or_insert(route.length);
                self.route = Some(route);
                self.route_start = Some(here);
                self.failed_from = None;
                Some(0)
            }
            Err(_) => {
                self.stats.plan_failures += 1;
                self.events.push((
                    now,
                    format!(
                        "no route to node {} from edge {}→{} without a U-turn",
                        graph.nodes[self.goal].source,
                        graph.nodes[other_end(graph, b.edge, b.toward)].source,
                        graph.nodes[b.toward].source
                    ),
                ));
                self.failed_from = Some(here);
                None
            }
        }
    }

    /// The point `lookahead` metres ahead of the belief along the route (or along the belief's
    /// edge without a route), in world metres.
    fn pursuit_target(&self, graph: &RoadGraph, b: RoadStart, step: Option<usize>) -> [f64; 2] {
        let l = self.params.lookahead;
        let head = graph.nodes[b.toward].pos;
        let from = graph.nodes[other_end(graph, b.edge, b.toward)].pos;
        let len = graph.edges[b.edge].length.max(1e-9);
        let dir = [(head[0] - from[0]) / len, (head[1] - from[1]) / len];
        if b.remaining >= l {
            return [
                head[0] - dir[0] * (b.remaining - l),
                head[1] - dir[1] * (b.remaining - l),
            ];
        }
        let (Some(k), Some(route)) = (step, &self.route) else {
            return [
                head[0] + dir[0] * (l - b.remaining),
                head[1] + dir[1] * (l - b.remaining),
            ];
        };
        let mut left = l - b.remaining;
        let mut at = b.toward;
        for &e in &route.edges[k.min(route.edges.len())..] {
            let next = other_end(graph, e, at);
            let (p, q) = (graph.nodes[at].pos, graph.nodes[next].pos);
            let el = graph.edges[e].length.max(1e-9);
            if left <= el {
                let t = left / el;
                return [p[0] + (q[0] - p[0]) * t, p[1] + (q[1] - p[1]) * t];
            }
            left -= el;
            at = next;
        }
        graph.nodes[at].pos
    }

    /// The pursuit target in the robot frame, from the belief (the robot on the edge's centre
    /// line) and the heading from the compass.
    fn map_pursuit(
        &self,
        graph: &RoadGraph,
        b: RoadStart,
        step: Option<usize>,
        compass: f64,
    ) -> [f64; 2] {
        let target = self.pursuit_target(graph, b, step);
        let head = graph.nodes[b.toward].pos;
        let from = graph.nodes[other_end(graph, b.edge, b.toward)].pos;
        let len = graph.edges[b.edge].length.max(1e-9);
        let t = 1.0 - (b.remaining / len).min(1.0);
        let p = [
            from[0] + (head[0] - from[0]) * t,
            from[1] + (head[1] - from[1]) * t,
        ];
        let th = heading_of_azimuth(compass);
        let (dx, dy) = (target[0] - p[0], target[1] - p[1]);
        [
            th.cos() * dx + th.sin() * dy,
            -th.sin() * dx + th.cos() * dy,
        ]
    }

    /// One control step: the body velocities (v, ω) to drive.
    pub fn step(&mut self, graph: &RoadGraph, input: &RoadDriveInput) -> (f64, f64) {
        let p = self.params.clone();
        if self.phase == RoadPhase::Arrived {
            return (0.0, 0.0);
        }
        if let RoadPhase::TurningRound { azimuth } = self.phase {
            let done = input
                .compass
                .is_none_or(|c| wrap_angle(azimuth - c).abs() < 0.5 * TURNED_ROUND);
            if !done {
                let v = p.speed * p.slow_factor * 0.5;
                // turn the shorter way round: azimuth clockwise, yaw anticlockwise
                let sign = match input.compass {
                    Some(c) if wrap_angle(azimuth - c) > 0.0 => -1.0,
                    _ => 1.0,
                };
                return (v, v * sign * p.max_curvature);
            }
            self.phase = RoadPhase::Driving;
            self.failed_from = None;
        }
        let Some(b) = input.belief else {
            // creep along the road by camera so the localization sees motion
            self.phase = RoadPhase::Localizing;
            let v = p.speed * p.slow_factor;
            let k = (input.follow)(FollowSide::Centre).map_or(0.0, pursuit_curvature);
            return self.drive(&p, input, v, k);
        };
        if self.phase == RoadPhase::Localizing {
            self.phase = RoadPhase::Driving;
        }
        let step = self.check_route(graph, input.now, b);
        if step.is_none() && self.failed_from == Some((b.edge, b.toward)) && b.remaining < 2.0 {
            let back = graph.azimuth_from(b.edge, b.toward);
            if input
                .compass
                .is_some_and(|c| wrap_angle(back - c).abs() < TURNED_ROUND)
            {
                // the compass says the robot already faces back along the edge: the belief's
                // direction is wrong, so drive on by camera until the localization (which
                // drops estimates the compass contradicts) has it right
                let v = p.speed * p.slow_factor;
                let k = (input.follow)(FollowSide::Centre).map_or(0.0, pursuit_curvature);
                return self.drive(&p, input, v, k);
            }
            // a dead end ahead and no way on without turning: turn round
            self.events
                .push((input.now, "turning round at a dead end".into()));
            self.phase = RoadPhase::TurningRound { azimuth: back };
            return (0.0, 0.0);
        }
        if self.at_goal(graph, b, p.tolerance) {
            self.phase = RoadPhase::Arrived;
            self.stats.arrived_at = Some(input.now);
            self.events.push((input.now, "arrived".into()));
            return (0.0, 0.0);
        }
        if let RoadPhase::Junction { until, .. } = self.phase
            && input.odometer >= until
        {
            self.phase = RoadPhase::Driving;
        }
        if self.phase == RoadPhase::Driving
            && b.remaining <= p.junction_radius
            && let Some(k) = step
            && let Some(route) = &self.route
            && let Some(&next) = route.edges.get(k)
            && graph.degree(b.toward) >= 3
        {
            let mut mv = junction_move(graph, b.toward, b.edge, next);
            // the camera only sees roads of a learned surface as road
            let surface = graph.roads[graph.edges[next].road].surface;
            if !matches!(mv, JunctionMove::Compass(_)) && !input.learned.contains(&surface) {
                mv = JunctionMove::Compass(graph.azimuth_from(next, b.toward));
            }
            self.stats.junctions[match mv {
                JunctionMove::KeepLeft => 0,
                JunctionMove::KeepRight => 1,
                JunctionMove::Compass(_) => 2,
            }] += 1;
            self.events.push((
                input.now,
                format!(
                    "junction {}: {}",
                    graph.nodes[b.toward].source,
                    describe(mv)
                ),
            ));
            self.phase = RoadPhase::Junction {
                node: b.toward,
                next,
                mv,
                until: input.odometer + b.remaining + p.exit_distance,
            };
        }
        let (side, slow) = match self.phase {
            RoadPhase::Junction { mv, .. } => match mv {
                JunctionMove::KeepLeft => (Some(FollowSide::Left), true),
                JunctionMove::KeepRight => (Some(FollowSide::Right), true),
                JunctionMove::Compass(_) => (None, true),
            },
            _ => (Some(FollowSide::Centre), false),
        };
        let v = if slow {
            p.speed * p.slow_factor
        } else {
            p.speed
        };
        let camera = side.and_then(|s| (input.follow)(s));
        let map = input.compass.map(|c| self.map_pursuit(graph, b, step, c));
        // the camera leads where it sees the road the map says the route takes; where it
        // does not (a crossing road of another surface, a junction's open area) the map leads
        let half_width = 0.5 * graph.roads[graph.edges[b.edge].road].width;
        let agrees = |c: [f64; 2], m: [f64; 2]| {
            if slow {
                angle_between(c, m) <= p.junction_agreement
            } else {
                // the belief has no lateral position: the camera's road may lie anywhere
                // within the road's width of the map's line, give or take a heading error
                angle_between(c, m) <= p.road_agreement
                    && lateral_gap(c, m) <= half_width + p.road_margin + p.heading_slack * c[0]
            }
        };
        let target = match (camera, map) {
            (Some(c), Some(m)) if agrees(c, m) => Some(c),
            (Some(c), None) => Some(c),
            (_, m) => m,
        };
        self.drive(&p, input, v, target.map_or(0.0, pursuit_curvature))
    }

    /// (v, ω) for speed `v` on curvature `k`, or a stop when a front sonar hears something near.
    fn drive(&mut self, p: &RoadNavParams, input: &RoadDriveInput, v: f64, k: f64) -> (f64, f64) {
        if input.front_range < p.stop_distance {
            self.stats.sonar_stop_time += input.dt;
            return (0.0, 0.0);
        }
        (v, v * k.clamp(-p.max_curvature, p.max_curvature))
    }
}

/// Pure-pursuit curvature (1/m, left positive) to a point in the robot frame.
fn pursuit_curvature(t: [f64; 2]) -> f64 {
    2.0 * t[1] / (t[0] * t[0] + t[1] * t[1]).max(1e-6)
}

/// How far (m) the point `c` lies to the side of the line from the robot through `m`.
fn lateral_gap(c: [f64; 2], m: [f64; 2]) -> f64 {
    let len = m[0].hypot(m[1]).max(1e-9);
    ((m[0] * c[1] - m[1] * c[0]) / len).abs()
}

/// Angle (rad) between two directions from the robot.
fn angle_between(a: [f64; 2], b: [f64; 2]) -> f64 {
    wrap_angle(a[1].atan2(a[0]) - b[1].atan2(b[0])).abs()
}

impl RoadNavigator {
    /// Whether belief `b` puts the robot within `tolerance` of the goal node: before it, or
    /// just past it after approaching it (a localizer update may move the belief onto the
    /// next edge).
    fn at_goal(&mut self, graph: &RoadGraph, b: RoadStart, tolerance: f64) -> bool {
        if b.toward == self.goal {
            self.goal_ahead = true;
            return b.remaining <= tolerance;
        }
        self.goal_ahead
            && other_end(graph, b.edge, b.toward) == self.goal
            && graph.edges[b.edge].length - b.remaining <= tolerance
    }
}

fn describe(mv: JunctionMove) -> String {
    match mv {
        JunctionMove::KeepLeft => "keep to the left edge".into(),
        JunctionMove::KeepRight => "keep to the right edge".into(),
        JunctionMove::Compass(az) => format!("by compass to {:.0}°", az.to_degrees()),
    }
}

/// The end of `edge` that is not `node`.
pub fn other_end(graph: &RoadGraph, edge: EdgeId, node: NodeId) -> NodeId {
    let e = &graph.edges[edge];
    if e.a == node { e.b } else { e.a }
}

#[cfg(test)]
mod tests;
