//! `sim experiment …`: the experiments' subcommands; each takes its experiment's own options
//! and prints a table, or JSON rows with `--json`.

use crate::experiment::de_match::{DeMatchOptions, run_de_match_experiment};
use crate::experiment::localization::{LocalizationOptions, run_localization_experiment};
use crate::experiment::park::{ParkOptions, run_park_experiment};
use crate::experiment::slam_compare::{SlamExperimentOptions, run_slam_experiment};
use crate::experiment::{localization, park, slam_compare};
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
    /// Whether the localizers of a scenario (default: hospital_patrol, every robot carrying
    /// five) find their robot and hold it, over many seeds: one row per localizer
    /// (convergence, time tracked after it, lost episodes, map-frame error, odometry drift),
    /// the runs' collisions and speed, and the targets they are held to.
    Localization {
        #[command(flatten)]
        options: LocalizationOptions,
        /// JSON lines: {"row": "localizer", ...} per localizer, one {"row": "runs", ...} and
        /// {"row": "target", ...} per target.
        #[arg(long)]
        json: bool,
        /// With --json: also one {"row": "run", ...} per localizer of each robot of each run.
        #[arg(long, requires = "json")]
        per_run: bool,
        /// Exit with code 1 when a target other than speed is not met.
        #[arg(long)]
        check: bool,
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
        ExperimentCommand::Localization {
            mut options,
            json,
            per_run,
            check,
        } => {
            options.progress = !json;
            let r = run_localization_experiment(&options)?;
            if json {
                let tagged = |row: &str, v: serde_json::Value| {
                    let mut v = v;
                    if let Some(o) = v.as_object_mut() {
                        o.insert("row".into(), row.into());
                    }
                    serde_json::to_string(&v)
                };
                for x in &r.rows {
                    println!("{}", tagged("localizer", serde_json::to_value(x)?)?);
                }
                println!("{}", tagged("runs", serde_json::to_value(&r.runs)?)?);
                for x in &r.targets {
                    println!("{}", tagged("target", serde_json::to_value(x)?)?);
                }
                if per_run {
                    for x in &r.per_run {
                        println!("{}", tagged("run", serde_json::to_value(x)?)?);
                    }
                }
            } else {
                print!("{}", localization::table(&r));
            }
            let missed = r.targets.iter().filter(|t| !t.met && !t.timing).count();
            if check && missed > 0 {
                anyhow::bail!("--check: {missed} target(s) other than speed not met");
            }
            Ok(())
        }
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
