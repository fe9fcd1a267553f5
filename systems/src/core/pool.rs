//! The per-run rayon pool that parallel kernels (ray casting, particles, DE populations) run on.
//! Its size comes from `--threads`; results never depend on it (fixed chunking, ordered output).

use bevy_ecs::prelude::Resource;
use std::sync::Arc;

#[derive(Resource, Clone)]
pub struct KernelPool(pub Arc<rayon::ThreadPool>);

impl KernelPool {
    /// A pool with `threads` workers (0 = one per core).
    pub fn new(threads: usize) -> Result<Self, rayon::ThreadPoolBuildError> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .thread_name(|i| format!("sim-kernel-{i}"))
            .build()?;
        Ok(KernelPool(Arc::new(pool)))
    }

    pub fn threads(&self) -> usize {
        self.0.current_num_threads()
    }

    pub fn install<R: Send>(&self, f: impl FnOnce() -> R + Send) -> R {
        self.0.install(f)
    }
}
