//! The belief's window. Once the belief has gathered, the selective update scores a few cells
//! of the lattice's million [Fox 1999b, §4.2], yet every pass of the prediction and the
//! correction still walked all of them. So the belief is then held cell by cell only on a
//! rectangle of the lattice (all θ layers) around the cells at or above the selective threshold,
//! [`super::WINDOW_MARGIN`] cells beyond them on every side; every free cell outside holds one
//! value, the background: the mass outside spread evenly, which the correction weighs as the
//! selective update weighs every cell it does not score (by the floor's likelihood), and the
//! motion carries in where the window's cells come from outside it
//! ([`super::prediction::Edge`]).
//!
//! The window follows the cells above the threshold, and the grid holds the whole lattice again
//! whenever the window would not do: the background reaches the threshold (the robot is lost and
//! the far cells count again), a motion or a blur would move mass further than half the margin,
//! or the cells above the threshold spread over half of the lattice. The belief's cells below
//! the threshold are all that the window changes, and only in how they are held: those outside
//! it are pooled into the background, never scored either way.

use super::layout::{Rect, Span};
use super::{MarkovGrid, WINDOW_MARGIN as MARGIN, belief_ops};

/// A window more than this many times the area it needs is made smaller.
const SLACK: usize = 4;

impl MarkovGrid {
    /// Whether the belief is held on a window smaller than the lattice.
    pub fn is_windowed(&self) -> bool {
        self.layout.nx != self.whole.nx || self.layout.ny != self.whole.ny
    }

    /// The window's cells in the whole lattice.
    pub fn window(&self) -> Rect {
        Rect {
            i0: self.at[0],
            j0: self.at[1],
            nx: self.layout.nx,
            ny: self.layout.ny,
        }
    }

    /// The probability of the whole belief: the window's cells and the background's mass.
    pub fn total_mass(&self) -> f64 {
        belief_ops::sum(&self.belief) + self.outside
    }

    /// Free cells (× θ layers) outside the window.
    pub(super) fn outside_cells(&self) -> usize {
        (self.whole.free_count() - self.layout.free_count()) * self.whole.n_theta
    }

    /// The belief of each free cell outside the window.
    pub fn background(&self) -> f32 {
        match self.outside_cells() {
            0 => 0.0,
            n => (self.outside / n as f64) as f32,
        }
    }

    /// Holds the whole lattice again, the cells outside the window at the background.
    pub(super) fn unwindow(&mut self) {
        if self.is_windowed() {
            self.set_window(self.whole.rect());
        }
    }

    /// Holds the belief on `r` (cells of the whole lattice): the cells it shares with the
    /// window keep their values, the others take the background, and the mass of the window's
    /// cells outside `r` joins the background's. The total is kept.
    pub(super) fn set_window(&mut self, r: Rect) {
        let background = self.background();
        let total = self.total_mass();
        let (old, old_at) = (self.window(), self.at);
        let layout = self.whole.crop(&r);
        let mut belief = vec![0.0f32; layout.len()];
        let (layer, old_layer) = (layout.layer(), self.layout.layer());
        // the rows and columns both hold, in whole-lattice cells
        let (i0, i1) = (r.i0.max(old.i0), (r.i0 + r.nx).min(old.i0 + old.nx));
        let (j0, j1) = (r.j0.max(old.j0), (r.j0 + r.ny).min(old.j0 + old.ny));
        for (k, out) in belief.chunks_mut(layer).enumerate() {
            for s in &layout.spans {
                let a = s.j as usize * layout.nx + s.i0 as usize;
                out[a..a + s.len as usize].fill(background);
            }
            let from = &self.belief[k * old_layer..(k + 1) * old_layer];
            for j in j0..j1.max(j0) {
                if i0 >= i1 {
                    break;
                }
                let src = (j - old_at[1]) * self.layout.nx + (i0 - old_at[0]);
                let dst = (j - r.j0) * layout.nx + (i0 - r.i0);
                out[dst..dst + (i1 - i0)].copy_from_slice(&from[src..src + (i1 - i0)]);
            }
        }
        self.scratch = vec![0.0; layout.len()];
        self.belief = belief;
        self.layout = layout;
        self.at = [r.i0, r.j0];
        self.outside = if self.is_windowed() {
            (total - belief_ops::sum(&self.belief)).max(0.0)
        } else {
            0.0
        };
    }

    /// After a correction whose active cells were `runs` (per θ layer, window cells) and whose
    /// most probable cell is `best` (an index of the belief): the window that holds them with
    /// its margin, made anew where the present one is too tight or too large. Returns `best`
    /// as an index of the belief after the move.
    pub(super) fn follow(&mut self, runs: &[Vec<Span>], best: Option<usize>) -> Option<usize> {
        let layer = self.layout.layer();
        let nx = self.layout.nx;
        let best_cell = best.map(|b| (b / layer, (b % layer) % nx, (b % layer) / nx));
        let cells = runs
            .iter()
            .flatten()
            .map(|s| (s.i0 as usize, s.j as usize, s.len as usize))
            .chain(best_cell.map(|(_, i, j)| (i, j, 1)));
        let mut held: Option<[usize; 4]> = None;
        for (i, j, len) in cells {
            let h = held.get_or_insert([i, j, i + len, j + 1]);
            *h = [h[0].min(i), h[1].min(j), h[2].max(i + len), h[3].max(j + 1)];
        }
        let Some([i0, j0, i1, j1]) = held else {
            return best;
        };
        let held = Rect {
            i0: i0 + self.at[0],
            j0: j0 + self.at[1],
            nx: i1 - i0,
            ny: j1 - j0,
        };
        let whole = self.whole.rect();
        let want = held.grown(MARGIN, &whole);
        let current = self.window();
        let target = if self.hold_whole || 2 * want.area() >= whole.area() {
            whole
        } else if current.contains(&held.grown(MARGIN / 2, &whole))
            && current.area() <= SLACK * want.area()
        {
            current
        } else {
            want
        };
        if target == current {
            return best;
        }
        self.set_window(target);
        best_cell.map(|(k, i, j)| {
            let (i, j) = (i + current.i0 - target.i0, j + current.j0 - target.j0);
            k * self.layout.layer() + j * self.layout.nx + i
        })
    }
}

#[cfg(test)]
mod tests {
    use super::super::{MarkovGrid, MarkovGridConfig};
    use crate::core::Pose2;
    use crate::localization::map_localizer::MapLocalizer;
    use crate::localization::mcl::BeamSubset;
    use crate::localization::motion_model::OdometryMotionModel;
    use crate::localization::test_drive::{CORRIDOR, drive, hospital};

    /// Along a drive from a global start the grid on its window estimates what the grid held
    /// whole does, to within a millimetre and a hundredth of a degree, and keeps its mass.
    #[test]
    fn the_window_estimates_what_the_whole_lattice_does() {
        let map = hospital();
        let config = MarkovGridConfig {
            motion: OdometryMotionModel {
                alpha1: 0.05,
                alpha2: 0.05,
                alpha3: 0.05,
                alpha4: 0.05,
            },
            ..MarkovGridConfig::default()
        };
        let mut windowed = MarkovGrid::new(config.clone(), &map);
        let mut whole = MarkovGrid::new(config, &map);
        whole.hold_whole = true;
        let (mut updates, mut on_window, mut moved) = (0, 0, 0);
        let mut last = windowed.window();
        let mut shares = Vec::new();
        drive(&map, &CORRIDOR, 0.0, 7, |_, odom, scan| {
            let pts = BeamSubset::from_scan(scan, &Pose2::IDENTITY, 60).returns();
            let a = windowed.update(&map, &pts, scan.range_max, odom);
            let b = whole.update(&map, &pts, scan.range_max, odom);
            assert_eq!(a, b);
            if !a {
                return;
            }
            updates += 1;
            assert!(!whole.is_windowed());
            on_window += usize::from(windowed.is_windowed());
            moved += usize::from(windowed.is_windowed() && windowed.window() != last);
            last = windowed.window();
            let (e, f) = (windowed.estimate().unwrap(), whole.estimate().unwrap());
            let dxy = e.pose.distance(&f.pose);
            let dth = crate::core::wrap_angle(e.pose.theta - f.pose.theta).abs();
            assert!(
                dxy < 1e-3 && dth < 0.01f64.to_radians(),
                "update {updates}: {:?} against {:?}",
                e.pose,
                f.pose
            );
            assert!((windowed.total_mass() - 1.0).abs() < 1e-5);
            if windowed.is_windowed() {
                shares.push(windowed.layout.len() as f64 / whole.layout.len() as f64);
            }
        });
        assert!(
            updates > 100 && on_window > updates / 2 && moved > 3,
            "{on_window} of {updates} updates on a window, which moved {moved} times"
        );
        // the window is a small part of the lattice
        shares.sort_by(f64::total_cmp);
        let median = shares[shares.len() / 2];
        assert!(median < 0.05, "the window holds {median} of the lattice");
    }
}
