//! One row per run: the job, its parameters, seed, status, wall time and every metric of the run
//! summary flattened to dotted keys (`robots.r1.localization.mcl.ate_rmse_m`; arrays of named
//! items are keyed by name, other arrays by index), plus fleet figures over the robots
//! (`fleet.*`). Written as `runs.csv` (header: the union of the rows' keys, in order of first
//! appearance) and `runs.jsonl` (one object per line, keys in the same order).

use crate::run::summary::Summary;
use crate::scenario::overrides::Override;
use serde_json::{Map, Value as Json, json};
use std::io::Write;
use std::path::Path;

/// A row: (column, value) in column order.
pub type Row = Vec<(String, Json)>;

/// A TOML override value as JSON (numbers stay numbers).
pub fn toml_json(v: &toml_edit::Value) -> Json {
    use toml_edit::Value as V;
    match v {
        V::String(s) => json!(s.value()),
        V::Integer(i) => json!(i.value()),
        V::Float(f) => json!(f.value()),
        V::Boolean(b) => json!(b.value()),
        V::Datetime(d) => json!(d.value().to_string()),
        V::Array(a) => Json::Array(a.iter().map(toml_json).collect()),
        V::InlineTable(t) => Json::Object(
            t.iter()
                .map(|(k, v)| (k.to_string(), toml_json(v)))
                .collect::<Map<_, _>>(),
        ),
    }
}

fn flatten(prefix: &str, v: &Json, out: &mut Row) {
    let key = |k: &str| {
        if prefix.is_empty() {
            k.to_string()
        } else {
            format!("{prefix}.{k}")
        }
    };
    match v {
        Json::Object(m) => {
            for (k, v) in m {
                flatten(&key(k), v, out);
            }
        }
        Json::Array(items) => {
            let named = !items.is_empty()
                && items
                    .iter()
                    .all(|i| i.get("name").and_then(Json::as_str).is_some());
            for (i, item) in items.iter().enumerate() {
                match item.get("name").and_then(Json::as_str).filter(|_| named) {
                    Some(name) => {
                        let mut rest = item.clone();
                        if let Some(m) = rest.as_object_mut() {
                            m.remove("name");
                        }
                        flatten(&key(name), &rest, out);
                    }
                    None => flatten(&key(&i.to_string()), item, out),
                }
            }
        }
        scalar => out.push((prefix.to_string(), scalar.clone())),
    }
}

fn mean(v: &[f64]) -> Option<f64> {
    (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64)
}

/// Figures over all robots: sums of distances, collisions, waypoints, tasks and arrivals, and
/// each localizer's ATE and final error averaged over the robots carrying it.
pub fn fleet(s: &Summary) -> Row {
    let r = &s.robots;
    let mut out: Row = vec![
        (
            "fleet.distance_m".into(),
            json!(r.iter().map(|r| r.distance_m).sum::<f64>()),
        ),
        (
            "fleet.collisions".into(),
            json!(r.iter().map(|r| r.collisions).sum::<u32>()),
        ),
        (
            "fleet.waypoints_reached".into(),
            json!(r.iter().map(|r| r.waypoints_reached).sum::<u32>()),
        ),
    ];
    let navs: Vec<_> = r.iter().filter_map(|r| r.navigation.as_ref()).collect();
    if !navs.is_empty() {
        out.push((
            "fleet.tasks_completed".into(),
            json!(navs.iter().map(|n| n.tasks_completed).sum::<u32>()),
        ));
        out.push((
            "fleet.tasks_failed".into(),
            json!(navs.iter().map(|n| n.tasks_failed).sum::<u32>()),
        ));
    }
    let roads: Vec<_> = r.iter().filter_map(|r| r.road.as_ref()).collect();
    if !roads.is_empty() {
        out.push((
            "fleet.reached".into(),
            json!(roads.iter().filter(|x| x.reached).count()),
        ));
    }
    let mut names: Vec<&String> = Vec::new();
    for robot in r {
        for n in robot.localization.keys() {
            if !names.contains(&n) {
                names.push(n);
            }
        }
    }
    for n in names {
        let ms: Vec<_> = r.iter().filter_map(|r| r.localization.get(n)).collect();
        let figure = |f: &dyn Fn(&systems::eval::LocalizerMetrics) -> Option<f64>| {
            mean(&ms.iter().filter_map(|m| f(m)).collect::<Vec<_>>())
        };
        out.push((
            format!("fleet.localization.{n}.ate_rmse_m"),
            json!(figure(&|m| m.ate_rmse_m)),
        ));
        if ms.iter().any(|m| m.in_map) {
            out.push((
                format!("fleet.localization.{n}.ate_map_rmse_m"),
                json!(figure(&|m| m.ate_map_rmse_m)),
            ));
        }
        out.push((
            format!("fleet.localization.{n}.final_error_m"),
            json!(figure(&|m| m.final_error_m)),
        ));
        if ms.iter().any(|m| m.final_trajectory.is_some()) {
            out.push((
                format!("fleet.localization.{n}.final_trajectory.ate_rmse_m"),
                json!(figure(&|m| m.final_trajectory.and_then(|t| t.ate_rmse_m))),
            ));
        }
    }
    out
}

/// Every metric of a summary: run times, fleet figures, then each robot's fields.
pub fn metrics(s: &Summary) -> Row {
    let mut out: Row = vec![
        ("sim_time_s".into(), json!(s.sim_time_s)),
        ("wall_time_s".into(), json!(s.wall_time_s)),
        ("real_time_factor".into(), json!(s.real_time_factor)),
    ];
    out.extend(fleet(s));
    if let Ok(robots) = serde_json::to_value(&s.robots) {
        flatten("robots", &robots, &mut out);
    }
    out
}

/// The leading columns of a run: job, set, the set's parameters, seed, status, error, wall time.
pub fn run_columns(
    job: &super::runner::Job,
    keys: &[String],
    overrides: &[Override],
    error: Option<&str>,
    wall_s: f64,
) -> Row {
    let mut row: Row = vec![
        ("job".into(), json!(job.index)),
        ("set".into(), json!(job.set)),
    ];
    for k in keys {
        let v = overrides
            .iter()
            .find(|o| &o.key == k)
            .map_or(Json::Null, |o| toml_json(&o.value));
        row.push((format!("set.{k}"), v));
    }
    row.push(("seed".into(), json!(job.seed)));
    row.push((
        "status".into(),
        json!(if error.is_some() { "failed" } else { "ok" }),
    ));
    row.push(("error".into(), error.map_or(Json::Null, |e| json!(e))));
    row.push(("job_wall_s".into(), json!(wall_s)));
    row
}

/// The union of the rows' keys in order of first appearance.
pub fn columns(rows: &[Row]) -> Vec<String> {
    let mut seen = std::collections::HashSet::new();
    let mut cols = Vec::new();
    for r in rows {
        for (k, _) in r {
            if seen.insert(k.as_str()) {
                cols.push(k.clone());
            }
        }
    }
    cols
}

/// A JSON value as CSV text: null is empty, strings unquoted, arrays and tables as JSON.
pub fn cell(v: &Json) -> String {
    match v {
        Json::Null => String::new(),
        Json::String(s) => s.clone(),
        other => other.to_string(),
    }
}

fn io_err(path: &Path, e: impl std::fmt::Display) -> anyhow::Error {
    anyhow::anyhow!("{}: cannot write: {e}", path.display())
}

/// Writes `rows` as CSV with `cols` as the header (a missing key is an empty cell).
pub fn write_csv(path: &Path, cols: &[String], rows: &[Row]) -> anyhow::Result<()> {
    let mut w = csv::Writer::from_path(path).map_err(|e| io_err(path, e))?;
    w.write_record(cols).map_err(|e| io_err(path, e))?;
    for r in rows {
        let rec = cols.iter().map(|c| {
            r.iter()
                .find(|(k, _)| k == c)
                .map_or(String::new(), |(_, v)| cell(v))
        });
        w.write_record(rec).map_err(|e| io_err(path, e))?;
    }
    w.flush().map_err(|e| io_err(path, e))
}

/// Writes one JSON object per row and line, keys in row order.
pub fn write_jsonl(path: &Path, rows: &[Row]) -> anyhow::Result<()> {
    let f = std::fs::File::create(path).map_err(|e| io_err(path, e))?;
    let mut w = std::io::BufWriter::new(f);
    for r in rows {
        writeln!(w, "{}", row_line(r)).map_err(|e| io_err(path, e))?;
    }
    w.flush().map_err(|e| io_err(path, e))
}

/// A row as one line of JSON (without the newline), keys in row order.
pub fn row_line(r: &Row) -> String {
    let fields: Vec<String> = r
        .iter()
        .map(|(k, v)| format!("{}:{}", Json::String(k.clone()), v))
        .collect();
    format!("{{{}}}", fields.join(","))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flattens_named_arrays_by_name() {
        let v = json!({"robots": [{"name": "r1", "d": 1.5, "loc": {"mcl": {"ate": 0.1}},
                                   "pose": [1, 2], "nav": null}]});
        let mut out = Row::new();
        flatten("", &v, &mut out);
        let keys: Vec<&str> = out.iter().map(|(k, _)| k.as_str()).collect();
        assert_eq!(
            keys,
            [
                "robots.r1.d",
                "robots.r1.loc.mcl.ate",
                "robots.r1.nav",
                "robots.r1.pose.0",
                "robots.r1.pose.1"
            ]
        );
    }

    #[test]
    fn jsonl_keeps_column_order_and_csv_fills_gaps() {
        let dir = tempfile::tempdir().unwrap();
        let rows = vec![
            vec![("b".to_string(), json!(1)), ("a".to_string(), json!("x,y"))],
            vec![("b".to_string(), json!(2.5)), ("c".to_string(), Json::Null)],
        ];
        let cols = columns(&rows);
        assert_eq!(cols, ["b", "a", "c"]);
        write_csv(&dir.path().join("r.csv"), &cols, &rows).unwrap();
        write_jsonl(&dir.path().join("r.jsonl"), &rows).unwrap();
        let csv = std::fs::read_to_string(dir.path().join("r.csv")).unwrap();
        assert_eq!(csv, "b,a,c\n1,\"x,y\",\n2.5,,\n");
        let jl = std::fs::read_to_string(dir.path().join("r.jsonl")).unwrap();
        assert_eq!(jl, "{\"b\":1,\"a\":\"x,y\"}\n{\"b\":2.5,\"c\":null}\n");
    }
}
