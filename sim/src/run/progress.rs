//! The progress bar of a run: simulated time and real-time factor, updated about 500 times a run.

use indicatif::{ProgressBar, ProgressStyle};
use std::time::Instant;

pub(super) struct Progress {
    bar: ProgressBar,
    ticks: u64,
    update_every: u64,
    duration: f64,
    dt: f64,
}

impl Progress {
    /// A bar for `ticks` ticks of `dt` (hidden unless `show`).
    pub(super) fn new(show: bool, ticks: u64, duration: f64, dt: f64) -> Self {
        let bar = if show {
            let b = ProgressBar::new(ticks);
            b.set_style(
                ProgressStyle::with_template(
                    "{bar:40.cyan/blue} {percent:>3}%  {msg}  [{elapsed_precise} < {eta}]",
                )
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
            );
            b
        } else {
            ProgressBar::hidden()
        };
        Progress {
            bar,
            ticks,
            update_every: (ticks / 500).max(1),
            duration,
            dt,
        }
    }

    /// Tick `tick` (from 0) is done.
    pub(super) fn tick(&self, tick: u64, started: Instant) {
        if tick.is_multiple_of(self.update_every) || tick + 1 == self.ticks {
            let sim_t = (tick + 1) as f64 * self.dt;
            let wall = started.elapsed().as_secs_f64().max(1e-9);
            self.bar.set_position(tick + 1);
            self.bar.set_message(format!(
                "sim {sim_t:.1}/{:.1} s  {:.1}× real time",
                self.duration,
                sim_t / wall
            ));
        }
    }

    pub(super) fn finish(&self) {
        self.bar.finish_and_clear();
    }
}
