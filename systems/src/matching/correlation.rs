//! The thesis's fitness: cross-correlation of rasterised scans, [Hospital thesis §5.2, eq. 29]
//! and [Hospital thesis §6, eqs. 31–32].
//!
//! Both point sets (eq. 28) are scaled into a square binary "correlation map" of `cells × cells`
//! over `[−half_extent, half_extent)²` metres around the reference sensor (the thesis: 100 cells
//! over −10 000 … 10 000 mm, so 200 mm cells): `X' = (X − MIN) · size / (MAX − MIN)` (eq. 31,
//! likewise Y, eq. 32), and a cell is 1 if at least one point falls in it; points outside the map
//! are dropped. The current scan is first moved by the candidate `p = (p_x, p_y, ω)`:
//! `b ↦ R(ω) b + (p_x, p_y)`. The fitness is the number of cells that are 1 in both maps (higher
//! is better; 0 when the scans do not overlap). The point-count-weighted map of §6.1 was rejected
//! by the thesis (it mis-aligns large shifts) and is not implemented.
//!
//! Cost per evaluation: the reference map is a bitset built once per match; an evaluation moves
//! the current points only, tests the reference bit of each point's cell and counts each common
//! cell once (a visited bitset on the stack deduplicates), so it is O(points), not O(cells).

use super::de::Vector;
use super::error::MatchError;

/// Size of the square correlation map.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RasterSpec {
    /// Cells per side (thesis: 100).
    pub cells: usize,
    /// The map covers `[−half_extent, half_extent)` metres on both axes (thesis: 10 m).
    pub half_extent: f32,
}

impl Default for RasterSpec {
    /// The thesis's map: 100 × 100 cells over −10 m … 10 m (0.2 m cells).
    fn default() -> Self {
        RasterSpec {
            cells: 100,
            half_extent: 10.0,
        }
    }
}

impl RasterSpec {
    /// Side of one cell in metres.
    pub fn cell_size(&self) -> f32 {
        2.0 * self.half_extent / self.cells as f32
    }

    pub fn validate(&self) -> Result<(), MatchError> {
        if self.cells == 0 || self.cells > 8192 {
            return Err(MatchError::InvalidParameter {
                name: "raster.cells",
                value: self.cells as f64,
                expected: "1 ..= 8192 cells per side",
            });
        }
        if !(self.half_extent.is_finite() && self.half_extent > 0.0) {
            return Err(MatchError::InvalidParameter {
                name: "raster.half_extent",
                value: self.half_extent as f64,
                expected: "a finite extent > 0 m",
            });
        }
        Ok(())
    }
}

/// Visited-bitset words kept on the stack (maps up to 128 × 128 cells).
const STACK_WORDS: usize = 256;

/// The correlation fitness of one (reference, current) pair.
#[derive(Clone, Debug)]
pub struct CorrelationFitness {
    cells: usize,
    /// cells / (MAX − MIN): eq. 31's scale.
    scale: f32,
    /// −MIN · scale.
    offset: f32,
    /// The reference map, one bit per cell, row-major.
    reference: Vec<u64>,
    reference_cells: usize,
    /// Current points pre-multiplied by `scale`.
    current: Vec<[f32; 2]>,
}

impl CorrelationFitness {
    /// Rasterises the reference once and keeps the current points. Non-finite points are
    /// ignored; an empty scan is an error.
    pub fn new(
        reference: &[[f32; 2]],
        current: &[[f32; 2]],
        spec: RasterSpec,
    ) -> Result<Self, MatchError> {
        spec.validate()?;
        let finite = |p: &&[f32; 2]| p[0].is_finite() && p[1].is_finite();
        if !reference.iter().any(|p| finite(&p)) {
            return Err(MatchError::EmptyReference);
        }
        let current: Vec<[f32; 2]> = current.iter().filter(finite).copied().collect();
        if current.is_empty() {
            return Err(MatchError::EmptyCurrent);
        }
        let cells = spec.cells;
        let scale = cells as f32 / (2.0 * spec.half_extent);
        let offset = spec.half_extent * scale;
        let mut map = vec![0u64; (cells * cells).div_ceil(64)];
        let mut reference_cells = 0;
        for p in reference.iter().filter(finite) {
            if let Some(i) = cell_index(cells, p[0] * scale + offset, p[1] * scale + offset) {
                if map[i / 64] & (1 << (i % 64)) == 0 {
                    reference_cells += 1;
                }
                map[i / 64] |= 1 << (i % 64);
            }
        }
        Ok(CorrelationFitness {
            cells,
            scale,
            offset,
            reference: map,
            reference_cells,
            current: current
                .iter()
                .map(|p| [p[0] * scale, p[1] * scale])
                .collect(),
        })
    }

    /// Number of cells of the reference map that are 1.
    pub fn reference_cells(&self) -> usize {
        self.reference_cells
    }

    /// Eq. 29: the number of cells that are 1 in the reference map and in the map of the current
    /// scan moved by `p`.
    pub fn correlation(&self, p: &Vector) -> u32 {
        let words = self.reference.len();
        let mut stack = [0u64; STACK_WORDS];
        let mut heap = Vec::new();
        let visited: &mut [u64] = if words <= STACK_WORDS {
            &mut stack[..words]
        } else {
            heap.resize(words, 0u64);
            &mut heap
        };
        let (s, c) = p[2].sin_cos();
        let (s, c) = (s as f32, c as f32);
        let tx = p[0] as f32 * self.scale + self.offset;
        let ty = p[1] as f32 * self.scale + self.offset;
        let mut count = 0;
        for b in &self.current {
            let u = c * b[0] - s * b[1] + tx;
            let v = s * b[0] + c * b[1] + ty;
            if let Some(i) = cell_index(self.cells, u, v) {
                let (w, bit) = (i / 64, 1u64 << (i % 64));
                if self.reference[w] & bit != 0 && visited[w] & bit == 0 {
                    visited[w] |= bit;
                    count += 1;
                }
            }
        }
        count
    }

    /// The DE cost: −correlation (DE minimises).
    pub fn cost(&self, p: &Vector) -> f64 {
        -(self.correlation(p) as f64)
    }
}

/// Row-major index of the cell containing map coordinates (u, v) (in cells), if inside.
#[inline(always)]
fn cell_index(cells: usize, u: f32, v: f32) -> Option<usize> {
    let n = cells as f32;
    // NaN fails the comparisons; truncation equals floor for non-negative values.
    if u >= 0.0 && v >= 0.0 && u < n && v < n {
        Some((v as usize).min(cells - 1) * cells + (u as usize).min(cells - 1))
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_common_cells_once() {
        let spec = RasterSpec::default(); // 0.2 m cells
        // three reference points in two cells
        let reference = [[0.05, 0.05], [0.15, 0.1], [1.05, 0.05]];
        // current: two points in the first cell, one in the second, one nowhere near
        let current = [[0.01, 0.01], [0.11, 0.02], [1.1, 0.1], [5.0, 5.0]];
        let f = CorrelationFitness::new(&reference, &current, spec).unwrap();
        assert_eq!(f.reference_cells(), 2);
        assert_eq!(f.correlation(&[0.0, 0.0, 0.0]), 2);
        assert_eq!(f.cost(&[0.0, 0.0, 0.0]), -2.0);
        // a 1 m shift leaves only the first cell's points over the second reference cell
        assert_eq!(f.correlation(&[1.0, 0.0, 0.0]), 1);
        // no overlap at all
        assert_eq!(f.correlation(&[-3.0, 3.0, 0.0]), 0);
        // rotation by 180° about the sensor maps (1.1, 0.1) to (−1.1, −0.1): no common cell
        assert_eq!(f.correlation(&[0.0, 0.0, std::f64::consts::PI]), 0);
    }

    #[test]
    fn points_outside_the_map_are_dropped() {
        let spec = RasterSpec {
            cells: 10,
            half_extent: 1.0,
        };
        let f =
            CorrelationFitness::new(&[[0.95, 0.95], [1.5, 0.0]], &[[0.95, 0.95]], spec).unwrap();
        assert_eq!(f.reference_cells(), 1);
        assert_eq!(f.correlation(&[0.0, 0.0, 0.0]), 1);
        assert_eq!(f.correlation(&[0.1, 0.0, 0.0]), 0);
    }

    #[test]
    fn large_maps_use_the_heap_and_agree() {
        let pts: Vec<[f32; 2]> = (0..500)
            .map(|k| {
                let a = k as f32 * 0.0125;
                [5.0 * a.cos(), 3.0 * a.sin()]
            })
            .collect();
        let small = CorrelationFitness::new(&pts, &pts, RasterSpec::default()).unwrap();
        let big = RasterSpec {
            cells: 1000,
            half_extent: 10.0,
        };
        let large = CorrelationFitness::new(&pts, &pts, big).unwrap();
        assert_eq!(
            small.correlation(&[0.0; 3]) as usize,
            small.reference_cells()
        );
        assert_eq!(
            large.correlation(&[0.0; 3]) as usize,
            large.reference_cells()
        );
        assert!(large.reference_cells() > small.reference_cells());
    }

    #[test]
    fn empty_or_bad_input_is_an_error() {
        let s = RasterSpec::default();
        assert_eq!(
            CorrelationFitness::new(&[], &[[0.0, 0.0]], s).unwrap_err(),
            MatchError::EmptyReference
        );
        assert_eq!(
            CorrelationFitness::new(&[[0.0, 0.0]], &[[f32::NAN, 0.0]], s).unwrap_err(),
            MatchError::EmptyCurrent
        );
        assert!(
            CorrelationFitness::new(
                &[[0.0, 0.0]],
                &[[0.0, 0.0]],
                RasterSpec {
                    cells: 0,
                    half_extent: 1.0
                }
            )
            .is_err()
        );
    }
}
