//! Correction of the grid by the likelihood field (Probabilistic Robotics §6.4, Table 6.3, used
//! by grid localization, Table 8.1 line 4): every cell (x, y, θ) scores
//! Σ_beams ln(z_hit·exp(−d²/2σ²) + z_rand/z_max), d the distance of the beam's endpoint, seen
//! from the cell's centre pose, to the nearest obstacle.
//!
//! For one θ layer every beam's endpoint is the same offset from every cell centre, so the
//! kernel is, per beam, a shifted read of the distance field along each run of free cells: a
//! byte load and a table lookup per cell and beam, no trigonometry. The field is padded by the
//! longest beam so no read needs a bounds check.
//!
//! A cell stands for every pose inside it, not only its centre: a pose up to half a cell and
//! half a θ bin away moves a beam's endpoint by up to ½·cell + range·½·Δθ. Scoring centres with
//! the laser's own σ_hit would punish the cell that holds the robot for that quantisation, so
//! each beam is scored with σ_b² = σ_hit² + cell²/12 + (range·Δθ)²/12, the variance of the
//! endpoint over a cell (an approximation of integrating the likelihood over the cell).

use super::layout::{Layout, Span};
use crate::localization::map::LocalizationMap;
use crate::localization::mcl::LaserModelParams;
use crate::world::DistanceField;
use crate::world::distance_field::FAR;
use std::borrow::Cow;

/// A copy of the distance field with a border of `pad` cells reading "far".
#[derive(Clone, Debug)]
pub struct PaddedField {
    pub width: usize,
    pub pad: usize,
    pub resolution: f64,
    pub cells: Vec<u8>,
    /// The longest beam (m) the padding covers.
    pub reach: f64,
}

impl PaddedField {
    pub fn new(field: &DistanceField, reach: f64) -> Self {
        let pad = (reach / field.resolution).ceil() as usize + 2;
        let width = field.width + 2 * pad;
        let height = field.height + 2 * pad;
        let mut cells = vec![FAR; width * height];
        for r in 0..field.height {
            let dst = (r + pad) * width + pad;
            cells[dst..dst + field.width]
                .copy_from_slice(&field.cells[r * field.width..(r + 1) * field.width]);
        }
        PaddedField {
            width,
            pad,
            resolution: field.resolution,
            cells,
            reach,
        }
    }

    /// Flat index offset of a displacement (m) in the field.
    pub fn offset(&self, dx: f64, dy: f64) -> isize {
        let cx = (dx / self.resolution).round() as isize;
        let cy = (dy / self.resolution).round() as isize;
        cy * self.width as isize + cx
    }
}

/// Adds to `out` (one θ layer, `nx · ny`, row-major) the log-likelihood of the beams whose
/// endpoints, rotated into this layer's heading, sit at field offsets `offsets` from a cell
/// centre, beam b scored with `tables[b]`. Only the cells of `spans` (runs of free cells: the
/// layout's, or the active part of them) are touched.
pub fn layer_log_likelihood(
    field: &PaddedField,
    tables: &[[f32; 256]],
    layout: &Layout,
    spans: &[Span],
    offsets: &[isize],
    out: &mut [f32],
) {
    let cells = &field.cells;
    let pad = field.pad as isize;
    let w = field.width as isize;
    for s in spans {
        let (i0, len, j) = (s.i0 as usize, s.len as usize, s.j as usize);
        let cols = &layout.fine_col[i0..i0 + len];
        let acc = &mut out[j * layout.nx + i0..j * layout.nx + i0 + len];
        let row = (layout.fine_row[j] as isize + pad) * w + pad;
        for (&o, table) in offsets.iter().zip(tables) {
            let base = (row + o) as usize;
            let src = &cells[base..];
            for (a, &c) in acc.iter_mut().zip(cols) {
                *a += table[src[c as usize] as usize];
            }
        }
    }
}

/// The log-likelihood of one cell (i, j) of a layer: [`layer_log_likelihood`] for a single cell.
pub fn cell_log_likelihood(
    field: &PaddedField,
    tables: &[[f32; 256]],
    layout: &Layout,
    offsets: &[isize],
    i: usize,
    j: usize,
) -> f32 {
    let (pad, w) = (field.pad as isize, field.width as isize);
    let centre = (layout.fine_row[j] as isize + pad) * w + pad + layout.fine_col[i] as isize;
    offsets
        .iter()
        .zip(tables)
        .map(|(&o, table)| table[field.cells[(centre + o) as usize] as usize])
        .sum()
}

/// [`cell_log_likelihood`] of each cell (i, j) of `cells`, into `out`: eight cells at a time,
/// beam by beam, so the eight reads of the field at each beam overlap (the cells lie far apart,
/// each read a likely cache miss); each cell's sum still adds its beams in order.
pub fn cells_log_likelihood(
    field: &PaddedField,
    tables: &[[f32; 256]],
    layout: &Layout,
    offsets: &[isize],
    cells: &[(u32, u32)],
    out: &mut Vec<f32>,
) {
    const GROUP: usize = 8;
    let (pad, w) = (field.pad as isize, field.width as isize);
    let centre = |&(i, j): &(u32, u32)| {
        (layout.fine_row[j as usize] as isize + pad) * w
            + pad
            + layout.fine_col[i as usize] as isize
    };
    let (groups, rest) = cells.as_chunks::<GROUP>();
    for g in groups {
        let centres = g.each_ref().map(centre);
        let mut acc = [-0.0f32; GROUP];
        for (&o, table) in offsets.iter().zip(tables) {
            for (a, &c) in acc.iter_mut().zip(&centres) {
                *a += table[field.cells[(c + o) as usize] as usize];
            }
        }
        out.extend_from_slice(&acc);
    }
    out.extend(rest.iter().map(|&(i, j)| {
        cell_log_likelihood(field, tables, layout, offsets, i as usize, j as usize)
    }));
}

/// The log-likelihood table of a beam of length `range` (m): ln(z_hit·exp(−d²/2σ_b²) + z_rand/z_max)
/// per stored distance byte, σ_b widened for the cell's extent (module docs).
pub fn beam_table(
    field: &DistanceField,
    laser: &LaserModelParams,
    range_max: f64,
    cell: f64,
    theta_step: f64,
    range: f64,
) -> [f32; 256] {
    let var = laser.sigma_hit * laser.sigma_hit
        + cell * cell / 12.0
        + (range * theta_step).powi(2) / 12.0;
    let rand = laser.z_rand / range_max.max(1e-6);
    field.table(|d| {
        let d = d.min(laser.max_dist);
        ((laser.z_hit * (-d * d / (2.0 * var)).exp() + rand).max(1e-30)).ln() as f32
    })
}

/// The endpoints of `points` a cell can see: finite and within the map's diagonal. Borrowed
/// when that is all of them (a scan of the map always is).
pub fn reachable<'a>(map: &LocalizationMap, points: &'a [[f32; 2]]) -> Cow<'a, [[f32; 2]]> {
    let g = &map.grid;
    let diagonal = (g.width as f64 * g.resolution).hypot(g.height as f64 * g.resolution);
    let ok = |p: &[f32; 2]| (p[0] as f64).hypot(p[1] as f64) <= diagonal;
    if points.iter().all(ok) {
        Cow::Borrowed(points)
    } else {
        Cow::Owned(points.iter().copied().filter(ok).collect())
    }
}
