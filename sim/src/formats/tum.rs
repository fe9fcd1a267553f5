//! Trajectories in the TUM format (`t x y z qx qy qz qw`, one pose per line), the format evo
//! reads: `evo_ape tum TRUTH EST --align_origin` and `evo_rpe tum TRUTH EST --delta 1
//! --delta_unit f` reproduce the summary's ATE and RPE from the files written here.

use std::fmt::Write as _;
use std::path::Path;
use systems::core::Pose2;
use systems::eval::{Sample, judged_samples};

/// The estimate/truth samples of one robot's localizers.
#[derive(Clone, Debug)]
pub struct RobotLocalization {
    pub robot: String,
    /// (localizer name, samples) in the order of the scenario.
    pub localizers: Vec<(String, Vec<Sample>)>,
}

/// One TUM line (planar pose: z = 0, rotation about z). Positions to 1e-9 m, so evo's figures
/// from the file agree with ours far below the 1e-6 m the checks ask for.
pub fn tum_line(t: f64, p: &Pose2) -> String {
    let (s, c) = (p.theta / 2.0).sin_cos();
    format!("{t:.6} {:.9} {:.9} 0 0 0 {s:.12} {c:.12}", p.x, p.y)
}

/// Which of a localizer's estimates a trajectory file holds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Estimates {
    /// From convergence on: the samples the summary's ATE and RPE judge.
    #[default]
    FromConvergence,
    /// Every estimate from the first, so a global localizer can be scored over the whole run.
    All,
}

/// Writes `DIR/<robot>/<localizer>.tum` (estimates) and `DIR/<robot>/<localizer>.truth.tum`
/// (ground truth at the same timestamps), over the samples `which` names. Returns the files
/// written.
pub fn write_trajectories(
    dir: &Path,
    robots: &[RobotLocalization],
    which: Estimates,
) -> anyhow::Result<Vec<std::path::PathBuf>> {
    let mut written = Vec::new();
    for r in robots {
        let rdir = dir.join(&r.robot);
        std::fs::create_dir_all(&rdir)
            .map_err(|e| anyhow::anyhow!("{}: cannot create: {e}", rdir.display()))?;
        for (name, samples) in &r.localizers {
            let kept = match which {
                Estimates::FromConvergence => judged_samples(samples),
                Estimates::All => samples,
            };
            let (mut est, mut truth) = (String::new(), String::new());
            for s in kept {
                let _ = writeln!(est, "{}", tum_line(s.t, &s.estimate));
                let _ = writeln!(truth, "{}", tum_line(s.t, &s.truth));
            }
            for (file, text) in [
                (rdir.join(format!("{name}.tum")), est),
                (rdir.join(format!("{name}.truth.tum")), truth),
            ] {
                std::fs::write(&file, text)
                    .map_err(|e| anyhow::anyhow!("{}: cannot write: {e}", file.display()))?;
                written.push(file);
            }
        }
    }
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn yaw_becomes_a_unit_quaternion_about_z() {
        let l = tum_line(1.5, &Pose2::new(1.0, -2.0, std::f64::consts::FRAC_PI_2));
        let v: Vec<f64> = l.split(' ').map(|x| x.parse().unwrap()).collect();
        assert_eq!(v.len(), 8);
        assert_eq!(&v[..4], &[1.5, 1.0, -2.0, 0.0]);
        assert!((v[6] - (0.5f64).sqrt()).abs() < 1e-9 && (v[7] - (0.5f64).sqrt()).abs() < 1e-9);
    }
}
