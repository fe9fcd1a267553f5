//! The road navigators' system (Control set): each robot's belief from its road localization,
//! its compass, its front sonars and the camera road follower go into
//! [`RoadNavigator::step`](super::RoadNavigator::step), which writes the drive command.

use super::{FollowSide, RoadDriveInput, RoadNavigator, RoadPhase};
use crate::body::DriveCommand;
use crate::core::SimClock;
use crate::localization::road_wiring::RoadLocalization;
use crate::navigation::road_follow::{Keep, RoadFollowParams, road_steering};
use crate::navigation::road_recognition::RoadDetector;
use crate::sensors::{Camera, SonarReadings, Sonars};
use crate::world::roads::RoadMap;
use bevy_ecs::prelude::*;

/// Sonars facing within this angle (rad) of straight ahead guard the way forward.
const FRONT_CONE: f64 = 1.0;
/// The camera learns a new surface this far (m) from both ends of an edge…
const MID_EDGE: f64 = 3.0;
/// …from this many frames.
const RELEARN_FRAMES: u32 = 5;
/// How far inside the road edge the follower keeps at a junction (m).
const EDGE_OFFSET: f64 = 0.8;

/// The nearest echo of the front-facing sonars (m), infinite without any.
fn front_range(sonars: Option<(&Sonars, &SonarReadings)>) -> f64 {
    let Some((s, r)) = sonars else {
        return f64::INFINITY;
    };
    s.mounts
        .iter()
        .zip(&r.latest)
        .filter(|(m, _)| m.theta.abs() <= FRONT_CONE)
        .map(|(_, &d)| if d < 0.0 { 0.0 } else { d as f64 })
        .fold(f64::INFINITY, f64::min)
}

/// Control: one navigator step per robot with a route.
#[allow(clippy::type_complexity)]
pub fn drive_road_navigators(
    clock: Res<SimClock>,
    roads: Option<Res<RoadMap>>,
    mut robots: Query<(
        &mut RoadNavigator,
        &RoadLocalization,
        Option<(&Sonars, &SonarReadings)>,
        Option<(&Camera, &mut RoadDetector)>,
        &mut DriveCommand,
    )>,
) {
    let Some(roads) = roads else { return };
    let graph = &*roads.0;
    for (mut nav, loc, sonars, mut camera, mut cmd) in robots.iter_mut() {
        let belief = loc.belief();
        // a road of a surface the camera has not seen: learn its colours while on it, mid-edge
        if let (Some(b), Some((_, det))) = (belief, camera.as_mut())
            && nav.phase == RoadPhase::Driving
            && b.remaining > MID_EDGE
            && graph.edges[b.edge].length - b.remaining > MID_EDGE
        {
            let surface = graph.roads[graph.edges[b.edge].road].surface;
            if !nav.learned.contains(&surface) {
                det.recognizer.relearn(RELEARN_FRAMES);
                nav.learned.push(surface);
            }
        }
        let learned = nav.learned.clone();
        let camera = camera.as_ref().map(|(c, d)| (*c, &**d));
        let max_curvature = nav.params.max_curvature;
        let follow = |side: FollowSide| -> Option<[f64; 2]> {
            let (cam, det) = camera?;
            let det = det.detection.as_ref().filter(|d| !d.learning)?;
            let keep = match side {
                FollowSide::Centre => Keep::Centre,
                FollowSide::Left => Keep::Left(EDGE_OFFSET),
                FollowSide::Right => Keep::Right(EDGE_OFFSET),
            };
            let params = RoadFollowParams {
                keep,
                max_curvature,
                ..RoadFollowParams::default()
            };
            road_steering(&cam.spec, det, &params).map(|c| c.target)
        };
        let input = RoadDriveInput {
            now: clock.start(),
            dt: clock.dt,
            belief,
            compass: loc.compass,
            odometer: loc.odometer,
            front_range: front_range(sonars),
            follow: &follow,
            learned: &learned,
        };
        let (v, w) = nav.step(graph, &input);
        *cmd = DriveCommand::new(v, w);
    }
}
