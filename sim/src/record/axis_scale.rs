//! A plot axis that fits the bulk of a run's values: the .rrd's error plots and the HTML
//! report's figures end their axes where most of a run's errors lie, so a global localizer's
//! first seconds of tens of metres leave the plot at its top while the tracking errors of all
//! stay readable.

/// A histogram of non-negative values on a logarithmic scale (1 mm to 10 km, 20 bins per
/// decade), for an axis bound that fits the bulk of a run's values in constant memory.
#[derive(Clone, Debug)]
pub struct AxisScale {
    bins: Vec<u64>,
    count: u64,
}

const DECADES: f64 = 7.0;
const PER_DECADE: f64 = 20.0;
const LOWEST: f64 = 1e-3;

impl Default for AxisScale {
    fn default() -> Self {
        AxisScale {
            bins: vec![0; (DECADES * PER_DECADE) as usize + 1],
            count: 0,
        }
    }
}

impl AxisScale {
    /// Counts `v` (NaN and negative values are left out).
    pub fn push(&mut self, v: f64) {
        if v.is_nan() || v < 0.0 {
            return;
        }
        let k = if v <= LOWEST {
            0
        } else {
            ((v / LOWEST).log10() * PER_DECADE).ceil() as usize
        };
        let last = self.bins.len() - 1;
        self.bins[k.min(last)] += 1;
        self.count += 1;
    }

    /// The upper end of an axis from 0 that holds share `q` of the values with a margin of a
    /// quarter, at least `floor`; `floor` when nothing was counted. The recorder asks for
    /// three quarters of the errors: a global localizer's first seconds of tens of metres
    /// leave the plot at its top while the tracking errors of all stay readable.
    pub fn top(&self, q: f64, floor: f64) -> f64 {
        if self.count == 0 {
            return floor;
        }
        let want = (q * self.count as f64).ceil() as u64;
        let mut seen = 0;
        for (k, n) in self.bins.iter().enumerate() {
            seen += n;
            if seen >= want.max(1) {
                let upper = LOWEST * 10f64.powf(k as f64 / PER_DECADE);
                return (1.25 * upper).max(floor);
            }
        }
        floor
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_axis_holds_the_bulk_and_leaves_out_the_outliers() {
        let mut s = AxisScale::default();
        assert_eq!(s.top(0.95, 0.5), 0.5);
        for k in 0..990 {
            s.push(0.1 + 0.0001 * k as f64);
        }
        for _ in 0..10 {
            s.push(50.0);
        }
        s.push(f64::NAN);
        s.push(-1.0);
        let top = s.top(0.95, 0.05);
        // the 95th percentile is about 0.19 m: the axis ends a quarter above, not near 50 m
        assert!(top > 0.19 * 1.2 && top < 0.19 * 1.25 * 1.13, "{top}");
        // the floor wins for small values
        assert_eq!(s.top(0.95, 5.0), 5.0);
        // everything, outliers included
        assert!(s.top(1.0, 0.0) >= 50.0 * 1.25);
    }
}
