//! Where the source tree is: the bundled assets, test fixtures and check scripts are found
//! from it.
//!
//! Every crate of the workspace lies one level below the repository's root. Cargo tells a
//! process it runs (`cargo run`, `cargo test`, `cargo bench`, `cargo nextest`) the directory
//! of the crate being run in `CARGO_MANIFEST_DIR`; that is read at run time, because a build
//! cache shared between clones of the repository (CI keeps one outside the clone) reuses a
//! binary compiled in another clone whenever the crate's sources are the same, and the path
//! compiled into it may be gone. Outside cargo, the path this crate was compiled in is used.

use std::path::PathBuf;

/// The repository's root directory.
pub fn source_root() -> PathBuf {
    let runtime = std::env::var_os("CARGO_MANIFEST_DIR").map(PathBuf::from);
    let crate_dir = runtime
        .filter(|d| d.join("..").join("Cargo.toml").is_file())
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")));
    crate_dir.join("..")
}

/// `rel` (a path relative to the repository's root, e.g. `assets/maps/hospital/hospital.yaml`).
pub fn source_path(rel: &str) -> PathBuf {
    source_root().join(rel)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_root_holds_the_workspace_and_its_assets() {
        let root = source_root();
        assert!(root.join("Cargo.toml").is_file(), "{}", root.display());
        assert!(source_path("assets/maps/hospital/hospital.yaml").is_file());
    }
}
