//! The .rrd's frequent rows (poses, points, line strips, scalar series) written as plain
//! component values ([`RrdStream::row`]), so they cost a few pushes instead of an archetype's
//! Arrow arrays per row. Each returns the row, for more components (labels, radii).

use super::stream::{Row, RrdStream};
use rerun::components::{Color, LineStrip3D, Position3D, Radius, Scalar, Vector3D};
use rerun::{Arrows3D, LineStrips3D, Points3D, Scalars};
use systems::core::Pose2;

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
}

/// One value of a scalar series.
pub fn scalar<'a>(rec: &'a mut RrdStream, path: &str, v: f64) -> Row<'a> {
    rec.row(path)
        .with(Scalars::descriptor_scalars(), [Scalar::from(v)])
}

/// Line strips of one colour.
pub fn strips<'a, S: IntoIterator<Item = [f32; 3]>>(
    rec: &'a mut RrdStream,
    path: &str,
    strips: impl IntoIterator<Item = S>,
    c: Color,
) -> Row<'a> {
    rec.row(path)
        .with(
            LineStrips3D::descriptor_strips(),
            strips.into_iter().map(LineStrip3D::from),
        )
        .with(LineStrips3D::descriptor_colors(), [c])
}

/// Points of one radius (m).
pub fn points<'a>(
    rec: &'a mut RrdStream,
    path: &str,
    pts: impl IntoIterator<Item = [f32; 3]>,
    radius: f32,
) -> Row<'a> {
    rec.row(path)
        .with(
            Points3D::descriptor_positions(),
            pts.into_iter().map(Position3D::from),
        )
        .with(
            Points3D::descriptor_radii(),
            [Radius::new_scene_units(radius)],
        )
}
