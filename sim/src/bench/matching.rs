//! `sim bench de-match`: wall time per alignment of 1081-beam SICK LMS100 scan pairs from the
//! hospital scenario, on one core (alignments run one after another on the calling thread).
//! Pairs: the scans of the first 60 s of `hospital_patrol`, one per robot every 0.1 s, a random
//! reference and the scan 5, 10, 20 or 30 steps later (fixed seed, so every run times the same
//! pairs). Methods: the improved matcher, and the thesis's DE with the correlation fitness
//! (rand/1, population 20, F 0.5, CR 0.9) for a fixed 1000 generations (no early stop, so its
//! time is the cost of 20 020 fitness evaluations).

use crate::experiment::de_match::{MAX_XY_M, PERIOD_S, STEPS, check_pairs, thesis_de};
use crate::experiment::match_pair::TransformError;
use crate::experiment::scan_pairs::{LMS100_BEAMS, bundled, capture, draw_pairs};
use crate::stats::{median, quantile};
use serde::Serialize;
use systems::core::stream_rng;
use systems::matching::{MatchConfig, Strategy, ThesisFitness, match_scans};

/// `sim bench de-match`: DE scan-matching time per alignment of 1081-beam hospital scans (one
/// core).
#[derive(clap::Args, Clone, Debug)]
pub struct DeMatchBenchOptions {
    /// One JSON object per method, one per line.
    #[arg(long)]
    pub json: bool,
    /// Number of hospital scan pairs timed.
    #[arg(long, default_value_t = 100)]
    pub pairs: usize,
}

#[derive(Serialize)]
struct BenchRow {
    bench: &'static str,
    method: &'static str,
    beams: usize,
    pairs: usize,
    /// Median wall time per alignment (ms, one core).
    ms_per_alignment: f64,
    mean_ms: f64,
    p90_ms: f64,
    median_evaluations: u64,
    /// Share of the pairs aligned within 0.1 m and 2° (a sanity check, not the experiment).
    right_pct: f64,
    threads: usize,
}

pub fn run_de_match_bench(o: &DeMatchBenchOptions) -> anyhow::Result<()> {
    check_pairs(o.pairs)?;
    let sc = bundled("hospital_patrol")?;
    let data = vec![capture(&sc, PERIOD_S, Some(60.0), 0)?];
    let mut rng = stream_rng(0, "bench/de-match", "pairs");
    let pairs = draw_pairs(&data, o.pairs, &STEPS, MAX_XY_M, &mut rng)?;
    let points: Vec<_> = pairs
        .iter()
        .map(|p| (p.reference(&data).points(), p.current(&data).points()))
        .collect();
    let mut correlation = thesis_de(Strategy::Rand1, 1000);
    correlation.stall = None;
    correlation.collapse_tolerance = None;
    let methods: [(&'static str, MatchConfig); 2] = [
        ("improved", MatchConfig::improved()),
        (
            "de-correlation rand/1 (pop 20, 1000 generations)",
            MatchConfig::thesis(ThesisFitness::Correlation, correlation),
        ),
    ];
    if !o.json {
        println!(
            "DE scan matching on {} hospital pairs of {LMS100_BEAMS}-beam scans, one core",
            pairs.len()
        );
        println!(
            "{:<50} {:>10} {:>10} {:>10} {:>10} {:>8}",
            "method", "median ms", "mean ms", "p90 ms", "evals", "right %"
        );
    }
    for (name, config) in methods {
        let mut ms = Vec::with_capacity(pairs.len());
        let mut evals = Vec::with_capacity(pairs.len());
        let mut right = 0;
        // one warm-up alignment (page faults, caches) that is not timed
        let _ = match_scans(&points[0].0, &points[0].1, &config);
        for (i, (p, (a, b))) in pairs.iter().zip(&points).enumerate() {
            let out = match_scans(a, b, &config.clone().with_seed(i as u64))?;
            ms.push(out.elapsed.as_secs_f64() * 1e3);
            evals.push(out.evaluations as f64);
            if TransformError::of(&out.transform, &p.truth).right() {
                right += 1;
            }
        }
        let n = ms.len();
        let mean = ms.iter().sum::<f64>() / n as f64;
        let (mut ms, mut evals) = (ms, evals);
        let row = BenchRow {
            bench: "de-match",
            method: name,
            beams: LMS100_BEAMS,
            pairs: n,
            ms_per_alignment: median(&mut ms),
            mean_ms: mean,
            p90_ms: quantile(&mut ms, 0.9),
            median_evaluations: median(&mut evals).round() as u64,
            right_pct: 100.0 * right as f64 / n as f64,
            threads: 1,
        };
        if o.json {
            println!("{}", crate::bench::machine::json_line(&row)?);
        } else {
            println!(
                "{:<50} {:>10.3} {:>10.3} {:>10.3} {:>10} {:>8.1}",
                row.method,
                row.ms_per_alignment,
                row.mean_ms,
                row.p90_ms,
                row.median_evaluations,
                row.right_pct
            );
        }
    }
    Ok(())
}
