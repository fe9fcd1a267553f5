//! Laser scan → Cartesian points in the sensor frame ([Hospital thesis §5.2, eq. 28]):
//! `(x, y) = (r(Φ) cos Φ, r(Φ) sin Φ)` with `Φ = angle_min + k · angle_increment` (ROS
//! `sensor_msgs/LaserScan` convention). Readings that are not finite (+Inf = no return, −Inf =
//! below the minimum range, NaN = invalid, REP 117) or outside `[range_min, range_max]` are
//! dropped; the kept points stay in beam order, which the improved matcher's normal estimation
//! relies on.

use crate::sensors::LaserScan;

/// Appends the Cartesian end points of the valid readings of a scan to `out` (beam order).
pub fn scan_to_points_into(
    angle_min: f32,
    angle_increment: f32,
    ranges: &[f32],
    range_min: f32,
    range_max: f32,
    out: &mut Vec<[f32; 2]>,
) {
    out.reserve(ranges.len());
    for (k, &r) in ranges.iter().enumerate() {
        // NaN fails both comparisons, ±Inf fails is_finite.
        if !(r.is_finite() && r >= range_min && r <= range_max) {
            continue;
        }
        // The angle in f64: k · increment summed in f32 loses ~1e-7 rad at k = 1080.
        let a = angle_min as f64 + k as f64 * angle_increment as f64;
        let (s, c) = a.sin_cos();
        out.push([(r as f64 * c) as f32, (r as f64 * s) as f32]);
    }
}

/// The Cartesian end points of the valid readings of a scan (beam order), eq. 28.
pub fn scan_to_points(
    angle_min: f32,
    angle_increment: f32,
    ranges: &[f32],
    range_min: f32,
    range_max: f32,
) -> Vec<[f32; 2]> {
    let mut out = Vec::new();
    scan_to_points_into(
        angle_min,
        angle_increment,
        ranges,
        range_min,
        range_max,
        &mut out,
    );
    out
}

/// The points of a [`LaserScan`] (its own range limits apply).
pub fn laser_scan_points(scan: &LaserScan) -> Vec<[f32; 2]> {
    scan_to_points(
        scan.angle_min,
        scan.angle_increment,
        &scan.ranges,
        scan.range_min,
        scan.range_max,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn drops_invalid_readings_and_keeps_beam_order() {
        let inc = std::f32::consts::FRAC_PI_2;
        let ranges = [
            1.0,
            f32::INFINITY,
            2.0,
            f32::NAN,
            f32::NEG_INFINITY,
            0.1,
            30.0,
        ];
        let pts = scan_to_points(-std::f32::consts::FRAC_PI_2, inc, &ranges, 0.5, 20.0);
        assert_eq!(pts.len(), 2);
        // beam 0 at −90°: (0, −1); beam 2 at +90°: (0, 2)
        assert!(pts[0][0].abs() < 1e-6 && (pts[0][1] + 1.0).abs() < 1e-6);
        assert!(pts[1][0].abs() < 1e-6 && (pts[1][1] - 2.0).abs() < 1e-6);
    }

    #[test]
    fn laser_scan_uses_its_limits() {
        let scan = LaserScan {
            stamp: 0.0,
            angle_min: 0.0,
            angle_increment: 0.1,
            range_min: 0.5,
            range_max: 3.0,
            ranges: vec![0.4, 1.0, 3.5],
        };
        let pts = laser_scan_points(&scan);
        assert_eq!(pts.len(), 1);
        assert!((pts[0][0] - 0.1f32.cos()).abs() < 1e-6);
    }
}
