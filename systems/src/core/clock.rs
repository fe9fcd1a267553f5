//! The simulation clock: a fixed timestep, time kept as an integer tick count so it never drifts.

use bevy_ecs::prelude::Resource;

#[derive(Resource, Clone, Debug)]
pub struct SimClock {
    /// Fixed timestep in seconds.
    pub dt: f64,
    /// Number of completed ticks.
    pub tick: u64,
}

impl SimClock {
    pub fn new(dt: f64) -> Self {
        SimClock { dt, tick: 0 }
    }

    /// Simulated time at the end of the current tick (the time the systems of this tick compute).
    pub fn now(&self) -> f64 {
        (self.tick + 1) as f64 * self.dt
    }

    /// Simulated time at the start of the current tick.
    pub fn start(&self) -> f64 {
        self.tick as f64 * self.dt
    }

    pub fn advance(&mut self) {
        self.tick += 1;
    }
}

/// A periodic trigger on the simulation clock, independent of `dt`: it yields every firing time
/// `k / rate` that falls inside a tick's half-open interval (start, end].
#[derive(Clone, Debug)]
pub struct RateTimer {
    period: f64,
    next_index: u64,
    offset: f64,
}

impl RateTimer {
    /// `rate` in Hz (> 0); `offset` in seconds shifts every firing (sensors need not be in phase).
    pub fn new(rate: f64, offset: f64) -> Self {
        RateTimer {
            period: 1.0 / rate,
            next_index: 0,
            offset,
        }
    }

    pub fn period(&self) -> f64 {
        self.period
    }

    /// Collects the firing times in (start, end] (times ≤ start that were never reached are
    /// skipped, so a timer created mid-run does not fire a burst).
    pub fn due(&mut self, start: f64, end: f64, out: &mut Vec<f64>) {
        out.clear();
        if end.is_nan() {
            return; // no time compares with it: the loop below would never end
        }
        loop {
            let t = self.offset + self.next_index as f64 * self.period;
            if t > end + 1e-9 {
                break;
            }
            self.next_index += 1;
            if t > start + 1e-9 || (start == 0.0 && t <= 1e-9) {
                out.push(t);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Regression: a tick ending at NaN (a clock with a NaN step) made the timer loop for
    /// ever; it fires nothing.
    #[test]
    fn a_timer_fires_nothing_in_a_tick_ending_at_nan() {
        let mut timer = RateTimer::new(10.0, 0.0);
        let mut out = vec![1.0];
        timer.due(f64::NAN, f64::NAN, &mut out);
        assert!(out.is_empty());
        timer.due(0.0, 0.25, &mut out);
        assert_eq!(out, [0.0, 0.1, 0.2]);
    }

    #[test]
    fn timer_rate_is_independent_of_dt() {
        for dt in [0.01, 0.02, 0.05, 0.1, 0.3] {
            let mut timer = RateTimer::new(50.0, 0.0);
            let mut clock = SimClock::new(dt);
            let mut due = Vec::new();
            let mut count = 0;
            while clock.start() < 10.0 - 1e-9 {
                timer.due(clock.start(), clock.now(), &mut due);
                count += due.iter().filter(|&&t| t <= 10.0 + 1e-9).count();
                clock.advance();
            }
            // t = 0, 0.02, ..., 10.0 → 501 firings whatever dt is.
            assert_eq!(count, 501, "dt = {dt}");
        }
    }
}
