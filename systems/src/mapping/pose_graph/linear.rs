//! The sparse normal equations of one Gauss-Newton / Levenberg-Marquardt step, solved by faer's
//! sparse Cholesky (LLᵀ).
//!
//! H is symmetric: only its lower triangle is assembled, as (row, col, value) triplets in a fixed
//! order — for every variable node the 6 lower entries of its 3 × 3 diagonal block, then for
//! every edge between two variable nodes the 9 entries of its off-diagonal block (Grisetti et
//! al. 2010: an edge ⟨i, j⟩ touches only the blocks ii, ij, ji, jj). The sparsity pattern
//! does not change between iterations, so the column structure, the order in which triplet
//! values land in it (faer's `Argsort`, duplicates summed) and the symbolic factorization —
//! with its approximate-minimum-degree fill-reducing ordering — are computed once per
//! [`super::optimize`] call; each iteration refills the values and refactors numerically.

use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Llt, SymbolicLlt};
use faer::sparse::{Argsort, Pair, SparseColMat, SymbolicSparseColMat};
use faer::{ColMut, Side};

/// Lower-triangle positions (row ≥ col) of a 3 × 3 diagonal block.
const LOWER: [(usize, usize); 6] = [(0, 0), (1, 0), (1, 1), (2, 0), (2, 1), (2, 2)];

pub(super) type Mat3 = [[f64; 3]; 3];

/// The fixed structure of H for one graph.
pub(super) struct System {
    /// Variables (3 per non-fixed node that has an edge).
    n: usize,
    /// Per edge: where its off-diagonal block starts in `values`, if both ends are variables.
    edge_offset: Vec<Option<usize>>,
    /// Per edge: (from slot, to slot) — whether `from` is the lower (larger) block row.
    from_below: Vec<bool>,
    symbolic: SymbolicSparseColMat<usize>,
    argsort: Argsort<usize>,
    llt: SymbolicLlt<usize>,
    /// Triplet values in the fixed order: diagonal blocks, then edge blocks.
    pub(super) values: Vec<f64>,
}

impl System {
    /// `slots[node]` is the node's variable index (None: fixed or unconnected); `edges` the
    /// (from, to) nodes of every edge.
    pub(super) fn new(
        slots: &[Option<usize>],
        n_slots: usize,
        edges: &[(usize, usize)],
    ) -> Result<System, String> {
        let n = 3 * n_slots;
        let mut idx: Vec<Pair<usize, usize>> = Vec::new();
        for s in 0..n_slots {
            for &(a, b) in &LOWER {
                idx.push(Pair::new(3 * s + a, 3 * s + b));
            }
        }
        let mut edge_offset = Vec::with_capacity(edges.len());
        let mut from_below = Vec::with_capacity(edges.len());
        for &(i, j) in edges {
            match (slots[i], slots[j]) {
                (Some(p), Some(q)) if p != q => {
                    edge_offset.push(Some(idx.len()));
                    from_below.push(p > q);
                    let (hi, lo) = (p.max(q), p.min(q));
                    for a in 0..3 {
                        for b in 0..3 {
                            idx.push(Pair::new(3 * hi + a, 3 * lo + b));
                        }
                    }
                }
                _ => {
                    edge_offset.push(None);
                    from_below.push(false);
                }
            }
        }
        let (symbolic, argsort) = SymbolicSparseColMat::try_new_from_indices(n, n, &idx)
            .map_err(|e| format!("sparse structure: {e:?}"))?;
        let llt = SymbolicLlt::try_new(symbolic.as_ref(), Side::Lower)
            .map_err(|e| format!("symbolic Cholesky: {e:?}"))?;
        Ok(System {
            n,
            edge_offset,
            from_below,
            symbolic,
            argsort,
            llt,
            values: vec![0.0; idx.len()],
        })
    }

    pub(super) fn clear(&mut self) {
        self.values.iter_mut().for_each(|v| *v = 0.0);
    }

    /// Adds a 3 × 3 block to the diagonal block of variable slot `s` (lower part).
    pub(super) fn add_diagonal(&mut self, s: usize, m: &Mat3) {
        for (k, &(a, b)) in LOWER.iter().enumerate() {
            self.values[6 * s + k] += m[a][b];
        }
    }

    /// Adds H_{from,to} (rows of `from`, columns of `to`) of edge `e`, stored in the lower
    /// triangle (transposed when `from` is the upper block row).
    pub(super) fn add_edge(&mut self, e: usize, m: &Mat3) {
        let Some(off) = self.edge_offset[e] else {
            return;
        };
        let below = self.from_below[e];
        for (k, v) in self.values[off..off + 9].iter_mut().enumerate() {
            let (a, b) = (k / 3, k % 3);
            *v += if below { m[a][b] } else { m[b][a] };
        }
    }

    /// Solves (H + λ·diag(H)) Δ = rhs in place (Marquardt's damping, as SPA does: Konolige et
    /// al. 2010); `false` if the damped H is not positive definite.
    pub(super) fn solve(&self, lambda: f64, rhs: &mut [f64]) -> bool {
        debug_assert_eq!(rhs.len(), self.n);
        let mut values = self.values.clone();
        if lambda > 0.0 {
            let diag = [0, 2, 5];
            for s in 0..self.n / 3 {
                for &k in &diag {
                    // 1e-9: a variable no edge constrains in some direction stays solvable
                    values[6 * s + k] += lambda * (values[6 * s + k] + 1e-9);
                }
            }
        }
        let Ok(h) = SparseColMat::new_from_argsort(self.symbolic.clone(), &self.argsort, &values)
        else {
            return false;
        };
        match Llt::try_new_with_symbolic(self.llt.clone(), h.as_ref(), Side::Lower) {
            Ok(llt) => {
                llt.solve_in_place(ColMut::from_slice_mut(rhs));
                rhs.iter().all(|v| v.is_finite())
            }
            Err(_) => false,
        }
    }
}
