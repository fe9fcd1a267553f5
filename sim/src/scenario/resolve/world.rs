//! Points read from the map and its places, for robots, events and people.

use crate::scenario::check::{Checker, PointOrPlace, R};
use crate::scenario::error::KeyPath;
use std::collections::BTreeMap;
use systems::core::Pose2;
use systems::world::OccupancyGrid;

/// The map and its places, as every robot, event and person reads points from them.
pub(super) struct World<'a> {
    pub(super) c: &'a Checker<'a>,
    pub(super) grid: &'a OccupancyGrid,
    pub(super) places: &'a BTreeMap<String, Pose2>,
}

impl World<'_> {
    /// A pose from coordinates (`[x, y]` or `[x, y, yaw]`) or a place name.
    pub(super) fn point(&self, path: &KeyPath, p: &PointOrPlace) -> R<Pose2> {
        let c = self.c;
        match p {
            PointOrPlace::Coords(v) if v.len() == 2 || v.len() == 3 => {
                c.finite(path, v)?;
                Ok(Pose2::new(v[0], v[1], v.get(2).copied().unwrap_or(0.0)))
            }
            PointOrPlace::Coords(v) => c.err(
                path,
                format!("expected [x, y] or [x, y, yaw], got {} numbers", v.len()),
            ),
            PointOrPlace::Place(name) => self.places.get(name).copied().ok_or_else(|| {
                let known: Vec<&str> = self.places.keys().map(String::as_str).collect();
                c.cx.at(
                    path,
                    if known.is_empty() {
                        format!("unknown place `{name}` (the map has no places file)")
                    } else {
                        format!("unknown place `{name}`; known places: {}", known.join(", "))
                    },
                )
            }),
        }
    }

    /// An error unless `p` lies on the map.
    pub(super) fn inside(&self, path: &KeyPath, p: &Pose2) -> R<()> {
        let b = self.grid.bounds();
        if p.x < b[0] || p.y < b[1] || p.x > b[2] || p.y > b[3] {
            return self.c.err(
                path,
                format!(
                    "({:.3}, {:.3}) lies outside the map [{:.2}, {:.2}] × [{:.2}, {:.2}]",
                    p.x, p.y, b[0], b[2], b[1], b[3]
                ),
            );
        }
        Ok(())
    }

    /// The `points` key under `path`: at least one point, each on the map.
    pub(super) fn points(
        &self,
        path: &KeyPath,
        pts: &Option<Vec<PointOrPlace>>,
    ) -> R<Vec<[f64; 2]>> {
        let Some(pts) = pts else {
            return self
                .c
                .err(path, "missing `points` (a list of [x, y] or place names)");
        };
        if pts.is_empty() {
            return self
                .c
                .err(&path.key("points"), "expected at least one point");
        }
        let mut out = Vec::new();
        for (i, p) in pts.iter().enumerate() {
            let pp = path.key("points").index(i);
            let pose = self.point(&pp, p)?;
            self.inside(&pp, &pose)?;
            out.push([pose.x, pose.y]);
        }
        Ok(out)
    }

    /// A point on the map.
    pub(super) fn point_inside(&self, path: &KeyPath, v: &PointOrPlace) -> R<Pose2> {
        let pose = self.point(path, v)?;
        self.inside(path, &pose)?;
        Ok(pose)
    }
}
