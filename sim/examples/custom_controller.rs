//! A controller written by the user: a left-hand wall follower that drives the bundled maze
//! (`maze_run`) from its entrance to the room in its middle, seeing nothing but its laser scan.
//!
//! ```text
//! cargo run --release -p sim --example custom_controller [TIME_LIMIT_S]
//! ```
//!
//! The controller keeps the nearest obstacle on its left at half a corridor's width, at right
//! angles to its heading: along a straight wall it drives parallel to it, at an opening it
//! circles the wall's end into the new corridor, and a wall ahead becomes the wall to follow.
//! Keeping to the left wall is enough here because the maze's left-hand walls lead to the room.
//! The program, not the controller, uses the true pose to see when the robot is in the room.

use sim::prelude::*;
use std::f64::consts::FRAC_PI_2;

/// The maze's room (x and y from 6.25 to 12.25 m), less a margin so the robot is well inside.
const ROOM: [f64; 4] = [6.75, 6.75, 11.75, 11.75];

/// Beams from this angle (rad, sensor frame) leftwards find the wall to follow; those ahead
/// only slow the robot down and turn it away.
const LEFT_FROM: f64 = 0.35;

/// Follows the wall on its left at `distance` metres, reading only the laser scan.
struct WallFollower {
    /// Wanted distance to the wall (m): half the maze's 1.85 m corridors.
    distance: f64,
    /// Top forward speed (m/s).
    speed: f64,
    /// How far ahead the path must be clear for full speed (m).
    clear_ahead: f64,
    /// Half the robot's width plus a margin: beams closer than this to the robot's axis are in
    /// its way (m).
    half_width: f64,
}

impl WallFollower {
    fn new() -> Self {
        WallFollower {
            distance: 0.9,
            speed: 0.8,
            clear_ahead: 1.0,
            half_width: 0.35,
        }
    }
}

impl Controller for WallFollower {
    fn control(&mut self, obs: &Observation) -> Twist {
        // Before the laser's first scan: wait.
        let Some(scan) = obs.robot.scan() else {
            return Twist::default();
        };
        // The nearest return on the left (sensor frame: angle 0 is forward, positive to the
        // left), and the free distance straight ahead within the robot's width.
        let mut nearest = (f64::INFINITY, 0.0);
        let mut ahead = f64::INFINITY;
        for (a, &r) in scan.angles().zip(scan.ranges()) {
            if !r.is_finite() {
                continue; // no return
            }
            let (a, r) = (a as f64, r as f64);
            if a > LEFT_FROM && r < nearest.0 {
                nearest = (r, a);
            }
            let (x, y) = (r * a.cos(), r * a.sin());
            if x > 0.0 && y.abs() < self.half_width {
                ahead = ahead.min(x);
            }
        }
        let (d, bearing) = nearest;
        // Turn so the nearest point on the left comes abeam (+90°) and `distance` away: a
        // point ahead of abeam turns the robot right, one behind it (a wall's end) turns it
        // left, round the end. Nothing on the left at all: turn left to find a wall.
        let (mut w, heading_error) = if d.is_finite() {
            let heading_error = bearing - FRAC_PI_2;
            let distance_error = (d - self.distance).clamp(-0.5, 0.5);
            (3.0 * heading_error + 2.0 * distance_error, heading_error)
        } else {
            (1.0, 1.0)
        };
        // A wall ahead turns the robot right, harder the closer it is.
        w -= 2.5 * (self.clear_ahead - ahead).max(0.0);
        let w = w.clamp(-2.0, 2.0);
        // Slow down for a wall ahead and while the wall is not abeam (rounding a corner, so the
        // turn is tight); turn in place when close.
        let room = ((ahead - 0.45) / (self.clear_ahead - 0.45)).clamp(0.0, 1.0);
        let v = self.speed * room * (1.0 - 2.0 * heading_error.abs()).max(0.1);
        Twist { v, w }
    }
}

/// What a run through the maze did.
#[derive(Debug)]
struct Report {
    /// Whether the robot got into the room before the time limit.
    reached: bool,
    /// Simulated time taken (s).
    time_s: f64,
    /// Distance driven (m).
    path_m: f64,
    collisions: Collisions,
}

/// Drives the maze's robot `scout` with the wall follower from the maze's entrance until it is
/// in the room or `limit_s` simulated seconds have passed.
fn run(limit_s: f64) -> anyhow::Result<Report> {
    // The wall follower replaces the scenario's own driver (its waypoint route).
    let mut sim = Simulation::load("maze_run")
        .duration(limit_s)
        .controller("scout", WallFollower::new())
        .build()?;
    // The program judges arrival with the true pose; the controller never sees it.
    let in_room = |s: &Simulation| {
        s.robot("scout").is_ok_and(|r| {
            let p = r.pose();
            p.x > ROOM[0] && p.y > ROOM[1] && p.x < ROOM[2] && p.y < ROOM[3]
        })
    };
    let reached = sim.run_until(in_room, limit_s)?;
    let scout = sim.robot("scout")?;
    Ok(Report {
        reached,
        time_s: sim.time(),
        path_m: scout.distance(),
        collisions: scout.collisions(),
    })
}

fn main() -> anyhow::Result<()> {
    // optional argument: the time limit in simulated seconds
    let limit_s = match std::env::args().nth(1) {
        Some(a) => a.parse()?,
        None => 300.0,
    };
    let report = run(limit_s)?;
    println!(
        "reached the room: {}\ntime: {:.1} s\npath length: {:.1} m\ncollisions: {} (walls {}, robots {}, people {})",
        report.reached,
        report.time_s,
        report.path_m,
        report.collisions.total(),
        report.collisions.wall,
        report.collisions.robot,
        report.collisions.person,
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_wall_follower_reaches_the_room_without_collisions() {
        let report = run(300.0).unwrap();
        assert!(report.reached, "{report:?}");
        assert_eq!(report.collisions.total(), 0, "{report:?}");
        // the bundled route to the room's door is about 60 m; the left wall adds a dead end
        assert!((55.0..90.0).contains(&report.path_m), "{report:?}");
    }
}
