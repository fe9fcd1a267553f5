//! The `[[people]]` tables: walking people with a route of points or place names. Every error
//! names the person and the key.

use super::check::PointOrPlace;
use super::check::{Checker, R, check_name};
use super::error::{KeyPath, ScenarioError};
use serde::Deserialize;
use systems::body::Person;
use systems::body::people::{DEFAULT_RADIUS, DEFAULT_SPEED};
use systems::core::Pose2;
use systems::world::OccupancyGrid;

/// Fastest walking speed accepted (m/s): a brisk walk is 1.5–2, above 3 is running.
const MAX_SPEED: f64 = 3.0;
/// Largest body radius accepted (m).
const MAX_RADIUS: f64 = 1.0;

/// One `[[people]]` table as written.
#[derive(Deserialize, Debug, Clone, Default)]
#[serde(deny_unknown_fields)]
pub struct PersonFile {
    pub name: String,
    /// [x, y] points or place names, walked in order (at least two).
    pub route: Vec<PointOrPlace>,
    pub speed: Option<f64>,
    #[serde(rename = "loop")]
    pub looping: Option<bool>,
    pub pause: Option<f64>,
    pub start_at: Option<f64>,
    pub radius: Option<f64>,
}

/// A validated person.
#[derive(Clone, Debug, PartialEq)]
pub struct PersonConfig {
    pub name: String,
    pub person: Person,
}

/// Resolves every `[[people]]` table; `point` resolves a point or place name, `inside` checks it
/// lies on the map.
pub(super) fn resolve_people(
    c: &Checker,
    path: &KeyPath,
    files: &[PersonFile],
    point: &dyn Fn(&KeyPath, &PointOrPlace) -> R<Pose2>,
    inside: &dyn Fn(&KeyPath, &Pose2) -> R<()>,
    grid: &OccupancyGrid,
) -> R<Vec<PersonConfig>> {
    let mut out: Vec<PersonConfig> = Vec::with_capacity(files.len());
    for (i, f) in files.iter().enumerate() {
        let p = path.index(i);
        let named = |mut e: ScenarioError| {
            e.message = format!("person `{}`: {}", f.name, e.message);
            e
        };
        if !check_name(&f.name) {
            return c.err(
                &p.key("name"),
                format!(
                    "person `{}`: expected letters, digits, `_` or `-` (it names the Rerun path \
                     people/<name>)",
                    f.name
                ),
            );
        }
        if out.iter().any(|o| o.name == f.name) {
            return c.err(
                &p.key("name"),
                format!("duplicate person name `{}`", f.name),
            );
        }
        let person = resolve_person(c, &p, f, point, inside, grid).map_err(named)?;
        out.push(PersonConfig {
            name: f.name.clone(),
            person,
        });
    }
    Ok(out)
}

fn resolve_person(
    c: &Checker,
    p: &KeyPath,
    f: &PersonFile,
    point: &dyn Fn(&KeyPath, &PointOrPlace) -> R<Pose2>,
    inside: &dyn Fn(&KeyPath, &Pose2) -> R<()>,
    grid: &OccupancyGrid,
) -> R<Person> {
    let speed = match f.speed {
        Some(v) => c.range(&p.key("speed"), v, Some(0.0), Some(MAX_SPEED), true)?,
        None => DEFAULT_SPEED,
    };
    let radius = match f.radius {
        Some(v) => c.range(&p.key("radius"), v, Some(0.0), Some(MAX_RADIUS), true)?,
        None => DEFAULT_RADIUS,
    };
    let pause = match f.pause {
        Some(v) => c.range(&p.key("pause"), v, Some(0.0), None, false)?,
        None => 0.0,
    };
    let start_at = match f.start_at {
        Some(v) => c.range(&p.key("start_at"), v, Some(0.0), None, false)?,
        None => 0.0,
    };
    let rp = p.key("route");
    if f.route.len() < 2 {
        return c.err(
            &rp,
            format!(
                "expected at least 2 points ([x, y] or place names), got {}",
                f.route.len()
            ),
        );
    }
    let mut route = Vec::with_capacity(f.route.len());
    for (k, q) in f.route.iter().enumerate() {
        let pp = rp.index(k);
        let pose = point(&pp, q)?;
        inside(&pp, &pose)?;
        if !grid.disc_is_clear(pose.x, pose.y, radius) {
            return c.err(
                &pp,
                format!(
                    "route point ({:.2}, {:.2}) lies inside an obstacle (radius {radius:.2} m)",
                    pose.x, pose.y
                ),
            );
        }
        route.push([pose.x, pose.y]);
    }
    Ok(Person {
        route,
        looping: f.looping.unwrap_or(true),
        speed,
        pause,
        start_at,
        radius,
    })
}

#[cfg(test)]
mod tests {
    use crate::scenario::{Scenario, assets_dir, parse_scenario};

    /// A 10 × 10 m room with a 1 × 1 m pillar at (5, 5).
    const ROOM: &str = r#"
duration = 1.0
walls = [
  { from = [0.0, 0.0], to = [10.0, 0.0], thickness = 0.2 },
  { from = [0.0, 10.0], to = [10.0, 10.0], thickness = 0.2 },
  { from = [0.0, 0.0], to = [0.0, 10.0], thickness = 0.2 },
  { from = [10.0, 0.0], to = [10.0, 10.0], thickness = 0.2 },
]
boxes = [{ center = [5.0, 5.0], size = [1.0, 1.0] }]
"#;

    fn parse(text: &str) -> Result<Scenario, String> {
        parse_scenario(text, "test.toml", &assets_dir().join("scenarios"), "test")
            .map_err(|e| e.to_string())
    }

    /// A room with one person `alice` whose table ends with `extra`.
    fn with_person(route: &str, extra: &str) -> String {
        format!("{ROOM}\n[[people]]\nname = \"alice\"\nroute = {route}\n{extra}")
    }

    /// The error names the file and line of `key`, the person and every fragment.
    fn expect_error(text: &str, key: &str, fragments: &[&str]) {
        let e = match parse(text) {
            Ok(_) => panic!("should have been rejected:\n{text}"),
            Err(e) => e,
        };
        let line = text
            .lines()
            .position(|l| l.starts_with(key))
            .map_or(0, |l| l + 1);
        assert!(
            e.starts_with(&format!("test.toml:{line}:")),
            "expected line {line} in: {e}"
        );
        for f in fragments {
            assert!(e.contains(f), "expected `{f}` in: {e}");
        }
    }

    #[test]
    fn people_resolve_with_defaults() {
        let s = parse(&with_person("[[1.0, 1.0], [8.0, 1.0, 0.0]]", "")).unwrap();
        assert_eq!(s.people.len(), 1);
        let p = &s.people[0];
        assert_eq!(p.name, "alice");
        assert_eq!(p.person.route, vec![[1.0, 1.0], [8.0, 1.0]]);
        assert!(p.person.looping);
        assert_eq!(p.person.speed, 1.2);
        assert_eq!(
            (p.person.pause, p.person.start_at, p.person.radius),
            (0.0, 0.0, 0.25)
        );
        let s = parse(&with_person(
            "[[1.0, 1.0], [8.0, 1.0]]",
            "speed = 0.9\nloop = false\npause = 2.0\nstart_at = 5.0\nradius = 0.3\n",
        ))
        .unwrap();
        let p = &s.people[0].person;
        assert_eq!(
            (p.speed, p.looping, p.pause, p.start_at, p.radius),
            (0.9, false, 2.0, 5.0, 0.3)
        );
    }

    #[test]
    fn places_resolve_through_the_maps_places_file() {
        let text = "duration = 1.0\n[map]\nfile = \"../maps/hospital/hospital.yaml\"\nplaces = \"../maps/hospital/places.toml\"\n[[people]]\nname = \"nurse\"\nroute = [\"corridor_main_w\", \"corridor_main_c\"]\n";
        let s = parse(text).unwrap();
        assert_eq!(s.people[0].person.route, vec![[5.0, 16.0], [32.0, 16.0]]);
    }

    #[test]
    fn unknown_place() {
        let text = "duration = 1.0\n[map]\nfile = \"../maps/hospital/hospital.yaml\"\nplaces = \"../maps/hospital/places.toml\"\n[[people]]\nname = \"nurse\"\nroute = [\"corridor_main_w\", \"canteen\"]\n";
        expect_error(
            text,
            "route",
            &[
                "people[0].route[1]",
                "person `nurse`",
                "unknown place `canteen`",
            ],
        );
    }

    #[test]
    fn route_point_outside_the_map() {
        expect_error(
            &with_person("[[1.0, 1.0], [40.0, 1.0]]", ""),
            "route",
            &["people[0].route[1]", "person `alice`", "outside the map"],
        );
    }

    #[test]
    fn route_point_inside_an_obstacle() {
        expect_error(
            &with_person("[[1.0, 1.0], [5.0, 5.0]]", ""),
            "route",
            &["people[0].route[1]", "person `alice`", "inside an obstacle"],
        );
    }

    #[test]
    fn speed_out_of_range() {
        let route = "[[1.0, 1.0], [8.0, 1.0]]";
        expect_error(
            &with_person(route, "speed = 0.0\n"),
            "speed",
            &["people[0].speed", "person `alice`", "(0, 3]"],
        );
        expect_error(
            &with_person(route, "speed = 3.5\n"),
            "speed",
            &["people[0].speed", "person `alice`", "3.5"],
        );
    }

    #[test]
    fn radius_not_positive() {
        expect_error(
            &with_person("[[1.0, 1.0], [8.0, 1.0]]", "radius = 0.0\n"),
            "radius",
            &["people[0].radius", "person `alice`", "got 0"],
        );
    }

    #[test]
    fn duplicate_names() {
        let text = format!(
            "{}\n[[people]]\nname = \"alice\"\nroute = [[2.0, 2.0], [2.0, 8.0]]\n",
            with_person("[[1.0, 1.0], [8.0, 1.0]]", "")
        );
        let e = parse(&text).unwrap_err();
        let lines: Vec<&str> = text.lines().collect();
        let line = lines.iter().rposition(|l| l.starts_with("name")).unwrap() + 1;
        assert!(e.starts_with(&format!("test.toml:{line}:")), "{e}");
        assert!(
            e.contains("people[1].name") && e.contains("duplicate person name `alice`"),
            "{e}"
        );
    }

    #[test]
    fn fewer_than_two_points() {
        expect_error(
            &with_person("[[1.0, 1.0]]", ""),
            "route",
            &[
                "people[0].route",
                "person `alice`",
                "at least 2 points",
                "got 1",
            ],
        );
    }

    #[test]
    fn unknown_key() {
        expect_error(
            &with_person("[[1.0, 1.0], [8.0, 1.0]]", "colour = \"red\"\n"),
            "colour",
            &["colour"],
        );
    }
}
