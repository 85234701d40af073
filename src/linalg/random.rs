//! SplitMix64 (Steele, Lea & Flood 2014): the deterministic pseudo-random numbers of the
//! eigensolver's start vector and the POD's sketch — the same numbers on every run and machine.

/// The SplitMix64 increment (the golden ratio in 64 bits), also the state of seed 0.
const GAMMA: u64 = 0x9E37_79B9_7F4A_7C15;

/// A SplitMix64 generator.
pub(crate) struct SplitMix64 {
    state: u64,
}

impl SplitMix64 {
    /// The generator of `seed` (state `GAMMA ^ seed`).
    pub(crate) fn new(seed: u64) -> SplitMix64 {
        SplitMix64 {
            state: GAMMA ^ seed,
        }
    }

    /// The next 64 random bits.
    pub(crate) fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(GAMMA);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// The next number in [−1, 1): the top 53 bits of [`SplitMix64::next_u64`] over 2⁵², minus 1.
    pub(crate) fn next_signed(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }
}
