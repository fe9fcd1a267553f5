//! `sim bench facade`: what a tick costs through the library facade ([`Simulation::step`], which
//! `sim run` uses) against the same world's schedule run directly. The two alternate, a simulated
//! second each, on one world (which goes first alternates too), so both see the same robots in the same
//! places and the same state of the machine; the figure is the median of the paired differences.
//! Timing two separate runs cannot show a cost this small: on a shared virtual machine the same
//! run spreads by ±25 %.

use crate::Simulation;
use crate::bench::swarm::{check_beams, swarm_scenario, swarm_world};
use serde::Serialize;
use std::time::{Duration, Instant};
use systems::core::SimClock;

/// `sim bench facade`: a tick through the facade against the bare schedule, paired.
#[derive(clap::Args, Clone, Debug)]
pub struct FacadeBenchOptions {
    /// One JSON object per population, one per line.
    #[arg(long)]
    pub json: bool,
    /// Populations of the swarm benchmark's world (wandering robots, lasers at 10 Hz).
    #[arg(long, value_delimiter = ',', num_args = 1.., default_values_t = [1usize, 1000])]
    pub robots: Vec<usize>,
    /// Beams per scan.
    #[arg(long, default_value_t = 180)]
    pub beams: usize,
    /// Wall-clock seconds of pairs per population (at least 30 pairs are run).
    #[arg(long, default_value_t = 10.0)]
    pub seconds: f64,
    /// Worker threads (0 = one per core; at most 1024).
    #[arg(long, default_value_t = 1, value_parser = crate::options::parse_threads)]
    pub threads: usize,
}

#[derive(Serialize, Debug)]
struct FacadeResult {
    bench: &'static str,
    robots: usize,
    beams: usize,
    threads: usize,
    pairs: usize,
    /// Median tick through the facade (µs).
    facade_tick_us: f64,
    /// Median tick of the schedule run directly (µs).
    schedule_tick_us: f64,
    /// Median of (facade − schedule) over the pairs (µs).
    overhead_us: f64,
    /// 95 % confidence interval of that median (µs), from the order statistics.
    overhead_ci95_us: [f64; 2],
    /// The overhead as a share of the schedule's tick (%).
    overhead_percent: f64,
}

/// Runs the paired benchmark for each population.
pub fn run_facade_bench(o: &FacadeBenchOptions) -> anyhow::Result<()> {
    if !(o.seconds.is_finite() && o.seconds > 0.0 && o.seconds <= 86_400.0) {
        anyhow::bail!(
            "--seconds: expected wall-clock seconds in (0, 86400], got {}",
            o.seconds
        );
    }
    if let Some(n) = o.robots.iter().find(|n| **n == 0) {
        anyhow::bail!("--robots: expected populations of at least 1 robot, got {n}");
    }
    check_beams(o.beams)?;
    let grid = swarm_world()?;
    if !o.json {
        println!(
            "facade benchmark: simulated seconds alternating through the facade and the bare schedule"
        );
        println!("machine: {}", crate::bench::machine::describe());
        println!(
            "{:>7} {:>6} {:>8} {:>12} {:>12} {:>12} {:>20} {:>9}",
            "robots",
            "beams",
            "pairs",
            "facade µs",
            "schedule µs",
            "overhead µs",
            "95 % interval µs",
            "share"
        );
    }
    for &n in &o.robots {
        // long enough never to end while measured
        let sc = swarm_scenario(&grid, n, o.beams, 1e6)?;
        let robots = sc.robots.len();
        let mut s = Simulation::from_scenario(sc).threads(o.threads).build()?;
        let row = measure(&mut s, Duration::from_secs_f64(o.seconds))?;
        let threads = if o.threads == 0 {
            std::thread::available_parallelism().map_or(1, |n| n.get())
        } else {
            o.threads
        };
        let r = FacadeResult {
            bench: "facade",
            robots,
            beams: o.beams,
            threads,
            ..row
        };
        if o.json {
            println!("{}", crate::bench::machine::json_line(&r)?);
        } else {
            println!(
                "{:>7} {:>6} {:>8} {:>12.3} {:>12.3} {:>12.3} {:>9.3} to {:>7.3} {:>8.2} %",
                r.robots,
                r.beams,
                r.pairs,
                r.facade_tick_us,
                r.schedule_tick_us,
                r.overhead_us,
                r.overhead_ci95_us[0],
                r.overhead_ci95_us[1],
                r.overhead_percent
            );
        }
    }
    Ok(())
}

/// The paired measurement on `s`: a warm-up of a tenth of the budget, then pairs of blocks of
/// one simulated second until the budget is spent (at least 30 pairs). Blocks, not single ticks:
/// sensors fire every few ticks (a 10 Hz laser every other tick at dt 0.05 s), and whole seconds
/// give both sides of a pair the same firings.
fn measure(s: &mut Simulation, budget: Duration) -> anyhow::Result<FacadeResult> {
    let block = (1.0 / s.scenario().dt).round().max(1.0) as u32;
    let warm_up = Instant::now();
    while warm_up.elapsed() < budget / 10 {
        s.step()?;
    }
    let mut facade = Vec::new();
    let mut schedule = Vec::new();
    let started = Instant::now();
    while facade.len() < 30 || started.elapsed() < budget {
        let first_facade = facade.len() % 2 == 0;
        for through_facade in [first_facade, !first_facade] {
            let t = Instant::now();
            if through_facade {
                for _ in 0..block {
                    s.step()?;
                }
                facade.push(t.elapsed() / block);
            } else {
                for _ in 0..block {
                    step_schedule(s);
                }
                schedule.push(t.elapsed() / block);
            }
        }
    }
    Ok(summarize(&facade, &schedule))
}

/// One tick of `s`'s world on its schedule, as the facade's step runs it, without the facade.
fn step_schedule(s: &mut Simulation) {
    let (world, schedule) = s.world_and_schedule();
    schedule.run(world);
    world.resource_mut::<SimClock>().advance();
}

/// Medians of paired tick times (same length), the median of their differences and its 95 %
/// interval.
fn summarize(facade: &[Duration], schedule: &[Duration]) -> FacadeResult {
    let us = |d: &Duration| d.as_secs_f64() * 1e6;
    let mut diff: Vec<f64> = facade
        .iter()
        .zip(schedule)
        .map(|(f, s)| us(f) - us(s))
        .collect();
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let mut f: Vec<f64> = facade.iter().map(us).collect();
    let mut s: Vec<f64> = schedule.iter().map(us).collect();
    let (facade_tick_us, schedule_tick_us) = (median(&mut f), median(&mut s));
    let overhead_us = median(&mut diff);
    // the median's rank has a binomial(n, 1/2) distribution: n/2 ± 1.96 √n / 2
    let n = diff.len();
    let half_width = (1.96 * (n as f64).sqrt() / 2.0).ceil() as usize;
    let lo = diff[(n / 2).saturating_sub(half_width)];
    let hi = diff[(n / 2 + half_width).min(n - 1)];
    FacadeResult {
        bench: "facade",
        robots: 0,
        beams: 0,
        threads: 0,
        pairs: n,
        facade_tick_us,
        schedule_tick_us,
        overhead_us,
        overhead_ci95_us: [lo, hi],
        overhead_percent: 100.0 * overhead_us / schedule_tick_us,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn us(v: &[f64]) -> Vec<Duration> {
        v.iter()
            .map(|x| Duration::from_secs_f64(x * 1e-6))
            .collect()
    }

    #[test]
    fn the_overhead_is_the_median_of_the_paired_differences() {
        // the schedule's ticks drift from 10 to 19 µs; the facade's are 0.5 µs longer, paired
        let schedule: Vec<f64> = (0..101).map(|i| 10.0 + (i % 10) as f64).collect();
        let facade: Vec<f64> = schedule.iter().map(|s| s + 0.5).collect();
        let r = summarize(&us(&facade), &us(&schedule));
        assert_eq!(r.pairs, 101);
        assert!((r.overhead_us - 0.5).abs() < 1e-3, "{r:?}");
        assert!((r.overhead_ci95_us[0] - 0.5).abs() < 1e-3, "{r:?}");
        assert!((r.overhead_ci95_us[1] - 0.5).abs() < 1e-3, "{r:?}");
        // 10, 11, … 19 µs ten or eleven times each: the 51st of 101 is 14
        assert!((r.schedule_tick_us - 14.0).abs() < 1e-3, "{r:?}");
        assert!(
            (r.overhead_percent - 100.0 * 0.5 / 14.0).abs() < 1e-2,
            "{r:?}"
        );
    }

    #[test]
    fn a_few_outlying_pairs_do_not_move_the_overhead() {
        let schedule = vec![20.0; 200];
        let mut facade = vec![20.2; 200];
        // a descheduled thread now and then
        for i in (0..200).step_by(25) {
            facade[i] = 900.0;
        }
        let r = summarize(&us(&facade), &us(&schedule));
        assert!((r.overhead_us - 0.2).abs() < 1e-3, "{r:?}");
        assert!(r.overhead_ci95_us[1] < 1.0, "{r:?}");
    }

    #[test]
    fn bad_options_are_errors() {
        let o = FacadeBenchOptions {
            json: true,
            robots: vec![1],
            beams: 180,
            seconds: f64::NAN,
            threads: 1,
        };
        let e = run_facade_bench(&o).unwrap_err().to_string();
        assert!(e.contains("--seconds"), "{e}");
        let o = FacadeBenchOptions {
            beams: 1,
            seconds: 1.0,
            ..o
        };
        let e = run_facade_bench(&o).unwrap_err().to_string();
        assert!(e.contains("--beams"), "{e}");
        let o = FacadeBenchOptions {
            robots: vec![1, 0],
            beams: 180,
            ..o
        };
        let e = run_facade_bench(&o).unwrap_err().to_string();
        assert!(e.contains("--robots"), "{e}");
    }
}
