//! What the processor can do, detected at run time: the kernels with an AVX2 twin (the ray
//! streams, the camera's row rendering) pick it with this.

/// Whether the CPU supports AVX2.
#[cfg(target_arch = "x86_64")]
pub fn has_avx2() -> bool {
    std::arch::is_x86_feature_detected!("avx2")
}

/// Whether the CPU supports AVX2 (never, off x86-64).
#[cfg(not(target_arch = "x86_64"))]
pub fn has_avx2() -> bool {
    false
}
