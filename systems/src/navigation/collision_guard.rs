//! A collision guard for laser-driven behaviours: how far a robot's disc can move on the arc it
//! drives before it touches a point the laser sees ([`arc_contact`], exact, per point), and the
//! speed from which it can still stop short of that ([`guarded_speed`]).

use super::avoid::SectorRanges;

/// How far (m, along the path) the robot's disc of radius `radius` can move forward on an
/// arc of curvature `curvature` (1/m, positive to the left; 0 straight) before it touches a
/// seen point; at most `reach`. Points already inside the disc that the motion leaves behind
/// do not stop it (a robot grazing a wall may still drive away from it).
pub fn free_arc(s: &SectorRanges, curvature: f64, radius: f64, reach: f64) -> f64 {
    s.points()
        .filter_map(|(x, y)| arc_contact(x as f64, y as f64, curvature, radius))
        .fold(reach, f64::min)
        .max(0.0)
}

/// The path length at which a disc of radius `r`, starting at the origin heading +x and moving
/// forward on an arc of curvature `k`, first touches the point (`x`, `y`); None if it never
/// does within one turn, or if the point is inside the disc already and the motion takes the
/// disc away from it.
pub fn arc_contact(x: f64, y: f64, k: f64, r: f64) -> Option<f64> {
    let inside = x * x + y * y <= r * r;
    if k.abs() < 1e-9 {
        // straight ahead: the centre passes at |y| from the point
        if y.abs() >= r {
            return None;
        }
        let s = x - (r * r - y * y).sqrt();
        return if inside {
            (x > 0.0).then_some(0.0)
        } else {
            (s >= 0.0).then_some(s)
        };
    }
    // the centre turns about c = (0, 1/k) on a circle of radius R; it starts at angle φ0 and
    // turns by +Δ (left) or −Δ (right). Contact while the angle to the point is within ±α.
    let big_r = 1.0 / k.abs();
    let cy = 1.0 / k;
    let (px, py) = (x, y - cy);
    let rho = px.hypot(py);
    let cos_alpha = (big_r * big_r + rho * rho - r * r) / (2.0 * big_r * rho.max(1e-12));
    if cos_alpha >= 1.0 {
        return None;
    }
    let alpha = cos_alpha.max(-1.0).acos();
    let psi = py.atan2(px);
    let phi0 = (-cy).atan2(0.0);
    let turn = k.signum();
    // the angle still to turn (in the direction of motion) from φ0 to ψ
    let tau = std::f64::consts::TAU;
    let ahead = (turn * (psi - phi0)).rem_euclid(tau);
    if inside {
        // approaching if the point lies ahead within a half turn
        return (ahead > 0.0 && ahead < std::f64::consts::PI).then_some(0.0);
    }
    // the contact interval starts α before ψ
    let delta = (ahead - alpha).rem_euclid(tau);
    Some(big_r * delta)
}

/// What the collision guard adds to the footprint's radius (m): small, so that a robot driving
/// along a wall inside the heading band is not taken for one touching it.
pub const CONTACT_MARGIN: f64 = 0.01;
/// The collision guard's braking (m/s², well inside what the wheels can do), reaction time (s,
/// about two ticks and a scan) and the gap it keeps (m).
const GUARD_DECEL: f64 = 1.0;
const GUARD_REACTION: f64 = 0.1;
const GUARD_GAP: f64 = 0.05;

/// The forward speed, at most `v`, from which the robot can still stop short of every seen
/// point on the arc it drives (yaw rate `w` kept): v·t + v²/2a ≤ free arc − gap, as a collision
/// monitor's "approach" action does [Nav2 collision monitor]. Lowering v tightens the arc, which
/// is checked again (a few rounds; every round can only lower v). A disc turning in place
/// sweeps nothing new, so a stopped robot may always turn.
pub fn guarded_speed(s: &SectorRanges, v: f64, w: f64, radius: f64) -> f64 {
    let (a, t) = (GUARD_DECEL, GUARD_REACTION);
    // nothing within stopping distance of the disc in any direction: nothing to check
    let reach = radius + GUARD_GAP + v * t + v * v / (2.0 * a);
    if s.nearest_squared() >= (reach * reach) as f32 {
        return v;
    }
    let mut v = v;
    for _ in 0..4 {
        if v <= 1e-6 {
            return 0.0;
        }
        let free = (free_arc(s, w / v, radius, 5.0) - GUARD_GAP).max(0.0);
        let allowed = (-a * t + ((a * t).powi(2) + 2.0 * a * free).sqrt()).max(0.0);
        if allowed >= v {
            return v;
        }
        v = allowed;
    }
    v
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::core::Pose2;

    /// The plain version of [`arc_contact`]: step the disc along the arc 1 mm at a time.
    fn arc_contact_stepped(x: f64, y: f64, k: f64, r: f64, reach: f64) -> Option<f64> {
        let d0 = x.hypot(y);
        let n = (reach / 0.001) as usize;
        for i in 0..=n {
            let s = i as f64 * 0.001;
            let (cx, cy) = if k.abs() < 1e-9 {
                (s, 0.0)
            } else {
                ((k * s).sin() / k, (1.0 - (k * s).cos()) / k)
            };
            let d = (x - cx).hypot(y - cy);
            if d0 > r && d <= r {
                return Some(s);
            }
            if d0 <= r && i == 1 {
                // inside at the start: contact now only when the first step comes closer
                return (d < d0).then_some(0.0);
            }
        }
        None
    }

    #[test]
    fn arc_contact_agrees_with_stepping_the_disc() {
        use rand::{RngExt, SeedableRng};
        let mut rng = crate::core::SimRng::seed_from_u64(7);
        let mut checked = 0;
        for _ in 0..3000 {
            let (x, y) = (rng.random_range(-3.0..3.0), rng.random_range(-3.0..3.0));
            let k = match rng.random_range(0..4) {
                0 => 0.0,
                _ => rng.random_range(-4.0..4.0),
            };
            let r = 0.35;
            let want = arc_contact_stepped(x, y, k, r, 6.0);
            let got = arc_contact(x, y, k, r).filter(|&s| s <= 6.0);
            match (want, got) {
                (Some(a), Some(b)) => assert!((a - b).abs() < 0.003, "{x} {y} {k}: {a} {b}"),
                (None, None) => {}
                // within a step of the reach, or grazing the disc's edge
                (a, b) => {
                    let edge = arc_contact(x, y, k, r + 0.002) != arc_contact(x, y, k, r - 0.002);
                    assert!(
                        edge || a.or(b).is_some_and(|s| s > 5.99),
                        "{x} {y} {k}: {a:?} {b:?}"
                    );
                }
            }
            checked += 1;
        }
        assert_eq!(checked, 3000);
        // by hand: a wall point 1 m ahead stops a 0.35 m disc after 0.65 m; a point behind
        // never; a point inside the disc stops it only if it lies ahead
        assert!((arc_contact(1.0, 0.0, 0.0, 0.35).unwrap() - 0.65).abs() < 1e-12);
        assert_eq!(arc_contact(-1.0, 0.0, 0.0, 0.35), None);
        assert_eq!(arc_contact(0.2, 0.1, 0.0, 0.35), Some(0.0));
        assert_eq!(arc_contact(-0.2, 0.1, 0.0, 0.35), None);
        // turning left on a 1 m circle meets a point on that circle a quarter turn ahead
        // (at (1, 1)) when the disc's edge reaches it: R (π/2 − 2 asin(0.35 / 2))
        let want = std::f64::consts::FRAC_PI_2 - 2.0 * (0.175f64).asin();
        assert!((arc_contact(1.0, 1.0, 1.0, 0.35).unwrap() - want).abs() < 1e-9);
    }

    /// What a 360° laser at the centre sees of a wall across the front at x = `dist`.
    fn facing_wall(dist: f32) -> SectorRanges {
        let mut s = SectorRanges::default();
        s.update(
            &crate::navigation::avoid::tests::wall_scan(dist),
            &Pose2::IDENTITY,
        );
        s
    }

    #[test]
    fn the_guard_stops_short_of_a_wall_and_leaves_free_driving_and_turning_alone() {
        let (a, t) = (GUARD_DECEL, GUARD_REACTION);
        let stop = |v: f64| v * t + v * v / (2.0 * a);
        // far from the wall: the speed asked for
        assert_eq!(guarded_speed(&facing_wall(5.0), 0.8, 0.0, 0.31), 0.8);
        // 0.6 m ahead of a 0.31 m disc: the room, less the gap, bounds the stopping distance;
        // the speed given stops exactly there
        let v = guarded_speed(&facing_wall(0.6), 0.8, 0.0, 0.31);
        assert!(v < 0.8, "{v}");
        assert!((stop(v) - (0.6 - 0.31 - GUARD_GAP)).abs() < 1e-3, "{v}");
        // touching it: no forward speed, but turning away is the caller's to do
        assert_eq!(guarded_speed(&facing_wall(0.31), 0.5, 1.0, 0.31), 0.0);
        // turning hard away from the wall just ahead: the arc leaves it, so more speed than
        // straight at it
        let straight = guarded_speed(&facing_wall(0.6), 0.8, 0.0, 0.31);
        let turning = guarded_speed(&facing_wall(0.6), 0.8, 1.5, 0.31);
        assert!(turning > straight, "{turning} {straight}");
    }
}
