//! `sim experiment …`: the experiments' subcommands; each takes its experiment's own options
//! and prints a table, or JSON rows with `--json`.

use crate::experiment::de_match::{DeMatchOptions, run_de_match_experiment};
use crate::experiment::park::{ParkOptions, run_park_experiment};
use crate::experiment::slam_compare::{SlamExperimentOptions, run_slam_experiment};
use crate::experiment::{park, slam_compare};
use clap::Subcommand;
use serde::Serialize;

#[derive(Subcommand)]
pub enum ExperimentCommand {
    /// The park runs of the park thesis: each route N times (seeds 0..N), navigating by
    /// road-grid localization and by road MCL; reached-goal rate, wrong turns, recoveries,
    /// time and localization error of both localizers. A route with several robots judges each
    /// of them: `robot runs` = runs × robots with a route, and reached %, wrong turns and
    /// recoveries count robot runs.
    Park {
        #[command(flatten)]
        options: ParkOptions,
        /// One JSON object per row, one per line (and one per run with --per-run).
        #[arg(long)]
        json: bool,
        /// With --json: also print every run.
        #[arg(long, requires = "json")]
        per_run: bool,
    },
    /// The scan-matching protocol of the hospital thesis on maze and hospital scans:
    /// success λ, σx, σy, σθ and time per alignment for every DE strategy, the Euclidean
    /// reference and the improved matcher.
    DeMatch(DeMatchOptions),
    /// The maze run of the hospital thesis and the hospital loop: ATE, RPE and map quality
    /// of wheel odometry, DE scan-to-scan odometry, scan-to-map, RBPF and graph SLAM on
    /// identical data.
    MazeSlam {
        #[command(flatten)]
        options: SlamExperimentOptions,
        /// One JSON object per scenario and method, one per line.
        #[arg(long)]
        json: bool,
    },
}

/// `sim experiment …`.
pub fn experiment_command(which: ExperimentCommand) -> anyhow::Result<()> {
    match which {
        ExperimentCommand::Park {
            mut options,
            json,
            per_run,
        } => {
            options.progress = !json;
            let (rows, all) = run_park_experiment(&options)?;
            if json {
                print_json(&rows)?;
                if per_run {
                    print_json(&all)?;
                }
            } else {
                print!("{}", park::table(&rows));
            }
            Ok(())
        }
        ExperimentCommand::DeMatch(o) => run_de_match_experiment(&o),
        ExperimentCommand::MazeSlam { mut options, json } => {
            options.progress = !json;
            let rows = run_slam_experiment(&options)?;
            if json {
                print_json(&rows)?;
            } else {
                print!("{}", slam_compare::table(&rows));
            }
            Ok(())
        }
    }
}

/// One JSON object per row, one per line.
fn print_json<T: Serialize>(rows: &[T]) -> anyhow::Result<()> {
    for r in rows {
        println!("{}", serde_json::to_string(r)?);
    }
    Ok(())
}
