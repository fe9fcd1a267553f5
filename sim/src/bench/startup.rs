//! `sim bench startup`: how long `sim run` takes before its first tick, part by part (reading
//! and resolving the scenario, then each phase of building the world, [`BuildTimes`]), and the
//! first tick beside the ticks after it (global localizers do their widest work in the first
//! update). Every run builds its world from nothing in this process; the first run of each
//! scenario is reported apart from the median of the others, since it also reads the files and
//! fills the allocator's pages.

use crate::Simulation;
use crate::build::BuildTimes;
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

/// One scenario's start-up (ms).
#[derive(Serialize, Debug, Clone)]
pub struct StartupRow {
    pub scenario: String,
    pub runs: u32,
    /// Reading, parsing and resolving the scenario (maps, places, defaults).
    pub load_ms: f64,
    /// Building the world, phase by phase (in build order), and the outputs and schedule.
    pub build_ms: f64,
    pub phases_ms: Vec<(String, f64)>,
    /// `load_ms + build_ms`: the time before the first tick.
    pub before_first_tick_ms: f64,
    /// The same for the first run in the process.
    pub first_run_before_first_tick_ms: f64,
    pub first_tick_ms: f64,
    /// Median of the ticks after the first.
    pub tick_ms: f64,
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

fn sample(path: &std::path::Path, threads: usize, ticks: u32) -> anyhow::Result<Sample> {
    let started = Instant::now();
    let scenario = crate::scenario::load_scenario(path)?;
    let load = ms(started.elapsed());
    let started = Instant::now();
    let mut sim = Simulation::from_scenario(scenario)
        .threads(threads)
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

/// Start-up of the scenario at `path`, `runs` times.
pub fn measure(
    name: &str,
    path: &std::path::Path,
    o: &StartupOptions,
) -> anyhow::Result<StartupRow> {
    let samples = (0..o.runs)
        .map(|_| sample(path, o.threads, o.ticks))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let (first, rest) = samples.split_first().expect("at least two runs");
    let med = |f: &dyn Fn(&Sample) -> f64| median(&mut rest.iter().map(f).collect::<Vec<_>>());
    let load_ms = med(&|s| s.load);
    let build_ms = med(&|s| s.build);
    let phases_ms = first
        .phases
        .iter()
        .enumerate()
        .map(|(i, &(name, _))| (name.to_string(), med(&|s| s.phases[i].1)))
        .collect();
    Ok(StartupRow {
        scenario: name.to_string(),
        runs: o.runs,
        load_ms,
        build_ms,
        phases_ms,
        before_first_tick_ms: med(&|s| s.load + s.build),
        first_run_before_first_tick_ms: first.load + first.build,
        first_tick_ms: med(&|s| s.first_tick),
        tick_ms: med(&|s| {
            let mut t = s.ticks.clone();
            median(&mut t)
        }),
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
            "start-up before the first tick, medians of {} runs after the first; {}",
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
        "{}: {:.1} ms before the first tick (first run {:.1} ms); first tick {:.1} ms, then {:.3} ms per tick\n  load {:.1} ms\n",
        r.scenario,
        r.before_first_tick_ms,
        r.first_run_before_first_tick_ms,
        r.first_tick_ms,
        r.tick_ms,
        r.load_ms
    );
    let phases: f64 = r.phases_ms.iter().map(|p| p.1).sum();
    for (name, t) in &r.phases_ms {
        out.push_str(&format!("  {name} {t:.1} ms\n"));
    }
    out.push_str(&format!(
        "  outputs and schedule {:.1} ms\n",
        (r.build_ms - phases).max(0.0)
    ));
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
        let names: Vec<&str> = row.phases_ms.iter().map(|p| p.0.as_str()).collect();
        assert_eq!(names.first(), Some(&"kernel pool"));
        assert_eq!(names.last(), Some(&"plugins"));
        assert!(names.contains(&"localization map"), "{names:?}");
        let sum: f64 = row.phases_ms.iter().map(|p| p.1).sum();
        assert!(
            sum <= row.build_ms * 1.001 + 1e-3,
            "{sum} > {}",
            row.build_ms
        );
        assert!(row.before_first_tick_ms >= row.build_ms);
        assert!(row.first_tick_ms > 0.0 && row.tick_ms > 0.0);
        let text = format_row(&row);
        assert!(text.contains("outputs and schedule"), "{text}");
    }
}
