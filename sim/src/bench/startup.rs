//! `sim bench startup`: how long `sim run` takes before its first tick, part by part (reading
//! and resolving the scenario, then each phase of building the world, [`BuildTimes`]), and the
//! first tick beside the ticks after it (global localizers do their widest work in the first
//! update). Every run builds its world from nothing in this process, cold (an empty cache of
//! map-derived structures, a new folder per run: everything is built, then written) and warm (the
//! cache filled: the map-derived structures are read). The first run of each series is reported
//! apart from the median of the others, since it also reads the files and fills the allocator's
//! pages.

use crate::Simulation;
use crate::build::BuildTimes;
use crate::cache::MapCache;
use crate::scenario::{bundled_scenarios, scenario_path};
use crate::stats::median;
use serde::Serialize;
use std::time::{Duration, Instant};

/// `sim bench startup`.
#[derive(clap::Args, Clone, Debug)]
pub struct StartupOptions {
    /// Scenario files or names of bundled scenarios (default: every bundled scenario).
    pub scenarios: Vec<String>,
    /// Runs per scenario; the figures are the medians of all but the first.
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(2..))]
    pub runs: u32,
    /// Ticks timed after the first one.
    #[arg(long, default_value_t = 10, value_parser = clap::value_parser!(u32).range(1..))]
    pub ticks: u32,
    /// Kernel threads (0: every core, as `sim run`).
    #[arg(long, default_value_t = 0)]
    pub threads: usize,
    /// One JSON object per scenario, one per line.
    #[arg(long)]
    pub json: bool,
}

/// One scenario's start-up (ms), cold and warm.
#[derive(Serialize, Debug, Clone)]
pub struct StartupRow {
    pub scenario: String,
    pub runs: u32,
    /// Every run with an empty cache (a new folder each).
    pub cold: StartupSeries,
    /// Every run with the cache filled.
    pub warm: StartupSeries,
    /// The first tick (median over both series).
    pub first_tick_ms: f64,
    /// Median of the ticks after the first.
    pub tick_ms: f64,
}

/// The start-up of one series of runs (ms).
#[derive(Serialize, Debug, Clone)]
pub struct StartupSeries {
    /// Reading, parsing and resolving the scenario (maps, places, defaults).
    pub load_ms: f64,
    /// Building the world, phase by phase (in build order), and the outputs and schedule.
    pub build_ms: f64,
    pub phases_ms: Vec<(String, f64)>,
    /// `load_ms + build_ms`: the time before the first tick.
    pub before_first_tick_ms: f64,
    /// The same for the series' first run.
    pub first_run_before_first_tick_ms: f64,
}

struct Sample {
    load: f64,
    build: f64,
    phases: Vec<(&'static str, f64)>,
    first_tick: f64,
    ticks: Vec<f64>,
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

fn sample(
    path: &std::path::Path,
    threads: usize,
    ticks: u32,
    cache: MapCache,
) -> anyhow::Result<Sample> {
    let started = Instant::now();
    let scenario = crate::scenario::load_scenario(path)?;
    let load = ms(started.elapsed());
    let started = Instant::now();
    let mut sim = Simulation::from_scenario(scenario)
        .threads(threads)
        .cache(cache)
        .build()?;
    let build = ms(started.elapsed());
    let phases = sim
        .world()
        .get_resource::<BuildTimes>()
        .map(|t| t.phases.iter().map(|&(n, d)| (n, ms(d))).collect())
        .unwrap_or_default();
    let started = Instant::now();
    sim.step()?;
    let first_tick = ms(started.elapsed());
    let mut times = Vec::with_capacity(ticks as usize);
    for _ in 0..ticks {
        if sim.is_over() {
            break;
        }
        let started = Instant::now();
        sim.step()?;
        times.push(ms(started.elapsed()));
    }
    Ok(Sample {
        load,
        build,
        phases,
        first_tick,
        ticks: times,
    })
}

/// The medians of a series (its first run apart).
fn series(samples: &[Sample]) -> StartupSeries {
    let (first, rest) = samples.split_first().expect("at least two runs");
    let med = |f: &dyn Fn(&Sample) -> f64| median(&mut rest.iter().map(f).collect::<Vec<_>>());
    StartupSeries {
        load_ms: med(&|s| s.load),
        build_ms: med(&|s| s.build),
        phases_ms: first
            .phases
            .iter()
            .enumerate()
            .map(|(i, &(name, _))| (name.to_string(), med(&|s| s.phases[i].1)))
            .collect(),
        before_first_tick_ms: med(&|s| s.load + s.build),
        first_run_before_first_tick_ms: first.load + first.build,
    }
}

/// Start-up of the scenario at `path`, `runs` times cold and `runs` times warm, with cache
/// folders under a temporary folder (removed at the end).
pub fn measure(
    name: &str,
    path: &std::path::Path,
    o: &StartupOptions,
) -> anyhow::Result<StartupRow> {
    let tmp = tempfile::tempdir()?;
    let cold = (0..o.runs)
        .map(|k| {
            let cache = MapCache::in_dir(tmp.path().join(format!("cold-{k}")));
            sample(path, o.threads, o.ticks, cache)
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    // the last cold run's folder holds every entry
    let filled = tmp.path().join(format!("cold-{}", o.runs - 1));
    let warm = (0..o.runs)
        .map(|_| sample(path, o.threads, o.ticks, MapCache::in_dir(&filled)))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let after_first = || cold[1..].iter().chain(&warm[1..]);
    Ok(StartupRow {
        scenario: name.to_string(),
        runs: o.runs,
        cold: series(&cold),
        warm: series(&warm),
        first_tick_ms: median(&mut after_first().map(|s| s.first_tick).collect::<Vec<_>>()),
        tick_ms: median(
            &mut after_first()
                .map(|s| median(&mut s.ticks.clone()))
                .collect::<Vec<_>>(),
        ),
    })
}

/// `sim bench startup`.
pub fn run_startup_bench(o: &StartupOptions) -> anyhow::Result<()> {
    let scenarios: Vec<(String, std::path::PathBuf)> = if o.scenarios.is_empty() {
        bundled_scenarios()?
    } else {
        o.scenarios
            .iter()
            .map(|s| Ok((s.clone(), scenario_path(Some(s))?)))
            .collect::<anyhow::Result<_>>()?
    };
    if !o.json {
        println!(
            "start-up before the first tick, cold (empty cache) and warm (cache filled), medians \
             of {} runs after the first; {}",
            o.runs - 1,
            crate::bench::machine::describe()
        );
    }
    for (name, path) in &scenarios {
        let row = measure(name, path, o)?;
        if o.json {
            println!("{}", crate::bench::machine::json_line(&row)?);
        } else {
            print!("{}", format_row(&row));
        }
    }
    Ok(())
}

fn format_row(r: &StartupRow) -> String {
    let mut out = format!(
        "{}: cold {:.1} ms, warm {:.1} ms before the first tick (first runs {:.1} and {:.1} ms); \
         first tick {:.1} ms, then {:.3} ms per tick\n  {:<30}{:>9}{:>9}\n",
        r.scenario,
        r.cold.before_first_tick_ms,
        r.warm.before_first_tick_ms,
        r.cold.first_run_before_first_tick_ms,
        r.warm.first_run_before_first_tick_ms,
        r.first_tick_ms,
        r.tick_ms,
        "(ms)",
        "cold",
        "warm",
    );
    let mut line = |name: &str, cold: f64, warm: f64| {
        out.push_str(&format!("  {name:<30}{cold:>9.1}{warm:>9.1}\n"));
    };
    line("load", r.cold.load_ms, r.warm.load_ms);
    for ((name, cold), (_, warm)) in r.cold.phases_ms.iter().zip(&r.warm.phases_ms) {
        line(name, *cold, *warm);
    }
    let rest =
        |s: &StartupSeries| (s.build_ms - s.phases_ms.iter().map(|p| p.1).sum::<f64>()).max(0.0);
    line("outputs and schedule", rest(&r.cold), rest(&r.warm));
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every phase of a bundled scenario's start-up is reported, in build order, and they add
    /// up to no more than the whole build.
    #[test]
    fn start_up_is_reported_phase_by_phase() {
        let o = StartupOptions {
            scenarios: vec![],
            runs: 2,
            ticks: 2,
            threads: 1,
            json: true,
        };
        let path = scenario_path(Some("maze_run")).unwrap();
        let row = measure("maze_run", &path, &o).unwrap();
        for series in [&row.cold, &row.warm] {
            let names: Vec<&str> = series.phases_ms.iter().map(|p| p.0.as_str()).collect();
            assert_eq!(names.first(), Some(&"kernel pool"));
            assert_eq!(names.last(), Some(&"plugins"));
            assert!(names.contains(&"localization map"), "{names:?}");
            let sum: f64 = series.phases_ms.iter().map(|p| p.1).sum();
            assert!(
                sum <= series.build_ms * 1.001 + 1e-3,
                "{sum} > {}",
                series.build_ms
            );
            assert!(series.before_first_tick_ms >= series.build_ms);
        }
        assert_eq!(row.cold.phases_ms.len(), row.warm.phases_ms.len());
        assert!(row.first_tick_ms > 0.0 && row.tick_ms > 0.0);
        let text = format_row(&row);
        assert!(text.contains("outputs and schedule"), "{text}");
        assert!(text.contains("cold") && text.contains("warm"), "{text}");
    }
}
