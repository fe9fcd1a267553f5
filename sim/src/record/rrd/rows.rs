//! The .rrd's frequent rows (poses, points, line strips, scalar series) written as plain
//! component values ([`RrdStream::row`]), so they cost a few pushes instead of an archetype's
//! Arrow arrays per row. Each returns the row, for more components (labels, radii).
//!
//! Sizes are in UI points (screen units), not metres, so robots, scans, particles and paths
//! stay visible at every zoom, the whole building included.

use super::stream::{Row, RrdStream};
use rerun::components::{Color, LineStrip3D, Position3D, Radius, Scalar, Vector3D};
use rerun::{Arrows3D, LineStrips3D, Points3D, Scalars};
use systems::core::Pose2;

/// Line width of arrows and outlines (UI points, as a radius).
pub const LINE: f32 = 1.5;
/// Line width of driven and estimated paths (UI points, as a radius).
pub const PATH: f32 = 1.5;

/// An arrow of length `len` from the pose's position along its heading (z = 0).
pub fn arrow<'a>(rec: &'a mut RrdStream, path: &str, p: &Pose2, len: f32, c: Color) -> Row<'a> {
    let (s, co) = p.theta.sin_cos();
    rec.row(path)
        .with(
            Arrows3D::descriptor_vectors(),
            [Vector3D::from([len * co as f32, len * s as f32, 0.0])],
        )
        .with(
            Arrows3D::descriptor_origins(),
            [Position3D::from([p.x as f32, p.y as f32, 0.0])],
        )
        .with(Arrows3D::descriptor_colors(), [c])
        .with(Arrows3D::descriptor_radii(), [Radius::new_ui_points(LINE)])
}

/// One value of a scalar series.
pub fn scalar<'a>(rec: &'a mut RrdStream, path: &str, v: f64) -> Row<'a> {
    rec.row(path)
        .with(Scalars::descriptor_scalars(), [Scalar::from(v)])
}

/// Line strips of one colour, [`LINE`] wide.
pub fn strips<'a, S: IntoIterator<Item = [f32; 3]>>(
    rec: &'a mut RrdStream,
    path: &str,
    strips: impl IntoIterator<Item = S>,
    c: Color,
) -> Row<'a> {
    lines(rec, path, strips, c, LINE)
}

/// New segments of a path (`…/path` entities), [`PATH`] wide.
pub fn path<'a, S: IntoIterator<Item = [f32; 3]>>(
    rec: &'a mut RrdStream,
    path: &str,
    strips: impl IntoIterator<Item = S>,
    c: Color,
) -> Row<'a> {
    lines(rec, path, strips, c, PATH)
}

/// Line strips of one colour and width (UI points, as a radius).
fn lines<'a, S: IntoIterator<Item = [f32; 3]>>(
    rec: &'a mut RrdStream,
    path: &str,
    strips: impl IntoIterator<Item = S>,
    c: Color,
    radius: f32,
) -> Row<'a> {
    rec.row(path)
        .with(
            LineStrips3D::descriptor_strips(),
            strips.into_iter().map(LineStrip3D::from),
        )
        .with(LineStrips3D::descriptor_colors(), [c])
        .with(
            LineStrips3D::descriptor_radii(),
            [Radius::new_ui_points(radius)],
        )
}

/// Points of one radius (`Radius::new_ui_points` or `new_scene_units`).
pub fn points<'a>(
    rec: &'a mut RrdStream,
    path: &str,
    pts: impl IntoIterator<Item = [f32; 3]>,
    radius: Radius,
) -> Row<'a> {
    rec.row(path)
        .with(
            Points3D::descriptor_positions(),
            pts.into_iter().map(Position3D::from),
        )
        .with(Points3D::descriptor_radii(), [radius])
}
