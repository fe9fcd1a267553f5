//! Per-entity random streams. Every random draw in the simulator comes from a stream seeded from
//! (scenario seed, entity name, stream name), so adding a robot or a sensor never changes the
//! numbers another one sees, and results do not depend on iteration or thread order.

use rand::SeedableRng;

/// The simulator's PRNG: PCG-64 MCG (O'Neill 2014), portable and reproducible across platforms.
pub type SimRng = rand_pcg::Pcg64Mcg;

/// 64-bit FNV-1a over the bytes, then a SplitMix64 finaliser; stable across Rust versions and
/// platforms (unlike `std::hash`).
fn mix(mut h: u64, bytes: &[u8]) -> u64 {
    for &b in bytes {
        h ^= b as u64;
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    // a separator so ("ab","c") and ("a","bc") differ
    h ^= 0xff;
    h.wrapping_mul(0x0000_0100_0000_01b3)
}

fn splitmix64(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// The seed of the stream `stream` of entity `entity` in a run seeded with `seed`.
pub fn stream_seed(seed: u64, entity: &str, stream: &str) -> u64 {
    let mut h = 0xcbf2_9ce4_8422_2325u64;
    h = mix(h, &seed.to_le_bytes());
    h = mix(h, entity.as_bytes());
    h = mix(h, stream.as_bytes());
    splitmix64(h)
}

/// A fresh generator for (seed, entity, stream).
pub fn stream_rng(seed: u64, entity: &str, stream: &str) -> SimRng {
    SimRng::seed_from_u64(stream_seed(seed, entity, stream))
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::RngExt;

    const PINNED: u64 = 1_488_049_740_616_935_655;

    #[test]
    fn streams_are_reproducible_and_distinct() {
        let a: Vec<u64> = (0..4)
            .map(|_| 0)
            .scan(stream_rng(7, "r1", "laser"), |r, _| Some(r.random()))
            .collect();
        let b: Vec<u64> = (0..4)
            .map(|_| 0)
            .scan(stream_rng(7, "r1", "laser"), |r, _| Some(r.random()))
            .collect();
        assert_eq!(a, b);
        assert_ne!(stream_seed(7, "r1", "laser"), stream_seed(7, "r2", "laser"));
        assert_ne!(
            stream_seed(7, "r1", "laser"),
            stream_seed(7, "r1", "encoder")
        );
        assert_ne!(stream_seed(7, "r1", "laser"), stream_seed(8, "r1", "laser"));
        assert_ne!(stream_seed(7, "ab", "c"), stream_seed(7, "a", "bc"));
    }

    #[test]
    fn stream_seed_is_pinned() {
        // Changing the derivation silently changes every recorded result: pin it.
        assert_eq!(stream_seed(42, "r1", "laser"), PINNED);
    }
}
