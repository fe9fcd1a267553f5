//! The road localizers as an ECS system: each robot with a route runs the thesis's road-grid
//! localization and the road MCL side by side on the same readings (drive-shaft encoder
//! distance, GPS fixes projected to local metres, compass), so one run compares them; the
//! navigator drives by one of them. Both are updated every tick with the encoder distance since
//! the last tick and the compass, and with a GPS fix about once a second ([`GPS_PERIOD`]).

use super::road::{RoadLocalizer, RoadObservation, RoadPosition};
use crate::core::SimRng;
use crate::sensors::{CompassReadings, EncoderReadings, GpsReadings};
use crate::world::roads::RoadStart;
use crate::world::roads::{GeoFrame, RoadMap};
use bevy_ecs::prelude::*;

/// One road localizer of a robot.
pub struct RoadLocalizerSlot {
    pub name: &'static str,
    pub filter: Box<dyn RoadLocalizer + Send + Sync>,
    pub rng: SimRng,
    /// The latest estimate and the odometer reading it belongs to.
    pub estimate: Option<RoadPosition>,
    pub odometer_at: f64,
    /// True on the ticks a GPS fix was fed (the filter's full iterations).
    pub updated: bool,
    /// Driven (m, encoder) since the estimate's direction began to contradict the compass.
    pub contradicted: f64,
    /// Times the localizer was reset because its direction contradicted the compass.
    pub resets: u32,
}

/// An estimate whose direction is this far (rad) from the compass…
const CONTRADICTION: f64 = 1.8;
/// …over this distance driven (m) is dropped: the robot turned round (at a dead end), which
/// the road localizers, whose robot never reverses its direction of travel, cannot follow.
const CONTRADICTION_DISTANCE: f64 = 3.0;

#[derive(Component)]
pub struct RoadLocalization {
    pub slots: Vec<RoadLocalizerSlot>,
    /// The slot the navigator drives by.
    pub nav: usize,
    /// Metres per encoder tick (the calibration odometry assumes).
    pub metres_per_tick: f64,
    /// Distance driven (m) by the encoder.
    pub odometer: f64,
    /// Odometer at the previous filter update.
    last_update: f64,
    last_ticks: Option<i64>,
    /// Stamp of the last fix fed to the localizers.
    last_fix: f64,
    /// Latest compass azimuth.
    pub compass: Option<f64>,
    /// The GPS fixes of this tick in local metres (for recording).
    pub fixes: Vec<(f64, [f64; 2])>,
}

impl RoadLocalization {
    pub fn new(slots: Vec<RoadLocalizerSlot>, nav: usize, metres_per_tick: f64) -> Self {
        RoadLocalization {
            slots,
            nav,
            metres_per_tick,
            odometer: 0.0,
            last_update: 0.0,
            last_ticks: None,
            last_fix: f64::NEG_INFINITY,
            compass: None,
            fixes: Vec::new(),
        }
    }

    /// The navigating localizer's belief carried forward by the encoder to now; `None` until it
    /// has accepted a hypothesis. Past the end of its edge the belief waits at the node (the
    /// next update tells which edge the robot took).
    pub fn belief(&self) -> Option<RoadStart> {
        let slot = self.slots.get(self.nav)?;
        let e = slot.estimate?;
        let moved = self.odometer - slot.odometer_at;
        Some(RoadStart {
            edge: e.edge,
            toward: e.toward,
            remaining: (e.remaining - moved).max(0.0),
        })
    }
}

/// Fixes fed to the localizers at most this often (s): the grid blurs its probabilities at every
/// iteration and successive fixes share the receiver's slow bias, so the thesis's ~1 Hz is used
/// whatever the receiver's rate.
pub const GPS_PERIOD: f64 = 0.95;

/// Estimate: feed encoder distance, GPS and compass to every road localizer.
pub fn run_road_localizers(
    roads: Option<Res<RoadMap>>,
    frame: Option<Res<GeoFrame>>,
    mut robots: Query<(
        &EncoderReadings,
        Option<&GpsReadings>,
        Option<&CompassReadings>,
        &mut RoadLocalization,
    )>,
) {
    let (Some(roads), Some(frame)) = (roads, frame) else {
        return;
    };
    let graph = &*roads.0;
    for (enc, gps, compass, mut loc) in robots.iter_mut() {
        let loc = &mut *loc;
        for r in &enc.readings {
            if let Some(prev) = loc.last_ticks {
                loc.odometer += r.left_ticks.wrapping_sub(prev) as f64 * loc.metres_per_tick;
            }
            loc.last_ticks = Some(r.left_ticks);
        }
        if let Some(c) = compass.and_then(|c| c.readings.last()) {
            loc.compass = Some(c.azimuth);
        }
        loc.fixes.clear();
        let mut fed = None;
        for fix in gps.map_or(&[][..], |g| &g.fixes[..]) {
            let xy = frame.0.to_local(fix.position);
            loc.fixes.push((fix.stamp, xy));
            if fix.stamp >= loc.last_fix + GPS_PERIOD {
                loc.last_fix = fix.stamp;
                fed = Some(xy);
            }
        }
        let obs = RoadObservation {
            distance: loc.odometer - loc.last_update,
            gps: fed,
            compass: loc.compass,
        };
        loc.last_update = loc.odometer;
        for s in &mut loc.slots {
            s.filter.update(graph, &obs, &mut s.rng);
            s.estimate = s.filter.estimate();
            match (s.estimate, loc.compass) {
                (Some(e), Some(c))
                    if crate::core::wrap_angle(e.azimuth - c).abs() > CONTRADICTION =>
                {
                    s.contradicted += obs.distance.abs();
                    if s.contradicted > CONTRADICTION_DISTANCE {
                        s.filter.reset();
                        s.estimate = None;
                        s.contradicted = 0.0;
                        s.resets += 1;
                    }
                }
                _ => s.contradicted = 0.0,
            }
            s.odometer_at = loc.odometer;
            s.updated = fed.is_some();
        }
    }
}
