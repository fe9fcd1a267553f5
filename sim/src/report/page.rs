//! The report pages: one self-contained HTML file each (inline CSS and SVG figures; no script,
//! no link to any other file), readable in any browser without a viewer.

use super::data::RunReport;
use super::figures;
use serde_json::{Map, Value as Json};
use std::fmt::Write as _;

/// `&`, `<`, `>` and quotes escaped for HTML text and attributes.
pub fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

const STYLE: &str = "body{font-family:system-ui,sans-serif;margin:2em auto;max-width:1000px;\
color:#222;padding:0 1em}h1{font-size:1.6em}h2{margin-top:1.6em;border-bottom:1px solid #ccc}\
table{border-collapse:collapse;margin:.6em 0;font-size:.9em}th,td{padding:.25em .6em;\
border-bottom:1px solid #e4e4e4;text-align:right}th{background:#f4f4f4}\
td:first-child,th:first-child{text-align:left}.note{color:#666}figure{margin:.8em 0}\
svg{max-width:100%;height:auto}.wide{overflow-x:auto}\
.grid{display:flex;flex-wrap:wrap;gap:0 1em}.grid figure{margin:.3em 0}";

/// The page's head and title.
pub fn start(title: &str) -> String {
    format!(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <title>{}</title>\n<style>{STYLE}</style>\n</head>\n<body>\n<h1>{}</h1>\n",
        escape(title),
        escape(title)
    )
}

pub fn end(mut page: String) -> String {
    let _ = writeln!(
        page,
        "<p class=\"note\">Written by sim {}.</p>\n</body>\n</html>",
        env!("CARGO_PKG_VERSION")
    );
    page
}

/// An SVG figure in the page (without an XML declaration, which only a standalone file has),
/// with a caption unless it is empty.
pub fn figure(page: &mut String, svg: &str, caption: &str) {
    if svg.is_empty() {
        return;
    }
    let svg = match svg.find("<svg") {
        Some(k) => &svg[k..],
        None => svg,
    };
    let caption = if caption.is_empty() {
        String::new()
    } else {
        format!(
            "\n<figcaption class=\"note\">{}</figcaption>",
            escape(caption)
        )
    };
    let _ = writeln!(page, "<figure>\n{svg}{caption}\n</figure>");
}

/// A number as the tables show it: integers whole, others to 3 decimals (4 significant digits
/// below 1).
pub fn number(v: f64) -> String {
    if !v.is_finite() {
        "–".into()
    } else if v.fract() == 0.0 && v.abs() < 1e12 {
        format!("{v:.0}")
    } else if v.abs() < 1.0 {
        format!("{v:.4}")
    } else {
        format!("{v:.3}")
    }
}

/// A JSON scalar as a table cell.
fn cell(v: &Json) -> String {
    match v {
        Json::Null => "–".into(),
        Json::Bool(b) => if *b { "yes" } else { "no" }.into(),
        Json::Number(n) => n.as_f64().map_or_else(|| n.to_string(), number),
        Json::String(s) => escape(s),
        Json::Array(a) => escape(
            &a.iter()
                .map(|x| match x {
                    Json::Number(n) => n.as_f64().map_or_else(|| n.to_string(), number),
                    other => other.to_string(),
                })
                .collect::<Vec<_>>()
                .join(", "),
        ),
        Json::Object(_) => String::new(),
    }
}

/// A table of rows (a label, then a JSON object's scalar fields), the columns the union of the
/// rows' scalar keys in order of first appearance (objects and long arrays left out).
pub fn table(page: &mut String, head: &str, rows: &[(String, &Map<String, Json>)]) {
    let shown = |v: &Json| !v.is_object() && v.as_array().is_none_or(|a| a.len() <= 3);
    let mut cols: Vec<&str> = Vec::new();
    for (_, m) in rows {
        for (k, v) in m.iter() {
            // the row's label is its name
            if k != "name" && shown(v) && !cols.contains(&k.as_str()) {
                cols.push(k);
            }
        }
    }
    if rows.is_empty() {
        return;
    }
    page.push_str("<div class=\"wide\"><table>\n<tr>");
    let _ = write!(page, "<th>{}</th>", escape(head));
    for c in &cols {
        let _ = write!(page, "<th>{}</th>", escape(&c.replace('_', " ")));
    }
    page.push_str("</tr>\n");
    for (label, m) in rows {
        let _ = write!(page, "<tr><td>{}</td>", escape(label));
        for c in &cols {
            let _ = write!(page, "<td>{}</td>", m.get(*c).map_or(String::new(), cell));
        }
        page.push_str("</tr>\n");
    }
    page.push_str("</table></div>\n");
}

fn str_of<'a>(v: &'a Json, k: &str) -> &'a str {
    v.get(k).and_then(Json::as_str).unwrap_or("")
}

/// A run's page: the map with the paths, the summary tables, error over time per robot and,
/// with navigation, the task timeline.
pub fn run_page(r: &RunReport) -> anyhow::Result<String> {
    let s = &r.summary;
    let f = |k: &str| s.get(k).and_then(Json::as_f64).unwrap_or(f64::NAN);
    let mut page = start(&format!(
        "{}, seed {}",
        str_of(s, "scenario"),
        s.get("seed").map_or(String::new(), |v| v.to_string())
    ));
    let _ = writeln!(
        page,
        "<p>Simulated {} s in {} s of wall-clock time ({}× real time).</p>",
        number(f("sim_time_s")),
        number(f("wall_time_s")),
        number(f("real_time_factor"))
    );
    let robots: Vec<&Map<String, Json>> = s
        .get("robots")
        .and_then(Json::as_array)
        .map(|a| a.iter().filter_map(Json::as_object).collect())
        .unwrap_or_default();
    let name = |m: &Map<String, Json>| {
        m.get("name")
            .and_then(Json::as_str)
            .unwrap_or("")
            .to_string()
    };

    if r.map.is_some() || !r.robots.is_empty() {
        page.push_str("<h2>Map and paths</h2>\n");
        let svg = figures::map_figure(r.map.as_ref(), &r.roads, &r.robots)?;
        figure(
            &mut page,
            &svg,
            "Occupied cells grey; each robot's true path in its colour (thick), its localizers' \
             estimates in shades of it (thin). Paths break where they jump.",
        );
    } else {
        page.push_str(
            "<p class=\"note\">Made from a summary alone: the tables only (the figures need the \
             report.json that <code>--report</code> writes).</p>\n",
        );
    }

    page.push_str("<h2>Robots</h2>\n");
    let rows: Vec<(String, &Map<String, Json>)> = robots.iter().map(|m| (name(m), *m)).collect();
    table(&mut page, "robot", &rows);

    let loc_rows: Vec<(String, &Map<String, Json>)> = robots
        .iter()
        .flat_map(|m| {
            let robot = name(m);
            m.get("localization")
                .and_then(Json::as_object)
                .into_iter()
                .flat_map(move |l| {
                    let robot = robot.clone();
                    l.iter().filter_map(move |(k, v)| {
                        v.as_object().map(|o| (format!("{robot} {k}"), o))
                    })
                })
        })
        .collect();
    if !loc_rows.is_empty() {
        page.push_str("<h2>Localization</h2>\n");
        table(&mut page, "localizer", &loc_rows);
        let end_s = f("sim_time_s");
        for (i, t) in r.robots.iter().enumerate() {
            if t.localizers.iter().any(|l| !l.error.is_empty()) {
                let svg = figures::error_figure(i, t, end_s)?;
                figure(
                    &mut page,
                    &svg,
                    &format!(
                        "{}: position error of each localizer against the truth; the axis \
                         ends a quarter above three quarters of the errors (larger ones are \
                         drawn at its top).",
                        t.name
                    ),
                );
            }
        }
    }

    // the robots that have a section `key` (navigation, road), labelled with their names
    let section = |key: &str| -> Vec<(String, &Map<String, Json>)> {
        robots
            .iter()
            .filter_map(|m| m.get(key).and_then(Json::as_object).map(|n| (name(m), n)))
            .collect()
    };
    let nav_rows = section("navigation");
    if !nav_rows.is_empty() {
        page.push_str("<h2>Navigation</h2>\n");
        let svg = figures::timeline_figure(&r.robots, f("sim_time_s"))?;
        figure(
            &mut page,
            &svg,
            "Each robot's tasks from start to end: done green, failed red, unfinished grey.",
        );
        table(&mut page, "robot", &nav_rows);
        let tasks: Vec<String> = r
            .robots
            .iter()
            .flat_map(|t| {
                t.tasks.iter().map(move |k| {
                    format!(
                        "<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
                        escape(&t.name),
                        escape(&k.task),
                        number(k.start),
                        number(k.end),
                        k.outcome.as_str()
                    )
                })
            })
            .collect();
        if !tasks.is_empty() {
            let _ = writeln!(
                page,
                "<table>\n<tr><th>robot</th><th>task</th><th>start s</th><th>end s</th>\
                 <th>outcome</th></tr>\n{}\n</table>",
                tasks.join("\n")
            );
        }
    }

    let road_rows = section("road");
    if !road_rows.is_empty() {
        page.push_str("<h2>Outdoor drive</h2>\n");
        table(&mut page, "robot", &road_rows);
    }
    Ok(end(page))
}
