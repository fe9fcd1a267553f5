//! Many seeds of a scenario in parallel from code, on the engine of `sim batch`: the same runs,
//! rows and statistics, so the table printed here is the one `sim batch` prints.
//!
//! ```text
//! cargo run --release -p sim --example parameter_sweep [SEEDS] [DURATION_S]
//! ```
//!
//! is the same batch as
//!
//! ```text
//! sim batch park_route_short --seeds 0..SEEDS --duration DURATION_S
//! ```

use sim::batch::{BatchResults, Sweep};

/// The bundled scenario swept: a short outdoor route, quick to run.
const SCENARIO: &str = "park_route_short";

/// Runs seeds `0..seeds` of the scenario for `duration_s` simulated seconds each, as many at a
/// time as there are cores. Every run is deterministic: the same seed gives the same row
/// however many run at once.
fn run(seeds: u64, duration_s: f64) -> anyhow::Result<BatchResults> {
    // `.set(key, value)` and `.sweep(key, values)` add parameter sets, as in `sim batch`.
    Sweep::new(SCENARIO, 0..seeds).duration(duration_s).run()
}

fn main() -> anyhow::Result<()> {
    // optional arguments: the number of seeds and the simulated seconds per run
    let mut args = std::env::args().skip(1);
    let seeds = args.next().map_or(Ok(8), |a| a.parse())?;
    let duration_s = args.next().map_or(Ok(20.0), |a| a.parse())?;
    let results = run(seeds, duration_s)?;
    print!("{}", results.table);
    println!("{} runs, {} failed", results.runs.len(), results.failed);
    // each run's full summary is there too, e.g. the distance of every run
    for (row, run) in results.runs.iter().enumerate() {
        if let Ok(summary) = &run.result {
            let distance: f64 = summary.robots.iter().map(|r| r.distance_m).sum();
            println!("run {row} (seed {}): {distance:.2} m", run.job.seed);
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;
    use sim::cli::{Cli, Command};

    /// The table without its wall-clock line (the real-time factor differs between any two
    /// runs of anything).
    fn deterministic(table: &str) -> String {
        table
            .lines()
            .filter(|l| !l.trim_start().starts_with("real_time_factor"))
            .collect::<Vec<_>>()
            .join("\n")
    }

    #[test]
    fn the_sweep_prints_what_sim_batch_prints() {
        let (seeds, duration) = (4, 10.0);
        let ours = run(seeds, duration).unwrap();
        assert_eq!((ours.runs.len(), ours.failed), (4, 0));
        // `sim batch` itself: its command line, parsed as the binary parses it, and its command
        let out = std::env::temp_dir().join(format!("parameter_sweep-{}", std::process::id()));
        let cli = Cli::try_parse_from([
            "sim",
            "batch",
            SCENARIO,
            "--seeds",
            &format!("0..{seeds}"),
            "--duration",
            &duration.to_string(),
            "--quiet",
            "--out",
            out.to_str().unwrap(),
        ])
        .unwrap();
        let Command::Batch(args) = cli.command else {
            panic!("not the batch command");
        };
        let theirs = sim::batch::batch_command(&args).unwrap();
        std::fs::remove_dir_all(&out).ok();
        assert_eq!(deterministic(&ours.table), deterministic(&theirs.table));
        assert!(ours.table.contains("fleet.distance_m"), "{}", ours.table);
    }
}
