//! Latitude/longitude and local metres. The park is a few hundred metres across, so a local
//! tangent plane around a reference point is exact enough: the equirectangular projection
//! x = R·cos φ₀·(λ − λ₀), y = R·(φ − φ₀) (x east, y north, the simulator's world frame). Over
//! 500 m its distances differ from the haversine distance by under 0.01 % (about 2 cm), less
//! than any GPS error. R = 6 378.135 km, the radius of the haversine in [Park thesis §5.3.1].

/// Earth radius of the thesis's haversine (m).
pub const EARTH_RADIUS_M: f64 = 6_378_135.0;

/// A point on the sphere, in degrees (WGS 84 latitude and longitude, as in NavSatFix).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GeoPoint {
    pub lat: f64,
    pub lon: f64,
}

impl GeoPoint {
    pub fn new(lat: f64, lon: f64) -> Self {
        GeoPoint { lat, lon }
    }

    /// Whether the coordinates are finite and in range (|lat| ≤ 90°, |lon| ≤ 180°).
    pub fn is_valid(&self) -> bool {
        self.lat.is_finite()
            && self.lon.is_finite()
            && self.lat.abs() <= 90.0
            && self.lon.abs() <= 180.0
    }
}

/// Great-circle distance (m) by the haversine formula on a sphere of radius
/// [`EARTH_RADIUS_M`].
pub fn haversine(a: GeoPoint, b: GeoPoint) -> f64 {
    let (p1, p2) = (a.lat.to_radians(), b.lat.to_radians());
    let dp = p2 - p1;
    let dl = (b.lon - a.lon).to_radians();
    let h = (dp / 2.0).sin().powi(2) + p1.cos() * p2.cos() * (dl / 2.0).sin().powi(2);
    2.0 * EARTH_RADIUS_M * h.sqrt().min(1.0).asin()
}

/// The local tangent plane around a reference point: metres east (x) and north (y).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LocalProjection {
    pub reference: GeoPoint,
    cos_lat0: f64,
}

impl LocalProjection {
    /// `reference` must be valid and not at a pole (|lat| < 89°).
    pub fn new(reference: GeoPoint) -> Option<Self> {
        (reference.is_valid() && reference.lat.abs() < 89.0).then(|| LocalProjection {
            reference,
            cos_lat0: reference.lat.to_radians().cos(),
        })
    }

    /// Metres east and north of the reference point.
    pub fn to_local(&self, p: GeoPoint) -> [f64; 2] {
        let mut dl = p.lon - self.reference.lon;
        // the short way round the antimeridian
        if dl > 180.0 {
            dl -= 360.0;
        } else if dl < -180.0 {
            dl += 360.0;
        }
        [
            EARTH_RADIUS_M * self.cos_lat0 * dl.to_radians(),
            EARTH_RADIUS_M * (p.lat - self.reference.lat).to_radians(),
        ]
    }

    /// The inverse of [`Self::to_local`].
    pub fn to_geo(&self, xy: [f64; 2]) -> GeoPoint {
        let lat = self.reference.lat + (xy[1] / EARTH_RADIUS_M).to_degrees();
        let mut lon = self.reference.lon + (xy[0] / (EARTH_RADIUS_M * self.cos_lat0)).to_degrees();
        if lon > 180.0 {
            lon -= 360.0;
        } else if lon < -180.0 {
            lon += 360.0;
        }
        GeoPoint { lat, lon }
    }
}

/// Compass azimuth (radians, clockwise from north, in [0, 2π)) of a direction in the world
/// frame (x east, y north).
pub fn azimuth_of(d: [f64; 2]) -> f64 {
    d[0].atan2(d[1]).rem_euclid(std::f64::consts::TAU)
}

/// World-frame heading (radians, counter-clockwise from east) of a compass azimuth.
pub fn heading_of_azimuth(azimuth: f64) -> f64 {
    crate::core::wrap_angle(std::f64::consts::FRAC_PI_2 - azimuth)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn haversine_known_distances() {
        // one degree of latitude on the thesis's sphere
        let d = haversine(GeoPoint::new(50.0, 14.0), GeoPoint::new(51.0, 14.0));
        assert!((d - EARTH_RADIUS_M * 1f64.to_radians()).abs() < 1e-6);
        assert_eq!(
            haversine(GeoPoint::new(50.0, 14.0), GeoPoint::new(50.0, 14.0)),
            0.0
        );
        // antipodes: half the circumference
        let d = haversine(GeoPoint::new(0.0, 0.0), GeoPoint::new(0.0, 180.0));
        assert!((d - EARTH_RADIUS_M * std::f64::consts::PI).abs() < 1e-3);
    }

    #[test]
    fn the_projection_round_trips_and_agrees_with_haversine_over_a_park() {
        let reference = GeoPoint::new(50.0645, 14.418);
        let proj = LocalProjection::new(reference).unwrap();
        for (x, y) in [
            (0.0, 0.0),
            (300.0, 0.0),
            (0.0, -250.0),
            (-350.0, 420.0),
            (123.4, 56.7),
        ] {
            let g = proj.to_geo([x, y]);
            let back = proj.to_local(g);
            assert!((back[0] - x).abs() < 1e-6 && (back[1] - y).abs() < 1e-6);
            let planar = (x * x + y * y).sqrt();
            let sphere = haversine(reference, g);
            assert!(
                (planar - sphere).abs() <= 1e-4 * planar.max(1.0),
                "({x}, {y}): plane {planar} m, sphere {sphere} m"
            );
        }
        assert!(LocalProjection::new(GeoPoint::new(90.0, 0.0)).is_none());
        assert!(LocalProjection::new(GeoPoint::new(f64::NAN, 0.0)).is_none());
    }

    #[test]
    fn azimuths_are_compass_angles() {
        let deg = |d: [f64; 2]| azimuth_of(d).to_degrees();
        assert!((deg([0.0, 1.0]) - 0.0).abs() < 1e-9); // north
        assert!((deg([1.0, 0.0]) - 90.0).abs() < 1e-9); // east
        assert!((deg([0.0, -1.0]) - 180.0).abs() < 1e-9); // south
        assert!((deg([-1.0, 0.0]) - 270.0).abs() < 1e-9); // west
        assert!((heading_of_azimuth(90f64.to_radians())).abs() < 1e-12); // east = heading 0
        assert!((heading_of_azimuth(0.0) - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
    }
}
