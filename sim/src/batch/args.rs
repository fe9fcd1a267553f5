//! `sim batch` arguments and the parsing of their values: the seed range `A..B`, the shard `k/n`,
//! `key=value` overrides and the comma-separated value lists of `--sweep` and `--zip`.

use clap::builder::RangedU64ValueParser;
use std::path::PathBuf;

/// The most runs `--jobs` may ask for at the same time.
pub const MAX_WORKERS: u64 = 1024;

// the field docs are the --help text: <placeholders> are not HTML
#[allow(rustdoc::invalid_html_tags)]
#[derive(clap::Args, Clone, Debug)]
pub struct BatchArgs {
    /// A scenario file or the name of a bundled scenario.
    pub scenario: String,
    /// Seeds to run, `A..B` (B excluded, as in Rust): `0..20` runs seeds 0 to 19.
    #[arg(long)]
    pub seeds: String,
    /// Simulate this many seconds per run (as `sim run --duration`: applied after loading, so
    /// events later than that are simply not reached).
    #[arg(long, allow_negative_numbers = true)]
    pub duration: Option<f64>,
    /// Override a scenario key in every run: `key=value`, a dotted path into the scenario
    /// (`record.rate=5`, `robots.0.sensors.laser.rate=5`, `robots[name=r1].behaviour.speed=0.5`);
    /// the value is TOML (number, bool, string, array, inline table) or else a bare string.
    /// Repeatable.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub sets: Vec<String>,
    /// Run each value of a key: `key=v1,v2,...` (commas inside [..], {..} and quotes do not
    /// split). Several sweeps form the Cartesian product; each combination is a parameter set.
    #[arg(long = "sweep", value_name = "KEY=V1,V2,...")]
    pub sweeps: Vec<String>,
    /// Like --sweep, but all --zip keys advance together (same number of values each): the i-th
    /// values of every --zip form one axis point, combined with the sweeps.
    #[arg(long = "zip", value_name = "KEY=V1,V2,...")]
    pub zips: Vec<String>,
    /// Runs at the same time (0 = one per core; default: one per core; at most 1024, and never
    /// more than the batch has runs).
    #[arg(long, default_value_t = 0,
          value_parser = RangedU64ValueParser::<usize>::new().range(0..=MAX_WORKERS))]
    pub jobs: usize,
    /// Kernel threads of each run (0 = one per core). Results do not depend on it.
    #[arg(long, default_value_t = 1, value_parser = crate::options::parse_threads)]
    pub threads: usize,
    /// Output folder (default: batch-<scenario>-<A>-<B>, plus -shard<k>of<n> with --shard).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Run only every n-th job starting at k (k from 0); jobs are numbered parameter sets
    /// major, seeds minor. For Slurm job arrays and Kubernetes indexed jobs.
    #[arg(long, value_name = "K/N")]
    pub shard: Option<String>,
    /// Run only the jobs the output folder has no successful row for (a batch that was
    /// stopped or killed, runs that failed), with the arguments it was started with; the
    /// folder's files then hold every run.
    #[arg(long)]
    pub resume: bool,
    /// Also write one Rerun recording per run into the output folder
    /// (`set<S>-seed<N>.rrd`).
    #[arg(long)]
    pub rrd: bool,
    /// Also write report.html into the output folder: a self-contained page with the
    /// parameter sets, the aggregate table and a box plot of every metric per set.
    #[arg(long)]
    pub report: bool,
    /// No progress bar and no table, only errors.
    #[arg(long)]
    pub quiet: bool,
}

/// `A..B` (B excluded): the seeds A, A+1, …, B−1.
pub fn parse_seeds(s: &str) -> anyhow::Result<std::ops::Range<u64>> {
    let bad = |why: &str| anyhow::anyhow!("--seeds {s}: {why}");
    let (a, b) = s
        .split_once("..")
        .ok_or_else(|| bad("expected a range A..B (B excluded), e.g. 0..20"))?;
    if b.starts_with('=') {
        return Err(bad("expected A..B (B excluded); `..=` is not supported"));
    }
    let num = |v: &str, which: &str| {
        v.trim().parse::<u64>().map_err(|_| {
            bad(&format!(
                "{which} `{v}` is not a non-negative integer (expected A..B, e.g. 0..20)"
            ))
        })
    };
    let (a, b) = (num(a, "start")?, num(b, "end")?);
    if a >= b {
        return Err(bad(&format!(
            "the range is empty: the start must be below the end (B is excluded; {a}..{} runs seed {a} only)",
            a + 1
        )));
    }
    Ok(a..b)
}

/// `k/n` with k < n: this process runs jobs k, k+n, k+2n, …
pub fn parse_shard(s: &str) -> anyhow::Result<(usize, usize)> {
    let bad = |why: String| anyhow::anyhow!("--shard {s}: {why}");
    let (k, n) = s
        .split_once('/')
        .ok_or_else(|| bad("expected K/N, e.g. 0/4 (shard K of N, K from 0)".into()))?;
    let num = |v: &str| {
        v.trim().parse::<usize>().map_err(|_| {
            bad(format!(
                "`{v}` is not a non-negative integer (expected K/N)"
            ))
        })
    };
    let (k, n) = (num(k)?, num(n)?);
    if n == 0 {
        return Err(bad("N must be at least 1".into()));
    }
    if k >= n {
        return Err(bad(format!(
            "K must be below N (shards are numbered 0 to {}), got K = {k}",
            n - 1
        )));
    }
    Ok((k, n))
}

/// Splits `key=value` at the first `=` that is not inside a `[..]` selector.
pub fn split_key_value<'a>(flag: &str, s: &'a str) -> anyhow::Result<(&'a str, &'a str)> {
    let mut depth = 0i32;
    for (i, c) in s.char_indices() {
        match c {
            '[' => depth += 1,
            ']' => depth -= 1,
            '=' if depth == 0 => {
                let (k, v) = (s[..i].trim(), s[i + 1..].trim());
                if k.is_empty() {
                    anyhow::bail!("{flag} {s}: the key before `=` is empty");
                }
                return Ok((k, v));
            }
            _ => {}
        }
    }
    anyhow::bail!("{flag} {s}: expected KEY=VALUE (e.g. duration=30), found no `=`")
}

/// Splits a value list at the commas outside brackets, braces and quotes:
/// `[1,2],[3,4]` → `[1,2]`, `[3,4]`. Errors name `flag` and the whole argument `arg`
/// (`KEY=V1,V2,...`) the list `s` comes from.
pub fn split_values(flag: &str, arg: &str, s: &str) -> anyhow::Result<Vec<String>> {
    let mut out = Vec::new();
    let mut cur = String::new();
    let mut depth = 0i32;
    let mut quote: Option<char> = None;
    for c in s.chars() {
        match (quote, c) {
            (Some(q), c) if c == q => quote = None,
            (Some(_), _) => {}
            (None, '"' | '\'') => quote = Some(c),
            (None, '[' | '{') => depth += 1,
            (None, ']' | '}') => depth -= 1,
            (None, ',') if depth == 0 => {
                out.push(std::mem::take(&mut cur).trim().to_string());
                continue;
            }
            _ => {}
        }
        cur.push(c);
    }
    if quote.is_some() || depth != 0 {
        anyhow::bail!("{flag} {arg}: unbalanced quotes or brackets in the value list");
    }
    out.push(cur.trim().to_string());
    if let Some(i) = out.iter().position(String::is_empty) {
        anyhow::bail!(
            "{flag} {arg}: value {} of the list is empty (expected V1,V2,...)",
            i + 1
        );
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn seeds() {
        assert_eq!(parse_seeds("0..3").unwrap(), 0..3);
        assert_eq!(parse_seeds("5..6").unwrap(), 5..6);
        for (bad, want) in [
            ("3", "expected a range A..B"),
            ("3..3", "the range is empty"),
            ("4..2", "the range is empty"),
            ("a..3", "start `a` is not a non-negative integer"),
            ("0..x", "end `x`"),
            ("-1..3", "start `-1`"),
            ("0..=3", "`..=` is not supported"),
        ] {
            let e = parse_seeds(bad).unwrap_err().to_string();
            assert!(e.contains(want), "{bad}: {e}");
            assert!(e.starts_with(&format!("--seeds {bad}:")), "{e}");
        }
    }

    #[test]
    fn shards() {
        assert_eq!(parse_shard("0/2").unwrap(), (0, 2));
        assert_eq!(parse_shard("3/4").unwrap(), (3, 4));
        for (bad, want) in [
            ("2/2", "K must be below N"),
            ("1/0", "N must be at least 1"),
            ("1", "expected K/N"),
            ("a/2", "`a` is not"),
        ] {
            let e = parse_shard(bad).unwrap_err().to_string();
            assert!(e.contains(want), "{bad}: {e}");
        }
    }

    #[test]
    fn key_values_and_lists() {
        assert_eq!(
            split_key_value("--set", "robots[name=r1].speed=0.5").unwrap(),
            ("robots[name=r1].speed", "0.5")
        );
        assert_eq!(split_key_value("--set", "a = b=c").unwrap(), ("a", "b=c"));
        let e = split_key_value("--set", "duration")
            .unwrap_err()
            .to_string();
        assert!(e.contains("expected KEY=VALUE"), "{e}");
        assert_eq!(
            split_values("--sweep", "k=…", "[1,2], [3,4],'a,b',{x=1,y=2}").unwrap(),
            ["[1,2]", "[3,4]", "'a,b'", "{x=1,y=2}"]
        );
        assert!(split_values("--sweep", "k=1,,2", "1,,2").is_err());
        assert!(split_values("--sweep", "k=[1,2", "[1,2").is_err());
        // the message names the key, whichever value is empty
        for (arg, list, i) in [("k=", "", 1), ("k=,", ",", 1), ("k=0.5,", "0.5,", 2)] {
            let e = split_values("--zip", arg, list).unwrap_err().to_string();
            assert_eq!(
                e,
                format!("--zip {arg}: value {i} of the list is empty (expected V1,V2,...)")
            );
        }
    }
}
