//! The outdoor part of a robot's summary: how its drive to a road node went (arrival, wrong
//! turns, recoveries, re-plans) and how well each road localizer tracked it.

use serde::Serialize;
use std::collections::BTreeMap;
use systems::eval::road_metrics::RoadRunMetrics;
use systems::localization::road_wiring::RoadLocalization;
use systems::navigation::road_drive::RoadNavigator;
use systems::world::roads::RoadGraph;

/// How a robot's drive to a road node went.
#[derive(Serialize, Clone, Debug, PartialEq)]
pub struct RoadSummary {
    /// The goal node's id in the road file.
    pub goal: String,
    /// The navigator stopped at the goal and the robot truly is within reach of it.
    pub reached: bool,
    /// When it stopped at the goal (simulated s).
    pub arrival_time_s: Option<f64>,
    /// True distance from the goal node where the navigator stopped (m).
    pub final_distance_m: Option<f64>,
    /// Length of the first route planned (m).
    pub planned_length_m: Option<f64>,
    /// Turns onto an edge off the route (judged on the true position).
    pub wrong_turns: u32,
    /// Re-plans made while off the route: wrong turns noticed by re-localization.
    pub recoveries: u32,
    /// Routes planned again.
    pub replans: u32,
    /// Plans that found no route.
    pub plan_failures: u32,
    /// Junction manoeuvres: keeping to the left edge, to the right edge, by compass.
    pub junctions_left_right_compass: [u32; 3],
    /// Time the robot truly spent off the roads (s).
    pub off_road_time_s: f64,
    /// Time stopped by the sonars for an obstacle ahead (s).
    pub sonar_stop_time_s: f64,
    /// The localizer the robot navigated by.
    pub navigated_by: String,
    /// Each road localizer's tracking, by name.
    pub localizers: BTreeMap<String, RoadLocalizerSummary>,
}

/// How well a road localizer tracked the robot.
#[derive(Serialize, Clone, Debug, PartialEq)]
pub struct RoadLocalizerSummary {
    /// Filter updates with an estimate (one per GPS fix once localized).
    pub updates: u32,
    /// Mean position error of those estimates (m).
    pub mean_error_m: Option<f64>,
    /// Largest position error (m).
    pub max_error_m: Option<f64>,
    /// Share of the judged updates (robot mid-edge) whose estimate was on another edge (%).
    pub wrong_edge_percent: Option<f64>,
    /// Time of the first estimate (s).
    pub first_estimate_s: Option<f64>,
}

/// The road summary of a robot from its navigator, road localizers and metrics.
pub fn road_summary(
    graph: &RoadGraph,
    nav: &RoadNavigator,
    loc: &RoadLocalization,
    m: &RoadRunMetrics,
) -> RoadSummary {
    let localizers = loc
        .slots
        .iter()
        .zip(
            m.errors
                .iter()
                .chain(std::iter::repeat(&Default::default())),
        )
        .map(|(s, e)| {
            (
                s.name.to_string(),
                RoadLocalizerSummary {
                    updates: e.n,
                    mean_error_m: (e.n > 0).then(|| e.mean()),
                    max_error_m: (e.n > 0).then_some(e.max),
                    wrong_edge_percent: (e.judged > 0)
                        .then(|| 100.0 * e.wrong_edge as f64 / e.judged as f64),
                    first_estimate_s: e.first_estimate,
                },
            )
        })
        .collect();
    RoadSummary {
        goal: graph.nodes[nav.goal].source.clone(),
        reached: m.reached,
        arrival_time_s: nav.stats.arrived_at,
        final_distance_m: m.final_distance,
        planned_length_m: nav.first_route_length,
        wrong_turns: m.wrong_turns,
        recoveries: m.recoveries,
        replans: nav.stats.replans,
        plan_failures: nav.stats.plan_failures,
        junctions_left_right_compass: nav.stats.junctions,
        off_road_time_s: m.off_road_time,
        sonar_stop_time_s: nav.stats.sonar_stop_time,
        navigated_by: loc
            .slots
            .get(loc.nav)
            .map_or_else(String::new, |s| s.name.to_string()),
        localizers,
    }
}
