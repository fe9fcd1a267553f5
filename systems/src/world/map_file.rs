//! ROS map_server maps: a YAML file (image, resolution, origin, negate, occupied_thresh,
//! free_thresh, mode) next to a PGM or PNG image. Semantics as in map_server's `loadMapFromFile`:
//! p = (255 − v) / 255 (or v / 255 with negate), occupied if p > occupied_thresh, free if
//! p < free_thresh, unknown otherwise; `origin` is the pose of the LOWER-left pixel while image
//! row 0 is the TOP row.

use super::grid::{Cell, OccupancyGrid};
use crate::core::input::{MAX_CONFIG_BYTES, read_text_bounded};
use serde::Deserialize;
use std::path::{Path, PathBuf};

#[derive(Debug, thiserror::Error)]
pub enum MapError {
    #[error("{path}: cannot read: {source}")]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path}: {message}")]
    Yaml { path: PathBuf, message: String },
    #[error("{path}: field `{field}`: {message}")]
    Field {
        path: PathBuf,
        field: &'static str,
        message: String,
    },
    #[error("{path}: cannot decode image: {message}")]
    Image { path: PathBuf, message: String },
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MapYaml {
    image: String,
    resolution: f64,
    origin: Vec<f64>,
    #[serde(default)]
    negate: u8,
    #[serde(default = "default_occupied")]
    occupied_thresh: f64,
    #[serde(default = "default_free")]
    free_thresh: f64,
    #[serde(default)]
    mode: Option<String>,
}

fn default_occupied() -> f64 {
    0.65
}
fn default_free() -> f64 {
    0.196
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Mode {
    Trinary,
    Scale,
    Raw,
}

/// Loads a map_server YAML and its image.
pub fn load_map(yaml_path: &Path) -> Result<OccupancyGrid, MapError> {
    let text = read_text_bounded(yaml_path, MAX_CONFIG_BYTES).map_err(|source| MapError::Read {
        path: yaml_path.to_path_buf(),
        source,
    })?;
    let y: MapYaml = serde_yaml_ng::from_str(&text).map_err(|e| MapError::Yaml {
        path: yaml_path.to_path_buf(),
        message: e.to_string(),
    })?;
    let field = |field: &'static str, message: String| MapError::Field {
        path: yaml_path.to_path_buf(),
        field,
        message,
    };
    if !(y.resolution.is_finite() && y.resolution > 0.0) {
        return Err(field(
            "resolution",
            format!(
                "expected a positive number of metres per cell, got {}",
                y.resolution
            ),
        ));
    }
    if y.origin.len() != 3 || y.origin.iter().any(|v| !v.is_finite()) {
        return Err(field(
            "origin",
            format!(
                "expected [x, y, yaw] (3 finite numbers), got {:?}",
                y.origin
            ),
        ));
    }
    if y.origin[2].abs() > 1e-9 {
        return Err(field(
            "origin",
            format!(
                "a rotated map origin (yaw {}) is not supported; rotate the image instead",
                y.origin[2]
            ),
        ));
    }
    if y.negate > 1 {
        return Err(field(
            "negate",
            format!("expected 0 or 1, got {}", y.negate),
        ));
    }
    for (name, v) in [
        ("occupied_thresh", y.occupied_thresh),
        ("free_thresh", y.free_thresh),
    ] {
        if !(0.0..=1.0).contains(&v) {
            return Err(field(
                if name == "free_thresh" {
                    "free_thresh"
                } else {
                    "occupied_thresh"
                },
                format!("expected a probability in [0, 1], got {v}"),
            ));
        }
    }
    if y.free_thresh >= y.occupied_thresh {
        return Err(field(
            "free_thresh",
            format!(
                "must be below occupied_thresh ({} >= {})",
                y.free_thresh, y.occupied_thresh
            ),
        ));
    }
    let mode = match y.mode.as_deref() {
        None | Some("trinary") => Mode::Trinary,
        Some("scale") => Mode::Scale,
        Some("raw") => Mode::Raw,
        Some(other) => {
            return Err(field(
                "mode",
                format!("expected trinary, scale or raw, got `{other}`"),
            ));
        }
    };
    if y.image.trim().is_empty() {
        return Err(field("image", "expected an image file name".into()));
    }
    let image_path = yaml_path.parent().unwrap_or(Path::new(".")).join(&y.image);
    let img = image::open(&image_path)
        .map_err(|e| match e {
            // the header was read: the pixels stop short of what it announced
            image::ImageError::IoError(source)
                if source.kind() == std::io::ErrorKind::UnexpectedEof =>
            {
                MapError::Image {
                    path: image_path.clone(),
                    message: "the image ends before its last pixel (the file is cut short)".into(),
                }
            }
            image::ImageError::IoError(source) => MapError::Read {
                path: image_path.clone(),
                source,
            },
            other => MapError::Image {
                path: image_path.clone(),
                message: other.to_string(),
            },
        })?
        .to_luma8();
    let (w, h) = (img.width() as usize, img.height() as usize);
    if w == 0 || h == 0 {
        return Err(MapError::Image {
            path: image_path,
            message: "the image is empty".into(),
        });
    }
    let mut grid = OccupancyGrid::new(
        w,
        h,
        y.resolution,
        [y.origin[0], y.origin[1]],
        Cell::Unknown,
    );
    for (x, img_row, px) in img.enumerate_pixels() {
        let v = px.0[0];
        let row = h - 1 - img_row as usize; // image row 0 is the top of the map
        let cell = classify(v, y.negate == 1, y.occupied_thresh, y.free_thresh, mode);
        grid.set(x as usize, row, cell);
    }
    Ok(grid)
}

fn classify(v: u8, negate: bool, occ: f64, free: f64, mode: Mode) -> Cell {
    if mode == Mode::Raw {
        return match v {
            0..=100 if v as f64 >= occ * 100.0 => Cell::Occupied,
            0..=100 if (v as f64) <= free * 100.0 => Cell::Free,
            _ => Cell::Unknown,
        };
    }
    let p = if negate {
        v as f64 / 255.0
    } else {
        (255.0 - v as f64) / 255.0
    };
    if p > occ {
        Cell::Occupied
    } else if p < free {
        Cell::Free
    } else {
        Cell::Unknown
    }
}

/// Writes a grid as a map_server YAML + PGM pair (trinary: 0 occupied, 254 free, 205 unknown).
pub fn save_map(grid: &OccupancyGrid, yaml_path: &Path) -> std::io::Result<()> {
    let stem = yaml_path
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("map");
    let pgm_name = format!("{stem}.pgm");
    let pgm_path = yaml_path.with_file_name(&pgm_name);
    let mut data = format!("P5\n{} {}\n255\n", grid.width, grid.height).into_bytes();
    for img_row in 0..grid.height {
        let row = grid.height - 1 - img_row;
        for col in 0..grid.width {
            data.push(match grid.get(col, row) {
                Cell::Occupied => 0,
                Cell::Free => 254,
                Cell::Unknown => 205,
            });
        }
    }
    std::fs::write(&pgm_path, data)?;
    let yaml = format!(
        "image: {pgm_name}\nresolution: {}\norigin: [{}, {}, 0.0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\nmode: trinary\n",
        grid.resolution, grid.origin[0], grid.origin[1]
    );
    std::fs::write(yaml_path, yaml)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write_fixture(dir: &Path, yaml: &str, pgm: &[u8]) -> PathBuf {
        std::fs::write(dir.join("m.pgm"), pgm).unwrap();
        let p = dir.join("m.yaml");
        std::fs::write(&p, yaml).unwrap();
        p
    }

    /// 3 × 2 image, rows top to bottom: [0 254 205] / [254 254 0].
    fn asymmetric_pgm() -> Vec<u8> {
        let mut v = b"P5\n3 2\n255\n".to_vec();
        v.extend_from_slice(&[0, 254, 205, 254, 254, 0]);
        v
    }

    #[test]
    fn asymmetric_fixture_maps_rows_bottom_up() {
        let dir = tempfile::tempdir().unwrap();
        let p = write_fixture(
            dir.path(),
            "image: m.pgm\nresolution: 0.5\norigin: [-1.0, 2.0, 0.0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n",
            &asymmetric_pgm(),
        );
        let g = load_map(&p).unwrap();
        assert_eq!((g.width, g.height), (3, 2));
        // the image's top-left pixel is the map's upper-left cell: (col 0, row 1)
        assert_eq!(g.get(0, 1), Cell::Occupied);
        assert_eq!(g.get(1, 1), Cell::Free);
        assert_eq!(g.get(2, 1), Cell::Unknown);
        assert_eq!(g.get(2, 0), Cell::Occupied);
        assert_eq!(g.get(0, 0), Cell::Free);
        // origin is the lower-left corner of the lower-left pixel
        assert_eq!(g.cell_of(-0.99, 2.01), Some((0, 0)));
        assert_eq!(g.cell_of(-0.99, 2.51), Some((0, 1)));
    }

    #[test]
    fn negate_inverts() {
        let dir = tempfile::tempdir().unwrap();
        let p = write_fixture(
            dir.path(),
            "image: m.pgm\nresolution: 1\norigin: [0, 0, 0]\nnegate: 1\n",
            &asymmetric_pgm(),
        );
        let g = load_map(&p).unwrap();
        assert_eq!(g.get(0, 1), Cell::Free);
        assert_eq!(g.get(1, 1), Cell::Occupied);
    }

    #[test]
    fn save_then_load_round_trips() {
        let dir = tempfile::tempdir().unwrap();
        let mut g = OccupancyGrid::new(4, 3, 0.05, [1.5, -2.0], Cell::Free);
        g.set(3, 0, Cell::Occupied);
        g.set(0, 2, Cell::Unknown);
        let p = dir.path().join("out.yaml");
        save_map(&g, &p).unwrap();
        assert_eq!(load_map(&p).unwrap(), g);
    }

    fn err_of(yaml: &str) -> String {
        let dir = tempfile::tempdir().unwrap();
        let p = write_fixture(dir.path(), yaml, &asymmetric_pgm());
        load_map(&p).unwrap_err().to_string()
    }

    /// A PGM cut short after its header is an image error saying so, not a read error.
    #[test]
    fn a_cut_image_says_it_is_cut_short() {
        let dir = tempfile::tempdir().unwrap();
        let pgm = asymmetric_pgm();
        let yaml = "image: m.pgm\nresolution: 1\norigin: [0,0,0]\n";
        let p = write_fixture(dir.path(), yaml, &pgm[..pgm.len() - 2]);
        let e = load_map(&p).unwrap_err().to_string();
        assert!(e.contains("m.pgm") && e.contains("cut short"), "{e}");
    }

    #[test]
    fn bad_yaml_fields_are_named() {
        let e = err_of("image: m.pgm\nresolution: -1\norigin: [0,0,0]\n");
        assert!(e.contains("m.yaml") && e.contains("resolution"), "{e}");
        let e = err_of("image: m.pgm\nresolution: 1\norigin: [0,0]\n");
        assert!(e.contains("origin") && e.contains("3 finite"), "{e}");
        let e = err_of("image: m.pgm\nresolution: 1\norigin: [0,0,0.5]\n");
        assert!(e.contains("rotated"), "{e}");
        let e = err_of("image: m.pgm\nresolution: 1\norigin: [0,0,0]\nfree_thresh: 0.9\n");
        assert!(e.contains("free_thresh"), "{e}");
        let e = err_of("image: m.pgm\nresolution: 1\norigin: [0,0,0]\nmode: fancy\n");
        assert!(e.contains("mode"), "{e}");
        let e = err_of("image: m.pgm\nresolution: 1\norigin: [0,0,0]\ncolour: red\n");
        assert!(e.contains("colour"), "{e}");
        let e = err_of("image: missing.pgm\nresolution: 1\norigin: [0,0,0]\n");
        assert!(e.contains("missing.pgm"), "{e}");
        let e = err_of("resolution: 1\norigin: [0,0,0]\n");
        assert!(e.contains("image"), "{e}");
    }

    #[test]
    fn corrupt_image_is_an_error() {
        let dir = tempfile::tempdir().unwrap();
        let p = write_fixture(
            dir.path(),
            "image: m.pgm\nresolution: 1\norigin: [0,0,0]\n",
            b"P5\n3 2\n255\n\x00",
        );
        let e = load_map(&p).unwrap_err().to_string();
        assert!(e.contains("m.pgm"), "{e}");
    }
}
