//! Other robots as laser obstacles: every robot's footprint in the world at the current tick,
//! bucketed on a coarse grid so a laser only looks at robots within its range.

use crate::body::{Footprint, TruePose};
use crate::core::RobotIndex;
use bevy_ecs::prelude::*;

/// Bucket side (m).
const BUCKET: f64 = 4.0;

/// Reusable output of [`RobotOutlines::near`].
#[derive(Default)]
pub struct NearbyRobots {
    pub circles: Vec<[f32; 3]>,
    pub segments: Vec<[f32; 4]>,
    ids: Vec<u32>,
}

#[derive(Resource, Default)]
pub struct RobotOutlines {
    /// Per robot (by index): circle (cx, cy, r) or polygon edges.
    circles: Vec<Option<[f32; 3]>>,
    polygons: Vec<Vec<[f32; 4]>>,
    centres: Vec<[f64; 3]>,
    /// Bucket → robots in it (a fast non-cryptographic hash: a scan looks up ~100 buckets).
    buckets: rustc_hash::FxHashMap<(i32, i32), Vec<u32>>,
}

impl RobotOutlines {
    /// Robots (other than `except`) whose bounding discs come within `range` of (x, y), in index
    /// order, as circles and segments.
    pub fn near(&self, x: f64, y: f64, range: f64, except: u32, out: &mut NearbyRobots) {
        let NearbyRobots {
            circles,
            segments,
            ids: scratch,
        } = out;
        circles.clear();
        segments.clear();
        scratch.clear();
        let b0 = (
            ((x - range) / BUCKET).floor() as i32,
            ((y - range) / BUCKET).floor() as i32,
        );
        let b1 = (
            ((x + range) / BUCKET).floor() as i32,
            ((y + range) / BUCKET).floor() as i32,
        );
        let nb = ((b1.0 - b0.0 + 1) as i64) * ((b1.1 - b0.1 + 1) as i64);
        if nb as usize > self.buckets.len() {
            // huge range relative to the world: scan the occupied buckets instead
            for (k, v) in &self.buckets {
                if k.0 >= b0.0 && k.0 <= b1.0 && k.1 >= b0.1 && k.1 <= b1.1 {
                    scratch.extend_from_slice(v);
                }
            }
        } else {
            for bx in b0.0..=b1.0 {
                for by in b0.1..=b1.1 {
                    if let Some(v) = self.buckets.get(&(bx, by)) {
                        scratch.extend_from_slice(v);
                    }
                }
            }
        }
        scratch.sort_unstable();
        for &i in scratch.iter() {
            if i == except {
                continue;
            }
            let c = self.centres[i as usize];
            let (dx, dy, reach) = (c[0] - x, c[1] - y, range + c[2]);
            if dx * dx + dy * dy > reach * reach {
                continue;
            }
            if let Some(circle) = self.circles[i as usize] {
                circles.push(circle);
            } else {
                segments.extend_from_slice(&self.polygons[i as usize]);
            }
        }
    }
}

/// Sense (first): refresh every robot's outline.
pub fn update_robot_outlines(
    mut outlines: ResMut<RobotOutlines>,
    robots: Query<(&RobotIndex, &TruePose, &Footprint)>,
) {
    let n = robots
        .iter()
        .map(|(i, _, _)| i.0 as usize + 1)
        .max()
        .unwrap_or(0);
    let o = &mut *outlines;
    o.circles.clear();
    o.circles.resize(n, None);
    o.polygons.resize_with(n, Vec::new);
    o.centres.clear();
    o.centres.resize(n, [f64::NAN; 3]);
    for v in o.buckets.values_mut() {
        v.clear();
    }
    for (idx, truth, footprint) in robots.iter() {
        let i = idx.0 as usize;
        let p = truth.pose;
        o.centres[i] = [p.x, p.y, footprint.bounding_radius()];
        match footprint {
            Footprint::Circle { radius } => {
                o.circles[i] = Some([p.x as f32, p.y as f32, *radius as f32]);
            }
            Footprint::Rectangle { .. } => {
                let pts = footprint.outline(&p);
                let poly = &mut o.polygons[i];
                poly.clear();
                for k in 0..pts.len() {
                    let a = pts[k];
                    let b = pts[(k + 1) % pts.len()];
                    poly.push([a[0] as f32, a[1] as f32, b[0] as f32, b[1] as f32]);
                }
            }
        }
        let key = ((p.x / BUCKET).floor() as i32, (p.y / BUCKET).floor() as i32);
        o.buckets.entry(key).or_default().push(idx.0);
    }
    o.buckets.retain(|_, v| !v.is_empty());
}
