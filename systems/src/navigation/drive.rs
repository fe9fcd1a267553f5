//! The navigation systems: plans in the Plan set, the navigators' state machines in the Control
//! set. Both run the robots in parallel on the kernel pool; each navigator touches only its own
//! state and reads shared data (costmaps, the fleet board published before the parallel part),
//! so the thread count never changes a result.

use super::avoid::SectorRanges;
use super::fleet::Fleet;
use super::local_map::echo_explained;
use super::navigator::{ControlContext, Navigator};
use super::shared_costmaps::NavCostmaps;
use crate::body::DriveCommand;
use crate::core::{KernelPool, RobotIndex, SimClock};
use crate::localization::NavBelief;
use crate::sensors::{Laser, LaserScans, SonarReadings, Sonars};
use bevy_ecs::prelude::*;

/// A sonar echo within this distance (m) of a wall the map knows in its cone is that wall (range
/// noise, belief error, the wall's cell size).
const ECHO_TOLERANCE: f64 = 0.25;
/// …and a wall this far (rad) outside either edge of the cone may be what it heard (heading error
/// of the belief, the map's cells against the true outline of a door frame's corner).
const ECHO_CONE_MARGIN: f64 = 0.15;

/// Plan: answer every pending plan request from the robot's belief.
pub fn plan_routes(
    clock: Res<SimClock>,
    pool: Res<KernelPool>,
    costmaps: Option<Res<NavCostmaps>>,
    mut robots: Query<(&mut Navigator, &NavBelief)>,
) {
    let Some(costmaps) = costmaps else {
        return;
    };
    let now = clock.start();
    let mut jobs: Vec<_> = robots
        .iter_mut()
        .filter(|(n, _)| n.request.is_some())
        .collect();
    if jobs.is_empty() {
        return;
    }
    let costmaps = &*costmaps;
    pool.for_each(&mut jobs, |(nav, belief)| {
        let map = costmaps.get(nav.params.costmap);
        nav.plan(now, map, &belief.pose);
    });
}

/// Control: publish the fleet board, then run every navigator.
#[allow(clippy::type_complexity)]
pub fn drive_navigators(
    clock: Res<SimClock>,
    pool: Res<KernelPool>,
    costmaps: Option<Res<NavCostmaps>>,
    mut fleet: ResMut<Fleet>,
    mut robots: Query<(
        &RobotIndex,
        &mut Navigator,
        &NavBelief,
        &mut DriveCommand,
        Option<(&Laser, &LaserScans)>,
        Option<(&Sonars, &SonarReadings)>,
    )>,
) {
    let Some(costmaps) = costmaps else {
        return;
    };
    // the board: every navigator's state at the start of this tick
    let n = robots
        .iter()
        .map(|(i, ..)| i.0 as usize + 1)
        .max()
        .unwrap_or(0);
    fleet.entries.clear();
    fleet.entries.resize(n, None);
    for (idx, nav, belief, ..) in robots.iter() {
        fleet.entries[idx.0 as usize] = Some(nav.fleet_entry(idx.0, &belief.pose));
    }
    let fleet = &*fleet;
    let (now, dt) = (clock.start(), clock.dt);
    let costmaps = &*costmaps;
    let mut jobs: Vec<_> = robots.iter_mut().collect();
    pool.for_each(&mut jobs, |(idx, nav, belief, cmd, laser, sonar)| {
        // sonar echoes join the laser points of the stop check (the laser is blind
        // behind and below its plane; the sonars cover front, ±45° and rear)
        nav.extra.clear();
        let costmap = costmaps.get(nav.params.costmap);
        if let Some((sonars, readings)) = sonar
            && sonars.enabled
        {
            for (m, &r) in sonars.mounts.iter().zip(&readings.latest) {
                let r = if r == f32::NEG_INFINITY {
                    sonars.spec.min_range as f32
                } else {
                    r
                };
                let sensor = belief.pose.compose(m);
                let explained = |r: f32| {
                    echo_explained(
                        costmap,
                        &sensor,
                        sonars.spec.cone + 2.0 * ECHO_CONE_MARGIN,
                        sonars.spec.fan_rays() + 4,
                        r as f64,
                        ECHO_TOLERANCE,
                    )
                };
                if r.is_finite() && !explained(r) {
                    // an echo short of every wall the map knows in the cone: something is
                    // somewhere in the cone at that range, an arc of points
                    let half = sonars.spec.cone / 2.0;
                    for k in 0..7 {
                        let a = -half + half * k as f64 / 3.0;
                        let (sa, ca) = a.sin_cos();
                        let p = m.transform_point([r as f64 * ca, r as f64 * sa]);
                        nav.extra.push((p[0] as f32, p[1] as f32));
                    }
                }
            }
        }
        if let Some((laser, scans)) = laser {
            if let Some(scan) = scans.scans.last() {
                nav.seen
                    .get_or_insert_with(SectorRanges::default)
                    .update(scan, &laser.spec.mount);
            } else if !laser.enabled {
                nav.seen = None;
            }
        }
        let ctx = ControlContext {
            now,
            dt,
            costmap,
            costmap_version: costmaps.version,
        };
        **cmd = nav.control(&ctx, idx.0, &belief.pose, fleet);
    });
}
