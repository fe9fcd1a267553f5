//! Simulation time in MCAP files. Every log time, publish time and header stamp the simulator
//! writes is the simulation time in integer nanoseconds, rounded to the nearest
//! ([`stamp_ns`]). The simulator computes every time as `k as f64 * period` for an integer `k`:
//! ticks end at `(tick + 1) · dt`, a sensor with rate `f` fires at `k · (1 / f)` (its timer has
//! no offset). So a replay gets the exact `f64` time back from a stamp and the period of what
//! was stamped ([`time_on_grid`]; the periods are in the `run.json` attachment), as long as
//! the period is longer than a nanosecond.

/// Nanoseconds of simulation time `t` (s), rounded to the nearest; negative times give 0.
pub fn stamp_ns(t: f64) -> u64 {
    (t * 1e9).round().max(0.0) as u64
}

/// The simulation time `k · period` (computed as the simulator does) whose stamp is `ns`.
pub fn time_on_grid(ns: u64, period: f64) -> f64 {
    (ns as f64 * 1e-9 / period).round() * period
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stamps_map_back_to_the_exact_times() {
        // sensor rates of the presets and scenarios, and tick lengths
        for rate in [50.0, 15.0, 10.0, 7.0, 5.0, 3.0, 1.0, 0.3] {
            let period = 1.0 / rate;
            for k in (0..200_000u64).chain([1 << 24, 1 << 30]) {
                let t = k as f64 * period;
                assert_eq!(
                    time_on_grid(stamp_ns(t), period).to_bits(),
                    t.to_bits(),
                    "k = {k}, rate {rate}"
                );
            }
        }
        for dt in [0.05, 0.01, 0.02, 0.1, 0.025] {
            for tick in 0..100_000u64 {
                let t = (tick + 1) as f64 * dt;
                assert_eq!(time_on_grid(stamp_ns(t), dt).to_bits(), t.to_bits());
            }
        }
        assert_eq!(stamp_ns(0.30000000000000004), 300_000_000);
        assert_eq!(stamp_ns(-1.0), 0);
    }
}
