//! `sim bench profile`: where a tick's time goes, system by system. bevy gives every system a
//! tracing span (its `trace` feature); while profiling, a subscriber of our own times the spans
//! of the systems and of their deferred commands, and nothing else (the executor's other spans
//! stay disabled, so their names are not even formatted). The schedule runs on one thread
//! (in `SimSet` order, [`systems::core::new_schedule`]), so the systems' times add up to the
//! tick's; what is left is the executor's own work (run conditions, sync points) and the timing.
//! A twin world stepped without the subscriber gives the tick's true wall time beside it.

use crate::Simulation;
use crate::bench::swarm::{check_beams, swarm_scenario, swarm_world};
use crate::scenario::{Scenario, scenario_arg};
use serde::Serialize;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};
use systems::core::{SimSet, tick_order};
use tracing::span::{Attributes, Id, Record};
use tracing::subscriber::Interest;
use tracing::{Event, Metadata, Subscriber};

/// `sim bench profile`: the time of each system per tick.
#[derive(clap::Args, Clone, Debug)]
pub struct ProfileOptions {
    /// A scenario file or the name of a bundled scenario (default: hospital_patrol); not with
    /// --robots.
    pub scenario: Option<String>,
    /// Profile the swarm benchmark's world with this many wandering robots (0: the map alone).
    #[arg(long, conflicts_with = "scenario")]
    pub robots: Option<usize>,
    /// Beams per scan of the swarm robots.
    #[arg(long, default_value_t = 180, requires = "robots")]
    pub beams: usize,
    /// The swarm robots also localize with MCL, with AMCL's defaults or sim's (as
    /// `sim bench swarm --mcl`).
    #[arg(
        long,
        requires = "robots",
        num_args = 0..=1,
        default_missing_value = "amcl",
        value_name = "DEFAULTS"
    )]
    pub mcl: Option<crate::bench::swarm::MclDefaults>,
    /// Simulated seconds profiled, after the first tick (which builds the schedule).
    #[arg(long, default_value_t = 60.0)]
    pub duration: f64,
    /// One JSON object per system, one per line, then one for the tick.
    #[arg(long)]
    pub json: bool,
}

/// One system's share.
#[derive(Serialize, Debug, Clone, PartialEq)]
pub struct SystemProfile {
    pub set: String,
    pub system: String,
    /// Runs per tick (below 1 for a system that skips ticks).
    pub runs_per_tick: f64,
    /// Mean time per tick (µs), its deferred commands included.
    pub us_per_tick: f64,
    /// Share of the profiled tick's wall time (%).
    pub share_percent: f64,
    /// Its time in the first tick (µs), which also builds caches the later ticks reuse.
    pub first_tick_us: f64,
}

/// The whole tick.
#[derive(Serialize, Debug, Clone)]
pub struct TickProfile {
    pub world: String,
    pub ticks: u64,
    /// The first tick (ms): its systems build caches the later ticks reuse.
    pub first_tick_ms: f64,
    /// Wall time per tick while profiled (µs).
    pub profiled_tick_us: f64,
    /// Wall time per tick of the same world stepped without profiling (µs).
    pub tick_us: f64,
    /// Sum of the systems' times per tick (µs).
    pub systems_us: f64,
    /// Profiled tick minus its systems: the executor, run conditions and the timing (µs).
    pub outside_systems_us: f64,
    pub systems: Vec<SystemProfile>,
}

/// `sim bench profile`.
pub fn run_profile(o: &ProfileOptions) -> anyhow::Result<()> {
    crate::options::check_duration(o.duration)?;
    let (label, sc) = match o.robots {
        Some(n) => {
            check_beams(o.beams)?;
            let grid = swarm_world()?;
            let mcl = match o.mcl {
                Some(d) => format!(", MCL with {d:?} defaults"),
                None => String::new(),
            };
            let label = format!("swarm world, {n} robots, {} beams{mcl}", o.beams);
            let mut sc = swarm_scenario(&grid, n, o.beams, o.duration + 1.0)?;
            if let Some(d) = o.mcl {
                crate::bench::swarm::localize_with_mcl(&mut sc, d);
            }
            (label, sc)
        }
        None => {
            let sc = scenario_arg(o.scenario.as_deref())?;
            (sc.name.clone(), sc)
        }
    };
    let p = profile(&sc, &label, o.duration)?;
    if o.json {
        for s in &p.systems {
            println!("{}", crate::bench::machine::json_line(s)?);
        }
        let mut tick = p.clone();
        tick.systems.clear();
        println!("{}", crate::bench::machine::json_line(&tick)?);
    } else {
        print!("{}", format_profile(&p));
    }
    Ok(())
}

/// Profiles `seconds` of `scenario` after its first tick, on one thread.
pub fn profile(scenario: &Scenario, label: &str, seconds: f64) -> anyhow::Result<TickProfile> {
    let ticks = (seconds / scenario.dt).round().max(1.0) as u64;
    // the twin first, without the subscriber: its systems' spans are disabled for good
    let mut plain = Simulation::from_scenario(scenario.clone())
        .threads(1)
        .build()?;
    plain.step()?;
    let started = Instant::now();
    for _ in 0..ticks {
        plain.step()?;
    }
    let tick_us = micros(started.elapsed()) / ticks as f64;
    drop(plain);

    let timer = SpanTimer::default();
    let times = timer.times.clone();
    let (first, wall, order, first_times) =
        tracing::subscriber::with_default(timer, || -> anyhow::Result<_> {
            let mut s = Simulation::from_scenario(scenario.clone())
                .threads(1)
                .build()?;
            let started = Instant::now();
            s.step()?;
            let first = started.elapsed();
            // the first tick builds what later ticks reuse: kept apart
            let first_times = times.lock().expect("profile times").take_times();
            let started = Instant::now();
            for _ in 0..ticks {
                s.step()?;
            }
            let wall = started.elapsed();
            let (world, schedule) = s.world_and_schedule();
            let order = tick_order(schedule, world).map_err(anyhow::Error::msg)?;
            Ok((first, wall, order, first_times))
        })?;
    let profiled_tick_us = micros(wall) / ticks as f64;
    let spans = times.lock().expect("profile times");
    let systems: Vec<SystemProfile> = order
        .iter()
        .map(|sys| {
            let (time, runs) = spans.of(&sys.name);
            let (first, _) = first_times.of(&sys.name);
            let us_per_tick = micros(time) / ticks as f64;
            SystemProfile {
                set: sys
                    .set
                    .map_or("(none)".into(), |s: SimSet| format!("{s:?}")),
                system: sys.name.clone(),
                runs_per_tick: runs as f64 / ticks as f64,
                us_per_tick,
                share_percent: 100.0 * us_per_tick / profiled_tick_us,
                first_tick_us: micros(first),
            }
        })
        .collect();
    let systems_us = systems.iter().map(|s| s.us_per_tick).sum::<f64>();
    Ok(TickProfile {
        world: label.to_string(),
        ticks,
        first_tick_ms: micros(first) / 1e3,
        profiled_tick_us,
        tick_us,
        systems_us,
        outside_systems_us: profiled_tick_us - systems_us,
        systems,
    })
}

fn micros(d: Duration) -> f64 {
    d.as_secs_f64() * 1e6
}

/// The profile as a table, systems in tick order.
pub fn format_profile(p: &TickProfile) -> String {
    let mut out = format!(
        "profile of {} over {} ticks, one thread\nmachine: {}\n",
        p.world,
        p.ticks,
        crate::bench::machine::describe()
    );
    out += &format!(
        "{:<10} {:<58} {:>6} {:>10} {:>7} {:>12}\n",
        "set", "system", "runs", "µs/tick", "share", "first tick"
    );
    for s in &p.systems {
        let name = s.system.strip_prefix("systems::").unwrap_or(&s.system);
        out += &format!(
            "{:<10} {:<58} {:>6.2} {:>10.3} {:>6.1} % {:>9.1} µs\n",
            s.set, name, s.runs_per_tick, s.us_per_tick, s.share_percent, s.first_tick_us
        );
    }
    let share = |us: f64| 100.0 * us / p.profiled_tick_us;
    out += &format!(
        "{:<10} {:<58} {:>6} {:>10.3} {:>6.1} %\n",
        "",
        "outside the systems (executor, conditions, timing)",
        "",
        p.outside_systems_us,
        share(p.outside_systems_us)
    );
    out += &format!(
        "tick: {:.3} µs profiled, {:.3} µs without profiling; the first tick {:.2} ms\n",
        p.profiled_tick_us, p.tick_us, p.first_tick_ms
    );
    out
}

/// Time inside each timed span, by the span's system name.
#[derive(Default)]
struct SpanTimes {
    /// Indexed by span id − 1.
    spans: Vec<TimedSpan>,
}

struct TimedSpan {
    system: String,
    entered: Option<Instant>,
    time: Duration,
    runs: u64,
    /// A system's own span (not its commands'): counts runs.
    counts_runs: bool,
}

impl SpanTimes {
    /// The times so far (names, times and runs), leaving zero in their place.
    fn take_times(&mut self) -> SpanTimes {
        let spans = self
            .spans
            .iter_mut()
            .map(|s| TimedSpan {
                system: s.system.clone(),
                entered: None,
                time: std::mem::take(&mut s.time),
                runs: std::mem::take(&mut s.runs),
                counts_runs: s.counts_runs,
            })
            .collect();
        SpanTimes { spans }
    }

    /// Time and runs of the system called `name` (its commands' time included).
    fn of(&self, name: &str) -> (Duration, u64) {
        self.spans
            .iter()
            .filter(|s| s.system == name)
            .fold((Duration::ZERO, 0), |(t, n), s| {
                (t + s.time, n + u64::from(s.counts_runs) * s.runs)
            })
    }
}

/// A tracing subscriber that times bevy's `system` and `system_commands` spans.
#[derive(Default)]
struct SpanTimer {
    times: Arc<Mutex<SpanTimes>>,
}

/// bevy's span of a system's run, and of the commands it deferred.
fn timed(meta: &Metadata<'_>) -> bool {
    matches!(meta.name(), "system" | "system_commands")
}

/// Reads a span's `name` field.
struct NameField(String);

impl tracing::field::Visit for NameField {
    fn record_str(&mut self, field: &tracing::field::Field, value: &str) {
        if field.name() == "name" {
            self.0 = value.to_string();
        }
    }

    fn record_debug(&mut self, field: &tracing::field::Field, value: &dyn std::fmt::Debug) {
        if field.name() == "name" {
            self.0 = format!("{value:?}");
        }
    }
}

impl Subscriber for SpanTimer {
    fn register_callsite(&self, meta: &'static Metadata<'static>) -> Interest {
        if timed(meta) {
            Interest::always()
        } else {
            Interest::never()
        }
    }

    fn enabled(&self, meta: &Metadata<'_>) -> bool {
        timed(meta)
    }

    fn new_span(&self, span: &Attributes<'_>) -> Id {
        let mut name = NameField(String::new());
        span.record(&mut name);
        let mut t = self.times.lock().expect("profile times");
        t.spans.push(TimedSpan {
            system: name.0,
            entered: None,
            time: Duration::ZERO,
            runs: 0,
            counts_runs: span.metadata().name() == "system",
        });
        Id::from_u64(t.spans.len() as u64)
    }

    fn record(&self, _: &Id, _: &Record<'_>) {}

    fn record_follows_from(&self, _: &Id, _: &Id) {}

    fn event(&self, _: &Event<'_>) {}

    fn enter(&self, span: &Id) {
        let now = Instant::now();
        let mut t = self.times.lock().expect("profile times");
        if let Some(s) = t.spans.get_mut(span.into_u64() as usize - 1) {
            s.entered = Some(now);
        }
    }

    fn exit(&self, span: &Id) {
        let now = Instant::now();
        let mut t = self.times.lock().expect("profile times");
        if let Some(s) = t.spans.get_mut(span.into_u64() as usize - 1)
            && let Some(at) = s.entered.take()
        {
            s.time += now - at;
            s.runs += 1;
        }
    }
}

#[cfg(test)]
mod tests;
