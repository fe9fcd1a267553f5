//! CARMEN logs and maps on the command line: `sim run
//! --carmen-out` / `--save-map`, `sim slam --carmen`, and the SLAM entities of the recordings,
//! parsed as the binary parses them (exit codes and printed text: sim/tests/cli/carmen.rs).

use crate::common::*;
use sim::{RunOptions, run_scenario};
use systems::core::Pose2;
use systems::mapping::map_quality;
use systems::world::map_file::load_map;

/// The run is exported without changing it, its known-pose map is right, and the log replays
/// through scan-to-map SLAM to a trajectory and map close to the truth.
#[test]
fn a_run_exported_as_carmen_replays_through_slam() {
    let dir = tempfile::tempdir().unwrap();
    let p = |f: &str| dir.path().join(f).display().to_string();
    let file = bundled("hospital_loop").display().to_string();
    let args = [
        file.as_str(),
        "--duration",
        "40",
        "--no-rrd",
        "--quiet",
        "--carmen-out",
        &p("loop.log"),
        "--save-map",
        &p("known"),
        "--summary",
        &p("run.json"),
    ];
    sim_run(&args).unwrap();

    // the same run without exports, with scan-to-map SLAM inside the simulation (SLAM never
    // steers the robot): exporting changed nothing but the SLAM entry it lacks
    let text = std::fs::read_to_string(bundled("hospital_loop")).unwrap();
    let mut sc = scenario(&text.replacen(
        "# lap 1\n",
        "[[robots.slam]]\ntype = \"scan_to_map\"\n# lap 1\n",
        1,
    ));
    sc.duration = 40.0;
    let inside = run_scenario(&sc, &RunOptions::default()).unwrap();
    let exported: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(p("run.json")).unwrap()).unwrap();
    let mut plain = serde_json::to_value(&inside.summary).unwrap();
    let slam_entry = plain["robots"][0]["localization"]
        .as_object_mut()
        .unwrap()
        .remove("scan_to_map");
    assert!(slam_entry.is_some());
    assert_eq!(exported["robots"], plain["robots"]);

    // the robot has no SLAM: a known-pose map, judged against the true map (same frame)
    let known = load_map(std::path::Path::new(&p("known.yaml"))).unwrap();
    let q = map_quality(&known, &sc.grid, &Pose2::default());
    assert!(
        q.precision > 0.95 && q.recall > 0.95,
        "known-pose map: {q:?}"
    );

    let report = sim_slam(&[
        "--carmen",
        &p("loop.log"),
        "--slam",
        "scan_to_map",
        "--trajectory",
        &p("t.tum"),
        "--save-map",
        &p("m"),
        "--rrd",
        &p("s.rrd"),
        "--quiet",
    ])
    .unwrap();
    assert_eq!(report.skipped.len(), 0, "{report:?}");
    assert!(report.scans >= 390, "10 Hz for 40 s: {report:?}");
    let slam = report.slam_metrics.as_ref().unwrap();
    let odom = report.odometry_metrics.as_ref().unwrap();
    let ate = slam.ate_rmse_m.unwrap();
    assert!(ate < ATE_BOUND_M, "SLAM ATE {ate} m ({report:?})");
    assert_eq!(slam.estimates, report.scans);
    assert!(
        odom.ate_rmse_m.unwrap() > 3.0 * ate,
        "odometry drifts: {odom:?}"
    );
    // replaying the log reproduces the SLAM run inside the simulation, pose for pose (TUM
    // files hold 6 decimals)
    let tum = std::fs::read_to_string(p("t.tum")).unwrap();
    let replayed: Vec<Vec<f64>> = tum
        .lines()
        .map(|l| l.split(' ').map(|v| v.parse().unwrap()).collect())
        .collect();
    let (_, online) = inside.localization[0]
        .localizers
        .iter()
        .find(|(n, _)| n == "scan_to_map")
        .unwrap();
    assert_eq!(replayed.len(), online.len());
    for (r, s) in replayed.iter().zip(online) {
        let d = (r[1] - s.estimate.x).hypot(r[2] - s.estimate.y);
        assert!((r[0] - s.t).abs() < 1e-6 && d < 1e-5, "{r:?} vs {s:?}");
    }
    assert!(std::fs::read_to_string(p("t.truth.tum")).is_ok());

    // the SLAM map is in the odometry frame, which `sim run` starts at the true start pose
    let m = load_map(std::path::Path::new(&p("m.yaml"))).unwrap();
    let q = map_quality(&m, &sc.grid, &Pose2::default());
    assert!(
        q.precision > SLAM_PRECISION && q.recall > SLAM_RECALL,
        "SLAM map: {q:?}"
    );

    // any type of the scenario's slam key runs, here graph SLAM named by a config file
    std::fs::write(p("g.toml"), "type = \"graph\"\nname = \"g\"\n").unwrap();
    let graph = sim_slam(&[
        "--carmen",
        &p("loop.log"),
        "--slam-config",
        &p("g.toml"),
        "--no-rrd",
        "--quiet",
    ])
    .unwrap();
    assert_eq!(
        (graph.slam.as_str(), graph.slam_type.as_str()),
        ("g", "graph")
    );
    let fin = graph.slam_metrics.unwrap().final_trajectory.unwrap();
    assert!(fin.ate_rmse_m.unwrap() < ATE_BOUND_M, "graph: {fin:?}");

    let Some(v) = check_rrd(std::path::Path::new(&p("s.rrd"))) else {
        return;
    };
    let paths = entity_paths(&v);
    for want in [
        "/robots/loop/slam/map",
        "/robots/loop/slam/trajectory",
        "/robots/loop/slam/scan",
        "/robots/loop/odometry/path",
        "/robots/loop/truth/path",
    ] {
        assert!(
            paths.iter().any(|p| p == want),
            "missing {want} in {paths:?}"
        );
    }
}

/// SLAM on the first 40 s of hospital_loop replayed from CARMEN, measured: ATE 0.033 m for
/// scan_to_map and graph (odometry 0.348 m); scan_to_map's map: precision 99.7 %, recall
/// 87.8 % (it inserts a scan every 0.2 m or 0.15 rad, the known-pose map every scan). Bounds
/// with margin:
const ATE_BOUND_M: f64 = 0.08;
const SLAM_PRECISION: f64 = 0.95;
const SLAM_RECALL: f64 = 0.8;

/// Two SLAM systems on one robot: the recording holds each under its name, and --save-map
/// writes one map per system with `-<robot>-<name>` after the stem.
#[test]
fn sim_run_records_and_saves_every_slam_system() {
    let dir = tempfile::tempdir().unwrap();
    let p = |f: &str| dir.path().join(f).display().to_string();
    let maps = sim::scenario::assets_dir().join("maps");
    let text = std::fs::read_to_string(bundled("hospital_loop"))
        .unwrap()
        .replace("../maps", &maps.display().to_string())
        .replacen(
            "# lap 1\n",
            "[[robots.slam]]\ntype = \"scan_to_map\"\n[[robots.slam]]\ntype = \"scan_to_map\"\n\
             name = \"coarse\"\nresolution = 0.1\n# lap 1\n",
            1,
        );
    std::fs::write(p("two.toml"), text).unwrap();
    let scenario = p("two.toml");
    sim_run(&[
        scenario.as_str(),
        "--duration",
        "6",
        "--rrd",
        &p("two.rrd"),
        "--save-map",
        &p("maps.yaml"),
        "--quiet",
    ])
    .unwrap();
    for name in ["scan_to_map", "coarse"] {
        let m = load_map(std::path::Path::new(&p(&format!(
            "maps-mapper-{name}.yaml"
        ))))
        .unwrap();
        assert!(m.width > 0 && m.height > 0);
    }
    let Some(v) = check_rrd(std::path::Path::new(&p("two.rrd"))) else {
        return;
    };
    let paths = entity_paths(&v);
    for name in ["scan_to_map", "coarse"] {
        for leaf in ["map", "trajectory", "scan"] {
            let want = format!("/robots/mapper/slam/{name}/{leaf}");
            assert!(paths.contains(&want), "missing {want} in {paths:?}");
        }
    }
}

/// A SLAM system with a pose graph (a stand-in until graph SLAM lands): a square of four
/// nodes, sequential edges, one accepted and one rejected loop closure.
#[derive(Clone, Debug)]
struct SquareGraph;

impl systems::localization::ScanEstimator for SquareGraph {
    fn kind(&self) -> &'static str {
        "square"
    }
    fn update(&mut self, _: &systems::sensors::LaserScan, _: &Pose2, _: &Pose2) -> bool {
        false
    }
    fn estimate(&self) -> Option<systems::localization::PoseEstimate> {
        None
    }
    fn map(&self) -> Option<systems::matching::ProbGrid> {
        Some(systems::matching::ProbGrid::new(
            40,
            40,
            0.05,
            [-0.5, -0.5],
            0.3,
        ))
    }
    fn trajectory(&self) -> Vec<(f64, Pose2)> {
        self.nodes()
            .into_iter()
            .enumerate()
            .map(|(k, p)| (k as f64, p))
            .collect()
    }
    fn graph(&self) -> Option<systems::localization::GraphView> {
        use systems::localization::{GraphEdgeKind as K, GraphEdgeView, GraphView};
        let e = |from, to, kind| GraphEdgeView { from, to, kind };
        Some(GraphView {
            nodes: self.nodes(),
            edges: vec![
                e(0, 1, K::Sequential),
                e(1, 2, K::Sequential),
                e(2, 3, K::Local),
                e(3, 0, K::LoopClosure),
                e(2, 0, K::Rejected),
            ],
        })
    }
    fn box_clone(&self) -> Box<dyn systems::localization::ScanEstimator> {
        Box::new(self.clone())
    }
    fn as_any(&self) -> &dyn std::any::Any {
        self
    }
}

impl SquareGraph {
    fn nodes(&self) -> Vec<Pose2> {
        [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
            .map(|(x, y)| Pose2::new(x, y, 0.0))
            .to_vec()
    }
}

#[test]
fn a_pose_graph_is_recorded_with_its_edges_and_nodes() {
    use sim::record::rrd::slam::{log_slam_state, slam_entity};
    let Some(rerun) = test_tool(TestTool::Rerun) else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("g.rrd");
    let mut rec = sim::record::rrd::open_recording(&path, "graph").unwrap();
    rec.set_duration_secs("sim_time", 1.0);
    log_slam_state(&mut rec, &slam_entity("r", "square", 1), &SquareGraph).unwrap();
    rec.close().unwrap();
    drop(rec);
    let paths = entity_paths(&check_rrd_with(&rerun, &path));
    for leaf in ["map", "trajectory", "graph", "graph/nodes"] {
        let want = format!("/robots/r/slam/{leaf}");
        assert!(paths.contains(&want), "missing {want} in {paths:?}");
    }
}
