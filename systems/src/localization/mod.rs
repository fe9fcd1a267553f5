//! Estimators: they read sensor readings only, never ground truth. Wheel odometry (which also
//! provides the belief controllers navigate by), the odometry motion model the filters share,
//! the map localizers believe in, and the localizers themselves (Monte Carlo localization and the
//! others, behind one interface a user's own localizer implements too: [`MapLocalizer`]).

pub mod de_filter;
pub mod de_mc;
pub mod de_odometry;
pub mod de_places;
pub mod de_population;
pub mod de_tracker;
pub mod fixtures;
pub mod localizer;
pub mod map;
pub mod map_localizer;
pub mod markov_grid;
pub mod mcl;
pub mod motion_model;
pub mod nav_source;
pub mod odometry;
pub mod road;
pub mod road_wiring;
pub mod scan_estimator;

#[cfg(test)]
pub(crate) mod props;
#[cfg(test)]
pub(crate) mod test_drive;

pub use localizer::{Filter, Localizer, Localizers, StampedEstimate, UpdateCost};
pub use map::LocalizationMap;
pub use map_localizer::MapLocalizer;
pub use markov_grid::{MarkovGrid, MarkovGridConfig};
pub use mcl::{BeamSubset, Mcl, MclConfig, PoseEstimate};
pub use motion_model::OdometryMotionModel;
pub use nav_source::NavSource;
pub use odometry::{NavBelief, OdometryModel, WheelOdometry};
pub use road::{RoadGrid, RoadLocalizer, RoadMcl, RoadObservation, RoadPosition};
pub use scan_estimator::{GraphEdgeKind, GraphEdgeView, GraphView, ScanEstimator};

use crate::core::{Chained, SimPlugin, SimSet, any_with};
use bevy_ecs::prelude::*;

pub struct LocalizationPlugin;

impl SimPlugin for LocalizationPlugin {
    fn build(&self, world: &mut World, schedule: &mut Schedule) {
        Chained::new()
            .add(
                any_with::<WheelOdometry>(world),
                odometry::integrate_odometry,
            )
            .add(
                any_with::<road_wiring::RoadLocalization>(world),
                road_wiring::run_road_localizers,
            )
            .add(any_with::<Localizers>(world), localizer::run_localizers)
            .add(any_with::<NavSource>(world), nav_source::fuse_nav_belief)
            .add_to(schedule, SimSet::Estimate);
    }
}

#[cfg(test)]
mod tests {
    use crate::body::{TruePose, TrueTwist};
    use crate::sensors::LaserTruth;
    use bevy_ecs::prelude::*;
    use bevy_ecs::system::SystemAccess;

    /// The rule of systems/ARCHITECTURE.md, "Ground truth and belief": estimators never read
    /// ground truth. Their systems' declared world access (what bevy lets them touch) contains
    /// no ground-truth component.
    #[test]
    fn localization_systems_never_read_ground_truth() {
        let mut world = World::new();
        let truth = [
            world.register_component::<TruePose>(),
            world.register_component::<TrueTwist>(),
            world.register_component::<LaserTruth>(),
        ];
        let mut systems: Vec<Box<dyn System<In = (), Out = ()>>> = vec![
            Box::new(IntoSystem::into_system(super::odometry::integrate_odometry)),
            Box::new(IntoSystem::into_system(super::localizer::run_localizers)),
        ];
        for s in systems.iter_mut() {
            match s.initialize(&mut world) {
                SystemAccess::Shared(set) => {
                    let access = set.combined_access();
                    for id in truth {
                        assert!(
                            !access.has_read(id) && !access.has_write(id),
                            "{} touches ground truth",
                            s.name()
                        );
                    }
                    // and they do read something (the test would be empty otherwise)
                    assert!(access.has_any_read(), "{}", s.name());
                }
                other => panic!("{}: unexpected access {other:?}", s.name()),
            }
        }
    }
}
