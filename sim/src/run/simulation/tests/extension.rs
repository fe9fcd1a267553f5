//! A program's own systems, added to the schedule in the engine's sets, run in tick order.

use super::*;

/// Every robot's true pose, each tick, as a program's own Evaluate system saw it.
#[derive(Resource, Default)]
struct Watched(Vec<(u64, Entity, Pose2)>);

fn watch(
    clock: Res<systems::core::SimClock>,
    robots: Query<(Entity, &systems::body::TruePose), With<systems::core::RobotId>>,
    mut seen: ResMut<Watched>,
) {
    for (e, p) in &robots {
        seen.0.push((clock.tick, e, p.pose));
    }
}

/// A program's own Control system, ordered after held commands: r1 stands still.
fn hold_r1(mut robots: Query<(&systems::core::RobotId, &mut systems::body::DriveCommand)>) {
    for (name, mut cmd) in &mut robots {
        if name.0 == "r1" {
            *cmd = systems::body::DriveCommand::default();
        }
    }
}

#[test]
fn a_programs_own_systems_run_in_their_sets() {
    use systems::core::SimSet;
    let mut s = Simulation::load("hospital_patrol")
        .duration(2.0)
        .threads(2)
        .build()
        .unwrap();
    let start = s.robot("r1").unwrap().pose();
    let (world, schedule) = s.world_and_schedule();
    world.init_resource::<Watched>();
    schedule.add_systems((
        watch.in_set(SimSet::Evaluate),
        hold_r1
            .in_set(SimSet::Control)
            .after(systems::navigation::held::apply_held_commands),
    ));
    s.run_for(1.0).unwrap();
    let seen = &s.world().resource::<Watched>().0;
    // four robots, twenty ticks, in tick order
    assert_eq!(seen.len(), 4 * 20);
    assert!(seen.windows(2).all(|w| w[0].0 <= w[1].0));
    let r2 = s.robot("r2").unwrap();
    let last = seen
        .iter()
        .rev()
        .find(|(_, e, _)| *e == r2.entity())
        .unwrap();
    assert_eq!(last.2, r2.pose(), "Evaluate sees the tick's final poses");
    let r1 = s.robot("r1").unwrap().pose();
    assert!(
        r1.distance(&start) < 1e-6,
        "r1 held still: {r1:?} from {start:?}"
    );
    assert!(r2.distance() > 0.1, "r2 drove on");
}
