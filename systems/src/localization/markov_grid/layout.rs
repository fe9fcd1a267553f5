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
