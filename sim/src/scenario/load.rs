//! Finding and loading scenario files: a path or the name of a bundled scenario.

use super::check::OdometrySource;
use super::error::ScenarioError;
use super::model::Scenario;
use std::path::{Path, PathBuf};
use systems::core::input::{MAX_CONFIG_BYTES, read_bounded};

/// Loads and validates a scenario file.
pub fn load_scenario(path: &Path) -> Result<Scenario, ScenarioError> {
    let text = read_scenario_text(path)?;
    let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let stem = path
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("scenario");
    parse_scenario(&text, &path.display().to_string(), &base, stem)
}

/// A scenario file's text; where it is not UTF-8, the error gives the line and column.
pub fn read_scenario_text(path: &Path) -> Result<String, ScenarioError> {
    let error = |line, column, message| ScenarioError {
        file: path.display().to_string(),
        line,
        column,
        key: None,
        message,
    };
    let bytes = read_bounded(path, MAX_CONFIG_BYTES)
        .map_err(|e| error(None, None, format!("cannot read: {e}")))?;
    String::from_utf8(bytes).map_err(|e| {
        let good = &e.as_bytes()[..e.utf8_error().valid_up_to()];
        let line = good.iter().filter(|&&b| b == b'\n').count() + 1;
        let start = good.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
        let column = String::from_utf8_lossy(&good[start..]).chars().count() + 1;
        error(
            Some(line),
            Some(column),
            "not UTF-8 text (a scenario file is TOML, which is UTF-8)".into(),
        )
    })
}

/// Parses and validates scenario text; relative paths resolve against `base_dir`.
pub fn parse_scenario(
    text: &str,
    file_label: &str,
    base_dir: &Path,
    default_name: &str,
) -> Result<Scenario, ScenarioError> {
    parse_scenario_with(
        text,
        file_label,
        base_dir,
        default_name,
        OdometrySource::Encoders,
    )
}

/// [`parse_scenario`] for robots whose odometry comes from `odometry` (a replay of recorded
/// odometry needs no encoders in the scenario).
pub fn parse_scenario_with(
    text: &str,
    file_label: &str,
    base_dir: &Path,
    default_name: &str,
    odometry: OdometrySource,
) -> Result<Scenario, ScenarioError> {
    super::resolve::resolve(text, file_label, base_dir, default_name, odometry)
}

/// A copy of the assets that a package carries with it ([`use_bundled_assets`]).
static PACKAGED_ASSETS: std::sync::OnceLock<PathBuf> = std::sync::OnceLock::new();

/// Makes `dir` the assets' folder wherever `$SIM_ASSETS` does not name one: for a package that
/// ships its own copy (the Python wheel), so it keeps working when the repository it was built
/// from moves or is gone. The first call wins.
pub fn use_bundled_assets(dir: PathBuf) {
    let _ = PACKAGED_ASSETS.set(dir);
}

/// The folder of the bundled assets: `$SIM_ASSETS`, else a package's own copy
/// ([`use_bundled_assets`]), else the repository's `assets/` ([`systems::core::source`]).
pub fn assets_dir() -> PathBuf {
    if let Some(p) = std::env::var_os("SIM_ASSETS") {
        return PathBuf::from(p);
    }
    match PACKAGED_ASSETS.get() {
        Some(p) => p.clone(),
        None => systems::core::source::source_path("assets"),
    }
}

/// Bundled scenarios: (name, path), sorted; an error naming the folder when it cannot be read
/// (a `sim` binary run away from its repository, without `SIM_ASSETS`).
pub fn bundled_scenarios() -> anyhow::Result<Vec<(String, PathBuf)>> {
    let dir = assets_dir().join("scenarios");
    let entries = std::fs::read_dir(&dir).map_err(|e| {
        anyhow::anyhow!(
            "{}: cannot read the bundled scenarios ({e}); set SIM_ASSETS to the repository's \
             assets folder",
            dir.display()
        )
    })?;
    let mut out: Vec<(String, PathBuf)> = entries
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .filter_map(|p| Some((p.file_stem()?.to_str()?.to_string(), p.clone())))
        .collect();
    out.sort();
    Ok(out)
}

/// The scenario `sim run` uses without an argument.
pub const DEFAULT_SCENARIO: &str = "hospital_patrol";

/// Resolves a scenario argument: a path, or the name of a bundled scenario; otherwise an error
/// that lists the bundled ones.
pub fn find_scenario(arg: &str) -> anyhow::Result<PathBuf> {
    let p = PathBuf::from(arg);
    if p.exists() {
        return Ok(p);
    }
    let all = bundled_scenarios()
        .map_err(|e| anyhow::anyhow!("{arg}: no such file, and no bundled scenarios: {e}"))?;
    if let Some((_, p)) = all.iter().find(|(name, _)| name == arg) {
        return Ok(p.clone());
    }
    let names: Vec<&str> = all.iter().map(|(n, _)| n.as_str()).collect();
    anyhow::bail!(
        "{arg}: no such file and no bundled scenario of that name (bundled: {})",
        names.join(", ")
    )
}

/// A scenario file or the name of a bundled scenario (default: hospital_patrol).
pub fn scenario_arg(arg: Option<&str>) -> anyhow::Result<Scenario> {
    Ok(load_scenario(&scenario_path(arg)?)?)
}

/// The file of a scenario argument: a path, or the name of a bundled scenario (default:
/// hospital_patrol).
pub fn scenario_path(arg: Option<&str>) -> anyhow::Result<PathBuf> {
    find_scenario(arg.unwrap_or(DEFAULT_SCENARIO))
}
