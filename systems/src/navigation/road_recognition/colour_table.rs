//! The learned road colours ([Park thesis §5.2]): colours are compared in HSV by the thesis's
//! weighted distance
//!
//! ΔE = √((H_e − H_l)² + (S_e − S_l)²/4 + (V_e − V_l)²/16)
//!
//! (e: the evaluated pixel, l: a learned road pixel; hue weighs most, value least, which makes
//! the test tolerant of lighting), and the result is cached in a 64 × 64 × 64 table over RGB,
//! one cell per 4 levels of each channel, holding 1 for a road colour. Learning a colour sets
//! every cell within the threshold of it to 1; at run time a pixel is tested by one table read,
//! with no HSV conversion.
//!
//! Scales, which the thesis does not state: its program used OpenCV, whose 8-bit HSV has
//! H ∈ [0, 180) (2° per unit) and S, V ∈ [0, 255]; those are used here, and the hue difference
//! wraps around (179 and 1 are 2 apart). The table is a bit set (32 KB), so lookups stay in L1.

use std::sync::OnceLock;

/// (H, S, V) in OpenCV's 8-bit scales: H ∈ [0, 180), S and V ∈ [0, 255].
pub type Hsv = [f32; 3];

/// Cells per channel.
pub const LEVELS: usize = 64;
const CELLS: usize = LEVELS * LEVELS * LEVELS;

/// HSV of an RGB colour (channels 0–255, not necessarily integers).
pub fn rgb_to_hsv(rgb: [f32; 3]) -> Hsv {
    let [r, g, b] = rgb;
    let max = r.max(g).max(b);
    let min = r.min(g).min(b);
    let d = max - min;
    let s = if max > 0.0 { 255.0 * d / max } else { 0.0 };
    let h_deg = if d <= 0.0 {
        0.0
    } else if max == r {
        60.0 * (g - b) / d
    } else if max == g {
        120.0 + 60.0 * (b - r) / d
    } else {
        240.0 + 60.0 * (r - g) / d
    };
    [0.5 * h_deg.rem_euclid(360.0), s, max]
}

/// The thesis's colour distance squared, hue wrapping at 180.
#[inline]
pub fn delta_e2(e: Hsv, l: Hsv) -> f32 {
    let mut dh = (e[0] - l[0]).abs();
    if dh > 90.0 {
        dh = 180.0 - dh;
    }
    let ds = e[1] - l[1];
    let dv = e[2] - l[2];
    dh * dh + ds * ds / 4.0 + dv * dv / 16.0
}

/// The thesis's colour distance ΔE.
pub fn delta_e(e: Hsv, l: Hsv) -> f32 {
    delta_e2(e, l).sqrt()
}

/// Table cell of an RGB colour.
#[inline]
pub fn cell_of(rgb: [u8; 3]) -> usize {
    ((rgb[0] as usize >> 2) << 12) | ((rgb[1] as usize >> 2) << 6) | (rgb[2] as usize >> 2)
}

/// HSV of every cell's central colour (4·k + 1.5 per channel), computed once.
fn cell_hsv() -> &'static [Hsv] {
    static TABLE: OnceLock<Vec<Hsv>> = OnceLock::new();
    TABLE.get_or_init(|| {
        (0..CELLS)
            .map(|i| {
                let c = |k: usize| ((i >> k) & (LEVELS - 1)) as f32 * 4.0 + 1.5;
                rgb_to_hsv([c(12), c(6), c(0)])
            })
            .collect()
    })
}

/// The 64³ road-colour table and the colours it was learned from.
#[derive(Clone, Debug, PartialEq)]
pub struct ColourTable {
    bits: Vec<u64>,
    learned: Vec<Hsv>,
    /// ΔE below which a colour counts as a learned one.
    pub threshold: f32,
    /// At most this many colours are learned.
    pub max_colours: usize,
}

impl ColourTable {
    /// An empty table: nothing is road yet.
    pub fn new(threshold: f32, max_colours: usize) -> Self {
        ColourTable {
            bits: vec![0; CELLS / 64],
            learned: Vec::new(),
            threshold,
            max_colours,
        }
    }

    /// Whether the colour is a road colour: one table read.
    #[inline]
    pub fn is_road(&self, rgb: [u8; 3]) -> bool {
        let i = cell_of(rgb);
        (self.bits[i >> 6] >> (i & 63)) & 1 != 0
    }

    /// Learns `rgb` as a road colour unless the table already holds it or is full; returns
    /// whether it was added.
    pub fn learn(&mut self, rgb: [u8; 3]) -> bool {
        if self.is_road(rgb) || self.learned.len() >= self.max_colours {
            return false;
        }
        let l = rgb_to_hsv(rgb.map(f32::from));
        let t2 = self.threshold * self.threshold;
        for (i, hsv) in cell_hsv().iter().enumerate() {
            if delta_e2(*hsv, l) < t2 {
                self.bits[i >> 6] |= 1 << (i & 63);
            }
        }
        // the colour's own cell counts even when its centre is just beyond the threshold
        let i = cell_of(rgb);
        self.bits[i >> 6] |= 1 << (i & 63);
        self.learned.push(l);
        true
    }

    /// The learned colours, in learning order.
    pub fn learned(&self) -> &[Hsv] {
        &self.learned
    }

    /// Number of table cells marked as road.
    pub fn road_cells(&self) -> usize {
        self.bits.iter().map(|w| w.count_ones() as usize).sum()
    }

    /// Forgets everything.
    pub fn clear(&mut self) {
        self.bits.fill(0);
        self.learned.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hsv_uses_opencv_scales_and_the_hue_wraps() {
        assert_eq!(rgb_to_hsv([255.0, 0.0, 0.0]), [0.0, 255.0, 255.0]);
        assert_eq!(rgb_to_hsv([0.0, 255.0, 0.0]), [60.0, 255.0, 255.0]);
        assert_eq!(rgb_to_hsv([0.0, 0.0, 128.0]), [120.0, 255.0, 128.0]);
        assert_eq!(rgb_to_hsv([90.0, 90.0, 90.0]), [0.0, 0.0, 90.0]);
        // red just below and just above 0° are close; hue weighs most, value least
        let a = rgb_to_hsv([255.0, 0.0, 8.0]);
        let b = rgb_to_hsv([255.0, 8.0, 0.0]);
        assert!(delta_e(a, b) < 2.0, "{a:?} {b:?}");
        let base = [50.0, 100.0, 100.0];
        assert_eq!(delta_e(base, [60.0, 100.0, 100.0]), 10.0);
        assert_eq!(delta_e(base, [50.0, 120.0, 100.0]), 10.0);
        assert_eq!(delta_e(base, [50.0, 100.0, 140.0]), 10.0);
    }

    #[test]
    fn learned_asphalt_is_road_and_grass_is_not() {
        let mut t = ColourTable::new(20.0, 64);
        assert!(!t.is_road([74, 74, 78]));
        // asphalt as the camera shows it: grey with a little noise in every channel
        let asphalt = [
            [74, 74, 78],
            [70, 72, 69],
            [80, 76, 77],
            [66, 69, 72],
            [77, 79, 74],
        ];
        for c in asphalt {
            t.learn(c);
        }
        assert!(!t.learned().is_empty() && t.learned().len() <= asphalt.len());
        for c in asphalt {
            assert!(t.is_road(c), "{c:?}");
        }
        // a darker and a brighter asphalt (shadow, sun): V weighs little
        assert!(t.is_road([60, 60, 63]) && t.is_road([92, 92, 96]));
        // grass, the verge, the sky are not road
        for c in [[78, 118, 48], [60, 100, 40], [92, 76, 46], [170, 200, 235]] {
            assert!(!t.is_road(c), "{c:?}");
        }
        // a colour already in the table is not learned again
        let n = t.learned().len();
        assert!(!t.learn([74, 74, 78]));
        assert_eq!(t.learned().len(), n);
        let cells = t.road_cells();
        assert!(cells > 0 && cells < CELLS / 50, "{cells}");
        t.clear();
        assert!(!t.is_road([74, 74, 78]) && t.learned().is_empty());
    }

    #[test]
    fn the_table_agrees_with_the_distance() {
        let mut t = ColourTable::new(15.0, 8);
        let learned = [150u8, 118, 102];
        t.learn(learned);
        let l = rgb_to_hsv(learned.map(f32::from));
        // away from the threshold the table read and the distance agree
        let mut checked = 0;
        for r in (0..=255u16).step_by(5) {
            for g in (0..=255u16).step_by(7) {
                for b in (0..=255u16).step_by(9) {
                    let c = [r as u8, g as u8, b as u8];
                    let d = delta_e(rgb_to_hsv(c.map(f32::from)), l);
                    if d < 9.0 {
                        assert!(t.is_road(c), "{c:?} at {d}");
                        checked += 1;
                    } else if d > 25.0 {
                        assert!(!t.is_road(c), "{c:?} at {d}");
                    }
                }
            }
        }
        assert!(checked > 10, "{checked}");
    }
}
