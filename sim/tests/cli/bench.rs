//! `sim bench`: the JSON lines of `mcl`, `markov-grid`, `swarm` and `slam`, and options refused
//! before anything runs or prints (absurd sizes, unknown modes, bad scenarios).

use crate::common::{expect_failure, run_ok, sim};

/// Parses every line of a `--json` bench output and checks the fields each row must have.
fn bench_rows(args: &[&str], fields: &[&str]) -> Vec<serde_json::Value> {
    let dir = tempfile::tempdir().unwrap();
    let out = sim(args, dir.path());
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let rows: Vec<serde_json::Value> = text
        .lines()
        .map(|l| serde_json::from_str(l).unwrap_or_else(|e| panic!("{e}: {l}")))
        .collect();
    for row in &rows {
        // the processor, so figures from different machines are not compared unawares
        let machine = row["machine"].as_str().unwrap_or_default();
        assert!(machine.contains("CPU"), "no machine in {row}");
        for f in fields {
            let x = row[f].as_f64().unwrap_or_else(|| panic!("no {f} in {row}"));
            assert!(x.is_finite() && x > 0.0, "{f} = {x} in {row}");
        }
    }
    rows
}

#[test]
fn bench_mcl_prints_json_lines() {
    let rows = bench_rows(
        &["bench", "mcl", "--json", "--reps", "1"],
        &["particles", "beams", "ms_per_update", "evals_per_s"],
    );
    let counts: Vec<u64> = rows
        .iter()
        .map(|r| r["particles"].as_u64().unwrap())
        .collect();
    assert_eq!(counts, [1000, 5000, 20000]);
    assert!(rows.iter().all(|r| r["beams"] == 60), "{rows:?}");
}

/// Lists take commas or spaces, and each row reports the population and laser asked for.
#[test]
fn bench_swarm_prints_one_row_per_population_and_laser() {
    let fields = [
        "robots",
        "beams",
        "real_time_factor",
        "rays_per_s",
        "sim_time_s",
    ];
    let spaced = bench_rows(
        &[
            "bench",
            "swarm",
            "--json",
            "--robots",
            "1",
            "3",
            "--beams",
            "30",
            "--duration",
            "0.3",
        ],
        &fields,
    );
    let commas = bench_rows(
        &[
            "bench",
            "swarm",
            "--json",
            "--robots",
            "1,3",
            "--beams",
            "30,45",
            "--duration",
            "0.3",
        ],
        &fields,
    );
    let asked = |rows: &[serde_json::Value]| -> Vec<(u64, u64)> {
        rows.iter()
            .map(|r| (r["robots"].as_u64().unwrap(), r["beams"].as_u64().unwrap()))
            .collect()
    };
    assert_eq!(asked(&spaced), [(1, 30), (3, 30)]);
    assert_eq!(asked(&commas), [(1, 30), (3, 30), (1, 45), (3, 45)]);
    let ran = |r: &serde_json::Value| (r["sim_time_s"].as_f64().unwrap() - 0.3).abs() < 1e-9;
    assert!(commas.iter().all(ran), "{commas:?}");
    assert!(
        commas.iter().all(|r| r["stepped_by"] == "facade"),
        "{commas:?}"
    );
    // --direct steps the bare schedule for the same simulated time
    let direct = bench_rows(
        &[
            "bench",
            "swarm",
            "--json",
            "--robots",
            "3",
            "--beams",
            "30",
            "--duration",
            "0.3",
            "--direct",
        ],
        &fields,
    );
    assert!(direct.iter().all(ran), "{direct:?}");
    assert_eq!(direct[0]["stepped_by"], "schedule");
}

/// At constant density each population gets its own tiling of the hospital, and the rows say
/// which; `--mcl` names whose defaults the localizers took.
#[test]
fn bench_swarm_at_constant_density_tiles_the_map_with_the_robot_count() {
    let fields = ["robots", "real_time_factor", "us_per_robot_step"];
    let rows = bench_rows(
        &[
            "bench",
            "swarm",
            "--json",
            "--robots",
            "2,5",
            "--beams",
            "30",
            "--duration",
            "0.2",
            "--per-hospital",
            "2",
        ],
        &fields,
    );
    let maps: Vec<&str> = rows.iter().map(|r| r["map"].as_str().unwrap()).collect();
    assert!(maps[0].starts_with("hospital tiled 1x1"), "{maps:?}");
    // 5 robots at 2 per copy: 3 copies, so 2 x 2
    assert!(maps[1].starts_with("hospital tiled 2x2"), "{maps:?}");
    let mcl = |defaults: Option<&str>| {
        let mut args = vec![
            "bench",
            "swarm",
            "--json",
            "--robots",
            "1",
            "--beams",
            "30",
            "--duration",
            "0.2",
            "--mcl",
        ];
        args.extend(defaults);
        bench_rows(&args, &["real_time_factor"])[0]["localizer"].clone()
    };
    assert_eq!(mcl(None), "mcl-amcl");
    assert_eq!(mcl(Some("sim")), "mcl-sim");
}

/// Options the swarm benchmark cannot honour are refused before anything runs, naming the
/// option, instead of being clamped or running forever.
#[test]
fn bench_swarm_refuses_bad_options() {
    let dir = tempfile::tempdir().unwrap();
    for (args, expected) in [
        (
            &["--duration", "-5"][..],
            &["--duration", "positive", "-5"][..],
        ),
        (&["--duration=0"], &["--duration", "positive"]),
        (&["--duration", "nan"], &["--duration", "positive"]),
        (&["--duration", "inf"], &["--duration", "positive"]),
        (&["--beams", "1"], &["--beams", "2 to 20000", "got 1"]),
        (&["--beams", "180,20001"], &["--beams", "got 20001"]),
        (&["--robots", "10,0"], &["--robots", "at least 1", "got 0"]),
        (&["--per-hospital", "0"], &["--per-hospital", "0"]),
        (&["--per-hospital", "100000"], &["--per-hospital", "100000"]),
        (&["--mcl", "ros"], &["--mcl", "ros", "amcl"]),
        (
            &["--robots", "1000000"],
            &["--robots 1000000", "free floor"],
        ),
    ] {
        let mut all = vec!["bench", "swarm", "--json"];
        all.extend_from_slice(args);
        expect_failure(&all, dir.path(), expected);
    }
}

#[test]
fn bench_markov_grid_prints_json_lines() {
    let rows = bench_rows(
        &["bench", "markov-grid", "--json", "--reps", "1"],
        &["particles", "cells", "beams", "ms_per_update"],
    );
    let modes: Vec<&str> = rows.iter().map(|r| r["mode"].as_str().unwrap()).collect();
    assert_eq!(modes, ["global", "selective"]);
}

/// Fails like [`expect_failure`] and prints nothing on standard output (no table header).
fn fails_silently(args: &[&str], fragments: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    expect_failure(args, dir.path(), fragments);
    let out = sim(args, dir.path());
    assert!(out.stdout.is_empty(), "{args:?} printed {:?}", out.stdout);
}

#[test]
fn bench_mcl_refuses_absurd_particle_counts_before_the_header() {
    for p in ["4294967296", "1000,1000001"] {
        fails_silently(
            &["bench", "mcl", "--particles", p],
            &["--particles: expected 1 to 1000000 particles"],
        );
    }
    fails_silently(&["bench", "mcl", "--particles", "0"], &["got 0"]);
}

#[test]
fn localization_benches_refuse_more_beams_than_the_scans_have() {
    for bench in ["mcl", "markov-grid"] {
        for beams in ["1082", "100000", "4294967296"] {
            fails_silently(
                &["bench", bench, "--beams", beams],
                &["--beams: expected 1 to 1081", beams],
            );
        }
    }
}

#[test]
fn localization_benches_refuse_absurd_repetitions() {
    for bench in ["mcl", "markov-grid"] {
        fails_silently(
            &["bench", bench, "--reps", "4294967296"],
            &["--reps: expected 1 to 10000 updates", "4294967296"],
        );
    }
}

/// A bad scenario or duration stops `bench record` before its table's header is printed.
#[test]
fn bench_record_checks_its_options_before_printing() {
    let dir = tempfile::tempdir().unwrap();
    for args in [
        &["bench", "record", "--duration", "-1"][..],
        &["bench", "record", "--scenario", "hospital_patrol,nowhere"],
    ] {
        let out = sim(args, dir.path());
        assert!(!out.status.success(), "{args:?} should fail");
        assert!(out.stdout.is_empty(), "{args:?} printed: {:?}", out.stdout);
    }
}

#[test]
fn bench_slam_refuses_long_durations_and_unknown_modes_naming_its_own_options() {
    let dir = tempfile::tempdir().unwrap();
    for d in ["700", "1e12"] {
        expect_failure(
            &["bench", "slam", "--duration", d],
            dir.path(),
            &["--duration", "hospital_loop lasts 600 s"],
        );
    }
    for m in ["nosuch", ""] {
        let out = sim(
            &["bench", "slam", "--duration", "1", "--modes", m],
            dir.path(),
        );
        assert!(!out.status.success(), "--modes {m:?} accepted");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains("--modes") && err.contains("scan_to_map, graph, rbpf"),
            "{err}"
        );
        assert!(!err.contains("--slam"), "{err}");
    }
}

#[test]
fn bench_slam_prints_the_thread_count_it_ran_on() {
    let dir = tempfile::tempdir().unwrap();
    let out = run_ok(
        &[
            "bench",
            "slam",
            "--json",
            "--modes",
            "scan_to_map",
            "--duration",
            "1",
            "--threads",
            "0",
        ],
        dir.path(),
    );
    let row: serde_json::Value = serde_json::from_str(out.lines().next().unwrap()).unwrap();
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    assert_eq!(row["threads"], cores as u64, "{row}");
}
