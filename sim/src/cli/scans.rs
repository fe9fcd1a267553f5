//! `sim scans`: capture laser scans with their true sensor poses into a SCANS file.

use crate::formats::scans::write_scans;
use crate::options::check_duration;
use crate::run::{ScanCapture, capture_scans};
use crate::scenario::scenario_arg;
use std::path::PathBuf;

#[derive(clap::Args, Clone, Debug)]
pub struct ScansArgs {
    /// A scenario file or the name of a bundled scenario (default: hospital_patrol).
    pub scenario: Option<String>,
    /// The SCANS file to write.
    #[arg(long)]
    pub out: PathBuf,
    /// Keep one scan per robot every this many simulated seconds.
    #[arg(long, default_value_t = 0.1, allow_negative_numbers = true)]
    pub period: f64,
    /// Override the scenario's duration (simulated seconds).
    #[arg(long, allow_negative_numbers = true)]
    pub duration: Option<f64>,
    /// Only this robot's scans (repeatable; default: every robot with a laser).
    #[arg(long = "robot")]
    pub robots: Vec<String>,
    /// Override the scenario's seed.
    #[arg(long)]
    pub seed: Option<u64>,
    /// Worker threads for parallel kernels (0 = one per core; at most 1024). Results do not
    /// depend on it.
    #[arg(long, default_value_t = 0, value_parser = crate::options::parse_threads)]
    pub threads: usize,
    /// No progress bar and no report, only errors.
    #[arg(long)]
    pub quiet: bool,
}

/// `sim scans`.
pub fn scans_command(a: ScansArgs) -> anyhow::Result<()> {
    let mut sc = scenario_arg(a.scenario.as_deref())?;
    if let Some(s) = a.seed {
        sc.seed = s;
    }
    if let Some(d) = a.duration {
        sc.duration = check_duration(d)?;
    }
    let period = a.period;
    if !(period.is_finite() && period > 0.0) {
        anyhow::bail!("--period: expected a positive number of seconds, got {period}");
    }
    let capture = ScanCapture {
        period_s: period,
        robots: (!a.robots.is_empty()).then_some(a.robots),
    };
    if !a.quiet {
        eprintln!(
            "capturing scans of {} ({} robots, {:.1} s simulated, seed {}, one scan per \
             robot every {period} s)",
            sc.name,
            sc.robots.len(),
            sc.duration,
            sc.seed
        );
    }
    let scans = capture_scans(&sc, &capture, a.threads, !a.quiet)?;
    if scans.is_empty() {
        anyhow::bail!(
            "{}: no laser scans captured (does any selected robot carry a laser?)",
            sc.source
        );
    }
    write_scans(&a.out, &scans)?;
    if !a.quiet {
        println!("{} scans written to {}", scans.len(), a.out.display());
    }
    Ok(())
}
