//! The outdoor part of world building: the road network, its geographic frame, the road surface
//! the cameras see and the GPS/compass zones as resources; per robot the GPS, compass and
//! camera, and for a robot with a route its road localizers (road grid and road MCL, side by
//! side), its road navigator and its outdoor metrics.

use crate::scenario::outdoor_robot::RoadLocalizerKind;
use crate::scenario::{RobotConfig, Scenario};
use bevy_ecs::prelude::*;
use std::sync::Arc;
use systems::body::Kinematics;
use systems::core::{MapCache, stream_rng};
use systems::eval::road_metrics::RoadRunMetrics;
use systems::localization::road_wiring::{RoadLocalization, RoadLocalizerSlot};
use systems::localization::{RoadGrid, RoadLocalizer, RoadMcl};
use systems::navigation::Behaviour;
use systems::navigation::road_drive::{RoadNavParams, RoadNavigator};
use systems::navigation::road_recognition::{RecognitionConfig, RoadDetector};
use systems::sensors::{Camera, CameraImages, Compass, CompassReadings, Gps, GpsReadings};
use systems::world::Zones;
use systems::world::roads::{GeoFrame, RoadMap, RoadSurface, SurfaceRaster};

/// Cell size of the road surface the cameras render (m).
const SURFACE_RESOLUTION: f64 = 0.05;

/// Road network, geographic frame, road surface (when a robot has a camera, through `cache`)
/// and zones.
pub fn insert_outdoor_world(world: &mut World, scenario: &Scenario, cache: &MapCache) {
    if let Some(r) = &scenario.roads {
        world.insert_resource(RoadMap(r.graph.clone()));
        world.insert_resource(GeoFrame(r.graph.projection));
        if scenario.robots.iter().any(|r| r.camera.is_some()) {
            let raster = SurfaceRaster::build_cached(&r.graph, SURFACE_RESOLUTION, r.margin, cache);
            world.insert_resource(RoadSurface(Arc::new(raster)));
        }
    }
    if !scenario.zones.is_empty() {
        world.insert_resource(Zones {
            zones: scenario.zones.clone(),
        });
    }
}

/// A robot's GPS, compass and camera, and its road navigation when it has a route.
pub fn insert_outdoor_parts(world: &mut World, seed: u64, id: Entity, r: &RobotConfig) {
    let mut e = world.entity_mut(id);
    if let Some(spec) = &r.gps {
        e.insert((
            Gps::new(spec.clone(), stream_rng(seed, &r.name, "gps")),
            GpsReadings::default(),
        ));
    }
    if let Some(spec) = &r.compass {
        e.insert((
            Compass::new(spec.clone(), stream_rng(seed, &r.name, "compass")),
            CompassReadings::default(),
        ));
    }
    if let Some(spec) = &r.camera {
        e.insert((
            Camera::new(spec.clone(), stream_rng(seed, &r.name, "camera")),
            CameraImages::default(),
            RoadDetector::new(RecognitionConfig::default()),
        ));
    }
    let (Some(route), Some(enc)) = (&r.route, &r.encoder) else {
        return;
    };
    // the distance per tick odometry assumes: the calibrated wheel radius
    let radius = match &r.kinematics {
        Kinematics::Ackermann(a) => a.wheel_radius,
        Kinematics::DiffDrive(d) => d.wheel_radius,
    } * (1.0 + enc.left_radius_error);
    let metres_per_tick = std::f64::consts::TAU * radius / enc.ticks_per_rev as f64;
    let slots = RoadLocalizerKind::ALL
        .iter()
        .map(|k| {
            let filter: Box<dyn RoadLocalizer + Send + Sync> = match k {
                RoadLocalizerKind::Grid => Box::new(RoadGrid::default()),
                RoadLocalizerKind::Mcl => Box::new(RoadMcl::default()),
            };
            RoadLocalizerSlot {
                name: k.as_str(),
                filter,
                rng: stream_rng(seed, &r.name, &format!("localizer/{}", k.as_str())),
                estimate: None,
                odometer_at: 0.0,
                updated: false,
                contradicted: 0.0,
                resets: 0,
            }
        })
        .collect();
    let nav = RoadLocalizerKind::ALL
        .iter()
        .position(|k| *k == route.navigate_by)
        .unwrap_or(0);
    let params = RoadNavParams {
        speed: route.speed,
        tolerance: route.tolerance,
        ..RoadNavParams::default()
    };
    e.remove::<Behaviour>();
    e.insert((
        RoadLocalization::new(slots, nav, metres_per_tick),
        RoadNavigator::new(route.goal, params),
        RoadRunMetrics::default(),
    ));
}
