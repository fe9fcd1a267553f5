use super::data::*;
use super::*;
use serde_json::json;

/// A page refers to no other file: no script, stylesheet, image, frame or link target outside
/// the page (data in it is fine).
fn assert_self_contained(html: &str) {
    let lower = html.to_lowercase();
    for needle in [
        "<script", "<link", "<img", "<iframe", "<object", "<embed", "@import", "url(", "src=",
    ] {
        assert!(!lower.contains(needle), "the page has `{needle}`");
    }
    for (k, _) in lower.match_indices("href=") {
        let target = &lower[k + 6..];
        assert!(
            target.starts_with('#'),
            "a link out of the page: {}",
            &html[k..k + 60.min(html.len() - k)]
        );
    }
    assert!(lower.starts_with("<!doctype html>"));
    assert!(lower.trim_end().ends_with("</html>"));
}

#[test]
fn bucket_max_keeps_the_largest_value_of_each_stretch() {
    let series: Vec<[f64; 2]> = (0..10_000)
        .map(|k| [k as f64 * 0.01, if k == 5_003 { 40.0 } else { 0.1 }])
        .collect();
    let b = bucket_max(&series, 1000);
    assert!(b.len() <= 1000 && b.len() >= 990, "{}", b.len());
    assert!(b.contains(&[50.03, 40.0]), "the spike survives");
    assert!(b.windows(2).all(|w| w[0][0] < w[1][0]), "in time order");
    let short = vec![[0.0, 1.0], [1.0, 2.0]];
    assert_eq!(bucket_max(&short, 1000), short);
}

#[test]
fn the_map_is_coarsened_to_runs_of_occupied_cells() {
    use systems::world::{Cell, OccupancyGrid};
    let (w, h) = (1000, 20);
    let mut cells = vec![Cell::Free; w * h];
    // a wall along row 0 and one cell at (999, 19)
    for c in cells.iter_mut().take(w) {
        *c = Cell::Occupied;
    }
    cells[19 * w + 999] = Cell::Occupied;
    let grid = OccupancyGrid {
        width: w,
        height: h,
        resolution: 0.05,
        origin: [-1.0, 2.0],
        cells,
    };
    let m = map_cells(&grid);
    // 1000 cells → a factor of 3: 334 × 7 cells of 0.15 m
    assert_eq!(m.size, [334, 7]);
    assert!((m.resolution - 0.15).abs() < 1e-12);
    assert_eq!(m.origin, [-1.0, 2.0]);
    assert_eq!(m.occupied, vec![[0, 0, 334], [6, 333, 334]]);
}

#[test]
fn task_spans_follow_the_navigators_lines() {
    let log: Vec<(f64, String, String)> = [
        (1.0, "r1", "task started: meals: deliver kitchen → ward_2"),
        (2.0, "r2", "task started: mail: deliver office → reception"),
        (30.0, "r1", "task meals completed"),
        (31.0, "r1", "task started: linen: go to store"),
        (40.0, "r1", "task linen FAILED: no path to store"),
        (41.0, "r1", "task started: drugs: deliver pharmacy → ward_1"),
        (45.0, "", "door d1 closed"),
    ]
    .into_iter()
    .map(|(t, r, s)| (t, r.to_string(), s.to_string()))
    .collect();
    let spans = task_spans(&log, "r1", 60.0);
    let got: Vec<(&str, f64, f64, Outcome)> = spans
        .iter()
        .map(|s| (s.task.as_str(), s.start, s.end, s.outcome))
        .collect();
    assert_eq!(
        got,
        vec![
            ("meals", 1.0, 30.0, Outcome::Done),
            ("linen", 31.0, 40.0, Outcome::Failed),
            ("drugs", 41.0, 60.0, Outcome::Unfinished),
        ]
    );
    assert_eq!(task_spans(&log, "r2", 60.0).len(), 1);
}

/// A short delivery run: its page draws the map, the errors and the timeline, names every
/// robot, refers to no other file, and `sim report` draws the same page from report.json.
#[test]
fn a_runs_page_is_self_contained_and_drawn_again_from_its_data() {
    let path = crate::scenario::load::assets_dir().join("scenarios/hospital_delivery.toml");
    let mut s = crate::scenario::load_scenario(&path).unwrap();
    s.duration = 40.0;
    let out = crate::run::run_scenario(
        &s,
        &crate::run::RunOptions {
            trajectory_period: Some(0.1),
            threads: 1,
            ..Default::default()
        },
    )
    .unwrap();
    let report = RunReport::of_run(&s, &out).unwrap();
    assert_eq!(report.robots.len(), s.robots.len());
    assert!(report.robots.iter().all(|r| !r.truth.is_empty()));
    assert!(report.robots.iter().any(|r| !r.tasks.is_empty()));
    let dir = tempfile::tempdir().unwrap();
    prepare_dir(dir.path()).unwrap();
    let page_path = write_run(dir.path(), &report).unwrap();
    let html = std::fs::read_to_string(&page_path).unwrap();
    assert_self_contained(&html);
    // map, one error plot per robot with localizers, the timeline
    let figures = html.matches("<svg").count();
    assert!(figures >= 2 + s.robots.len(), "{figures} figures");
    for r in &s.robots {
        assert!(html.contains(&format!(">{}<", r.name)), "robot {}", r.name);
    }
    assert!(html.contains("Navigation"));
    // a second report into the same folder is refused before anything runs
    let e = prepare_dir(dir.path()).unwrap_err().to_string();
    assert!(
        e.contains("report.html") && e.contains("already there"),
        "{e}"
    );
    // drawn again from report.json: the same page
    let again = dir.path().join("again.html");
    redraw(&dir.path().join(DATA), Some(&again), false).unwrap();
    assert_eq!(std::fs::read_to_string(&again).unwrap(), html);
    // the folder names the report; an existing page needs --force
    let e = redraw(dir.path(), None, false).unwrap_err().to_string();
    assert!(e.contains("--force"), "{e}");
    redraw(dir.path(), None, true).unwrap();
    // a plain --summary: the tables without figures
    let summary = dir.path().join("summary.json");
    std::fs::write(&summary, serde_json::to_string(&out.summary).unwrap()).unwrap();
    let tables = dir.path().join("tables.html");
    redraw(&summary, Some(&tables), false).unwrap();
    let html = std::fs::read_to_string(&tables).unwrap();
    assert_self_contained(&html);
    assert!(!html.contains("<svg") && html.contains("<table>"));
}

#[test]
fn files_that_are_not_ours_are_refused_naming_them() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        ("other.json", "{\"name\": \"x\"}", "no `scenario`"),
        ("text.json", "hello", "not JSON"),
        (
            "future.json",
            "{\"format\": \"sim-report/9\"}",
            "sim-report/9",
        ),
        ("rows.jsonl", "{\"a\": 1}\n", "line 1"),
    ];
    for (name, text, why) in cases {
        let p = dir.path().join(name);
        std::fs::write(&p, text).unwrap();
        let e = redraw(&p, Some(&dir.path().join("out.html")), false)
            .unwrap_err()
            .to_string();
        assert!(e.contains(&p.display().to_string()), "{e}");
        assert!(
            e.contains(why) && e.contains("not a file written by sim"),
            "{e}"
        );
    }
    let e = redraw(dir.path(), None, false).unwrap_err().to_string();
    assert!(e.contains("neither a report"), "{e}");
    // a report folder that cannot be made: under a file
    let file = dir.path().join("other.json");
    let e = prepare_dir(&file.join("sub")).unwrap_err().to_string();
    assert!(e.contains("cannot create the report folder"), "{e}");
}

/// Two parameter sets of three runs: the varying metric gets a box plot, the constant one
/// only its row in the table; failed runs are counted and left out.
#[test]
fn a_batch_page_has_the_sets_the_aggregate_and_a_box_per_varying_metric() {
    let row = |set: u64, seed: u64, status: &str, ate: f64| -> Row {
        vec![
            ("job".into(), json!(set * 3 + seed)),
            ("set".into(), json!(set)),
            ("set.robots.0.speed".into(), json!(0.5 + set as f64)),
            ("seed".into(), json!(seed)),
            ("status".into(), json!(status)),
            ("fleet.ate_rmse_m".into(), json!(ate)),
            ("fleet.robots".into(), json!(2)),
        ]
    };
    let rows = vec![
        row(0, 0, "ok", 0.10),
        row(0, 1, "ok", 0.12),
        row(0, 2, "error", 9.0),
        row(1, 0, "ok", 0.20),
        row(1, 1, "ok", 0.25),
        row(1, 2, "ok", 0.22),
    ];
    let cols = crate::batch::output::columns(&rows);
    let stats = crate::batch::aggregate::aggregate(2, &cols, &rows);
    let html = batch::batch_page("speed", &rows, &stats).unwrap();
    assert_self_contained(&html);
    assert_eq!(html.matches("<svg").count(), 1, "one varying metric");
    assert!(html.contains("fleet.ate_rmse_m") && html.contains("fleet.robots"));
    assert!(html.contains("6 runs in 2 parameter sets, 1 failed"));
    assert!(html.contains("speed=0.5") && html.contains("speed=1.5"));
    // drawn again from runs.jsonl: the same sets and plots
    let dir = tempfile::tempdir().unwrap();
    crate::batch::output::write_jsonl(&dir.path().join("runs.jsonl"), &rows).unwrap();
    let page = redraw(dir.path(), None, false).unwrap();
    let again = std::fs::read_to_string(page).unwrap();
    assert_eq!(again.matches("<svg").count(), 1);
    assert!(again.contains("1 failed"));
}

/// A report.json edited by hand with odd data (far-off and inverted values, an empty map, a
/// summary without its fields) still gives a page: figures clip, nothing panics.
#[test]
fn odd_report_data_draws_a_page_without_panicking() {
    let r = RunReport {
        format: FORMAT.into(),
        summary: json!({"robots": [{"name": "r1", "navigation": {"tasks": 1}}]}),
        map: Some(MapCells {
            origin: [0.0, 0.0],
            resolution: 0.0,
            size: [0, 0],
            occupied: vec![[3, 9, 2]],
        }),
        roads: vec![RoadLine {
            width: -1.0,
            points: vec![[1e30, 0.0]],
        }],
        robots: vec![RobotTrace {
            name: "r1".into(),
            truth: vec![vec![[0.0, 0.0], [f32::MAX, 1.0]]],
            localizers: vec![LocalizerTrace {
                name: "mcl".into(),
                path: vec![],
                error: vec![[0.0, 1e300], [5.0, -3.0]],
            }],
            tasks: vec![TaskSpan {
                task: "<b>".into(),
                start: 9.0,
                end: 2.0,
                outcome: Outcome::Failed,
            }],
        }],
    };
    let html = page::run_page(&r).unwrap();
    assert_self_contained(&html);
    assert!(
        html.contains("&lt;b&gt;") && !html.contains("<b>"),
        "names are escaped"
    );
}
