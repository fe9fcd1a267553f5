//! Value parsers and limits every command's options share: thread counts, durations, and parsing
//! one command's arguments as the binary does (for tests and tools).

/// Parses the arguments of one `sim` subcommand as the binary does (`args` without the
/// subcommand's name), for tests and tools.
pub fn parse_args<A: clap::Args>(args: &[&str]) -> Result<A, clap::Error> {
    #[derive(clap::Parser)]
    struct Wrap<A: clap::Args> {
        #[command(flatten)]
        args: A,
    }
    <Wrap<A> as clap::Parser>::try_parse_from(std::iter::once("sim").chain(args.iter().copied()))
        .map(|w| w.args)
}

/// `--duration`: a positive number of seconds.
pub fn check_duration(d: f64) -> anyhow::Result<f64> {
    if !(d.is_finite() && d > 0.0) {
        anyhow::bail!("--duration: expected a positive number of seconds, got {d}");
    }
    Ok(d)
}

/// The value parser of every `--threads`: 0 (one per core) or 1 to
/// [`systems::core::pool::MAX_THREADS`], checked before any thread starts.
pub fn parse_threads(s: &str) -> Result<usize, String> {
    use systems::core::pool::MAX_THREADS;
    let bad = || format!("expected 0 (one per core) or a thread count from 1 to {MAX_THREADS}");
    let n: usize = s.trim().parse().map_err(|_| bad())?;
    if n > MAX_THREADS {
        return Err(bad());
    }
    Ok(n)
}
