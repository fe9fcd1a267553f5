//! Localization end to end: MCL on the hospital scenario (global initialisation converges and then
//! tracks), TUM trajectories, and scenario errors of the localizer list.

use crate::common::*;
use sim::scenario::load_scenario;
use sim::{RunOptions, run_scenario};

fn run(sc: &sim::Scenario) -> sim::RunOutput {
    run_scenario(
        sc,
        &RunOptions {
            threads: 2,
            ..Default::default()
        },
    )
    .expect("scenario runs")
}

#[test]
fn mcl_converges_from_global_initialisation_and_tracks_on_the_hospital_patrol() {
    let mut sc = load_scenario(&bundled("hospital_patrol")).unwrap();
    sc.duration = 60.0;
    let out = run(&sc);
    for r in &out.summary.robots {
        for name in ["mcl", "mcl_global"] {
            let m = &r.localization[name];
            let conv = m.converged_after_s.unwrap_or(f64::INFINITY);
            let map_ate = m.ate_map_rmse_m.unwrap_or(f64::INFINITY);
            // tracking from the start pose is converged at once; the global filter within 40 s
            let limit = if name == "mcl" { 1.0 } else { 40.0 };
            assert!(conv <= limit, "{} {name}: converged after {conv} s", r.name);
            assert!(
                map_ate < 0.10,
                "{} {name}: ATE {map_ate} m after convergence",
                r.name
            );
            assert!(
                m.rpe_trans_m.unwrap() < 0.05 && m.rpe_rot_rad.unwrap() < 0.02,
                "{m:?}"
            );
            assert!(m.final_error_m.unwrap() < 0.2, "{} {name}: {m:?}", r.name);
        }
    }
    // the figures are in the JSON summary under robots[i].localization.<name>
    let json: serde_json::Value = serde_json::to_value(&out.summary).unwrap();
    let m = &json["robots"][0]["localization"]["mcl_global"];
    for key in [
        "ate_rmse_m",
        "rpe_trans_m",
        "rpe_rot_rad",
        "converged_after_s",
        "tracked_fraction",
    ] {
        assert!(m[key].is_number(), "{key} in {m}");
    }
}

#[test]
fn trajectories_are_written_for_evo() {
    let dir = tempfile::tempdir().unwrap();
    let mut sc = load_scenario(&bundled("hospital_patrol")).unwrap();
    sc.duration = 6.0;
    sc.robots.truncate(1);
    sc.robots[0].localizers.truncate(1);
    let out = run(&sc);
    let files = sim::record::write_trajectories(dir.path(), &out.localization).unwrap();
    assert_eq!(files.len(), 2);
    let est = std::fs::read_to_string(dir.path().join("r1/mcl.tum")).unwrap();
    let truth = std::fs::read_to_string(dir.path().join("r1/mcl.truth.tum")).unwrap();
    let (e, g): (Vec<&str>, Vec<&str>) = (est.lines().collect(), truth.lines().collect());
    assert!(e.len() > 5 && e.len() == g.len());
    for (a, b) in e.iter().zip(&g) {
        let (a, b): (Vec<f64>, Vec<f64>) = (
            a.split(' ').map(|v| v.parse().unwrap()).collect(),
            b.split(' ').map(|v| v.parse().unwrap()).collect(),
        );
        assert_eq!(a.len(), 8);
        assert_eq!(a[0], b[0], "truth at the estimate's timestamp");
        assert!((a[1] - b[1]).hypot(a[2] - b[2]) < 0.3);
    }
}

fn with_localizer(loc: &str) -> String {
    format!(
        "{SQUARE_ROOM}\n[[robots]]\nname = \"r1\"\nstart = [5.0, 5.0, 0.0]\n\
         [robots.sensors.laser]\n[robots.sensors.encoder]\n{loc}\n"
    )
}

fn expect_error(text: &str, fragments: &[&str]) {
    let e = scenario_error(text);
    for f in fragments {
        assert!(e.contains(f), "expected `{f}` in: {e}");
    }
    assert!(e.starts_with("test.toml:"), "{e}");
}

#[test]
fn localizer_errors_name_the_key() {
    expect_error(
        &with_localizer("[[robots.localization]]\ntype = \"kalman\""),
        &["kalman", "mcl"],
    );
    expect_error(
        &with_localizer("[[robots.localization]]\ntype = \"mcl\"\nparticles = 10"),
        &["particles"],
    );
    expect_error(
        &with_localizer(
            "[[robots.localization]]\ntype = \"mcl\"\nmin_particles = 900\nmax_particles = 100",
        ),
        &["robots[0].localization[0].min_particles", "exceeds"],
    );
    expect_error(
        &with_localizer("[[robots.localization]]\ntype = \"mcl\"\nz_hit = 1.5"),
        &["z_hit", "[0, 1]"],
    );
    expect_error(
        &with_localizer("[[robots.localization]]\ntype = \"mcl\"\nkld_z = 2.3"),
        &["kld_z", "probability"],
    );
    expect_error(
        &with_localizer("[[robots.localization]]\ntype = \"mcl\"\ninit_sd = [0.1, 0.1, 0.1]"),
        &["init_sd", "init = \"pose\""],
    );
    expect_error(
        &with_localizer(
            "[[robots.localization]]\ntype = \"mcl\"\n[[robots.localization]]\ntype = \"mcl\"",
        ),
        &["two localizers named `mcl`"],
    );
    expect_error(
        &with_localizer(
            "[[robots.localization]]\ntype = \"mcl\"\ninit = \"pose\"\ninit_pose = [50.0, 5.0]",
        ),
        &["init_pose", "outside the map"],
    );
    // a localizer without the sensors it reads
    let text = format!(
        "{SQUARE_ROOM}\n[[robots]]\nname = \"r1\"\nstart = [5.0, 5.0, 0.0]\n\
         [[robots.localization]]\ntype = \"mcl\"\n"
    );
    expect_error(&text, &["robots[0].localization", "sensors.laser"]);
}
