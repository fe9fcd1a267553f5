//! Where the on-disk cache of map-derived structures ([`systems::core::cache`]) lives for the
//! `sim` commands, and `sim cache info` / `sim cache clear`.
//!
//! The commands use the cache unless `--no-cache` or `SIM_NO_CACHE=1` turns it off; its folder
//! is `$SIM_CACHE_DIR`, else the platform's cache folder (`~/.cache/sim/maps` on Linux). A program
//! using the library builds without a cache unless it asks for one
//! ([`crate::SimulationBuilder::cache`]).

use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use systems::core::cache::ENTRY_EXTENSION;
pub use systems::core::cache::{CacheStats, MapCache};

/// The cache every world of this process is built with, unless told otherwise.
static PROCESS: OnceLock<MapCache> = OnceLock::new();

/// Sets the cache of this process's worlds (the command line does, once, before any build);
/// false if it was already set.
pub fn set_process_cache(cache: MapCache) -> bool {
    PROCESS.set(cache).is_ok()
}

/// The cache of this process's worlds: the one set by [`set_process_cache`], else none.
pub fn process_cache() -> MapCache {
    PROCESS.get().cloned().unwrap_or_default()
}

/// The cache folder: `$SIM_CACHE_DIR` if set and not empty, else `sim/maps` in the platform's
/// cache folder (`sim` itself also holds the test tools of `tests/run.sh`); none if neither is
/// known.
pub fn default_dir() -> Option<PathBuf> {
    match std::env::var_os("SIM_CACHE_DIR") {
        Some(d) if !d.is_empty() => Some(PathBuf::from(d)),
        _ => directories::BaseDirs::new().map(|b| b.cache_dir().join("sim").join("maps")),
    }
}

/// Whether `SIM_NO_CACHE` turns the cache off (set, and neither empty nor `0`).
pub fn disabled_by_env() -> bool {
    std::env::var_os("SIM_NO_CACHE").is_some_and(|v| !v.is_empty() && v != "0")
}

/// The commands' cache: off with `no_cache` or `SIM_NO_CACHE`, else in [`default_dir`].
pub fn from_env(no_cache: bool) -> MapCache {
    match default_dir() {
        Some(dir) if !no_cache && !disabled_by_env() => MapCache::in_dir(dir),
        _ => MapCache::disabled(),
    }
}

/// `sim cache …`.
#[derive(clap::Subcommand, Clone, Debug)]
pub enum CacheCommand {
    /// Where the cache is, how many entries it holds and their size.
    Info,
    /// Removes every entry.
    Clear,
}

/// The entries in `dir` (none if it does not exist).
fn entries(dir: &Path) -> anyhow::Result<Vec<(PathBuf, u64)>> {
    let list = match std::fs::read_dir(dir) {
        Ok(l) => l,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => anyhow::bail!("cannot read the cache folder {}: {e}", dir.display()),
    };
    let mut out = Vec::new();
    for e in list.flatten() {
        let p = e.path();
        let ours = p.extension().is_some_and(|x| x == ENTRY_EXTENSION)
            || p.extension().is_some_and(|x| x == "tmp");
        if ours && e.file_type().is_ok_and(|t| t.is_file()) {
            out.push((p, e.metadata().map(|m| m.len()).unwrap_or(0)));
        }
    }
    out.sort();
    Ok(out)
}

/// `sim cache info` and `sim cache clear`, on the folder the commands use.
pub fn cache_command(which: &CacheCommand) -> anyhow::Result<()> {
    let Some(dir) = default_dir() else {
        anyhow::bail!("no cache folder: set SIM_CACHE_DIR");
    };
    match which {
        CacheCommand::Info => print!("{}", info(&dir)?),
        CacheCommand::Clear => {
            let (n, bytes) = clear(&dir)?;
            println!(
                "removed {n} entries ({}) from {}",
                megabytes(bytes),
                dir.display()
            );
        }
    }
    Ok(())
}

fn megabytes(bytes: u64) -> String {
    format!("{:.1} MB", bytes as f64 / 1e6)
}

/// What `sim cache info` prints for `dir`.
pub fn info(dir: &Path) -> anyhow::Result<String> {
    let list = entries(dir)?;
    let bytes: u64 = list.iter().map(|e| e.1).sum();
    let state = if disabled_by_env() {
        " (off: SIM_NO_CACHE is set)"
    } else {
        ""
    };
    Ok(format!(
        "cache folder: {}{state}\nentries: {}\nsize: {}\n",
        dir.display(),
        list.len(),
        megabytes(bytes)
    ))
}

/// Removes the entries of `dir` (and leftover temporary files): how many and their bytes.
pub fn clear(dir: &Path) -> anyhow::Result<(usize, u64)> {
    let list = entries(dir)?;
    let mut bytes = 0;
    for (p, b) in &list {
        std::fs::remove_file(p)
            .map_err(|e| anyhow::anyhow!("cannot remove {}: {e}", p.display()))?;
        bytes += b;
    }
    Ok((list.len(), bytes))
}

#[cfg(test)]
mod tests;
