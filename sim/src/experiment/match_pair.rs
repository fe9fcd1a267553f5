//! `sim match SCANS --reference I --current J …`: aligns one pair of scans of a SCANS file, like
//! the thesis's program ([Hospital thesis §6]: `-file`, `-reference`, `-current`, `-gen`,
//! `-pop`, `-F`, `-C`, `-time`), and — since the file carries the true sensor poses — compares
//! the answer with the true transform `P_ref⁻¹ ⊕ P_cur`.

use crate::formats::scans::{ScanRecord, read_scans};
use serde::Serialize;
use std::path::PathBuf;
use std::time::Duration;
use systems::core::{Pose2, wrap_angle};
use systems::matching::{
    Crossover, DeParams, MatchConfig, MatchResult, SearchWindow, StallStop, Strategy,
    ThesisFitness, match_scans,
};

/// Which matcher `sim match` runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum FitnessArg {
    /// The thesis's DE with its raster cross-correlation (eq. 29); higher is better.
    Correlation,
    /// The thesis's DE with the Euclidean reference on a distance field (fast form).
    Euclidean,
    /// The thesis's DE with the brute-force Euclidean reference (§7.1); slow.
    EuclideanBrute,
    /// The improved matcher (rotation hypotheses, exhaustive translation search, refinement).
    Improved,
}

impl FitnessArg {
    pub fn thesis(self) -> Option<ThesisFitness> {
        match self {
            FitnessArg::Correlation => Some(ThesisFitness::Correlation),
            FitnessArg::Euclidean => Some(ThesisFitness::EuclideanField),
            FitnessArg::EuclideanBrute => Some(ThesisFitness::EuclideanBrute),
            FitnessArg::Improved => None,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            FitnessArg::Correlation => "correlation",
            FitnessArg::Euclidean => "euclidean",
            FitnessArg::EuclideanBrute => "euclidean-brute",
            FitnessArg::Improved => "improved",
        }
    }
}

/// Crossover of the thesis's DE.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum CrossoverArg {
    Binomial,
    Exponential,
}

impl From<CrossoverArg> for Crossover {
    fn from(c: CrossoverArg) -> Crossover {
        match c {
            CrossoverArg::Binomial => Crossover::Binomial,
            CrossoverArg::Exponential => Crossover::Exponential,
        }
    }
}

/// The command-line name of a strategy: the thesis's name without the slash (`rand1`,
/// `current-to-best2`, `either-or`).
pub fn strategy_cli_name(s: Strategy) -> String {
    s.name().replace('/', "")
}

/// Parses a strategy given as `rand1` or as the thesis writes it, `rand/1`.
pub fn parse_strategy(text: &str) -> Result<Strategy, String> {
    let t = text.trim().to_ascii_lowercase();
    Strategy::ALL
        .into_iter()
        .find(|s| s.name() == t || strategy_cli_name(*s) == t)
        .ok_or_else(|| {
            let names: Vec<String> = Strategy::ALL.into_iter().map(strategy_cli_name).collect();
            format!("expected one of {}, found `{text}`", names.join(", "))
        })
}

/// Largest `--pop`: a thousand times the thesis program's 100 (each generation evaluates the
/// whole population).
pub const MAX_POPULATION: usize = 100_000;
/// Largest `--gens`: a hundred times the thesis program's 10 000.
pub const MAX_GENERATIONS: usize = 1_000_000;
/// Largest `--max-xy` (m): far beyond any laser's range, so beyond any overlap of two scans.
pub const MAX_WINDOW_XY_M: f64 = 100.0;

/// Options of `sim match`.
/// Options of `sim match`.
#[derive(clap::Args, Clone, Debug)]
pub struct MatchOptions {
    /// The SCANS file.
    pub scans: PathBuf,
    /// Index of the reference scan (the `index` column).
    #[arg(long)]
    pub reference: u64,
    /// Index of the current (test) scan.
    #[arg(long)]
    pub current: u64,
    /// Matcher: the thesis's DE with a fitness, or the improved matcher.
    #[arg(long, value_enum, default_value_t = FitnessArg::Improved)]
    pub fitness: FitnessArg,
    /// DE mutation strategy (default rand1): rand1, rand2, best1, best2, current-to-best1,
    /// current-to-best2, rand-to-best1, rand-to-best2, either-or.
    #[arg(long, value_parser = parse_strategy)]
    pub strategy: Option<Strategy>,
    /// DE crossover (default binomial).
    #[arg(long, value_enum)]
    pub crossover: Option<CrossoverArg>,
    /// DE population size (default 100, the thesis program's).
    #[arg(long = "pop", allow_negative_numbers = true, value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(..=MAX_POPULATION as u64))]
    pub population: Option<usize>,
    /// DE generations (default 10000, the thesis program's).
    #[arg(long = "gens", value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(..=MAX_GENERATIONS as u64))]
    pub generations: Option<usize>,
    /// DE mutation constant F (default 0.9).
    #[arg(short = 'F', allow_negative_numbers = true)]
    pub f: Option<f64>,
    /// DE crossover rate CR (default 0.9).
    #[arg(short = 'C', allow_negative_numbers = true)]
    pub cr: Option<f64>,
    /// Stop the DE after this many generations without improvement (default: never).
    #[arg(long)]
    pub stall: Option<usize>,
    /// Wall-time limit of the DE in seconds (the thesis's -time; breaks determinism).
    #[arg(long = "time", allow_negative_numbers = true)]
    pub time_limit: Option<f64>,
    /// Search window: |x|, |y| <= this (m).
    #[arg(long, default_value_t = 3.0, allow_negative_numbers = true)]
    pub max_xy: f64,
    /// Search window: |θ| <= this (degrees).
    #[arg(
        long = "max-theta",
        default_value_t = 180.0,
        allow_negative_numbers = true
    )]
    pub max_theta_deg: f64,
    /// Seed of the matcher's random stream.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// One JSON object instead of the text report.
    #[arg(long)]
    pub json: bool,
}

/// Builds the matcher configuration of the options (errors name the option).
pub fn match_config(o: &MatchOptions) -> anyhow::Result<MatchConfig> {
    if !(o.max_xy > 0.0 && o.max_xy <= MAX_WINDOW_XY_M) {
        anyhow::bail!(
            "--max-xy: expected a positive distance in metres of at most {MAX_WINDOW_XY_M}, got {}",
            o.max_xy
        );
    }
    if !(o.max_theta_deg.is_finite() && o.max_theta_deg > 0.0 && o.max_theta_deg <= 180.0) {
        anyhow::bail!(
            "--max-theta: expected an angle in (0, 180] degrees, got {}",
            o.max_theta_deg
        );
    }
    let window = SearchWindow {
        max_xy: o.max_xy,
        max_theta: o.max_theta_deg.to_radians(),
    };
    let mut config = match o.fitness.thesis() {
        None => {
            let given = [
                ("--strategy", o.strategy.is_some()),
                ("--crossover", o.crossover.is_some()),
                ("--pop", o.population.is_some()),
                ("--gens", o.generations.is_some()),
                ("-F", o.f.is_some()),
                ("-C", o.cr.is_some()),
                ("--stall", o.stall.is_some()),
                ("--time", o.time_limit.is_some()),
            ];
            if let Some((name, _)) = given.iter().find(|(_, g)| *g) {
                anyhow::bail!(
                    "{name} sets the thesis's DE: use it with --fitness correlation, euclidean or \
                     euclidean-brute, not with --fitness improved"
                );
            }
            MatchConfig::improved()
        }
        Some(fitness) => {
            // the thesis program's defaults (§6): population 100, 10 000 generations, F 0.9,
            // CR 0.9, rand/1, binomial; the DE runs on all cores
            let mut de = DeParams::thesis_program();
            if let Some(s) = o.strategy {
                de.strategy = s;
            }
            if let Some(c) = o.crossover {
                de.crossover = c.into();
            }
            if let Some(p) = o.population {
                de.population = p;
            }
            if let Some(g) = o.generations {
                de.generations = g;
            }
            if let Some(f) = o.f {
                de.f = f;
            }
            if let Some(cr) = o.cr {
                de.cr = cr;
            }
            if let Some(k) = o.stall {
                if k == 0 {
                    anyhow::bail!("--stall: expected at least 1 generation, got 0");
                }
                de.stall = Some(StallStop {
                    generations: k,
                    tolerance: 0.0,
                });
            }
            if let Some(t) = o.time_limit {
                if !(t.is_finite() && t > 0.0) {
                    anyhow::bail!("--time: expected a positive number of seconds, got {t}");
                }
                de.time_limit = Some(Duration::try_from_secs_f64(t).map_err(|_| {
                    anyhow::anyhow!("--time: {t:e} seconds is too long for a time limit")
                })?);
            }
            de.validate()
                .map_err(|e| anyhow::anyhow!("{}", cli_param_error(e)))?;
            MatchConfig::thesis(fitness, de)
        }
    };
    config.window = window;
    config.seed = o.seed;
    Ok(config)
}

/// A DE parameter error with the command-line option that sets it.
fn cli_param_error(e: systems::matching::MatchError) -> String {
    use systems::matching::MatchError as E;
    match &e {
        E::PopulationTooSmall { .. } => format!("--pop: {e}"),
        E::InvalidF(_) => format!("-F: {e}"),
        E::InvalidCr(_) => format!("-C: {e}"),
        _ => e.to_string(),
    }
}

/// An error of a found transform against the truth.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct TransformError {
    pub x_m: f64,
    pub y_m: f64,
    pub theta_rad: f64,
    /// Translation error ‖(Δx, Δy)‖.
    pub distance_m: f64,
}

impl TransformError {
    pub fn of(found: &Pose2, truth: &Pose2) -> Self {
        let (x, y) = (found.x - truth.x, found.y - truth.y);
        TransformError {
            x_m: x,
            y_m: y,
            theta_rad: wrap_angle(found.theta - truth.theta),
            distance_m: x.hypot(y),
        }
    }

    /// The success criterion of the experiments: within 0.1 m and 2° of the truth.
    pub fn right(&self) -> bool {
        self.distance_m <= RIGHT_XY_M && self.theta_rad.abs() <= RIGHT_THETA_DEG.to_radians()
    }
}

/// An alignment is right within this translation error (m) …
pub const RIGHT_XY_M: f64 = 0.1;
/// … and this rotation error (degrees).
pub const RIGHT_THETA_DEG: f64 = 2.0;
/// The thesis's failure filter (§7.3): correlation below this means a wrong rotation.
pub const THESIS_CORRELATION_FILTER: f64 = 30.0;

#[derive(Serialize)]
struct TransformJson {
    x_m: f64,
    y_m: f64,
    theta_rad: f64,
    x_mm: f64,
    y_mm: f64,
    theta_deg: f64,
}

impl From<&Pose2> for TransformJson {
    fn from(p: &Pose2) -> Self {
        TransformJson {
            x_m: p.x,
            y_m: p.y,
            theta_rad: p.theta,
            x_mm: p.x * 1000.0,
            y_mm: p.y * 1000.0,
            theta_deg: p.theta.to_degrees(),
        }
    }
}

#[derive(Serialize)]
struct MatchJson<'a> {
    file: String,
    reference: u64,
    current: u64,
    reference_robot: &'a str,
    current_robot: &'a str,
    reference_stamp_s: f64,
    current_stamp_s: f64,
    method: &'static str,
    strategy: Option<String>,
    population: Option<usize>,
    generations: Option<usize>,
    f: Option<f64>,
    cr: Option<f64>,
    seed: u64,
    transform: TransformJson,
    fitness: f64,
    evaluations: u64,
    time_ms: f64,
    true_transform: TransformJson,
    error: TransformError,
    right: bool,
    /// Correlation only: the thesis's filter (correlation ≥ 30 counts as aligned).
    passes_thesis_filter: Option<bool>,
}

fn find<'a>(
    scans: &'a [ScanRecord],
    index: u64,
    option: &str,
    file: &str,
) -> anyhow::Result<&'a ScanRecord> {
    scans.iter().find(|s| s.index == index).ok_or_else(|| {
        let lo = scans.iter().map(|s| s.index).min().unwrap_or(0);
        let hi = scans.iter().map(|s| s.index).max().unwrap_or(0);
        anyhow::anyhow!(
            "{option} {index}: no scan with index {index} in {file} ({} scans, indices {lo}..={hi})",
            scans.len()
        )
    })
}

/// Runs `sim match`.
pub fn run_match(o: &MatchOptions) -> anyhow::Result<()> {
    let config = match_config(o)?;
    let file = o.scans.display().to_string();
    let scans = read_scans(&o.scans)?;
    let a = find(&scans, o.reference, "--reference", &file)?;
    let b = find(&scans, o.current, "--current", &file)?;
    let (pa, pb) = (a.points(), b.points());
    if pa.is_empty() {
        anyhow::bail!(
            "--reference {}: scan {} of {file} has no valid reading (every range is inf/nan or \
             outside [range_min, range_max])",
            o.reference,
            o.reference
        );
    }
    if pb.is_empty() {
        anyhow::bail!(
            "--current {}: scan {} of {file} has no valid reading (every range is inf/nan or \
             outside [range_min, range_max])",
            o.current,
            o.current
        );
    }
    let r: MatchResult = match_scans(&pa, &pb, &config)?;
    let truth = a.pose.between(&b.pose);
    let err = TransformError::of(&r.transform, &truth);
    let de = match &config.method {
        systems::matching::Method::Thesis(t) => Some(t.de.clone()),
        systems::matching::Method::Improved(_) => None,
    };
    let is_corr = o.fitness == FitnessArg::Correlation;
    let passes = is_corr.then_some(r.fitness >= THESIS_CORRELATION_FILTER);
    if o.json {
        let j = MatchJson {
            file: file.clone(),
            reference: a.index,
            current: b.index,
            reference_robot: &a.robot,
            current_robot: &b.robot,
            reference_stamp_s: a.stamp,
            current_stamp_s: b.stamp,
            method: o.fitness.name(),
            strategy: de.as_ref().map(|d| strategy_cli_name(d.strategy)),
            population: de.as_ref().map(|d| d.population),
            generations: de.as_ref().map(|d| d.generations),
            f: de.as_ref().map(|d| d.f),
            cr: de.as_ref().map(|d| d.cr),
            seed: o.seed,
            transform: (&r.transform).into(),
            fitness: r.fitness,
            evaluations: r.evaluations,
            time_ms: r.elapsed.as_secs_f64() * 1e3,
            true_transform: (&truth).into(),
            error: err,
            right: err.right(),
            passes_thesis_filter: passes,
        };
        println!("{}", serde_json::to_string(&j)?);
        return Ok(());
    }
    println!(
        "reference scan {} ({}, t = {:.2} s, {} points), current scan {} ({}, t = {:.2} s, {} points)",
        a.index,
        a.robot,
        a.stamp,
        pa.len(),
        b.index,
        b.robot,
        b.stamp,
        pb.len()
    );
    match &de {
        Some(d) => println!(
            "method: DE with {} fitness, {} {:?}, population {}, generations {}, F {}, CR {}, seed {}",
            o.fitness.name(),
            d.strategy,
            d.crossover,
            d.population,
            d.generations,
            d.f,
            d.cr,
            o.seed
        ),
        None => println!("method: improved matcher, seed {}", o.seed),
    }
    let show = |label: &str, p: &Pose2| {
        println!(
            "{label:<15} x = {:9.1} mm  y = {:9.1} mm  θ = {:8.2}°   ({:.4} m, {:.4} m, {:.5} rad)",
            p.x * 1000.0,
            p.y * 1000.0,
            p.theta.to_degrees(),
            p.x,
            p.y,
            p.theta
        )
    };
    show("transform:", &r.transform);
    let fitness_note = match o.fitness {
        FitnessArg::Correlation => {
            if r.fitness >= THESIS_CORRELATION_FILTER {
                " common cells (>= 30: passes the thesis's filter)"
            } else {
                " common cells (< 30: the thesis's filter calls this a failed alignment)"
            }
        }
        FitnessArg::Euclidean => " m (truncated distance sum on the field, lower is better)",
        FitnessArg::EuclideanBrute => " m (sum of minimum distances, lower is better)",
        FitnessArg::Improved => " (inlier fraction of the current scan)",
    };
    println!("fitness:        {}{fitness_note}", fmt_fitness(r.fitness));
    println!("evaluations:    {}", r.evaluations);
    println!("time:           {:.3} ms", r.elapsed.as_secs_f64() * 1e3);
    show("true transform:", &truth);
    println!(
        "error:          Δx = {:.1} mm  Δy = {:.1} mm  Δθ = {:.3}°  |Δ| = {:.1} mm  → {}",
        err.x_m * 1000.0,
        err.y_m * 1000.0,
        err.theta_rad.to_degrees(),
        err.distance_m * 1000.0,
        if err.right() {
            "right (within 0.1 m and 2°)"
        } else {
            "WRONG (not within 0.1 m and 2°)"
        }
    );
    Ok(())
}

fn fmt_fitness(f: f64) -> String {
    if f.fract() == 0.0 && f.abs() < 1e15 {
        format!("{f:.0}")
    } else {
        format!("{f:.4}")
    }
}
