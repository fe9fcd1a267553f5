//! Scenarios built in code: [`Scenario::builder`] and
//! [`RobotConfig::builder`](crate::scenario::RobotConfig::builder).
//!
//! The builders fill in the file model ([`ScenarioFile`],
//! [`RobotFile`](crate::scenario::RobotFile) and each feature's file tables) and
//! [`ScenarioBuilder::build`] runs the resolver a TOML file goes through. So a value
//! the builder is not given takes the file's default, and a bad value gets the file's error,
//! naming the key (`robots[0].sensors.laser.max_range`); only the line is missing. The
//! example is on [`Scenario::builder`].

use super::check::PointOrPlace;
use super::error::{ErrorContext, KeyPath, ScenarioError};
use super::events::EventFile;
use super::file::{BoxFile, DiscFile, MapFile, RecordFile, ScenarioFile, WallFile};
use super::model::Scenario;
use super::outdoor::{RoadsFile, ZoneFile};
use super::people::PersonFile;
use super::places::{DoorFile, PlaceFile};
use super::slam::SlamList;
use std::path::{Path, PathBuf};
use systems::core::Pose2;

mod deferred;
mod robot;
mod tables;
#[cfg(test)]
mod tests;

use deferred::Deferred;
pub use robot::RobotBuilder;

/// What errors of a built scenario name instead of a file.
pub const CODE_LABEL: &str = "<code>";

impl From<[f64; 2]> for PointOrPlace {
    fn from(p: [f64; 2]) -> Self {
        PointOrPlace::Coords(p.to_vec())
    }
}

impl From<[f64; 3]> for PointOrPlace {
    fn from(p: [f64; 3]) -> Self {
        PointOrPlace::Coords(p.to_vec())
    }
}

impl From<Pose2> for PointOrPlace {
    fn from(p: Pose2) -> Self {
        PointOrPlace::Coords(vec![p.x, p.y, p.theta])
    }
}

impl From<&str> for PointOrPlace {
    fn from(name: &str) -> Self {
        PointOrPlace::Place(name.to_string())
    }
}

impl From<String> for PointOrPlace {
    fn from(name: String) -> Self {
        PointOrPlace::Place(name)
    }
}

impl Scenario {
    /// A scenario built in code, named `name` (letters, digits, `_`, `-`: it names output
    /// files). Everything not given takes the scenario file's default; `duration` is required
    /// as in a file.
    ///
    /// ```
    /// use sim::scenario::{LaserFile, LocalizerFile, LocalizerType, RobotConfig, Scenario};
    ///
    /// let scenario = Scenario::builder("two_rooms")
    ///     .seed(7)
    ///     .duration(1.0)
    ///     .room([0.0, 0.0], [10.0, 8.0])
    ///     .wall([5.0, 0.0], [5.0, 5.0])
    ///     .place("dock", [2.0, 2.0, 0.0])
    ///     .robot(
    ///         RobotConfig::builder("r1", "dock")
    ///             .laser(LaserFile::preset("sick_lms100"))
    ///             .encoder(Default::default())
    ///             .localizer(LocalizerFile {
    ///                 max_particles: Some(500),
    ///                 ..LocalizerFile::of_type(LocalizerType::Mcl)
    ///             })
    ///             .waypoints([[8.0, 2.0], [8.0, 6.0]], true),
    ///     )
    ///     .build()?;
    /// assert_eq!(scenario.robots[0].localizers[0].name, "mcl");
    /// let done = sim::Simulation::from_scenario(scenario).threads(1).build()?.run()?;
    /// assert_eq!(done.summary.robots.len(), 1);
    /// # anyhow::Ok(())
    /// ```
    pub fn builder(name: impl Into<String>) -> ScenarioBuilder {
        ScenarioBuilder {
            file: ScenarioFile {
                name: Some(name.into()),
                ..Default::default()
            },
            base_dir: PathBuf::new(),
            label: CODE_LABEL.to_string(),
            deferred: None,
        }
    }
}

/// Builds a [`Scenario`] in code (see the [module](self) docs); made by [`Scenario::builder`].
#[derive(Clone, Debug)]
pub struct ScenarioBuilder {
    file: ScenarioFile,
    base_dir: PathBuf,
    label: String,
    deferred: Deferred,
}

impl ScenarioBuilder {
    /// One line about the scenario (the file's `description`).
    pub fn description(mut self, text: impl Into<String>) -> Self {
        self.file.description = Some(text.into());
        self
    }

    /// The random seed (`seed`).
    pub fn seed(mut self, seed: u64) -> Self {
        self.file.seed = Some(seed);
        self
    }

    /// The time step in seconds (`dt`).
    pub fn dt(mut self, dt: f64) -> Self {
        self.file.dt = Some(dt);
        self
    }

    /// Simulated seconds (`duration`, required).
    pub fn duration(mut self, seconds: f64) -> Self {
        self.file.duration = Some(seconds);
        self
    }

    /// End the run once every robot with tasks has done them (`end_when_done`).
    pub fn end_when_done(mut self, yes: bool) -> Self {
        self.file.end_when_done = Some(yes);
        self
    }

    /// Relative paths (map, places and road files) resolve against `dir` instead of the
    /// current folder.
    pub fn relative_to(mut self, dir: impl Into<PathBuf>) -> Self {
        self.base_dir = dir.into();
        self
    }

    /// What errors name as the scenario's source (default [`CODE_LABEL`]).
    pub fn label(mut self, label: impl Into<String>) -> Self {
        self.label = label.into();
        self
    }

    fn map(&mut self) -> &mut MapFile {
        self.file.map.get_or_insert_with(Default::default)
    }

    /// A ROS map_server YAML file (`map.file`).
    pub fn map_file(mut self, path: impl AsRef<Path>) -> Self {
        self.map().file = Some(path.as_ref().to_string_lossy().into_owned());
        self
    }

    /// A places file of named poses and doors (`map.places`).
    pub fn places_file(mut self, path: impl AsRef<Path>) -> Self {
        self.map().places = Some(path.as_ref().to_string_lossy().into_owned());
        self
    }

    /// The cell size (m) of a world made of shapes (`map.resolution`).
    pub fn resolution(mut self, metres: f64) -> Self {
        self.map().resolution = Some(metres);
        self
    }

    /// A wall of the default thickness (`[[walls]]`).
    pub fn wall(self, from: [f64; 2], to: [f64; 2]) -> Self {
        self.wall_table(WallFile {
            from,
            to,
            thickness: None,
        })
    }

    /// A wall given as its table (to set its `thickness`).
    pub fn wall_table(mut self, wall: WallFile) -> Self {
        self.file.walls.push(wall);
        self
    }

    /// Four walls (of the default thickness) around the rectangle from `min` to `max`.
    pub fn room(self, min: [f64; 2], max: [f64; 2]) -> Self {
        let [x0, y0] = min;
        let [x1, y1] = max;
        self.wall([x0, y0], [x1, y0])
            .wall([x1, y0], [x1, y1])
            .wall([x1, y1], [x0, y1])
            .wall([x0, y1], [x0, y0])
    }

    /// A box of `size` [length, width] (m) centred at `center`, yaw 0 (`[[boxes]]`).
    pub fn box_shape(self, center: [f64; 2], size: [f64; 2]) -> Self {
        self.box_table(BoxFile {
            center,
            size,
            yaw: None,
        })
    }

    /// A box given as its table (to set its `yaw`).
    pub fn box_table(mut self, b: BoxFile) -> Self {
        self.file.boxes.push(b);
        self
    }

    /// A disc (`[[discs]]`).
    pub fn disc(mut self, center: [f64; 2], radius: f64) -> Self {
        self.file.discs.push(DiscFile { center, radius });
        self
    }

    /// A named place `[x, y, yaw]` (`[places.<name>]`), beside those of the places file.
    pub fn place(mut self, name: impl Into<String>, pose: [f64; 3]) -> Self {
        self.file.places.insert(
            name.into(),
            PlaceFile {
                pose,
                ..Default::default()
            },
        );
        self
    }

    /// A door from `from` to `to` of the default thickness (`[doors.<name>]`); it starts open.
    pub fn door(self, name: impl Into<String>, from: [f64; 2], to: [f64; 2]) -> Self {
        self.door_table(
            name,
            DoorFile {
                from,
                to,
                thickness: None,
            },
        )
    }

    /// A door given as its table (to set its `thickness`).
    pub fn door_table(mut self, name: impl Into<String>, door: DoorFile) -> Self {
        self.file.doors.insert(name.into(), door);
        self
    }

    /// The recording's rates (`[record]`); the rates not given keep their defaults.
    pub fn record(mut self, record: RecordFile) -> Self {
        self.file.record = Some(record);
        self
    }

    /// A robot (`[[robots]]`), after those added before.
    pub fn robot(mut self, robot: RobotBuilder) -> Self {
        let at = KeyPath::default()
            .key("robots")
            .index(self.file.robots.len());
        if self.deferred.is_none()
            && let Some((key, message)) = robot.deferred
        {
            let mut path = at;
            path.0.extend(key.0);
            self.deferred = Some((path, message));
        }
        let mut file = robot.file;
        file.slam = match robot.slam.len() {
            0 => None,
            1 => robot
                .slam
                .into_iter()
                .next()
                .map(|s| SlamList::One(Box::new(s))),
            _ => Some(SlamList::Many(robot.slam)),
        };
        self.file.robots.push(file);
        self
    }

    /// A walking person (`[[people]]`).
    pub fn person(mut self, person: PersonFile) -> Self {
        self.file.people.push(person);
        self
    }

    /// A timed event (`[[events]]`); see [`EventFile`]'s constructors.
    pub fn event(mut self, event: EventFile) -> Self {
        self.file.events.push(event);
        self
    }

    /// An outdoor road network (`[roads]`).
    pub fn roads(mut self, roads: RoadsFile) -> Self {
        self.file.roads = Some(roads);
        self
    }

    /// An area that degrades GPS and compass (`[[zones]]`).
    pub fn zone(mut self, zone: ZoneFile) -> Self {
        self.file.zones.push(zone);
        self
    }

    /// The file model built so far.
    pub fn file(&self) -> &ScenarioFile {
        &self.file
    }

    /// Checks everything and fills in every default, as for a scenario file; the first problem
    /// is an error naming the key.
    pub fn build(self) -> Result<Scenario, ScenarioError> {
        if let Some((key, message)) = &self.deferred {
            return Err(ErrorContext::new(self.label.clone(), "").at(key, message.clone()));
        }
        super::resolve::resolve_model(self.file, &self.label, &self.base_dir, "scenario")
    }
}
