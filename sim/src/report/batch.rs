//! A batch's page: its parameter sets, the aggregate table (median, mean ± std and p95 of every
//! metric per set, as `aggregate.csv`) and a box plot per metric that varies between runs.

use super::figures;
use super::page::{self, escape, number};
use crate::batch::aggregate::{self, SetStats};
use crate::batch::output::{Row, cell};
use serde_json::Value as Json;
use std::fmt::Write as _;

/// A set's parameters as `key=value` (those that differ between sets).
fn set_label(st: &SetStats, stats: &[SetStats]) -> String {
    crate::batch::aggregate::differing_params(st, stats).join(" ")
}

/// The page of batch `name` from its rows (`runs.jsonl`) and statistics (`aggregate.csv`).
pub fn batch_page(name: &str, rows: &[Row], stats: &[SetStats]) -> anyhow::Result<String> {
    let ok = rows
        .iter()
        .filter(|r| aggregate::column(r, "status").and_then(Json::as_str) == Some("ok"))
        .count();
    let mut html = page::start(&format!("batch {name}"));
    let _ = writeln!(
        html,
        "<p>{} runs in {} parameter set{}, {} failed.</p>",
        rows.len(),
        stats.len(),
        if stats.len() == 1 { "" } else { "s" },
        rows.len() - ok
    );

    html.push_str("<h2>Parameter sets</h2>\n<table>\n<tr><th>set</th><th>parameters</th><th>runs</th><th>failed</th></tr>\n");
    for st in stats {
        let all: Vec<String> = st
            .params
            .iter()
            .map(|(k, v)| format!("{}={}", k.trim_start_matches("set."), cell(v)))
            .collect();
        let _ = writeln!(
            html,
            "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
            st.set,
            escape(&all.join(" ")),
            st.runs,
            st.failed
        );
    }
    html.push_str("</table>\n");

    // every metric of any set, in the order of the first set that has it
    let mut metrics: Vec<&str> = Vec::new();
    for st in stats {
        for (m, _) in &st.metrics {
            if !metrics.contains(&m.as_str()) {
                metrics.push(m);
            }
        }
    }

    html.push_str("<h2>Aggregate</h2>\n<p class=\"note\">Over each set's successful runs: median, mean ± standard deviation (n − 1), 95th percentile (nearest rank).</p>\n<table>\n<tr><th>metric</th>");
    for st in stats {
        let _ = write!(html, "<th>set {}</th>", st.set);
    }
    html.push_str("</tr>\n");
    for m in &metrics {
        let _ = write!(html, "<tr><td>{}</td>", escape(m));
        for st in stats {
            match st.metrics.iter().find(|(k, _)| k == m) {
                Some((_, s)) => {
                    let spread = if s.std.is_finite() {
                        format!(" ± {}", number(s.std))
                    } else {
                        String::new()
                    };
                    let _ = write!(
                        html,
                        "<td>{} ({}{spread}; p95 {})</td>",
                        number(s.median),
                        number(s.mean),
                        number(s.p95)
                    );
                }
                None => html.push_str("<td>–</td>"),
            }
        }
        html.push_str("</tr>\n");
    }
    html.push_str("</table>\n");

    html.push_str("<h2>Distributions</h2>\n<p class=\"note\">One box per parameter set over its successful runs: the median, the quartiles and whiskers to the extremes. Metrics equal in every run are left out (they are in the table above).</p>\n");
    let labels: Vec<String> = stats
        .iter()
        .map(|st| format!("set {}: {}", st.set, set_label(st, stats)))
        .filter(|l| !l.ends_with(": "))
        .collect();
    if !labels.is_empty() {
        let _ = writeln!(html, "<p>{}</p>", escape(&labels.join("; ")));
    }
    html.push_str("<div class=\"grid\">\n");
    let ok_rows: Vec<&Row> = rows
        .iter()
        .filter(|r| aggregate::column(r, "status").and_then(Json::as_str) == Some("ok"))
        .collect();
    for m in &metrics {
        let sets: Vec<(String, Vec<f64>)> = stats
            .iter()
            .map(|st| {
                let values = ok_rows
                    .iter()
                    .filter(|r| {
                        aggregate::column(r, "set").and_then(Json::as_u64) == Some(st.set as u64)
                    })
                    .filter_map(|r| aggregate::column(r, m).and_then(aggregate::number))
                    .filter(|v| v.is_finite())
                    .collect();
                (format!("set {}", st.set), values)
            })
            .collect();
        let all: Vec<f64> = sets.iter().flat_map(|(_, v)| v.iter().copied()).collect();
        if all.len() < 2 || all.iter().all(|v| *v == all[0]) {
            continue;
        }
        let svg = figures::box_figure(m, &sets)?;
        page::figure(&mut html, &svg, "");
    }
    html.push_str("</div>\n");
    Ok(page::end(html))
}
