//! The improved matcher's judge ([`super::improved`], steps 5–6): a candidate transform scores
//! `inliers − weight · violations`. Inliers are current points within `inlier_distance` of the
//! reference surface; violations are points of either scan that the transform puts well in
//! front of what the other scan measured along the same bearing ([`super::visibility`]),
//! counted by runs so that a person or robot that moved between the scans costs one violation.

use super::de::Vector;
use super::refine::Reference;
use super::visibility::RangeImage;

/// What the judge sees of both scans.
pub(super) struct Judge<'a> {
    pub model: Reference<'a>,
    pub ref_image: RangeImage,
    pub cur_image: RangeImage,
    pub inlier_distance: f32,
    pub end_tangent: f32,
    pub margin: f32,
    pub weight: f32,
    pub blob_extent: f32,
}

/// Free-space violations counted by runs. Consecutive violating points of one scan (in scan
/// order, each within [`RUN_GAP`] of the previous) form a run; a run whose end points lie less
/// than `blob_extent` apart is a compact object — in a right alignment, a person or robot that
/// moved between the scans — and counts once, any longer run counts every point. A wrong
/// alignment pushes whole walls through free space, which stays expensive.
struct ViolationRuns {
    blob_extent: f32,
    total: usize,
    first: [f32; 2],
    last: [f32; 2],
    len: usize,
}

/// Largest gap (m) between successive points of one violation run.
pub(super) const RUN_GAP: f32 = 0.25;

impl ViolationRuns {
    fn new(blob_extent: f32) -> Self {
        ViolationRuns {
            blob_extent,
            total: 0,
            first: [0.0; 2],
            last: [0.0; 2],
            len: 0,
        }
    }

    #[inline]
    fn violation(&mut self, p: [f32; 2]) {
        if self.len > 0 && dist2(self.last, p) > RUN_GAP * RUN_GAP {
            self.close();
        }
        if self.len == 0 {
            self.first = p;
        }
        self.last = p;
        self.len += 1;
    }

    /// A point that does not violate ends the current run.
    #[inline]
    fn other(&mut self) {
        if self.len > 0 {
            self.close();
        }
    }

    fn close(&mut self) {
        let compact = dist2(self.first, self.last) < self.blob_extent * self.blob_extent;
        self.total += if compact { 1 } else { self.len };
        self.len = 0;
    }

    fn finish(mut self) -> usize {
        self.other();
        self.total
    }
}

/// Squared distance of two points.
#[inline(always)]
pub(super) fn dist2(a: [f32; 2], b: [f32; 2]) -> f32 {
    (a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1])
}

impl Judge<'_> {
    /// (inliers of `current`, free-space violations of both sets) for transform `t`.
    /// Violations are counted per [`ViolationRuns`]: a compact run is one moving object.
    pub fn count(
        &self,
        current: &[[f32; 2]],
        reference: &[[f32; 2]],
        t: &Vector,
    ) -> (usize, usize) {
        let (s, c) = t[2].sin_cos();
        let (s, c, tx, ty) = (s as f32, c as f32, t[0] as f32, t[1] as f32);
        let mut inliers = 0;
        let mut runs = ViolationRuns::new(self.blob_extent);
        for b in current {
            let q = [c * b[0] - s * b[1] + tx, s * b[0] + c * b[1] + ty];
            if self
                .model
                .distance(q, self.end_tangent)
                .is_some_and(|d| d <= self.inlier_distance)
            {
                inliers += 1;
                runs.other();
            } else if self.ref_image.violates(q, self.margin) {
                runs.violation(*b);
            } else {
                runs.other();
            }
        }
        runs.other();
        // reference points in the current frame: b = Rᵀ (a − t)
        for a in reference {
            let (dx, dy) = (a[0] - tx, a[1] - ty);
            if self
                .cur_image
                .violates([c * dx + s * dy, -s * dx + c * dy], self.margin)
            {
                runs.violation(*a);
            } else {
                runs.other();
            }
        }
        (inliers, runs.finish())
    }

    /// Inliers of `current` only.
    pub fn inliers(&self, current: &[[f32; 2]], t: &Vector) -> usize {
        let (s, c) = t[2].sin_cos();
        let (s, c, tx, ty) = (s as f32, c as f32, t[0] as f32, t[1] as f32);
        current
            .iter()
            .filter(|b| {
                let q = [c * b[0] - s * b[1] + tx, s * b[0] + c * b[1] + ty];
                self.model
                    .distance(q, self.end_tangent)
                    .is_some_and(|d| d <= self.inlier_distance)
            })
            .count()
    }

    /// The judged score `inliers − weight · violations`, and the inliers.
    pub fn score(&self, current: &[[f32; 2]], reference: &[[f32; 2]], t: &Vector) -> (f64, usize) {
        let n = self.count(current, reference, t);
        (n.0 as f64 - self.weight as f64 * n.1 as f64, n.0)
    }
}

#[cfg(test)]
mod tests {
    use super::ViolationRuns;

    fn total(points: &[Option<[f32; 2]>], blob_extent: f32) -> usize {
        let mut runs = ViolationRuns::new(blob_extent);
        for p in points {
            match p {
                Some(p) => runs.violation(*p),
                None => runs.other(),
            }
        }
        runs.finish()
    }

    #[test]
    fn a_compact_run_counts_once_a_wall_counts_every_point() {
        // a person: 9 points over 0.4 m; a wall: 30 points over 1.5 m
        let person: Vec<_> = (0..9).map(|k| Some([5.0, 0.05 * k as f32])).collect();
        let wall: Vec<_> = (0..30)
            .map(|k| Some([2.0 + 0.05 * k as f32, 3.0]))
            .collect();
        assert_eq!(total(&person, 0.7), 1);
        assert_eq!(total(&wall, 0.7), 30);
        // a non-violating point or a gap over 0.25 m splits runs
        let mut two = person.clone();
        two.push(None);
        two.extend(person.iter().cloned());
        assert_eq!(total(&two, 0.7), 2);
        let far: Vec<_> = [[0.0, 0.0], [0.1, 0.0], [0.5, 0.0]].map(Some).to_vec();
        assert_eq!(total(&far, 0.7), 2);
        // blob_extent 0 counts every point
        assert_eq!(total(&person, 0.0), 9);
        assert_eq!(total(&[], 0.7), 0);
    }
}
