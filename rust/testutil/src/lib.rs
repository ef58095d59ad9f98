//! Test inputs shared by the workspace's tests, benches and examples: deterministic noise generators
//! (the same seed gives the same bits on every machine and every run) and the property tests'
//! configuration ([`proptest_config`]).
//!
//! A dev-dependency only (`publish = false`): no library or the wheel links it. Integration tests are
//! separate compilation targets, so before this crate each carried its own copy of these generators.

pub mod proptest_config;

/// The top 53 bits of `bits` as a uniform value in [−½, ½), each a multiple of 2⁻⁵³ (exact).
pub fn centered(bits: u64) -> f64 {
    (bits >> 11) as f64 / (1u64 << 53) as f64 - 0.5
}

/// Marsaglia's xorshift64 (shifts 13, 7, 17): a small generator with no dependency. A zero state
/// stays zero, so a caller whose seed may be 0 passes `seed.max(1)`.
#[derive(Debug, Clone)]
pub struct Xorshift(u64);

impl Xorshift {
    /// The generator whose state is `seed`.
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }

    /// The next state.
    pub fn next_u64(&mut self) -> u64 {
        let mut s = self.0;
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        self.0 = s;
        s
    }

    /// The next state as a uniform value in [−½, ½) ([`centered`]).
    pub fn next_centered(&mut self) -> f64 {
        centered(self.next_u64())
    }
}

/// A 64-bit linear congruential generator with Knuth's MMIX constants.
#[derive(Debug, Clone)]
pub struct Lcg(u64);

impl Lcg {
    /// The multiplier.
    pub const MUL: u64 = 6364136223846793005;
    /// The increment.
    pub const INC: u64 = 1442695040888963407;

    /// The generator whose state is `state`.
    pub fn new(state: u64) -> Self {
        Self(state)
    }

    /// The next state, `state · MUL + INC` (mod 2⁶⁴).
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_mul(Self::MUL).wrapping_add(Self::INC);
        self.0
    }

    /// The next state as a uniform value in [−½, ½) ([`centered`]).
    pub fn next_centered(&mut self) -> f64 {
        centered(self.next_u64())
    }
}

/// `n` values uniform in [−½, ½) from [`Xorshift`] with state `seed`.
pub fn xorshift_uniform(n: usize, seed: u64) -> Vec<f64> {
    let mut g = Xorshift::new(seed);
    (0..n).map(|_| g.next_centered()).collect()
}

/// `n` values uniform in [−½, ½) from [`Lcg`] with state `seed`.
pub fn lcg_uniform(n: usize, seed: u64) -> Vec<f64> {
    let mut g = Lcg::new(seed);
    (0..n).map(|_| g.next_centered()).collect()
}

/// `n` positive values of an irregular but fixed pattern, √((i · 2654435761 mod 1000) / 7) · 10⁻³
/// (Knuth's multiplicative hash of the index): a smooth-free input for bit-for-bit comparisons of
/// summation orders, with no generator state.
pub fn hashed_levels(n: usize) -> Vec<f64> {
    (0..n as u64)
        .map(|i| ((i.wrapping_mul(2654435761) % 1000) as f64 / 7.0).sqrt() * 1e-3)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    // Known answers: the first states of each generator, from the copies these replace. A changed
    // constant or shift changes every test's inputs, so it must show here first.
    #[test]
    fn xorshift_states_are_marsaglias() {
        let mut g = Xorshift::new(1);
        let s: Vec<u64> = (0..3).map(|_| g.next_u64()).collect();
        assert_eq!(s, [1082269761, 1152992998833853505, 11177516664432764457]);
        assert_eq!(Xorshift::new(0).next_u64(), 0);
    }

    #[test]
    fn lcg_states_are_mmix() {
        let mut g = Lcg::new(0);
        assert_eq!(g.next_u64(), Lcg::INC);
        assert_eq!(
            g.next_u64(),
            Lcg::INC.wrapping_mul(Lcg::MUL).wrapping_add(Lcg::INC)
        );
        assert_eq!(Lcg::new(1).next_u64(), 7806831264735756412);
    }

    #[test]
    fn centered_spans_half_open_unit_interval_exactly() {
        assert_eq!(centered(0), -0.5);
        assert_eq!(centered(u64::MAX), 0.5 - 2f64.powi(-53));
        assert_eq!(centered(1 << 63), 0.0);
        assert_eq!(centered((1 << 11) - 1), -0.5); // the low 11 bits are dropped
    }

    #[test]
    fn uniform_series_follow_their_generators() {
        let x = xorshift_uniform(4, 1);
        assert_eq!(x[0], centered(1082269761));
        assert_eq!(x[1], centered(1152992998833853505));
        let l = lcg_uniform(4, 7);
        let mut g = Lcg::new(7);
        assert!(l.iter().all(|&v| v == g.next_centered()));
        assert!(x.iter().chain(&l).all(|v| (-0.5..0.5).contains(v)));
    }

    #[test]
    fn hashed_levels_known_values() {
        let h = hashed_levels(3);
        assert_eq!(h[0], 0.0);
        // 2654435761 mod 1000 = 761, 2·2654435761 mod 1000 = 522
        assert_eq!(h[1], (761.0f64 / 7.0).sqrt() * 1e-3);
        assert_eq!(h[2], (522.0f64 / 7.0).sqrt() * 1e-3);
    }
}
