//! The outdoor world of a scenario: `[roads]` (a road network from OSM XML or GPX 1.1, projected
//! to local metres around a reference point) and `[[zones]]` (areas that degrade GPS and compass
//! readings: open sky, trees, buildings, electromagnetic interference), as in the park runs of
//! [Park thesis]. Errors name the file, line and key; a road file's own errors keep
//! their file:line:column.

use super::check::{Checker, R, check_name};
use super::error::KeyPath;
use serde::Deserialize;
use std::path::Path;
use std::sync::Arc;
use systems::world::roads::{GeoPoint, RoadGraph, RoadOptions, load_roads};
use systems::world::zones::{Zone, ZoneKind, ZoneShape};

/// `[roads]` as written.
#[derive(Deserialize, Debug, Clone, Default)]
#[serde(deny_unknown_fields)]
pub struct RoadsFile {
    /// OSM XML or GPX 1.1, relative to the scenario file.
    pub file: String,
    /// [latitude, longitude] (degrees) of the local origin; default: the centre of the roads.
    pub reference: Option<[f64; 2]>,
    /// Grass around the roads that the world extends over (m, default 15).
    pub margin: Option<f64>,
    /// Width (m) of every road without a width tag.
    pub width: Option<f64>,
    /// GPX points closer than this (m) are one node (default 0.5).
    pub merge_distance: Option<f64>,
}

/// One `[[zones]]` table as written.
#[derive(Deserialize, Debug, Clone, Default)]
#[serde(deny_unknown_fields)]
pub struct ZoneFile {
    pub name: String,
    /// `open`, `trees`, `buildings` or `em` (electromagnetic interference).
    pub kind: String,
    /// Vertices [[x, y], ...] in local metres.
    pub polygon: Option<Vec<[f64; 2]>>,
    /// `{ center = [x, y], radius = r }`.
    pub circle: Option<CircleFile>,
    /// Overrides of the kind's GPS error model.
    pub gps_mu: Option<f64>,
    pub gps_sigma: Option<f64>,
    pub gps_bias_std: Option<f64>,
    pub gps_outlier_probability: Option<f64>,
    /// Compass deflection (degrees) [at the edge, at the centre].
    pub compass_deflection_deg: Option<[f64; 2]>,
    /// Turn the compass anticlockwise instead of clockwise.
    pub compass_anticlockwise: Option<bool>,
}

/// A zone's `circle`.
#[derive(Deserialize, Debug, Clone, Default)]
#[serde(deny_unknown_fields)]
pub struct CircleFile {
    pub center: [f64; 2],
    pub radius: f64,
}

/// The resolved road network.
#[derive(Clone, Debug)]
pub struct RoadsConfig {
    /// The file it came from (for messages and recordings).
    pub file: String,
    pub graph: Arc<RoadGraph>,
    /// Grass around the roads (m).
    pub margin: f64,
}

pub(super) fn resolve_roads(
    c: &Checker,
    p: &KeyPath,
    f: &RoadsFile,
    base: &Path,
) -> R<RoadsConfig> {
    let mut options = RoadOptions::default();
    if let Some([lat, lon]) = f.reference {
        let g = GeoPoint::new(lat, lon);
        if !g.is_valid() {
            return c.err(
                &p.key("reference"),
                format!(
                    "expected [latitude in [-90, 90], longitude in [-180, 180]], got [{lat}, {lon}]"
                ),
            );
        }
        options.reference = Some(g);
    }
    if let Some(w) = f.width {
        options.width = Some(c.range(&p.key("width"), w, Some(0.0), Some(50.0), true)?);
    }
    if let Some(m) = f.merge_distance {
        options.merge_distance =
            c.range(&p.key("merge_distance"), m, Some(0.0), Some(10.0), false)?;
    }
    let margin = match f.margin {
        Some(m) => c.range(&p.key("margin"), m, Some(0.0), Some(500.0), false)?,
        None => 15.0,
    };
    let path = base.join(&f.file);
    let graph = load_roads(&path, &options).map_err(|e| c.cx.at(&p.key("file"), e.to_string()))?;
    Ok(RoadsConfig {
        file: path.display().to_string(),
        graph: Arc::new(graph),
        margin,
    })
}

pub(super) fn resolve_zones(c: &Checker, p: &KeyPath, files: &[ZoneFile]) -> R<Vec<Zone>> {
    let mut out: Vec<Zone> = Vec::with_capacity(files.len());
    for (i, f) in files.iter().enumerate() {
        let zp = p.index(i);
        if !check_name(&f.name) {
            return c.err(
                &zp.key("name"),
                format!("expected letters, digits, `_` or `-`, got `{}`", f.name),
            );
        }
        if out.iter().any(|z| z.name == f.name) {
            return c.err(&zp.key("name"), format!("duplicate zone name `{}`", f.name));
        }
        let Some(kind) = ZoneKind::parse(&f.kind) else {
            return c.err(
                &zp.key("kind"),
                format!(
                    "unknown zone kind `{}`; expected open, trees, buildings or em",
                    f.kind
                ),
            );
        };
        let shape = match (&f.polygon, &f.circle) {
            (Some(v), None) => {
                if v.len() < 3 {
                    return c.err(
                        &zp.key("polygon"),
                        format!("expected at least 3 vertices, got {}", v.len()),
                    );
                }
                for (j, q) in v.iter().enumerate() {
                    c.finite(&zp.key("polygon").index(j), q)?;
                }
                ZoneShape::Polygon(v.clone())
            }
            (None, Some(circle)) => {
                let cp = zp.key("circle");
                c.finite(&cp.key("center"), &circle.center)?;
                ZoneShape::Circle {
                    centre: circle.center,
                    radius: c.positive(&cp.key("radius"), circle.radius)?,
                }
            }
            _ => {
                return c.err(
                    &zp,
                    "expected exactly one of `polygon = [[x, y], ...]` or `circle = { center = [x, y], radius = r }`",
                );
            }
        };
        let mut zone = Zone::new(f.name.clone(), kind, shape);
        if let Some(v) = f.gps_mu {
            zone.gps.mu = c.range(&zp.key("gps_mu"), v, Some(-5.0), Some(5.0), false)?;
        }
        if let Some(v) = f.gps_sigma {
            zone.gps.sigma = c.range(&zp.key("gps_sigma"), v, Some(0.0), Some(3.0), true)?;
        }
        if let Some(v) = f.gps_bias_std {
            zone.gps.bias_std =
                c.range(&zp.key("gps_bias_std"), v, Some(0.0), Some(100.0), false)?;
        }
        if let Some(v) = f.gps_outlier_probability {
            zone.gps.outlier_probability = c.range(
                &zp.key("gps_outlier_probability"),
                v,
                Some(0.0),
                Some(1.0),
                false,
            )?;
        }
        if let Some(d) = f.compass_deflection_deg {
            let dp = zp.key("compass_deflection_deg");
            for v in d {
                c.range(&dp, v, Some(0.0), Some(180.0), false)?;
            }
            zone.compass.deflection_deg = d;
        }
        if f.compass_anticlockwise == Some(true) {
            zone.compass_sign = -1.0;
        }
        out.push(zone);
    }
    Ok(out)
}
