//! `sim experiment de-match`: the scan-matching experiments of [Hospital thesis] (§6.3,
//! the mutation study on N = 460 pairs, table 2; §7.2–7.3, the final comparison with the
//! Euclidean reference, tables 3–4) on scans captured in-process from the bundled maze and
//! hospital scenarios, plus our improved matcher.
//!
//! Protocol: one scan per robot every 0.1 s of simulated time (a "step" is one scan; robots
//! drive at 0.6–0.8 m/s), SICK LMS100 scans (1081 beams, 270°, 0.5–20 m), search window ±3 m
//! and ±180°. A pair is a random reference scan and the scan of the same robot 5, 10, 20 or 30
//! steps later.
//! * default: 460 pairs, alternating maze/hospital, steps cycling 5, 10, 20, 30; one alignment
//!   per pair and method; DE with at most 1000 generations and an early stop; the brute-force
//!   Euclidean reference on 50 evenly spread pairs of the 460;
//! * `--full`: 80 random reference scans (alternating scenarios) × steps 5, 10, 20, 30 × 50
//!   repeats (DE seeds), up to 5000 generations (the thesis's setting) with the same early stop.
//!
//! DE settings of every thesis row: the final experiment's (§7.2) population 20, F 0.5, CR 0.9,
//! binomial crossover; the nine strategy rows use the raster cross-correlation (eq. 29, 100 × 100
//! cells over ±10 m); the Euclidean rows use rand/1 with the distance-field form ("raster"
//! Euclidean, 5 cm cells) and the brute-force form (§7.1). Early stop: 200 generations without
//! improvement of the best fitness, or the population collapsed to within 1e-4 (m, rad).
//!
//! Scoring: an alignment is right if it is within 0.1 m (translation error norm) and 2° of the
//! true transform `P_ref⁻¹ ⊕ P_cur`; λ = right / alignments · 100 (eq. 36 with the truth as the
//! judge). For the correlation rows the thesis's own judge is reported too: λ_thesis counts the
//! alignments whose correlation is ≥ 30 (§7.3), and "accepted wrong" counts the wrong alignments
//! that filter lets through. σx, σy, σθ are the sample standard deviations of the errors of the
//! right alignments. Times are wall-clock per alignment on one core (pairs run in parallel, one
//! alignment per worker), median over the alignments.
//!
//! Determinism: the pairs come from a stream seeded by `--seed`, every alignment's matcher seed
//! from (seed, method, pair, repeat); only the times depend on the machine.

use super::scan_pairs::{
    LMS100_BEAMS, Pair, ScenarioScans, bundled, capture, draw_pairs, draw_reference_sets,
};
use crate::experiment::match_pair::{THESIS_CORRELATION_FILTER, TransformError, strategy_cli_name};
use crate::formats::scans::write_scans;
use crate::stats::{median, quantile};
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::time::Instant;
use systems::core::{stream_rng, stream_seed};
use systems::matching::{
    Crossover, DeParams, MatchConfig, StallStop, Strategy, ThesisFitness, match_scans,
};

/// Options of `sim experiment de-match`.
#[derive(clap::Args, Clone, Debug, Default)]
pub struct DeMatchOptions {
    /// One JSON object per row, one per line.
    #[arg(long)]
    pub json: bool,
    /// The thesis's full protocol: 80 reference scans × steps 5, 10, 20, 30 × 50 repeats,
    /// up to 5000 generations (hours).
    #[arg(long)]
    pub full: bool,
    /// Worker threads for the pairs (0 = one per core; at most 1024). Results do not
    /// depend on it.
    #[arg(long, default_value_t = 0, value_parser = crate::options::parse_threads)]
    pub threads: usize,
    /// Seed of the pair selection and of the matchers.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Pairs of the default protocol (default 460; a small number for quick checks).
    #[arg(long, hide = true, conflicts_with = "full")]
    pub pairs: Option<usize>,
    /// Pairs on which the brute-force Euclidean reference runs.
    #[arg(long, default_value_t = 50)]
    pub brute_pairs: usize,
    /// Write the captured scans of both scenarios to this folder (maze_run.csv,
    /// hospital_patrol.csv), for `sim match`.
    #[arg(long)]
    pub save_scans: Option<PathBuf>,
    /// Only the methods whose name contains this text (e.g. `improved`, `rand/1`).
    #[arg(long)]
    pub only: Option<String>,
    /// Print every wrong alignment (scan indices, truth, answer) to stderr.
    #[arg(long)]
    pub list_wrong: bool,
}

/// The scenarios of the experiment.
pub const SCENARIOS: [&str; 2] = ["maze_run", "hospital_patrol"];
/// One scan every this many simulated seconds.
pub const PERIOD_S: f64 = 0.1;
/// Steps between reference and test scan.
pub const STEPS: [usize; 4] = [5, 10, 20, 30];
/// Search window.
pub const MAX_XY_M: f64 = 3.0;
/// Pairs of the default protocol (the thesis's mutation study, §6.3).
pub const DEFAULT_PAIRS: usize = 460;
/// Largest `--pairs` of the experiment and of `sim bench de-match` (20 times the default; the
/// points of each pair are held in memory, about 17 KB a pair).
pub const MAX_PAIRS: usize = 10_000;

/// Checks a `--pairs` count: 1 to [`MAX_PAIRS`].
pub fn check_pairs(n: usize) -> anyhow::Result<usize> {
    if !(1..=MAX_PAIRS).contains(&n) {
        anyhow::bail!("--pairs: expected 1 to {MAX_PAIRS} pairs, got {n}");
    }
    Ok(n)
}

/// One method (row) of the experiment.
#[derive(Clone, Debug)]
pub struct Method {
    pub name: String,
    pub fitness: &'static str,
    pub strategy: Option<Strategy>,
    pub config: MatchConfig,
    /// Alignments restricted to the brute-force subset.
    pub brute_subset: bool,
}

/// The DE settings of the thesis rows: §7.2's population 20, F 0.5, CR 0.9, binomial, at most
/// `generations`, early stop after 200 generations without improvement or on collapse. One core
/// per alignment (pairs run in parallel).
pub fn thesis_de(strategy: Strategy, generations: usize) -> DeParams {
    DeParams {
        population: 20,
        generations,
        f: 0.5,
        cr: 0.9,
        strategy,
        crossover: Crossover::Binomial,
        either_or_probability: None,
        max_evaluations: None,
        time_limit: None,
        stall: Some(StallStop {
            generations: 200,
            tolerance: 0.0,
        }),
        collapse_tolerance: Some(1e-4),
        parallel: false,
    }
}

/// The rows, in table order.
pub fn methods(generations: usize) -> Vec<Method> {
    let mut out: Vec<Method> = Strategy::ALL
        .into_iter()
        .map(|s| Method {
            name: format!("de-correlation {}", s.name()),
            fitness: "correlation",
            strategy: Some(s),
            config: MatchConfig::thesis(ThesisFitness::Correlation, thesis_de(s, generations)),
            brute_subset: false,
        })
        .collect();
    out.push(Method {
        name: "de-euclidean-field rand/1".into(),
        fitness: "euclidean",
        strategy: Some(Strategy::Rand1),
        config: MatchConfig::thesis(
            ThesisFitness::EuclideanField,
            thesis_de(Strategy::Rand1, generations),
        ),
        brute_subset: false,
    });
    out.push(Method {
        name: "de-euclidean-brute rand/1".into(),
        fitness: "euclidean-brute",
        strategy: Some(Strategy::Rand1),
        config: MatchConfig::thesis(
            ThesisFitness::EuclideanBrute,
            thesis_de(Strategy::Rand1, generations),
        ),
        brute_subset: true,
    });
    out.push(Method {
        name: "improved".into(),
        fitness: "improved",
        strategy: None,
        config: MatchConfig::improved(),
        brute_subset: false,
    });
    for m in &mut out {
        m.config.window.max_xy = MAX_XY_M;
        m.config.window.max_theta = std::f64::consts::PI;
    }
    out
}

/// The outcome of one alignment.
#[derive(Clone, Copy, Debug)]
pub struct Alignment {
    pub pair: usize,
    pub repeat: usize,
    pub found: systems::core::Pose2,
    pub error: TransformError,
    pub fitness: f64,
    pub evaluations: u64,
    pub ms: f64,
}

/// One row of the result table (also the JSON object of `--json`).
#[derive(Clone, Debug, Serialize)]
pub struct Row {
    pub experiment: &'static str,
    pub protocol: &'static str,
    pub method: String,
    pub fitness: &'static str,
    pub strategy: Option<String>,
    pub population: Option<usize>,
    pub max_generations: Option<usize>,
    pub f: Option<f64>,
    pub cr: Option<f64>,
    pub beams: usize,
    pub pairs: usize,
    pub alignments: usize,
    pub right: usize,
    /// Right within 0.1 m and 2° of the truth, % of the alignments.
    pub lambda_pct: f64,
    /// Correlation rows: alignments with correlation ≥ 30 (the thesis's judge), %.
    pub lambda_thesis_filter_pct: Option<f64>,
    /// Correlation rows: wrong alignments with correlation ≥ 30.
    pub filter_accepts_wrong: Option<usize>,
    /// λ per step count (5, 10, 20, 30).
    pub lambda_by_step_pct: BTreeMap<String, f64>,
    /// λ per scenario.
    pub lambda_by_scenario_pct: BTreeMap<String, f64>,
    /// Sample standard deviations of the errors of the right alignments.
    pub sigma_x_mm: Option<f64>,
    pub sigma_y_mm: Option<f64>,
    pub sigma_theta_deg: Option<f64>,
    /// Median wall time per alignment (ms, one core).
    pub median_ms: f64,
    pub p90_ms: f64,
    pub median_evaluations: u64,
    pub seed: u64,
}

/// Sample standard deviation (n − 1); `None` for fewer than two values.
fn std_dev(v: &[f64]) -> Option<f64> {
    if v.len() < 2 {
        return None;
    }
    let mean = v.iter().sum::<f64>() / v.len() as f64;
    let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (v.len() - 1) as f64;
    Some(var.sqrt())
}

fn pct(k: usize, n: usize) -> f64 {
    if n == 0 {
        f64::NAN
    } else {
        100.0 * k as f64 / n as f64
    }
}

/// Summarises the alignments of one method.
#[allow(clippy::too_many_arguments)]
pub fn summarise(
    method: &Method,
    protocol: &'static str,
    pairs: &[Pair],
    scenario_names: &[String],
    results: &[Alignment],
    seed: u64,
) -> Row {
    let n = results.len();
    let right: Vec<&Alignment> = results.iter().filter(|a| a.error.right()).collect();
    let is_corr = method.fitness == "correlation";
    let passes = |a: &Alignment| a.fitness >= THESIS_CORRELATION_FILTER;
    let mut by_step = BTreeMap::new();
    for k in STEPS {
        let of: Vec<&Alignment> = results
            .iter()
            .filter(|a| pairs[a.pair].steps == k)
            .collect();
        if !of.is_empty() {
            let r = of.iter().filter(|a| a.error.right()).count();
            by_step.insert(format!("{k:02}"), pct(r, of.len()));
        }
    }
    let mut by_scenario = BTreeMap::new();
    for (i, name) in scenario_names.iter().enumerate() {
        let of: Vec<&Alignment> = results
            .iter()
            .filter(|a| pairs[a.pair].scenario == i)
            .collect();
        if !of.is_empty() {
            let r = of.iter().filter(|a| a.error.right()).count();
            by_scenario.insert(name.clone(), pct(r, of.len()));
        }
    }
    let xs: Vec<f64> = right.iter().map(|a| a.error.x_m * 1000.0).collect();
    let ys: Vec<f64> = right.iter().map(|a| a.error.y_m * 1000.0).collect();
    let ts: Vec<f64> = right
        .iter()
        .map(|a| a.error.theta_rad.to_degrees())
        .collect();
    let mut ms: Vec<f64> = results.iter().map(|a| a.ms).collect();
    let mut evals: Vec<f64> = results.iter().map(|a| a.evaluations as f64).collect();
    let distinct_pairs = {
        let mut p: Vec<usize> = results.iter().map(|a| a.pair).collect();
        p.sort_unstable();
        p.dedup();
        p.len()
    };
    let de = match &method.config.method {
        systems::matching::Method::Thesis(t) => Some(&t.de),
        systems::matching::Method::Improved(_) => None,
    };
    Row {
        experiment: "de-match",
        protocol,
        method: method.name.clone(),
        fitness: method.fitness,
        strategy: method.strategy.map(strategy_cli_name),
        population: de.map(|d| d.population),
        max_generations: de.map(|d| d.generations),
        f: de.map(|d| d.f),
        cr: de.map(|d| d.cr),
        beams: LMS100_BEAMS,
        pairs: distinct_pairs,
        alignments: n,
        right: right.len(),
        lambda_pct: pct(right.len(), n),
        lambda_thesis_filter_pct: is_corr
            .then(|| pct(results.iter().filter(|a| passes(a)).count(), n)),
        filter_accepts_wrong: is_corr.then(|| {
            results
                .iter()
                .filter(|a| passes(a) && !a.error.right())
                .count()
        }),
        lambda_by_step_pct: by_step,
        lambda_by_scenario_pct: by_scenario,
        sigma_x_mm: std_dev(&xs),
        sigma_y_mm: std_dev(&ys),
        sigma_theta_deg: std_dev(&ts),
        median_ms: median(&mut ms),
        p90_ms: quantile(&mut ms, 0.9),
        median_evaluations: median(&mut evals).round() as u64,
        seed,
    }
}

/// Captures the scans of both scenarios (in parallel).
pub fn capture_all(threads: usize) -> anyhow::Result<Vec<ScenarioScans>> {
    let scenarios = SCENARIOS
        .iter()
        .map(|n| bundled(n))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let per = if threads == 0 {
        0
    } else {
        threads.div_ceil(SCENARIOS.len())
    };
    let (a, b) = rayon::join(
        || capture(&scenarios[0], PERIOD_S, None, per),
        || capture(&scenarios[1], PERIOD_S, None, per),
    );
    Ok(vec![a?, b?])
}

/// The reference and current scan of a pair as points in their sensor frames.
type PointPair = (Vec<[f32; 2]>, Vec<[f32; 2]>);

/// Runs the experiment and prints the table (or JSON rows).
pub fn run_de_match_experiment(o: &DeMatchOptions) -> anyhow::Result<()> {
    let started = Instant::now();
    let rows = de_match_rows(o)?;
    if o.json {
        for r in &rows {
            println!("{}", crate::bench::machine::json_line(r)?);
        }
    } else {
        print!("{}", table(&rows));
        println!(
            "right = within 0.1 m and 2° of the true transform; λ_thesis = correlation >= 30 \
             (the thesis's filter); σ of the right alignments; ms = median wall time per \
             alignment on one core; {} s in total",
            started.elapsed().as_secs()
        );
    }
    Ok(())
}

/// Runs the experiment and returns its rows (progress and `--list-wrong` go to stderr).
pub fn de_match_rows(o: &DeMatchOptions) -> anyhow::Result<Vec<Row>> {
    if let Some(n) = o.pairs {
        check_pairs(n)?;
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(o.threads)
        .build()
        .map_err(|e| anyhow::anyhow!("cannot start {} threads: {e}", o.threads))?;
    let threads = pool.current_num_threads();
    pool.install(|| run_in_pool(o, threads))
}

fn run_in_pool(o: &DeMatchOptions, threads: usize) -> anyhow::Result<Vec<Row>> {
    if !o.json {
        eprintln!(
            "capturing scans of {} (one scan per robot every {PERIOD_S} s) ...",
            SCENARIOS.join(" and ")
        );
    }
    let data = capture_all(o.threads)?;
    if let Some(dir) = &o.save_scans {
        std::fs::create_dir_all(dir)
            .map_err(|e| anyhow::anyhow!("{}: cannot create the folder: {e}", dir.display()))?;
        for d in &data {
            write_scans(&dir.join(format!("{}.csv", d.name)), &d.all)?;
        }
    }
    let names: Vec<String> = data.iter().map(|d| d.name.clone()).collect();
    let mut rng = stream_rng(o.seed, "experiment/de-match", "pairs");
    let (protocol, pairs, repeats, generations) = if o.full {
        let p = draw_reference_sets(&data, 80, &STEPS, MAX_XY_M, &mut rng)?;
        ("full", p, 50usize, 5000usize)
    } else {
        let n = o.pairs.unwrap_or(DEFAULT_PAIRS);
        let p = draw_pairs(&data, n, &STEPS, MAX_XY_M, &mut rng)?;
        ("default", p, 1usize, 1000usize)
    };
    let mut methods = methods(generations);
    if let Some(only) = &o.only {
        methods.retain(|m| m.name.contains(only.as_str()));
        if methods.is_empty() {
            anyhow::bail!("--only {only}: no method name contains it");
        }
    }
    // the brute-force reference: the first pairs (they alternate between the scenarios and
    // cycle through the step counts), one alignment each
    let brute: Vec<usize> = (0..o.brute_pairs.min(pairs.len())).collect();

    // every needed point set once
    let points: Vec<PointPair> = pairs
        .par_iter()
        .map(|p| (p.reference(&data).points(), p.current(&data).points()))
        .collect();
    let jobs = plan_jobs(&methods, &brute, pairs.len(), repeats);
    if !o.json {
        eprintln!("{}", describe_scans(&data));
        eprintln!(
            "{} protocol: {} pairs × {} repeat(s), {} methods, brute-force Euclidean on {} pairs; \
             {} alignments on {threads} threads",
            protocol,
            pairs.len(),
            repeats,
            methods.len(),
            brute.len(),
            jobs.len()
        );
    }
    let bar = progress_bar(o.json, jobs.len());
    let results: Vec<anyhow::Result<Alignment>> = jobs
        .par_iter()
        .map(|&(mi, p, r)| {
            let out = align(&methods[mi], o.seed, p, r, &points[p], &pairs[p]);
            bar.inc(1);
            out
        })
        .collect();
    bar.finish_and_clear();
    let mut per_method: Vec<Vec<Alignment>> = vec![Vec::new(); methods.len()];
    for (&(mi, ..), r) in jobs.iter().zip(results) {
        per_method[mi].push(r?);
    }
    if o.list_wrong {
        list_wrong(&methods, &per_method, &pairs, &data);
    }
    Ok(methods
        .iter()
        .zip(&per_method)
        .map(|(m, res)| summarise(m, protocol, &pairs, &names, res, o.seed))
        .collect())
}

/// Every alignment of the experiment as (method, pair, repeat): the brute-force methods on the
/// `brute` pairs once, the others on every pair `repeats` times; the slow brute-force jobs
/// first, so they do not straggle at the end.
fn plan_jobs(
    methods: &[Method],
    brute: &[usize],
    pairs: usize,
    repeats: usize,
) -> Vec<(usize, usize, usize)> {
    let mut jobs: Vec<(usize, usize, usize)> = Vec::new();
    for (mi, m) in methods.iter().enumerate() {
        if m.brute_subset {
            jobs.extend(brute.iter().map(|&p| (mi, p, 0)));
        } else {
            for p in 0..pairs {
                jobs.extend((0..repeats).map(|r| (mi, p, r)));
            }
        }
    }
    jobs.sort_by_key(|&(mi, p, r)| (!methods[mi].brute_subset, p, mi, r));
    jobs
}

/// One alignment: `method` on pair `p` (its points and truth), repeat `r`, with the matcher
/// seed of (seed, method, pair, repeat).
fn align(
    method: &Method,
    seed: u64,
    p: usize,
    r: usize,
    (a, b): &PointPair,
    pair: &Pair,
) -> anyhow::Result<Alignment> {
    let seed = stream_seed(
        seed,
        &format!("experiment/de-match/{}", method.name),
        &format!("{p}/{r}"),
    );
    let config = method.config.clone().with_seed(seed);
    let out = match_scans(a, b, &config)
        .map_err(|e| anyhow::anyhow!("{}, pair {p}: {e}", method.name))?;
    Ok(Alignment {
        pair: p,
        repeat: r,
        found: out.transform,
        error: TransformError::of(&out.transform, &pair.truth),
        fitness: out.fitness,
        evaluations: out.evaluations,
        ms: out.elapsed.as_secs_f64() * 1e3,
    })
}

/// One line on the captured scans: per scenario the scans, robots, mean speed and replaced
/// lasers.
fn describe_scans(data: &[ScenarioScans]) -> String {
    let speeds: Vec<String> = data
        .iter()
        .map(|d| {
            let n: usize = d.streams.iter().map(|s| s.scans.len()).sum();
            let mut s = format!(
                "{}: {} scans of {} robots, mean speed {:.2} m/s",
                d.name,
                n,
                d.streams.len(),
                d.mean_speed
            );
            if !d.replaced_lasers.is_empty() {
                s += &format!(
                    " (laser replaced by a SICK LMS100 on {})",
                    d.replaced_lasers.join(", ")
                );
            }
            s
        })
        .collect();
    speeds.join("; ")
}

/// The alignments' progress bar on stderr (hidden with `--json`).
fn progress_bar(json: bool, alignments: usize) -> ProgressBar {
    if json {
        return ProgressBar::hidden();
    }
    let b = ProgressBar::new(alignments as u64);
    b.set_style(
        ProgressStyle::with_template(
            "{bar:40.cyan/blue} {pos}/{len} alignments  [{elapsed_precise} < {eta}]",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    b
}

/// `--list-wrong`: every wrong alignment on stderr, with its scans, truth and answer.
fn list_wrong(
    methods: &[Method],
    per_method: &[Vec<Alignment>],
    pairs: &[Pair],
    data: &[ScenarioScans],
) {
    for (m, res) in methods.iter().zip(per_method) {
        for a in res.iter().filter(|a| !a.error.right()) {
            let p = &pairs[a.pair];
            let (ra, rb) = (p.reference(data), p.current(data));
            eprintln!(
                "wrong: {} | {} scans {} -> {} ({}, {} steps, repeat {}) | truth ({:.3}, {:.3}, {:.1}°) found ({:.3}, {:.3}, {:.1}°) fitness {:.3}",
                m.name,
                data[p.scenario].name,
                ra.index,
                rb.index,
                ra.robot,
                p.steps,
                a.repeat,
                p.truth.x,
                p.truth.y,
                p.truth.theta.to_degrees(),
                a.found.x,
                a.found.y,
                a.found.theta.to_degrees(),
                a.fitness
            );
        }
    }
}

/// The text table of the rows.
pub fn table(rows: &[Row]) -> String {
    let opt = |v: Option<f64>, prec: usize| match v {
        Some(x) if x.is_finite() => format!("{x:.prec$}"),
        _ => "-".to_string(),
    };
    let mut s = format!(
        "{:<30} {:>6} {:>7} {:>9} {:>8} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7} {:>9} {:>8}\n",
        "method",
        "align.",
        "λ %",
        "λ_thes.%",
        "acc.wr.",
        "maze %",
        "hosp %",
        "σx mm",
        "σy mm",
        "σθ °",
        "ms",
        "evals",
        "λ5/10/20/30"
    );
    for r in rows {
        let steps: Vec<String> = r
            .lambda_by_step_pct
            .values()
            .map(|v| format!("{v:.0}"))
            .collect();
        s += &format!(
            "{:<30} {:>6} {:>7.1} {:>9} {:>8} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7.2} {:>9} {}\n",
            r.method,
            r.alignments,
            r.lambda_pct,
            opt(r.lambda_thesis_filter_pct, 1),
            r.filter_accepts_wrong
                .map_or("-".to_string(), |v| v.to_string()),
            opt(r.lambda_by_scenario_pct.get("maze_run").copied(), 1),
            opt(r.lambda_by_scenario_pct.get("hospital_patrol").copied(), 1),
            opt(r.sigma_x_mm, 1),
            opt(r.sigma_y_mm, 1),
            opt(r.sigma_theta_deg, 2),
            r.median_ms,
            r.median_evaluations,
            steps.join("/")
        );
    }
    s
}
