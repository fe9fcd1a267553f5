//! The code version that keys the on-disk cache of map-derived structures (`core::cache`): a
//! digest of this crate's source, the compiler's version and the target, so an entry written by
//! other code (an edited algorithm whose format constant was not bumped, another compiler) is
//! never read back.

use std::hash::Hasher;
use std::path::{Path, PathBuf};

fn main() {
    println!("cargo::rerun-if-changed=src");
    println!("cargo::rerun-if-changed=build.rs");
    let mut files = Vec::new();
    collect(Path::new("src"), &mut files);
    files.sort();
    // SipHash with fixed keys: the same digest for the same source on every build
    let mut h = std::hash::DefaultHasher::new();
    for f in &files {
        h.write(f.to_string_lossy().as_bytes());
        h.write(&std::fs::read(f).unwrap_or_default());
    }
    let rustc = std::env::var("RUSTC").unwrap_or_else(|_| "rustc".into());
    if let Ok(out) = std::process::Command::new(rustc).arg("-vV").output() {
        h.write(&out.stdout);
    }
    for var in ["TARGET", "CARGO_CFG_TARGET_FEATURE", "CARGO_PKG_VERSION"] {
        h.write(std::env::var(var).unwrap_or_default().as_bytes());
    }
    println!("cargo::rustc-env=SYSTEMS_CODE_DIGEST={:016x}", h.finish());
}

/// Every file under `dir`, depth first.
fn collect(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() {
            collect(&p, out);
        } else {
            out.push(p);
        }
    }
}
