//! The histogram's geometry: a coarse (x, y) lattice over the map, θ in equal bins, and which
//! (x, y) cells can hold the robot (free at their centre), as runs per row so the kernels walk
//! contiguous memory.

use crate::world::{Cell, OccupancyGrid};

/// A run of free histogram cells in row `j`: columns `i0 .. i0 + len`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Span {
    pub j: u32,
    pub i0: u32,
    pub len: u32,
}

#[derive(Clone, Debug)]
pub struct Layout {
    /// Cell size (m) and cells per row / column.
    pub resolution: f64,
    pub nx: usize,
    pub ny: usize,
    /// θ bins over (−π, π]; bin k is centred on −π + (k + ½)·2π/nθ.
    pub n_theta: usize,
    pub origin: [f64; 2],
    /// Map column / row of each histogram column / row's centre.
    pub fine_col: Vec<u32>,
    pub fine_row: Vec<u32>,
    /// Whether each (x, y) cell (row-major) is free at its centre.
    pub free: Vec<bool>,
    pub spans: Vec<Span>,
}

impl Layout {
    pub fn new(grid: &OccupancyGrid, resolution: f64, n_theta: usize) -> Self {
        let ratio = resolution / grid.resolution;
        let nx = ((grid.width as f64 / ratio).ceil() as usize).max(1);
        let ny = ((grid.height as f64 / ratio).ceil() as usize).max(1);
        let fine = |i: usize, n: usize| (((i as f64 + 0.5) * ratio) as usize).min(n - 1) as u32;
        let fine_col: Vec<u32> = (0..nx).map(|i| fine(i, grid.width)).collect();
        let fine_row: Vec<u32> = (0..ny).map(|j| fine(j, grid.height)).collect();
        let mut free = vec![false; nx * ny];
        let mut spans = Vec::new();
        for j in 0..ny {
            let mut run: Option<u32> = None;
            for i in 0..=nx {
                let f =
                    i < nx && grid.get(fine_col[i] as usize, fine_row[j] as usize) == Cell::Free;
                if i < nx {
                    free[j * nx + i] = f;
                }
                match (f, run) {
                    (true, None) => run = Some(i as u32),
                    (false, Some(i0)) => {
                        spans.push(Span {
                            j: j as u32,
                            i0,
                            len: i as u32 - i0,
                        });
                        run = None;
                    }
                    _ => {}
                }
            }
        }
        Layout {
            resolution,
            nx,
            ny,
            n_theta: n_theta.max(1),
            origin: grid.origin,
            fine_col,
            fine_row,
            free,
            spans,
        }
    }

    /// Cells per θ layer.
    pub fn layer(&self) -> usize {
        self.nx * self.ny
    }

    /// All cells.
    pub fn len(&self) -> usize {
        self.layer() * self.n_theta
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Free (x, y) cells.
    pub fn free_count(&self) -> usize {
        self.spans.iter().map(|s| s.len as usize).sum()
    }

    pub fn theta_step(&self) -> f64 {
        std::f64::consts::TAU / self.n_theta as f64
    }

    /// Centre heading of bin `k`.
    pub fn theta(&self, k: usize) -> f64 {
        -std::f64::consts::PI + (k as f64 + 0.5) * self.theta_step()
    }

    /// World centre of cell (i, j).
    pub fn centre(&self, i: usize, j: usize) -> (f64, f64) {
        (
            self.origin[0] + (i as f64 + 0.5) * self.resolution,
            self.origin[1] + (j as f64 + 0.5) * self.resolution,
        )
    }

    /// The (i, j, k) cell holding a pose, if it is on the lattice.
    pub fn cell_of(&self, x: f64, y: f64, theta: f64) -> Option<(usize, usize, usize)> {
        let i = ((x - self.origin[0]) / self.resolution).floor();
        let j = ((y - self.origin[1]) / self.resolution).floor();
        if i < 0.0 || j < 0.0 || i >= self.nx as f64 || j >= self.ny as f64 {
            return None;
        }
        let k = ((crate::core::wrap_angle(theta) + std::f64::consts::PI) / self.theta_step())
            .floor() as usize
            % self.n_theta;
        Some((i as usize, j as usize, k))
    }
}

/// A rectangle of the lattice: columns `i0 .. i0 + nx`, rows `j0 .. j0 + ny`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Rect {
    pub i0: usize,
    pub j0: usize,
    pub nx: usize,
    pub ny: usize,
}

impl Rect {
    pub fn area(&self) -> usize {
        self.nx * self.ny
    }

    /// Whether `other` lies wholly inside.
    pub fn contains(&self, other: &Rect) -> bool {
        other.i0 >= self.i0
            && other.j0 >= self.j0
            && other.i0 + other.nx <= self.i0 + self.nx
            && other.j0 + other.ny <= self.j0 + self.ny
    }

    /// Grown by `by` cells on every side, clipped to `bounds`.
    pub fn grown(&self, by: usize, bounds: &Rect) -> Rect {
        let (i0, j0) = (
            self.i0.saturating_sub(by).max(bounds.i0),
            self.j0.saturating_sub(by).max(bounds.j0),
        );
        let i1 = (self.i0 + self.nx + by).min(bounds.i0 + bounds.nx);
        let j1 = (self.j0 + self.ny + by).min(bounds.j0 + bounds.ny);
        Rect {
            i0,
            j0,
            nx: i1.saturating_sub(i0),
            ny: j1.saturating_sub(j0),
        }
    }
}

impl Layout {
    /// The whole lattice as a rectangle.
    pub fn rect(&self) -> Rect {
        Rect {
            i0: 0,
            j0: 0,
            nx: self.nx,
            ny: self.ny,
        }
    }

    /// The lattice of the cells of `r` (which must lie within this one) on their own: cell
    /// (i, j) of the result is cell (r.i0 + i, r.j0 + j) of this one, at the same place and
    /// equally free.
    pub fn crop(&self, r: &Rect) -> Layout {
        let (nx, ny) = (r.nx.max(1), r.ny.max(1));
        let mut free = Vec::with_capacity(nx * ny);
        for j in r.j0..r.j0 + ny {
            free.extend_from_slice(&self.free[j * self.nx + r.i0..][..nx]);
        }
        let mut spans = Vec::new();
        for s in &self.spans {
            let j = s.j as usize;
            let (a, b) = (
                (s.i0 as usize).max(r.i0),
                ((s.i0 + s.len) as usize).min(r.i0 + nx),
            );
            if j >= r.j0 && j < r.j0 + ny && a < b {
                spans.push(Span {
                    j: (j - r.j0) as u32,
                    i0: (a - r.i0) as u32,
                    len: (b - a) as u32,
                });
            }
        }
        Layout {
            resolution: self.resolution,
            nx,
            ny,
            n_theta: self.n_theta,
            origin: [
                self.origin[0] + r.i0 as f64 * self.resolution,
                self.origin[1] + r.j0 as f64 * self.resolution,
            ],
            fine_col: self.fine_col[r.i0..r.i0 + nx].to_vec(),
            fine_row: self.fine_row[r.j0..r.j0 + ny].to_vec(),
            free,
            spans,
        }
    }
}

impl Layout {
    /// The runs of one θ layer: `find(cells, emit)` is called for each span of free cells (its
    /// place in the layer) and reports runs within it as `emit(start, len)`.
    pub fn runs(
        &self,
        mut find: impl FnMut(std::ops::Range<usize>, &mut dyn FnMut(usize, usize)),
    ) -> Vec<Span> {
        let mut out = Vec::new();
        for sp in &self.spans {
            let a = sp.j as usize * self.nx + sp.i0 as usize;
            find(a..a + sp.len as usize, &mut |i, n| {
                out.push(Span {
                    j: sp.j,
                    i0: sp.i0 + i as u32,
                    len: n as u32,
                })
            });
        }
        out
    }
}

/// Runs per layer with their number of cells.
pub fn counted(runs: Vec<Vec<Span>>) -> (Vec<Vec<Span>>, usize) {
    let n = runs.iter().flatten().map(|r| r.len as usize).sum();
    (runs, n)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::localization::test_drive::hospital;

    /// A cropped lattice is the same cells: same places, same free cells, the same runs clipped.
    #[test]
    fn a_crop_is_the_same_cells_in_their_own_lattice() {
        let map = hospital();
        let whole = Layout::new(&map.grid, 0.25, 36);
        let r = Rect {
            i0: 37,
            j0: 20,
            nx: 41,
            ny: 23,
        };
        let c = whole.crop(&r);
        assert_eq!((c.nx, c.ny, c.n_theta), (41, 23, 36));
        let mut free = 0;
        for j in 0..c.ny {
            for i in 0..c.nx {
                let (x, y) = c.centre(i, j);
                let (wx, wy) = whole.centre(i + r.i0, j + r.j0);
                assert!((x - wx).abs() < 1e-9 && (y - wy).abs() < 1e-9);
                let f = whole.free[(j + r.j0) * whole.nx + i + r.i0];
                assert_eq!(c.free[j * c.nx + i], f);
                free += usize::from(f);
            }
        }
        assert!(free > 0 && free < r.area(), "{free}");
        assert_eq!(c.free_count(), free);
        // the runs cover exactly the free cells, in row then column order
        let mut covered = vec![false; c.layer()];
        for s in &c.spans {
            for i in s.i0..s.i0 + s.len {
                covered[s.j as usize * c.nx + i as usize] = true;
            }
        }
        assert_eq!(covered, c.free);
        assert!(
            c.spans
                .windows(2)
                .all(|w| (w[0].j, w[0].i0 + w[0].len) < (w[1].j, w[1].i0))
        );
        // the whole lattice cropped to itself is itself
        let same = whole.crop(&whole.rect());
        assert_eq!(
            (same.spans, same.free),
            (whole.spans.clone(), whole.free.clone())
        );
    }

    #[test]
    fn rects_grow_within_their_bounds() {
        let bounds = Rect {
            i0: 0,
            j0: 0,
            nx: 100,
            ny: 50,
        };
        let r = Rect {
            i0: 3,
            j0: 40,
            nx: 5,
            ny: 5,
        };
        let g = r.grown(10, &bounds);
        assert_eq!(
            g,
            Rect {
                i0: 0,
                j0: 30,
                nx: 18,
                ny: 20
            }
        );
        assert!(g.contains(&r) && bounds.contains(&g) && !r.contains(&g));
    }
}
