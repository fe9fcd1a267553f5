//! What a finished world says: one summary row per robot, every localizer's samples paired with
//! the truth, and the event log.

use super::{LocalizerTiming, NavigationFailure, NavigationSummary, RobotSummary, Timing};
use crate::formats::tum::RobotLocalization;
use bevy_ecs::prelude::*;
use systems::body::TruePose;
use systems::core::{RobotId, RobotIndex};
use systems::eval::road_metrics::RoadRunMetrics;
use systems::eval::{
    LocalizationSamples, LocalizerMetrics, NavOutcome, RobotMetrics, TrajectoryMetrics,
    pair_with_truth,
};
use systems::localization::road_wiring::RoadLocalization;
use systems::localization::{Filter, Localizers};
use systems::navigation::road_drive::RoadNavigator;
use systems::navigation::{Behaviour, NavStatus, Navigator};
use systems::world::roads::RoadMap;

/// One row per robot, in index order.
pub(crate) fn robot_summaries(w: &mut World) -> Vec<RobotSummary> {
    let mut q = w.query::<(
        &RobotIndex,
        &RobotId,
        &TruePose,
        &RobotMetrics,
        Option<&Behaviour>,
        Option<(&Localizers, &LocalizationSamples)>,
        Option<(&Navigator, &NavOutcome)>,
        Option<(&RoadNavigator, &RoadLocalization, &RoadRunMetrics)>,
    )>();
    let graph = w.get_resource::<RoadMap>().map(|r| r.0.clone());
    let mut rows: Vec<(RobotIndex, RobotSummary)> = q
        .iter(w)
        .map(|(i, id, truth, m, b, loc, nav, road)| {
            let localization = match loc {
                Some((locs, samples)) => locs
                    .items
                    .iter()
                    .map(|l| {
                        let s = samples
                            .per_localizer
                            .iter()
                            .find(|(n, _)| *n == l.name)
                            .map_or(&[][..], |(_, s)| &s[..]);
                        let mut m = LocalizerMetrics::from_samples(l.filter.kind(), s);
                        m.in_map = l.filter.as_map().is_some_and(|f| f.localizes_in_map());
                        if let Filter::Scan(e) = &l.filter {
                            let paired = pair_with_truth(s, &e.trajectory());
                            m.final_trajectory = Some(TrajectoryMetrics::from_samples(&paired));
                        }
                        (l.name.clone(), m)
                    })
                    .collect(),
                None => Default::default(),
            };
            let p = truth.pose;
            (
                *i,
                RobotSummary {
                    name: id.0.clone(),
                    distance_m: m.distance_m,
                    collisions: m.collisions.total(),
                    wall_collisions: m.collisions.wall,
                    robot_collisions: m.collisions.robot,
                    person_collisions: m.collisions.person,
                    odometry_drift_m: m.odometry_drift_m,
                    max_odometry_drift_m: m.max_odometry_drift_m,
                    odometry_ate_m: m.odometry_ate_m(),
                    odometry_drift_percent: if m.distance_m > 0.0 {
                        100.0 * m.odometry_drift_m / m.distance_m
                    } else {
                        0.0
                    },
                    odometry_heading_error_rad: m.odometry_heading_error_rad,
                    waypoints_reached: b.map_or(0, |b| b.reached),
                    // a waypoint route's behaviour arrived, or a road route reached its goal
                    route_completed: b.is_some_and(|b| b.status == NavStatus::Arrived)
                        || road.is_some_and(|(_, _, rm)| rm.reached),
                    final_pose: [p.x, p.y, p.theta],
                    localization,
                    navigation: nav.map(|(n, o)| navigation_summary(n, o, m)),
                    road: road
                        .zip(graph.as_deref())
                        .map(|((n, l, rm), g)| super::road::road_summary(g, n, l, rm)),
                },
            )
        })
        .collect();
    rows.sort_by_key(|(i, _)| *i);
    rows.into_iter().map(|(_, r)| r).collect()
}

/// Each localizer's wall-clock cost per update, robots in index order.
pub(crate) fn timing(w: &mut World) -> Timing {
    let mut q = w.query::<(&RobotIndex, &RobotId, &Localizers)>();
    let mut robots: Vec<_> = q.iter(w).collect();
    robots.sort_by_key(|(i, _, _)| **i);
    let localizers = robots
        .into_iter()
        .flat_map(|(_, id, locs)| {
            locs.items.iter().map(|l| LocalizerTiming {
                robot: id.0.clone(),
                localizer: l.name.clone(),
                kind: l.filter.kind().to_string(),
                updates: l.cost.updates,
                total_s: l.cost.total_s,
                mean_update_us: l.cost.mean_s() * 1e6,
                max_update_us: l.cost.max_s * 1e6,
            })
        })
        .collect();
    Timing { localizers }
}

fn navigation_summary(n: &Navigator, o: &NavOutcome, m: &RobotMetrics) -> NavigationSummary {
    let nm = &n.metrics;
    let times = &nm.delivery_times_s;
    NavigationSummary {
        tasks: n.tasks.len() as u32,
        tasks_completed: nm.tasks_completed,
        tasks_failed: nm.tasks_failed,
        all_tasks_done: n.finished(),
        deliveries_completed: nm.deliveries_completed,
        delivery_times_s: times.clone(),
        mean_delivery_time_s: (!times.is_empty())
            .then(|| times.iter().sum::<f64>() / times.len() as f64),
        legs: o.legs,
        path_length_m: o.driven_m,
        optimal_length_m: o.optimal_m,
        path_ratio: (o.optimal_m > 0.0).then(|| o.path_ratio()),
        collisions: m.collisions.total(),
        wall_collisions: m.collisions.wall,
        stops: nm.stops,
        waiting_time_s: nm.waiting_time_s,
        replans: nm.replans,
        yields: nm.yields,
        failures: nm
            .failures
            .iter()
            .map(|f| NavigationFailure {
                time_s: f.time,
                task: f.task.clone(),
                reason: f.reason.clone(),
            })
            .collect(),
    }
}

/// Every robot's localizer samples, in index order.
pub(crate) fn robot_localization(w: &mut World) -> Vec<RobotLocalization> {
    let mut q = w.query::<(&RobotIndex, &RobotId, &LocalizationSamples)>();
    let mut rows: Vec<(RobotIndex, RobotLocalization)> = q
        .iter(w)
        .map(|(i, id, s)| {
            (
                *i,
                RobotLocalization {
                    robot: id.0.clone(),
                    localizers: s.per_localizer.clone(),
                },
            )
        })
        .collect();
    rows.sort_by_key(|(i, _)| *i);
    rows.into_iter().map(|(_, r)| r).collect()
}

/// Scenario events and every navigator's events, in time order.
pub(crate) fn event_log(w: &mut World) -> Vec<(f64, String, String)> {
    let mut log = w
        .get_resource::<crate::build::script::EventQueue>()
        .map(|q| q.fired.clone())
        .unwrap_or_default();
    let mut q = w.query::<(&RobotIndex, &RobotId, &Navigator, &NavOutcome)>();
    let mut navs: Vec<_> = q.iter(w).collect();
    navs.sort_by_key(|(i, ..)| **i);
    for (_, id, n, o) in navs {
        log.extend(
            n.events
                .iter()
                .map(|e| (e.time, id.0.clone(), e.text.clone())),
        );
        log.extend(
            o.collision_log
                .iter()
                .map(|(t, e)| (*t, id.0.clone(), e.clone())),
        );
    }
    let mut q = w.query::<(&RobotIndex, &RobotId, &RoadNavigator)>();
    let mut navs: Vec<_> = q.iter(w).collect();
    navs.sort_by_key(|(i, ..)| **i);
    for (_, id, n) in navs {
        log.extend(n.events.iter().map(|(t, e)| (*t, id.0.clone(), e.clone())));
    }
    // stable: same-time lines keep world events first, then robots in index order
    log.sort_by(|a, b| a.0.total_cmp(&b.0));
    log
}
