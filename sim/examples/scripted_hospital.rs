//! A scripted hospital: the bundled delivery scenario (four robots with MCL, each with a queue of
//! deliveries) driven by a program that watches the robots between ticks and reacts:
//!
//! - when r1 reaches the pharmacy, the west fire door closes and r2 is also sent to ward 3;
//! - once r3's MCL has converged, r3 is kidnapped to the north corridor (will MCL find it?);
//! - the run stops when every robot has done its tasks.
//!
//! `cargo run --release -p sim --example scripted_hospital [MAX_SECONDS]`

use sim::prelude::*;

/// What happened, and when (simulated seconds).
#[derive(Debug, Default)]
struct Report {
    /// r1 reached the pharmacy: the door closed and r2 got its extra trip.
    door_closed_at: Option<f64>,
    /// r3 was kidnapped.
    kidnapped_at: Option<f64>,
    /// r3's MCL error (m) at the end of the run.
    r3_error_m: Option<f64>,
    /// Every robot did all its tasks.
    all_done: bool,
    seconds: f64,
    /// The scenario's events as they fired.
    log: Vec<(f64, String, String)>,
}

fn run(max_seconds: f64) -> anyhow::Result<Report> {
    let mut s = Simulation::load("hospital_delivery")
        .duration(max_seconds)
        .build()?;
    let pharmacy = s.scenario().places["pharmacy"];
    let mut report = Report::default();
    while !s.is_over() {
        // look at the world every half second of simulated time
        s.run_for(0.5)?;
        let now = s.time();
        if report.door_closed_at.is_none() && s.robot("r1")?.pose().distance(&pharmacy) < 1.0 {
            s.set_door("fire_door_w", false)?;
            s.command("r2", Command::GoTo(Target::Place("ward_3".into())))?;
            report.door_closed_at = Some(now);
        }
        let mcl_converged = s.robot("r3")?.localizer("mcl")?.converged_after.is_some();
        if report.kidnapped_at.is_none() && mcl_converged {
            let to = s.scenario().places["corridor_north_w"];
            s.command("r3", Command::Teleport(to))?;
            report.kidnapped_at = Some(now);
        }
        let done = s
            .robots()
            .iter()
            .all(|r| r.navigation().is_none_or(|n| n.finished()));
        if done {
            report.all_done = true;
            break;
        }
    }
    let r3 = s.robot("r3")?;
    report.r3_error_m = r3
        .localizer("mcl")?
        .estimate
        .map(|e| e.pose.distance(&r3.pose()));
    report.seconds = s.time();
    report.log = s.finish()?.log;
    Ok(report)
}

fn main() -> anyhow::Result<()> {
    let max_seconds = match std::env::args().nth(1) {
        Some(a) => a.parse()?,
        None => 900.0,
    };
    let r = run(max_seconds)?;
    for (t, robot, what) in &r.log {
        println!("{t:7.2} s  {robot:3} {what}");
    }
    println!(
        "door closed at {:?} s, r3 kidnapped at {:?} s, r3's MCL error at the end {:?} m",
        r.door_closed_at, r.kidnapped_at, r.r3_error_m
    );
    println!(
        "{} after {:.1} s",
        if r.all_done {
            "every delivery done"
        } else {
            "stopped before every delivery was done"
        },
        r.seconds
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_script_reacts_to_the_robots() {
        let r = run(60.0).unwrap();
        let door = r
            .door_closed_at
            .expect("r1 reached the pharmacy within a minute");
        let fired = |who: &str, what: &str| {
            r.log
                .iter()
                .any(|(t, robot, w)| robot == who && w.starts_with(what) && *t >= door)
        };
        assert!(fired("", "door fire_door_w closed"), "{:?}", r.log);
        assert!(fired("r2", "new tasks: go_ward_3"), "{:?}", r.log);
        let kidnapped = r.kidnapped_at.expect("r3's MCL converged");
        // convergence is known once the tracking has held for 5 s
        assert!(kidnapped >= 5.0, "{kidnapped}");
        assert!(
            r.log.iter().any(|(t, robot, w)| robot == "r3"
                && w.starts_with("teleported")
                && *t >= kidnapped),
            "{:?}",
            r.log
        );
    }
}
