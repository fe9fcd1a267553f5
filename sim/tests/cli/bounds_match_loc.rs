//! Absurd sizes given to `sim match`, `sim experiment de-match`, `sim bench de-match`,
//! `sim bench mcl` and `sim bench markov-grid` end with a clear message and a non-zero exit
//! before anything is allocated, run or printed (no abort, no endless run, no silent clamp).

use crate::{expect_failure, sim};

/// `sim match` on a file that is never read: the options are checked first.
fn match_args<'a>(extra: &[&'a str]) -> Vec<&'a str> {
    let mut args = vec![
        "match",
        "never-read.csv",
        "--reference",
        "0",
        "--current",
        "1",
    ];
    args.extend(extra);
    args
}

#[test]
fn match_refuses_a_population_or_generations_beyond_the_limit() {
    let dir = tempfile::tempdir().unwrap();
    for pop in ["100001", "4294967296"] {
        expect_failure(
            &match_args(&["--fitness", "euclidean", "--pop", pop]),
            dir.path(),
            &["--pop", pop, "100000"],
        );
    }
    for gens in ["1000001", "4294967296"] {
        expect_failure(
            &match_args(&["--fitness", "euclidean", "--gens", gens]),
            dir.path(),
            &["--gens", gens, "1000000"],
        );
    }
}

#[test]
fn match_refuses_a_window_beyond_100_m() {
    let dir = tempfile::tempdir().unwrap();
    for max_xy in ["100.5", "1e4", "1e5", "1e9", "inf"] {
        expect_failure(
            &match_args(&["--max-xy", max_xy]),
            dir.path(),
            &["--max-xy: expected a positive distance", "at most 100"],
        );
    }
}

#[test]
fn match_refuses_a_mutation_constant_above_2() {
    let dir = tempfile::tempdir().unwrap();
    for f in ["2.5", "1e12", "inf"] {
        expect_failure(
            &match_args(&["--fitness", "correlation", "-F", f]),
            dir.path(),
            &["-F:", "F must be in (0, 2]"],
        );
    }
}

#[test]
fn match_refuses_a_time_limit_too_long_for_a_duration() {
    let dir = tempfile::tempdir().unwrap();
    expect_failure(
        &match_args(&["--fitness", "correlation", "--time", "1e300"]),
        dir.path(),
        &["--time: 1e300 seconds is too long"],
    );
}

#[test]
fn de_match_refuses_too_many_pairs_before_capturing() {
    let dir = tempfile::tempdir().unwrap();
    for args in [
        &["bench", "de-match", "--pairs", "4294967296"][..],
        &["bench", "de-match", "--pairs", "0"],
        &["experiment", "de-match", "--pairs", "4294967296"],
        &["experiment", "de-match", "--pairs", "10001"],
    ] {
        expect_failure(args, dir.path(), &["--pairs: expected 1 to 10000 pairs"]);
    }
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
