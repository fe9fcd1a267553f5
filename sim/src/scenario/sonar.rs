//! `[robots.sensors.sonar]`: a robot's ring of ultrasonic rangers. One spec for all of them (a
//! preset, default `srf02`, with optional overrides) and their mounts, given as a list
//! `mounts = [[x, y, yaw_deg?], ...]` in the robot's base frame or as a named layout:
//! `hospital` = front, +45°, −45° and rear on the footprint's edge, the four SRF02 of seed 004
//! (sec. 4.1.2: three in front, straight ahead and 45° to either side, one at the back). Without
//! either, the robot gets the `hospital` layout. Errors name the robot and the key.

use super::check::{Checker, R};
use super::error::KeyPath;
use serde::Deserialize;
use systems::body::Footprint;
use systems::core::Pose2;
use systems::sensors::SonarSpec;
use systems::sensors::sonar::edge_mounts;

/// `[robots.sensors.sonar]` as written.
#[derive(Deserialize, Debug, Clone, Default)]
#[serde(deny_unknown_fields)]
pub struct SonarFile {
    pub preset: Option<String>,
    /// Full beam width (degrees).
    pub cone_deg: Option<f64>,
    pub min_range: Option<f64>,
    pub max_range: Option<f64>,
    /// Reading sets per second.
    pub rate: Option<f64>,
    pub noise_std: Option<f64>,
    /// [x, y] or [x, y, yaw_deg] per sonar, in the robot's base frame (m, m, degrees).
    pub mounts: Option<Vec<Vec<f64>>>,
    /// A named set of mounts (see [`LAYOUTS`]).
    pub layout: Option<String>,
}

/// A robot's resolved sonars.
#[derive(Clone, Debug, PartialEq)]
pub struct SonarConfig {
    pub spec: SonarSpec,
    pub mounts: Vec<Pose2>,
}

pub const LAYOUTS: [&str; 1] = ["hospital"];

/// More sonars than this on one robot is surely a mistake.
const MAX_MOUNTS: usize = 64;

/// The mounts of a named layout on a robot with this footprint.
pub fn layout_mounts(name: &str, footprint: &Footprint) -> Option<Vec<Pose2>> {
    match name {
        "hospital" => {
            let yaws = [0.0, 45f64, -45.0, 180.0].map(f64::to_radians);
            Some(edge_mounts(footprint, &yaws))
        }
        _ => None,
    }
}

/// Resolves robot `robot`'s sonar table at key path `p`; every error message names the robot.
pub(super) fn resolve_sonar(
    c: &Checker,
    p: &KeyPath,
    robot: &str,
    footprint: &Footprint,
    f: &SonarFile,
) -> R<SonarConfig> {
    resolve(c, p, footprint, f).map_err(|mut e| {
        e.message = format!("robot `{robot}`: {}", e.message);
        e
    })
}

fn resolve(c: &Checker, p: &KeyPath, footprint: &Footprint, f: &SonarFile) -> R<SonarConfig> {
    let preset = f.preset.as_deref().unwrap_or("srf02");
    let Some(mut s) = SonarSpec::preset(preset) else {
        return c.err(
            &p.key("preset"),
            format!(
                "unknown sonar preset `{preset}`; known: {}",
                SonarSpec::PRESETS.join(", ")
            ),
        );
    };
    if let Some(v) = f.cone_deg {
        s.cone = c
            .range(&p.key("cone_deg"), v, Some(0.0), Some(180.0), true)?
            .to_radians();
    }
    super::sensors::RangeKeys {
        min_range: f.min_range,
        max_range: f.max_range,
        rate: f.rate,
        noise_std: f.noise_std,
    }
    .apply(
        c,
        p,
        [
            &mut s.min_range,
            &mut s.max_range,
            &mut s.rate,
            &mut s.noise_std,
        ],
        100.0,
    )?;
    let mounts = match (&f.mounts, &f.layout) {
        (Some(_), Some(_)) => {
            return c.err(
                &p.key("layout"),
                "give either `mounts` or `layout`, not both",
            );
        }
        (None, layout) => {
            let name = layout.as_deref().unwrap_or("hospital");
            let Some(m) = layout_mounts(name, footprint) else {
                return c.err(
                    &p.key("layout"),
                    format!(
                        "unknown sonar layout `{name}`; known: {}",
                        LAYOUTS.join(", ")
                    ),
                );
            };
            m
        }
        (Some(list), None) => {
            let mp = p.key("mounts");
            if list.is_empty() || list.len() > MAX_MOUNTS {
                return c.err(
                    &mp,
                    format!(
                        "expected 1 to {MAX_MOUNTS} mounts [x, y, yaw_deg], got {}",
                        list.len()
                    ),
                );
            }
            let mut out = Vec::with_capacity(list.len());
            for (i, m) in list.iter().enumerate() {
                let ip = mp.index(i);
                if m.len() != 2 && m.len() != 3 {
                    return c.err(
                        &ip,
                        format!(
                            "expected [x, y] or [x, y, yaw_deg], got {} numbers",
                            m.len()
                        ),
                    );
                }
                c.finite(&ip, m)?;
                if m[0].hypot(m[1]) > 10.0 {
                    return c.err(
                        &ip,
                        format!(
                            "a sonar at ({}, {}) is more than 10 m from the robot's centre",
                            m[0], m[1]
                        ),
                    );
                }
                let yaw = m.get(2).copied().unwrap_or(0.0).to_radians();
                out.push(Pose2::new(m[0], m[1], yaw));
            }
            out
        }
    };
    Ok(SonarConfig { spec: s, mounts })
}

#[cfg(test)]
mod tests {
    use super::super::{Scenario, parse_scenario};
    use super::*;
    use std::path::Path;

    const ROBOTS: &str = r#"[[robots]]
name = "other"
start = [2.0, 2.0, 0.0]
[[robots]]
name = "porter"
start = [5.0, 5.0, 0.0]
footprint = { rectangle = [0.52, 0.4] }
[robots.sensors.sonar]
"#;

    fn parse(sonar: &str) -> Result<Scenario, String> {
        let text = format!("{}{ROBOTS}{sonar}\n", crate::scenario::TEST_ROOM);
        parse_scenario(&text, "t.toml", Path::new("."), "t").map_err(|e| e.to_string())
    }

    fn sonar(table: &str) -> SonarConfig {
        let s = parse(table).unwrap_or_else(|e| panic!("should parse: {e}"));
        assert!(s.robots[0].sonar.is_none());
        s.robots[1].sonar.clone().expect("porter has sonars")
    }

    /// The error of a bad sonar table: it names the robot and the key, with `fragment`.
    fn err(table: &str, key: &str, fragment: &str) {
        let e = parse(table).expect_err("should be rejected");
        assert!(e.contains("robot `porter`"), "robot name missing: {e}");
        assert!(
            e.contains(&format!("`robots[1].sensors.sonar.{key}`")),
            "key {key} missing: {e}"
        );
        assert!(e.contains(fragment), "`{fragment}` missing: {e}");
        assert!(e.starts_with("t.toml:"), "{e}");
    }

    #[test]
    fn defaults_are_the_srf02_in_the_hospital_layout() {
        let s = sonar("");
        assert_eq!(s.spec, SonarSpec::srf02());
        assert_eq!(s.mounts.len(), 4);
        // on the 520 × 400 mm chassis: front, ±45° at the side corners, rear
        assert!((s.mounts[0].x - 0.26).abs() < 1e-12 && s.mounts[0].theta == 0.0);
        assert!((s.mounts[1].theta - 45f64.to_radians()).abs() < 1e-12);
        assert!((s.mounts[2].theta + 45f64.to_radians()).abs() < 1e-12);
        assert!((s.mounts[3].x + 0.26).abs() < 1e-12);
        assert_eq!(sonar("layout = \"hospital\"\npreset = \"srf02\"\n"), s);
    }

    #[test]
    fn overrides_and_explicit_mounts() {
        let s = sonar(
            "cone_deg = 30.0\nmin_range = 0.2\nmax_range = 4.0\nrate = 10.0\nnoise_std = 0.0\n\
             mounts = [[0.3, 0.0], [-0.1, 0.2, 90.0]]\n",
        );
        assert!((s.spec.cone - 30f64.to_radians()).abs() < 1e-12);
        assert_eq!(
            (
                s.spec.min_range,
                s.spec.max_range,
                s.spec.rate,
                s.spec.noise_std
            ),
            (0.2, 4.0, 10.0, 0.0)
        );
        assert_eq!(s.mounts[0], Pose2::new(0.3, 0.0, 0.0));
        assert_eq!(s.mounts[1], Pose2::new(-0.1, 0.2, 90f64.to_radians()));
    }

    #[test]
    fn unknown_key_is_rejected() {
        let e = parse("beam_deg = 30.0").expect_err("should be rejected");
        assert!(e.contains("beam_deg") && e.contains("t.toml:17"), "{e}");
    }

    #[test]
    fn unknown_preset() {
        err("preset = \"maxbotix\"", "preset", "known: srf02");
    }

    #[test]
    fn cone_out_of_range() {
        err("cone_deg = 0.0", "cone_deg", "(0, 180]");
        err("cone_deg = 270.0", "cone_deg", "got 270");
    }

    #[test]
    fn negative_min_range() {
        err("min_range = -0.1", "min_range", "at least 0");
    }

    #[test]
    fn max_range_out_of_range() {
        err("max_range = 0.0", "max_range", "(0, 100]");
    }

    #[test]
    fn min_range_not_below_max_range() {
        err(
            "min_range = 7.0",
            "min_range",
            "must be below max_range (6)",
        );
        err(
            "max_range = 0.1",
            "max_range",
            "min_range (0.15) must be below",
        );
    }

    #[test]
    fn bad_rate() {
        err("rate = 0.0", "rate", "(0, 1000]");
    }

    #[test]
    fn negative_noise() {
        err("noise_std = -0.01", "noise_std", "[0, 10]");
    }

    #[test]
    fn unknown_layout() {
        err("layout = \"ring\"", "layout", "known: hospital");
    }

    #[test]
    fn layout_and_mounts_together() {
        err(
            "layout = \"hospital\"\nmounts = [[0.2, 0.0]]",
            "layout",
            "not both",
        );
    }

    #[test]
    fn empty_mounts() {
        err("mounts = []", "mounts", "got 0");
    }

    #[test]
    fn mount_with_the_wrong_length() {
        err("mounts = [[0.2, 0.0], [0.2]]", "mounts[1]", "got 1 numbers");
    }

    #[test]
    fn mount_not_finite() {
        err("mounts = [[0.2, nan, 0.0]]", "mounts[0]", "finite");
    }

    #[test]
    fn sonar_faults_need_sonars() {
        let event = "[[events]]\nat = 0.5\ntype = \"sensor_fault\"\nsensor = \"sonar\"\n";
        let s = parse(&format!("{event}robot = \"porter\"\n")).unwrap();
        assert!(matches!(
            s.events[0].action,
            super::super::EventAction::SensorFault {
                sensor: super::super::SensorName::Sonar,
                active: true
            }
        ));
        let e = parse(&format!("{event}robot = \"other\"\n")).expect_err("should be rejected");
        assert!(e.contains("robot `other` has no sonar sensor"), "{e}");
    }

    #[test]
    fn mount_far_away() {
        err("mounts = [[20.0, 0.0]]", "mounts[0]", "more than 10 m");
    }
}
