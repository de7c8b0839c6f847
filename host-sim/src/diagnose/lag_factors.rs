//! The pressure transducer's first-order lag over a substep (the hydraulic relation's
//! τ·dp_s/dt = p − p_s, solved exactly for p held over the substep): its step factor
//! 1 − e^(−h/τ), computed once for each substep length met.

/// The transducer's step factors 1 − e^(−h/τ) of the last few substep lengths h met, each
/// computed once. A logged time column's intervals differ in their last bits from row to
/// row (times written to a tenth of a millisecond and read back take a dozen or so
/// distinct differences, changing on most rows), so one remembered length would miss on
/// most rows; a handful, matched exactly, hits on nearly all, and every factor is the one
/// computed for its own length.
pub struct LagFactors {
    /// Time constant τ. [s]
    tau: f64,
    /// Lengths h [s] and their factors [1]; unused slots hold NaN, which matches nothing.
    seen: [(f64, f64); LagFactors::KEPT],
    /// The slot the next new length takes.
    next: usize,
}

impl LagFactors {
    /// Lengths kept.
    const KEPT: usize = 16;

    /// The factors of time constant `tau` [s], none computed yet.
    pub fn new(tau: f64) -> LagFactors {
        LagFactors {
            tau,
            seen: [(f64::NAN, 1.0); LagFactors::KEPT],
            next: 0,
        }
    }

    /// The factor of substep length `h`. [1]
    #[inline]
    pub fn at(&mut self, h: f64) -> f64 {
        if let Some((_, f)) = self.seen.iter().find(|(seen, _)| *seen == h) {
            return *f;
        }
        let f = if self.tau > 0.0 {
            1.0 - (-h / self.tau).exp()
        } else {
            1.0
        };
        self.seen[self.next] = (h, f);
        self.next = (self.next + 1) % LagFactors::KEPT;
        f
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_transducer_factors_are_those_of_their_own_lengths_whatever_was_kept() {
        // 1 − e^(−h/τ) for τ = 2 ms, over 40 distinct lengths met twice in a row and then
        // again in turn (more than the table keeps): each read equals the closed form
        // computed for its own length, bit for bit; without a lag every factor is 1.
        let tau = 2e-3;
        let lengths: Vec<f64> = (0..40).map(|k| 0.5e-3 * (1.0 + 1e-13 * k as f64)).collect();
        let mut factors = LagFactors::new(tau);
        for &h in lengths.iter().chain(&lengths).chain(lengths.iter().rev()) {
            let expected = 1.0 - (-h / tau).exp();
            assert_eq!(factors.at(h), expected, "{h:e}");
            assert_eq!(factors.at(h), expected, "{h:e} again");
        }
        // Against the exponential's series: for h ≪ τ the factor is h/τ − (h/τ)²/2 + (h/τ)³/6
        // to within (h/τ)⁴/24 (an alternating series), and 1 − e^(−x) loses a few units of
        // 1's last place to the cancellation.
        let mut fresh = LagFactors::new(1.0);
        let x = 1e-3;
        let series = x - x * x / 2.0 + x * x * x / 6.0;
        assert!((fresh.at(x) - series).abs() < x.powi(4) / 24.0 + 4.0 * f64::EPSILON);
        let mut none = LagFactors::new(0.0);
        assert_eq!(none.at(0.5e-3), 1.0);
    }
}
