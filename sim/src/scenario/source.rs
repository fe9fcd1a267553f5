//! A scenario file kept as its TOML document beside the validated scenario, so that overrides
//! (`--set`, sweeps, [`crate::scenario::overrides`]) edit the text and go through the same
//! loading and validation as the file itself.

use super::check::OdometrySource;
use super::load::parse_scenario_with;
use super::model::Scenario;
use super::overrides::{Override, blame};
use std::path::{Path, PathBuf};
use toml_edit::DocumentMut;

/// The scenario file every set starts from.
pub struct Source {
    pub path: PathBuf,
    pub label: String,
    base_dir: PathBuf,
    stem: String,
    doc: DocumentMut,
    odometry: OdometrySource,
    /// The file as it is (for sets without overrides).
    pub plain: Scenario,
}

impl Source {
    /// Loads and validates the file as `sim run` does, and keeps its TOML document.
    pub fn load(path: &Path) -> anyhow::Result<Source> {
        Self::load_with(path, OdometrySource::Encoders)
    }

    /// [`Source::load`] for robots whose odometry comes from `odometry`.
    pub fn load_with(path: &Path, odometry: OdometrySource) -> anyhow::Result<Source> {
        let label = path.display().to_string();
        let text = super::load::read_scenario_text(path)?;
        let base_dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
        let stem = path
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or("scenario");
        let mut source = Source::from_text_with(&text, &label, &base_dir, stem, odometry)?;
        source.path = path.to_path_buf();
        Ok(source)
    }

    /// Scenario text from elsewhere (the attachment of a recording), called `label` in errors,
    /// its relative paths resolved against `base_dir`, named `stem` unless it names itself.
    pub fn from_text(
        text: &str,
        label: &str,
        base_dir: &Path,
        stem: &str,
    ) -> anyhow::Result<Source> {
        Self::from_text_with(text, label, base_dir, stem, OdometrySource::Encoders)
    }

    /// [`Source::from_text`] for robots whose odometry comes from `odometry`.
    pub fn from_text_with(
        text: &str,
        label: &str,
        base_dir: &Path,
        stem: &str,
        odometry: OdometrySource,
    ) -> anyhow::Result<Source> {
        let plain = parse_scenario_with(text, label, base_dir, stem, odometry)?;
        let doc: DocumentMut = text
            .parse()
            .map_err(|e| anyhow::anyhow!("{label}: not TOML: {e}"))?;
        Ok(Source {
            base_dir: base_dir.to_path_buf(),
            stem: stem.to_string(),
            path: PathBuf::from(label),
            label: label.to_string(),
            doc,
            odometry,
            plain,
        })
    }

    /// The scenario of one parameter set, or the error naming the override(s) at fault.
    pub fn scenario(&self, overrides: &[Override]) -> Result<Scenario, String> {
        if overrides.is_empty() {
            return Ok(self.plain.clone());
        }
        let mut doc = self.doc.clone();
        let mut applied = Vec::new();
        for o in overrides {
            let at = o.apply(&mut doc).map_err(|e| e.to_string())?;
            applied.push((o.clone(), at));
        }
        let text = doc.to_string();
        let parsed = parse_scenario_with(
            &text,
            &self.label,
            &self.base_dir,
            &self.stem,
            self.odometry,
        );
        parsed.map_err(|e| {
            let culprits = e.key.as_deref().map_or(Vec::new(), |k| blame(&applied, k));
            let named: Vec<String> = if culprits.is_empty() {
                overrides.iter().map(Override::describe).collect()
            } else {
                culprits.iter().map(|o| o.describe()).collect()
            };
            format!("{}: {e}", named.join(", "))
        })
    }
}
