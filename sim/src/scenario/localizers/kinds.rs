//! Resolving a localizer table into the configuration of its type (MCL, Markov grid, DE
//! filter, DE-MC, DE odometry), defaults filled in from each type's `Default`.

use super::fields::Fields;
use super::*;

pub(super) fn resolve_mcl(
    c: &Checker,
    p: &KeyPath,
    l: &LocalizerFile,
    start: &Pose2,
    pose: &dyn Fn(&KeyPath, &PointOrPlace) -> R<Pose2>,
) -> R<MclConfig> {
    let d = MclConfig::default();
    let f = Fields { c, p, l };
    let max_particles = f.count(
        "max_particles",
        l.max_particles,
        d.max_particles,
        1,
        10_000_000,
    )?;
    let min_particles = f.count(
        "min_particles",
        l.min_particles,
        d.min_particles.min(max_particles),
        1,
        10_000_000,
    )?;
    if min_particles > max_particles {
        return c.err(
            &p.key("min_particles"),
            format!("min_particles ({min_particles}) exceeds max_particles ({max_particles})"),
        );
    }
    let kld_err = match l.kld_err {
        Some(v) => c.range(&p.key("kld_err"), v, Some(0.0), Some(1.0), true)?,
        None => d.kld_err,
    };
    let kld_z = match l.kld_z {
        Some(v) => {
            if !(v > 0.0 && v < 1.0) {
                return c.err(
                    &p.key("kld_z"),
                    format!("expected a probability in (0, 1) (AMCL's default is 0.99), got {v}"),
                );
            }
            v
        }
        None => d.kld_z,
    };
    Ok(MclConfig {
        min_particles,
        max_particles,
        kld: l.kld.unwrap_or(d.kld),
        kld_err,
        kld_z,
        update_min_d: f.nonneg("update_min_d", l.update_min_d, d.update_min_d)?,
        update_min_a: f.nonneg("update_min_a", l.update_min_a, d.update_min_a)?,
        resample_interval: match l.resample_interval {
            Some(0) => 0,
            _ => f.count(
                "resample_interval",
                l.resample_interval,
                d.resample_interval as usize,
                1,
                1_000_000,
            )? as u64,
        },
        max_beams: f.max_beams(d.max_beams)?,
        model: match l.model {
            Some(LaserModelType::Beam) => LaserModel::Beam,
            Some(LaserModelType::LikelihoodField) | None => LaserModel::LikelihoodField,
        },
        laser: f.laser(LaserModelParams::default())?,
        motion: f.motion(d.motion)?,
        recovery_alpha_slow: f.prob(
            "recovery_alpha_slow",
            l.recovery_alpha_slow,
            d.recovery_alpha_slow,
        )?,
        recovery_alpha_fast: f.prob(
            "recovery_alpha_fast",
            l.recovery_alpha_fast,
            d.recovery_alpha_fast,
        )?,
        recovery_ratio: match l.recovery_ratio {
            Some(v) => c.range(&p.key("recovery_ratio"), v, Some(0.0), Some(1.0), true)?,
            None => d.recovery_ratio,
        },
        injection_candidates: match l.injection_candidates {
            Some(0) => 0,
            _ => f.count(
                "injection_candidates",
                l.injection_candidates,
                d.injection_candidates,
                1,
                10_000_000,
            )?,
        },
        challenge_every: match l.challenge_every {
            Some(0) => 0,
            _ => f.count(
                "challenge_every",
                l.challenge_every,
                d.challenge_every as usize,
                1,
                1_000_000,
            )? as u64,
        },
        challenge_ratio: match l.challenge_ratio {
            Some(v) => c.range(&p.key("challenge_ratio"), v, Some(1.0), None, false)?,
            None => d.challenge_ratio,
        },
        challenge_fraction: f.prob(
            "challenge_fraction",
            l.challenge_fraction,
            d.challenge_fraction,
        )?,
        init: f.init(start, pose)?,
        bins: d.bins,
    })
}

pub(super) fn resolve_markov_grid(
    c: &Checker,
    p: &KeyPath,
    l: &LocalizerFile,
    start: &Pose2,
    pose: &dyn Fn(&KeyPath, &PointOrPlace) -> R<Pose2>,
) -> R<MarkovGridConfig> {
    let d = MarkovGridConfig::default();
    let f = Fields { c, p, l };
    let resolution = match l.resolution {
        Some(v) => c.range(&p.key("resolution"), v, Some(0.01), Some(10.0), false)?,
        None => d.resolution,
    };
    Ok(MarkovGridConfig {
        resolution,
        angular_bins: f.count("angular_bins", l.angular_bins, d.angular_bins, 4, 720)?,
        max_beams: f.max_beams(d.max_beams)?,
        laser: f.laser(d.laser)?,
        motion: f.motion(d.motion)?,
        likelihood_exponent: match l.likelihood_exponent {
            Some(v) => c.range(&p.key("likelihood_exponent"), v, Some(0.0), Some(1.0), true)?,
            None => d.likelihood_exponent,
        },
        uniform_mix: f.prob("uniform_mix", l.uniform_mix, d.uniform_mix)?,
        selective_threshold: f.prob(
            "selective_threshold",
            l.selective_threshold,
            d.selective_threshold,
        )?,
        update_min_d: f.nonneg("update_min_d", l.update_min_d, d.update_min_d)?,
        update_min_a: f.nonneg("update_min_a", l.update_min_a, d.update_min_a)?,
        init: f.init(start, pose)?,
    })
}

pub(super) fn resolve_de_filter(
    c: &Checker,
    p: &KeyPath,
    l: &LocalizerFile,
    start: &Pose2,
    pose: &dyn Fn(&KeyPath, &PointOrPlace) -> R<Pose2>,
) -> R<DeFilterConfig> {
    let d = DeFilterConfig::default();
    let f = Fields { c, p, l };
    let population = f.count("population", l.population, d.population, 4, 1_000_000)?;
    let min_population = f.count(
        "min_population",
        l.min_population,
        d.min_population.min(population),
        4,
        1_000_000,
    )?;
    if min_population > population {
        return c.err(
            &p.key("min_population"),
            format!("min_population ({min_population}) exceeds population ({population})"),
        );
    }
    Ok(DeFilterConfig {
        population,
        min_population,
        generations: f.count("generations", l.generations, d.generations, 0, 10_000)?,
        tracking_generations: f.count(
            "tracking_generations",
            l.tracking_generations,
            d.tracking_generations,
            0,
            10_000,
        )?,
        best_weight: f.prob("best_weight", l.best_weight, d.best_weight)?,
        f: f.positive("f", l.f, d.f)?,
        f_growth: match l.f_growth {
            Some(v) => c.range(&p.key("f_growth"), v, Some(1.0), Some(10.0), false)?,
            None => d.f_growth,
        },
        f_max: f.positive("f_max", l.f_max, d.f_max)?,
        cr: f.prob("cr", l.cr, d.cr)?,
        rejection: f.prob("rejection", l.rejection, d.rejection)?,
        discard: match l.discard {
            Some(v) => c.range(&p.key("discard"), v, Some(0.0), Some(0.9), false)?,
            None => d.discard,
        },
        metric: f.metric(),
        max_beams: f.max_beams(d.max_beams)?,
        motion: f.motion(d.motion)?,
        update_min_d: f.nonneg("update_min_d", l.update_min_d, d.update_min_d)?,
        update_min_a: f.nonneg("update_min_a", l.update_min_a, d.update_min_a)?,
        init: f.init(start, pose)?,
        converge_cost: f.positive("converge_cost", l.converge_cost, d.converge_cost)?,
        converge_updates: l.converge_updates.unwrap_or(d.converge_updates).max(1),
        refine_rounds: f.count("refine_rounds", l.refine_rounds, d.refine_rounds, 0, 20)?,
        refine_samples: f.count(
            "refine_samples",
            l.refine_samples,
            d.refine_samples,
            1,
            10_000,
        )?,
        refine_sd: d.refine_sd,
        injection_candidates: f.injection_candidates(d.injection_candidates)?,
    })
}

pub(super) fn resolve_de_mc(
    c: &Checker,
    p: &KeyPath,
    l: &LocalizerFile,
    start: &Pose2,
    pose: &dyn Fn(&KeyPath, &PointOrPlace) -> R<Pose2>,
) -> R<DeMcConfig> {
    let d = DeMcConfig::default();
    let f = Fields { c, p, l };
    Ok(DeMcConfig {
        population: f.count("population", l.population, d.population, 4, 1_000_000)?,
        iterations: f.count("iterations", l.iterations, d.iterations, 0, 10_000)?,
        tracking_iterations: f.count(
            "tracking_iterations",
            l.tracking_iterations,
            d.tracking_iterations,
            0,
            10_000,
        )?,
        f: f.positive("f", l.f, d.f)?,
        noise_sd: f.triple("noise_sd", l.noise_sd, d.noise_sd, 10.0)?,
        temperature: f.positive("temperature", l.temperature, d.temperature)?,
        metric: f.metric(),
        max_beams: f.max_beams(d.max_beams)?,
        motion: f.motion(d.motion)?,
        update_min_d: f.nonneg("update_min_d", l.update_min_d, d.update_min_d)?,
        update_min_a: f.nonneg("update_min_a", l.update_min_a, d.update_min_a)?,
        init: f.init(start, pose)?,
        converge_cost: f.positive("converge_cost", l.converge_cost, d.converge_cost)?,
        converge_updates: l.converge_updates.unwrap_or(d.converge_updates).max(1),
        refine_rounds: f.count("refine_rounds", l.refine_rounds, d.refine_rounds, 0, 20)?,
        refine_samples: f.count(
            "refine_samples",
            l.refine_samples,
            d.refine_samples,
            1,
            10_000,
        )?,
        refine_sd: d.refine_sd,
        injection_candidates: f.injection_candidates(d.injection_candidates)?,
    })
}

pub(super) fn resolve_de_odometry(
    c: &Checker,
    p: &KeyPath,
    l: &LocalizerFile,
    start: &Pose2,
    pose: &dyn Fn(&KeyPath, &PointOrPlace) -> R<Pose2>,
) -> R<DeOdometryConfig> {
    let d = DeOdometryConfig::default();
    let f = Fields { c, p, l };
    if l.init == Some(InitType::Global) {
        return c.err(
            &p.key("init"),
            "de_odometry integrates scan matches from a known pose: use `init = \"pose\"` \
             (the default) with `init_pose`, or leave both out to start at the robot's start",
        );
    }
    let start = match &l.init_pose {
        Some(v) => pose(&p.key("init_pose"), v)?,
        None => *start,
    };
    let mut matcher = match l.matcher {
        Some(MatcherType::Improved) | None => MatchConfig::improved(),
        Some(MatcherType::Correlation) => MatchConfig::thesis(ThesisFitness::Correlation, {
            let mut de = DeParams::thesis_final_experiment();
            de.generations = 1000;
            de.parallel = false;
            de
        }),
        Some(MatcherType::Euclidean) => MatchConfig::thesis(ThesisFitness::EuclideanField, {
            let mut de = DeParams::thesis_final_experiment();
            de.generations = 1000;
            de.parallel = false;
            de
        }),
    };
    matcher.window = SearchWindow {
        max_xy: f.positive("window_xy", l.window_xy, d.matcher.window.max_xy)?,
        max_theta: match l.window_theta {
            Some(v) => c.range(&p.key("window_theta"), v, Some(0.0), Some(PI), true)?,
            None => d.matcher.window.max_theta,
        },
    };
    Ok(DeOdometryConfig {
        matcher,
        max_beams: f.max_beams(d.max_beams)?,
        update_min_d: f.nonneg("update_min_d", l.update_min_d, d.update_min_d)?,
        update_min_a: f.nonneg("update_min_a", l.update_min_a, d.update_min_a)?,
        min_inliers: f.prob("min_inliers", l.min_inliers, d.min_inliers)?,
        step_sd: f.triple("step_sd", l.step_sd, d.step_sd, 10.0)?,
        start,
    })
}

/// Validates one robot's list. `pose` resolves coordinates or place names; `start` is the
/// robot's start pose.
pub(in crate::scenario) fn resolve_localizers(
    c: &Checker,
    p: &KeyPath,
    list: &[LocalizerFile],
    start: &Pose2,
    pose: &dyn Fn(&KeyPath, &PointOrPlace) -> R<Pose2>,
) -> R<Vec<LocalizerConfig>> {
    let mut out: Vec<LocalizerConfig> = Vec::new();
    for (i, l) in list.iter().enumerate() {
        let lp = p.index(i);
        let name = match &l.name {
            Some(n) => {
                if !crate::scenario::check::check_name(n) {
                    return c.err(
                        &lp.key("name"),
                        format!("expected letters, digits, `_` or `-`, got `{n}`"),
                    );
                }
                n.clone()
            }
            None => l.kind.name().to_string(),
        };
        if let Some(key) = l.given().into_iter().find(|k| !l.kind.keys().contains(k)) {
            return c.err(
                &lp.key(key),
                format!(
                    "`{key}` does not apply to a `{}` localizer (its keys: {})",
                    l.kind.name(),
                    l.kind.keys().join(", ")
                ),
            );
        }
        if out.iter().any(|o| o.name == name) {
            let key = if l.name.is_some() { "name" } else { "type" };
            return c.err(
                &lp.key(key),
                format!("two localizers named `{name}` on one robot: give each a `name`"),
            );
        }
        let kind = match l.kind {
            LocalizerType::Mcl => LocalizerKind::Mcl(resolve_mcl(c, &lp, l, start, pose)?),
            LocalizerType::MarkovGrid => {
                LocalizerKind::MarkovGrid(resolve_markov_grid(c, &lp, l, start, pose)?)
            }
            LocalizerType::DeFilter => {
                LocalizerKind::DeFilter(resolve_de_filter(c, &lp, l, start, pose)?)
            }
            LocalizerType::DeMc => LocalizerKind::DeMc(resolve_de_mc(c, &lp, l, start, pose)?),
            LocalizerType::DeOdometry => {
                LocalizerKind::DeOdometry(resolve_de_odometry(c, &lp, l, start, pose)?)
            }
        };
        out.push(LocalizerConfig { name, kind });
    }
    Ok(out)
}
