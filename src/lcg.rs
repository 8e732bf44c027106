//! A reproducible pseudo-random sequence for the unit tests: Knuth's MMIX linear
//! congruential generator,
//!
//! `s_{k+1} = 6364136223846793005 s_k + 1442695040888963407  (mod 2⁶⁴)`,
//!
//! read as `u_k = ⌊s_k / 2¹¹⌋ / 2⁵³ ∈ [0, 1)` (the state's top 53 bits, exactly representable).
//! Tests that compare two computations bit for bit need the same inputs on every machine and
//! run, which a fixed seed gives.

/// The generator's state.
pub(crate) struct Lcg(u64);

impl Lcg {
    /// A generator starting from `seed` (the first number is that of the next state).
    pub(crate) fn new(seed: u64) -> Self {
        Self(seed)
    }

    /// The next state `s_{k+1}`.
    pub(crate) fn next_u64(&mut self) -> u64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        self.0
    }

    /// The next number in `[0, 1)`.
    pub(crate) fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// The next number in `[−1, 1)`: `2 u − 1`.
    pub(crate) fn signed(&mut self) -> f64 {
        self.unit() * 2.0 - 1.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sequence is the written-out recurrence's (the tests' former inline copies).
    #[test]
    fn equals_the_recurrence_written_out() {
        let (mut lcg, mut s) = (Lcg::new(7), 7u64);
        for _ in 0..1000 {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let u = (s >> 11) as f64 / (1u64 << 53) as f64;
            let v = lcg.signed();
            assert_eq!(v.to_bits(), (u * 2.0 - 1.0).to_bits());
            assert!((-1.0..1.0).contains(&v));
        }
    }
}
