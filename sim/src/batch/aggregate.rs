//! Statistics per parameter set over its successful runs: mean, standard deviation (n − 1),
//! median and 95th percentile of every numeric metric (booleans count as 0/1), written to
//! `aggregate.csv`, and a printed table of the main ones (fleet figures and real-time factor).

use super::output::{Row, cell};
use crate::stats::{median, quantile};
use serde_json::Value as Json;
use std::path::Path;

#[derive(Clone, Debug, PartialEq)]
pub struct Stats {
    /// Runs with a value.
    pub n: usize,
    pub mean: f64,
    /// Sample standard deviation (NaN for one value).
    pub std: f64,
    pub median: f64,
    pub p95: f64,
}

impl Stats {
    pub fn of(values: &[f64]) -> Option<Stats> {
        if values.is_empty() {
            return None;
        }
        let n = values.len();
        let mean = values.iter().sum::<f64>() / n as f64;
        let std = if n > 1 {
            (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1) as f64).sqrt()
        } else {
            f64::NAN
        };
        let mut v = values.to_vec();
        Some(Stats {
            n,
            mean,
            std,
            median: median(&mut v),
            p95: quantile(&mut v, 0.95),
        })
    }
}

/// One parameter set's statistics.
#[derive(Clone, Debug)]
pub struct SetStats {
    pub set: usize,
    /// (`set.<key>` column, value) of the set's parameters.
    pub params: Vec<(String, Json)>,
    pub runs: usize,
    pub failed: usize,
    /// (metric, stats) in column order.
    pub metrics: Vec<(String, Stats)>,
}

/// Columns that describe a run rather than measure it.
fn is_metric(col: &str) -> bool {
    !matches!(col, "job" | "set" | "seed" | "status" | "error") && !col.starts_with("set.")
}

/// A metric's value as a number (booleans as 0/1).
pub fn number(v: &Json) -> Option<f64> {
    match v {
        Json::Number(n) => n.as_f64(),
        Json::Bool(b) => Some(f64::from(u8::from(*b))),
        _ => None,
    }
}

/// The value of column `k` of a row.
pub fn column<'a>(r: &'a Row, k: &str) -> Option<&'a Json> {
    r.iter().find(|(c, _)| c == k).map(|(_, v)| v)
}

/// Statistics of every set in `0..sets` over `rows` (whose `set` and `status` columns say which
/// set and whether the run succeeded), metrics in the order of `cols`.
pub fn aggregate(sets: usize, cols: &[String], rows: &[Row]) -> Vec<SetStats> {
    let get = |r: &Row, k: &str| column(r, k).cloned();
    (0..sets)
        .filter_map(|set| {
            let mine: Vec<&Row> = rows
                .iter()
                .filter(|r| get(r, "set").and_then(|v| v.as_u64()) == Some(set as u64))
                .collect();
            let first = mine.first()?;
            let ok: Vec<&&Row> = mine
                .iter()
                .filter(|r| {
                    get(r, "status").and_then(|v| v.as_str().map(|s| s == "ok")) == Some(true)
                })
                .collect();
            let metrics = cols
                .iter()
                .filter(|c| is_metric(c))
                .filter_map(|c| {
                    let vals: Vec<f64> = ok
                        .iter()
                        .filter_map(|r| get(r, c).as_ref().and_then(number))
                        .collect();
                    Some((c.clone(), Stats::of(&vals)?))
                })
                .collect();
            Some(SetStats {
                set,
                params: first
                    .iter()
                    .filter(|(k, _)| k.starts_with("set."))
                    .cloned()
                    .collect(),
                runs: mine.len(),
                failed: mine.len() - ok.len(),
                metrics,
            })
        })
        .collect()
}

fn csv_num(v: f64) -> String {
    if v.is_finite() {
        v.to_string()
    } else {
        String::new()
    }
}

/// `aggregate.csv`: one row per set and metric.
pub fn write_aggregate(path: &Path, stats: &[SetStats]) -> anyhow::Result<()> {
    let err = |e: csv::Error| anyhow::anyhow!("{}: cannot write: {e}", path.display());
    let mut w = csv::Writer::from_path(path).map_err(err)?;
    let params: Vec<String> = stats
        .first()
        .map(|s| s.params.iter().map(|(k, _)| k.clone()).collect())
        .unwrap_or_default();
    let mut head = vec!["set".to_string()];
    head.extend(params.iter().cloned());
    head.extend(
        [
            "runs", "failed", "metric", "n", "mean", "std", "median", "p95",
        ]
        .map(String::from),
    );
    w.write_record(&head).map_err(err)?;
    for s in stats {
        for (m, st) in &s.metrics {
            let mut rec = vec![s.set.to_string()];
            rec.extend(s.params.iter().map(|(_, v)| cell(v)));
            rec.extend([
                s.runs.to_string(),
                s.failed.to_string(),
                m.clone(),
                st.n.to_string(),
            ]);
            rec.extend([st.mean, st.std, st.median, st.p95].map(csv_num));
            w.write_record(&rec).map_err(err)?;
        }
    }
    w.flush()
        .map_err(|e| anyhow::anyhow!("{}: cannot write: {e}", path.display()))
}

/// The metrics of the printed table.
fn is_main(metric: &str) -> bool {
    metric.starts_with("fleet.") || matches!(metric, "real_time_factor" | "sim_time_s")
}

/// A number in about four significant digits.
fn fmt(v: f64) -> String {
    let a = v.abs();
    if !v.is_finite() {
        "-".to_string()
    } else if a >= 1000.0 {
        format!("{v:.0}")
    } else if a >= 10.0 {
        format!("{v:.2}")
    } else {
        format!("{v:.4}")
    }
}

/// `key=value` of the parameters of `st` that are not the same in every set of `stats`.
pub fn differing_params(st: &SetStats, stats: &[SetStats]) -> Vec<String> {
    let value = |set: &SetStats, k: &str| {
        set.params
            .iter()
            .find(|(c, _)| c == k)
            .map(|(_, v)| v.clone())
    };
    st.params
        .iter()
        .filter(|(k, _)| stats.iter().any(|o| value(o, k) != value(&stats[0], k)))
        .map(|(k, v)| format!("{}={}", k.trim_start_matches("set."), cell(v)))
        .collect()
}

/// The printed table: per set, the parameters that differ between sets, run and failure
/// counts, and the main metrics.
pub fn table(stats: &[SetStats]) -> String {
    let mut s = String::new();
    for st in stats {
        let params = differing_params(st, stats);
        s += &format!(
            "set {}{}{}: {} runs, {} failed\n",
            st.set,
            if params.is_empty() { "" } else { "  " },
            params.join("  "),
            st.runs,
            st.failed
        );
        let main: Vec<&(String, Stats)> = st.metrics.iter().filter(|(m, _)| is_main(m)).collect();
        if main.is_empty() {
            s += "  (no successful run)\n";
            continue;
        }
        let w = main.iter().map(|(m, _)| m.len()).max().unwrap_or(6).max(6);
        s += &format!(
            "  {:<w$} {:>10} {:>10} {:>10} {:>10}\n",
            "metric", "mean", "std", "median", "p95"
        );
        for (m, x) in main {
            s += &format!(
                "  {m:<w$} {:>10} {:>10} {:>10} {:>10}\n",
                fmt(x.mean),
                fmt(x.std),
                fmt(x.median),
                fmt(x.p95)
            );
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn stats() {
        let s = Stats::of(&[1.0, 2.0, 3.0, 4.0]).unwrap();
        assert_eq!((s.n, s.mean, s.median, s.p95), (4, 2.5, 2.5, 4.0));
        assert!((s.std - 1.2909944).abs() < 1e-6);
        assert!(Stats::of(&[]).is_none());
        assert!(Stats::of(&[3.0]).unwrap().std.is_nan());
    }

    #[test]
    fn only_successful_runs_count() {
        let row = |set: u64, ok: bool, v: Json| -> Row {
            vec![
                ("set".into(), json!(set)),
                ("set.x".into(), json!(set * 10)),
                ("status".into(), json!(if ok { "ok" } else { "failed" })),
                ("fleet.collisions".into(), v),
            ]
        };
        let rows = vec![
            row(0, true, json!(1)),
            row(0, true, json!(3)),
            row(0, false, Json::Null),
            row(1, false, Json::Null),
        ];
        let cols = super::super::output::columns(&rows);
        let st = aggregate(2, &cols, &rows);
        assert_eq!((st[0].runs, st[0].failed), (3, 1));
        assert_eq!(st[0].metrics.len(), 1);
        assert_eq!(st[0].metrics[0].1.mean, 2.0);
        assert_eq!((st[1].runs, st[1].failed, st[1].metrics.len()), (1, 1, 0));
        let t = table(&st);
        assert!(t.contains("set 0  x=0: 3 runs, 1 failed"), "{t}");
        assert!(t.contains("fleet.collisions"), "{t}");
        assert!(
            t.contains("set 1  x=10: 1 runs, 1 failed\n  (no successful run)"),
            "{t}"
        );
    }
}
