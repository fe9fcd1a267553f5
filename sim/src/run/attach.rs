//! A program's own parts joined to a built world before the first tick: its estimators (a
//! `ScanEstimator` or `MapLocalizer` in the robot's `Localizers`) and its controllers (in the
//! Control set, in place of the robot's behaviour or navigator).

use super::command::{SimError, names};
use super::controller::{Controlled, Controller, UserControllers, run_user_controllers};
use crate::build::SimWorld;
use crate::scenario::Scenario;
use bevy_ecs::prelude::*;
use systems::body::people::walk_people;
use systems::core::SimSet;
use systems::eval::{LocalizationSamples, NavOutcome};
use systems::localization::{Filter, LocalizationMap, Localizer, Localizers, WheelOdometry};
use systems::navigation::behaviour::drive_behaviours;
use systems::navigation::drive::drive_navigators;
use systems::navigation::held::apply_held_commands;
use systems::navigation::road_drive::RoadNavigator;
use systems::navigation::road_drive::system::drive_road_navigators;
use systems::navigation::{Behaviour, Navigator};
use systems::sensors::Laser;

/// How far from obstacles the localization map's distance field reaches when only a user's
/// localizer needs it (m): AMCL's `laser_likelihood_max_dist` [Thrun 2005, §6.4].
const DEFAULT_FIELD_MAX_DIST: f64 = 2.0;

fn robot_entity(
    sim: &SimWorld,
    scenario: &Scenario,
    name: &str,
) -> Result<(usize, Entity), SimError> {
    scenario
        .robots
        .iter()
        .position(|r| r.name == name)
        .map(|i| (i, sim.robots[i]))
        .ok_or_else(|| SimError::UnknownRobot {
            name: name.to_string(),
            known: names(scenario.robots.iter().map(|r| r.name.as_str())),
        })
}

/// The user's estimators join their robots' localizers, after the scenario's own (so those
/// keep their order and random streams).
pub(super) fn attach_estimators(
    sim: &mut SimWorld,
    scenario: &Scenario,
    estimators: Vec<(String, String, Filter)>,
) -> Result<(), SimError> {
    if estimators.is_empty() {
        return Ok(());
    }
    for (robot, name, filter) in estimators {
        let (_, e) = robot_entity(sim, scenario, &robot)?;
        let world = &mut sim.world;
        for (has, sensor) in [
            (world.get::<Laser>(e).is_some(), "laser"),
            (world.get::<WheelOdometry>(e).is_some(), "encoder"),
        ] {
            if !has {
                return Err(SimError::NoSuchSensor {
                    robot,
                    sensor: format!("{sensor} (estimator `{name}` needs one)"),
                });
            }
        }
        if name.is_empty()
            || world
                .get::<Localizers>(e)
                .is_some_and(|l| l.items.iter().any(|l| l.name == name))
        {
            return Err(SimError::BadValue {
                what: format!("estimator name on `{robot}`"),
                expected: "a name no other localizer of the robot has",
                got: format!("`{name}`"),
            });
        }
        if !filter.is_scan() && !world.contains_resource::<LocalizationMap>() {
            world.insert_resource(LocalizationMap::new(
                scenario.grid.clone(),
                DEFAULT_FIELD_MAX_DIST,
            ));
        }
        let mut ent = world.entity_mut(e);
        if !ent.contains::<Localizers>() {
            ent.insert((Localizers::default(), LocalizationSamples::default()));
        }
        ent.get_mut::<Localizers>()
            .expect("inserted above")
            .items
            .push(Localizer::new(name, filter));
    }
    // run_localizers, run_slam and the evaluation of localizers join the schedule if the
    // scenario had no localizer
    sim.compose_schedule();
    Ok(())
}

/// The user's controllers replace their robots' behaviours and navigators, and run in the
/// Control set after the built-in drivers, before held commands.
pub(super) fn attach_controllers(
    sim: &mut SimWorld,
    scenario: &Scenario,
    controllers: Vec<(String, Box<dyn Controller>)>,
) -> Result<(), SimError> {
    if controllers.is_empty() {
        return Ok(());
    }
    let mut items: Vec<Controlled> = Vec::with_capacity(controllers.len());
    for (robot, controller) in controllers {
        let (index, entity) = robot_entity(sim, scenario, &robot)?;
        if items.iter().any(|c| c.index == index) {
            return Err(SimError::BadValue {
                what: format!("controllers of `{robot}`"),
                expected: "one controller per robot",
                got: "two".into(),
            });
        }
        sim.world
            .entity_mut(entity)
            .remove::<(Behaviour, Navigator, NavOutcome, RoadNavigator)>();
        items.push(Controlled {
            entity,
            index,
            name: robot,
            controller,
        });
    }
    items.sort_by_key(|c| c.index);
    sim.world.insert_resource(UserControllers {
        items,
        failure: None,
    });
    // the drivers of the robots the program took over may have nothing left to drive
    sim.compose_schedule();
    sim.schedule.add_systems(
        run_user_controllers
            .in_set(SimSet::Control)
            .after(drive_navigators)
            .after(drive_road_navigators)
            .after(drive_behaviours)
            .after(walk_people)
            .before(apply_held_commands),
    );
    Ok(())
}
