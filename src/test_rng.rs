//! A seeded generator for the unit tests' random triangles and rays (Marsaglia's xorshift64, "Xorshift RNGs",
//! J. Stat. Softw. 8(14), 2003): the same sequence on every machine, no crate needed.

/// Uniform numbers in [−1, 1) from `seed` (not zero): 53 bits of each xorshift64 step.
pub fn uniform(mut seed: u64) -> impl FnMut() -> f64 {
    move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }
}
