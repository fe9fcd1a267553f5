//! 2-D rigid poses in SI units, REP 103: x forward, y left, yaw counter-clockwise from +x,
//! angles wrapped to (-π, π].

use std::f64::consts::PI;

/// Wraps an angle to (-π, π].
pub fn wrap_angle(a: f64) -> f64 {
    let mut r = a % (2.0 * PI);
    if r <= -PI {
        r += 2.0 * PI;
    } else if r > PI {
        r -= 2.0 * PI;
    }
    r
}

/// A pose on the plane (metres, radians).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Pose2 {
    pub x: f64,
    pub y: f64,
    pub theta: f64,
}

impl Pose2 {
    pub const IDENTITY: Pose2 = Pose2 {
        x: 0.0,
        y: 0.0,
        theta: 0.0,
    };

    pub fn new(x: f64, y: f64, theta: f64) -> Self {
        Pose2 {
            x,
            y,
            theta: wrap_angle(theta),
        }
    }

    /// `self ⊕ rel`: applies a pose expressed in this pose's frame.
    pub fn compose(&self, rel: &Pose2) -> Pose2 {
        let (s, c) = self.theta.sin_cos();
        Pose2::new(
            self.x + c * rel.x - s * rel.y,
            self.y + s * rel.x + c * rel.y,
            self.theta + rel.theta,
        )
    }

    /// The inverse transform.
    pub fn inverse(&self) -> Pose2 {
        let (s, c) = self.theta.sin_cos();
        Pose2::new(
            -c * self.x - s * self.y,
            s * self.x - c * self.y,
            -self.theta,
        )
    }

    /// `self⁻¹ ⊕ other`: `other` expressed in this pose's frame.
    pub fn between(&self, other: &Pose2) -> Pose2 {
        self.inverse().compose(other)
    }

    /// Transforms a point from this pose's frame to the parent frame.
    pub fn transform_point(&self, p: [f64; 2]) -> [f64; 2] {
        let (s, c) = self.theta.sin_cos();
        [self.x + c * p[0] - s * p[1], self.y + s * p[0] + c * p[1]]
    }

    pub fn distance(&self, other: &Pose2) -> f64 {
        (self.x - other.x).hypot(self.y - other.y)
    }

    /// Linear interpolation of position and shortest-arc interpolation of heading; `f` in [0, 1].
    pub fn lerp(&self, other: &Pose2, f: f64) -> Pose2 {
        Pose2::new(
            self.x + (other.x - self.x) * f,
            self.y + (other.y - self.y) * f,
            self.theta + wrap_angle(other.theta - self.theta) * f,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrap_is_half_open() {
        assert!((wrap_angle(PI) - PI).abs() < 1e-12);
        assert!((wrap_angle(-PI) - PI).abs() < 1e-12);
        assert!((wrap_angle(3.0 * PI / 2.0) + PI / 2.0).abs() < 1e-12);
        assert!((wrap_angle(-7.0) - (-7.0 + 2.0 * PI)).abs() < 1e-12);
    }

    #[test]
    fn compose_inverse_round_trip() {
        let a = Pose2::new(1.0, -2.0, 0.7);
        let b = Pose2::new(-0.3, 0.4, -2.9);
        let ab = a.compose(&b);
        let back = a.between(&ab);
        assert!((back.x - b.x).abs() < 1e-12 && (back.y - b.y).abs() < 1e-12);
        assert!(wrap_angle(back.theta - b.theta).abs() < 1e-12);
        let id = a.compose(&a.inverse());
        assert!(id.x.abs() < 1e-12 && id.y.abs() < 1e-12 && id.theta.abs() < 1e-12);
    }

    #[test]
    fn lerp_takes_the_short_way_round() {
        let a = Pose2::new(0.0, 0.0, 3.0);
        let b = Pose2::new(2.0, 0.0, -3.0);
        let m = a.lerp(&b, 0.5);
        assert!((m.x - 1.0).abs() < 1e-12);
        assert!(m.theta.abs() > 3.0);
    }
}
