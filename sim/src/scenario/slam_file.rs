//! A SLAM system configured outside a scenario (`sim slam --slam TYPE --slam-config FILE`): the
//! file holds the table of a robot's `slam` key, without the `slam =` around it, and goes
//! through the scenario's own resolution (`resolve_slam`), so every type the key
//! accepts is accepted here, with the same defaults, checks and error messages (file, line,
//! key).

use super::check::Checker;
use super::error::{ErrorContext, KeyPath, ScenarioError};
use super::localizers::LocalizerConfig;
use super::slam::SlamList;
use systems::core::Pose2;

/// The SLAM type used when neither `--slam` nor the file names one.
pub const DEFAULT_SLAM_TYPE: &str = "scan_to_map";

/// Where the `type` comes from when the file does not give it: a line put in front of the file's
/// text (errors on later lines are moved back by one).
const INJECTED_LINES: usize = 1;

/// Resolves a SLAM system of type `slam_type` (the command line's `--slam`; None: the file's
/// `type`, else [`DEFAULT_SLAM_TYPE`]) with the keys of `config` = (file name, text), starting
/// at `start` (its map frame's pose of the robot at the first scan). A type given both ways
/// must agree.
pub fn resolve_slam_config(
    slam_type: Option<&str>,
    config: Option<(&str, &str)>,
    start: &Pose2,
) -> Result<LocalizerConfig, ScenarioError> {
    let (label, text) = config.unwrap_or(("--slam", ""));
    let cx = ErrorContext::new(label.to_string(), text);
    let table: toml::Table = toml::from_str(text).map_err(|e| cx.from_toml(&e))?;
    let file_type = table.get("type").and_then(|v| v.as_str());
    let (text, injected) = match (slam_type, file_type) {
        (Some(a), Some(b)) if a != b => {
            return Err(cx.at(
                &KeyPath::default().key("type"),
                format!("the file says `{b}` but --slam says `{a}`: give one, or the same"),
            ));
        }
        (_, Some(_)) => (text.to_string(), false),
        (t, None) => {
            let t = toml::Value::String(t.unwrap_or(DEFAULT_SLAM_TYPE).to_string());
            (format!("type = {t}\n{text}"), true)
        }
    };
    let c = Checker {
        cx: ErrorContext::new(label.to_string(), &text),
        odometry: Default::default(),
    };
    let resolved = toml::from_str::<SlamList>(&text)
        .map_err(|e| locate_unknown_field(&c.cx, c.cx.from_toml(&e)))
        .and_then(|list| {
            super::slam::resolve_slam(&c, &KeyPath::default(), Some(&list), start, &[])
        });
    match resolved {
        Ok(mut v) if v.len() == 1 => Ok(v.remove(0)),
        Ok(v) => Err(ScenarioError {
            file: label.to_string(),
            line: None,
            column: None,
            key: None,
            message: format!("expected one SLAM system, found {}", v.len()),
        }),
        Err(e) if injected => Err(unshift(e, slam_type)),
        Err(e) => Err(e),
    }
}

/// Serde's "unknown field" errors lose their place on the way through the `slam` key's
/// deserializer: put them on the field's line.
fn locate_unknown_field(cx: &ErrorContext, e: ScenarioError) -> ScenarioError {
    let field = e
        .message
        .strip_prefix("unknown field `")
        .and_then(|rest| rest.split('`').next());
    match field {
        Some(f) if e.line.is_none() => cx.at(&KeyPath::default().key(f), e.message),
        _ => e,
    }
}

/// An error about the text with the injected `type` line: later lines moved back to the file's
/// numbering; one about the injected line itself is about `--slam`.
fn unshift(mut e: ScenarioError, slam_type: Option<&str>) -> ScenarioError {
    match e.line {
        Some(l) if l > INJECTED_LINES => e.line = Some(l - INJECTED_LINES),
        _ if e.key.as_deref() == Some("type") || e.message.contains("variant") => {
            return ScenarioError {
                file: "--slam".to_string(),
                line: None,
                column: None,
                key: None,
                message: format!(
                    "`{}`: {}",
                    slam_type.unwrap_or(DEFAULT_SLAM_TYPE),
                    e.message
                ),
            };
        }
        _ => {}
    }
    e
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::LocalizerKind;

    fn start() -> Pose2 {
        Pose2::new(1.0, 2.0, 0.5)
    }

    #[test]
    fn type_from_the_flag_the_file_or_the_default() {
        let c = resolve_slam_config(None, None, &start()).unwrap();
        assert_eq!(c.name, "scan_to_map");
        let LocalizerKind::ScanToMap(s) = &c.kind else {
            panic!("{c:?}")
        };
        assert_eq!(s.init_pose, start());
        let file = "name = \"fine\"\nresolution = 0.1\n";
        let c = resolve_slam_config(Some("scan_to_map"), Some(("s.toml", file)), &start()).unwrap();
        assert_eq!(c.name, "fine");
        let LocalizerKind::ScanToMap(s) = &c.kind else {
            panic!("{c:?}")
        };
        assert_eq!(s.resolution, 0.1);
        let typed = "type = \"scan_to_map\"\nlevels = 2\n";
        assert!(resolve_slam_config(None, Some(("s.toml", typed)), &start()).is_ok());
    }

    #[test]
    fn errors_name_the_file_line_and_key_or_the_flag() {
        // a bad value on line 2 of the file (line 3 of the text with the injected type)
        let e = resolve_slam_config(
            None,
            Some(("s.toml", "levels = 2\nresolution = 0\n")),
            &start(),
        )
        .unwrap_err()
        .to_string();
        assert!(e.starts_with("s.toml:2:"), "{e}");
        assert!(e.contains("`resolution`"), "{e}");
        let e = resolve_slam_config(None, Some(("s.toml", "\n\nspeed = 3\n")), &start())
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("s.toml:3:") && e.contains("speed"), "{e}");
        let e = resolve_slam_config(Some("nope"), None, &start())
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("--slam: `nope`: unknown variant"), "{e}");
        let e = resolve_slam_config(
            Some("nope"),
            Some(("s.toml", "type = \"scan_to_map\"\n")),
            &start(),
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.starts_with("s.toml:1:") && e.contains("--slam says `nope`"),
            "{e}"
        );
        let e = resolve_slam_config(None, Some(("s.toml", "levels = [\n")), &start())
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("s.toml:"), "{e}");
    }

    #[test]
    fn rbpf_takes_gmappings_parameter_names_and_rejects_the_matchers() {
        let file = "particles = 15\nlinearUpdate = 0.5\nangularUpdate = 0.25\n\
                    llsamplerange = 0.02\nlasamplestep = 0.01\nresolution = 0.04\n";
        let c = resolve_slam_config(Some("rbpf"), Some(("g.toml", file)), &start()).unwrap();
        let LocalizerKind::Rbpf(r) = &c.kind else {
            panic!("{c:?}")
        };
        assert_eq!((c.name.as_str(), r.particles), ("rbpf", 15));
        assert_eq!((r.linear_update, r.angular_update), (0.5, 0.25));
        assert_eq!(
            (r.sample.llsamplerange, r.sample.lasamplestep),
            (0.02, 0.01)
        );
        // the ones not given keep the seed's values
        assert_eq!(
            (r.sample.llsamplestep, r.sample.lasamplerange),
            (0.01, 0.005)
        );
        assert_eq!((r.resolution, r.init_pose), (0.04, start()));
        let err = |t: &str, f: &str| {
            resolve_slam_config(Some(t), Some(("g.toml", f)), &start())
                .unwrap_err()
                .to_string()
        };
        let e = err("rbpf", "\nparticles = 0\n");
        assert!(e.starts_with("g.toml:2:") && e.contains("particles"), "{e}");
        let e = err("rbpf", "linearUpdate = -1\n");
        assert!(
            e.starts_with("g.toml:1:") && e.contains("linearUpdate"),
            "{e}"
        );
        let e = err("rbpf", "llsamplestep = 2\n");
        assert!(e.contains("llsamplestep"), "{e}");
        let e = err("rbpf", "levels = 2\n");
        assert!(
            e.starts_with("g.toml:1:")
                && e.contains("`levels` applies to `scan_to_map` and `graph`"),
            "{e}"
        );
        let e = err("graph", "matcher = \"de\"\n");
        assert!(e.contains("`matcher` applies to `scan_to_map`"), "{e}");
        let c = resolve_slam_config(
            Some("scan_to_map"),
            Some(("g.toml", "matcher = \"de\"\n")),
            &start(),
        )
        .unwrap();
        let LocalizerKind::ScanToMap(s) = &c.kind else {
            panic!("{c:?}")
        };
        assert!(s.de_matcher.is_some());
        let e = err("graph", "\nparticles = 30\n");
        assert!(
            e.starts_with("g.toml:2:") && e.contains("`particles` applies to `rbpf`"),
            "{e}"
        );
    }
}
