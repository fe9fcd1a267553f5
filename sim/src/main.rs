//! `sim`: the command line of the simulator (the commands are in [`sim::cli`]).

use clap::Parser;
use sim::cli::{Cli, dispatch};
use sim::run::interrupt::{EXIT_CODE, Interrupted};
use std::process::ExitCode;

fn main() -> ExitCode {
    restore_sigpipe();
    sim::run::interrupt::ignore_file_size_signal();
    let cli = Cli::parse();
    sim::cache::set_process_cache(sim::cache::from_env(cli.no_cache));
    match dispatch(cli.command) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) if e.is::<Interrupted>() => {
            eprintln!("{e}");
            ExitCode::from(EXIT_CODE)
        }
        Err(e) => {
            eprintln!("error: {e:#}");
            if e.is::<sim::batch::RunsFailed>() {
                ExitCode::from(2)
            } else {
                ExitCode::FAILURE
            }
        }
    }
}

/// Ends quietly when whoever reads standard output goes away (`sim bench swarm --json | head -2`),
/// as Unix tools do: Rust ignores SIGPIPE, so the next write to the closed pipe panicked.
fn restore_sigpipe() {
    #[cfg(unix)]
    // SAFETY: the default disposition of a signal, set before any other thread exists
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}
