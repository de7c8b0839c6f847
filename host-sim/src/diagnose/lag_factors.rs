//! The pressure transducer's first-order lag over a substep (the hydraulic relation's
//! τ·dp_s/dt = p − p_s, solved exactly for p moving linearly from p₀ to p₁ over the
//! substep h: p_s ← p_s + a·(p₀ − p_s) + b·(p₁ − p₀), a = 1 − e^(−h/τ), b = 1 − τ·a/h —
//! the ramp's own response, so the reading trails a ramp of rate r by r·τ whatever h):
//! its step factors, computed once for each substep length met.

/// The transducer's step factors (a, b) of the last few substep lengths h met, each
/// computed once. A logged time column's intervals differ in their last bits from row to
/// row (times written to a tenth of a millisecond and read back take a dozen or so
/// distinct differences, changing on most rows), so one remembered length would miss on
/// most rows; a handful, matched exactly, hits on nearly all, and every factor is the one
/// computed for its own length.
pub struct LagFactors {
    /// Time constant τ. [s]
    tau: f64,
    /// Lengths h [s] and their factors (a, b) [1]; unused slots hold NaN, which matches
    /// nothing.
    seen: [(f64, Step); LagFactors::KEPT],
    /// The slot the next new length takes.
    next: usize,
}

/// The factors of one substep length. [1]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Step {
    /// Weight of the reading's distance from the pressure at the substep's start,
    /// 1 − e^(−h/τ). [1]
    pub a: f64,
    /// Weight of the pressure's change over the substep, 1 − τ·a/h. [1]
    pub b: f64,
}

impl Step {
    /// The reading after a substep over which the pressure moved from `p0` to `p1`, from
    /// `s`. [Pa]
    #[inline]
    pub fn next(self, s: f64, p0: f64, p1: f64) -> f64 {
        s + self.a * (p0 - s) + self.b * (p1 - p0)
    }
}

impl LagFactors {
    /// Lengths kept.
    const KEPT: usize = 16;

    /// The factors of time constant `tau` [s], none computed yet.
    pub fn new(tau: f64) -> LagFactors {
        LagFactors {
            tau,
            seen: [(f64::NAN, Step { a: 1.0, b: 1.0 }); LagFactors::KEPT],
            next: 0,
        }
    }

    /// The factors of substep length `h`.
    #[inline]
    pub fn at(&mut self, h: f64) -> Step {
        if let Some((_, f)) = self.seen.iter().find(|(seen, _)| *seen == h) {
            return *f;
        }
        let f = if self.tau > 0.0 && h > 0.0 {
            // −expm1 keeps a's digits where h ≪ τ; b = 1 − τ·a/h ≈ h/(2τ) there.
            let a = -(-h / self.tau).exp_m1();
            Step {
                a,
                b: 1.0 - self.tau * a / h,
            }
        } else {
            Step { a: 1.0, b: 1.0 }
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
        // The factors for τ = 2 ms, over 40 distinct lengths met twice in a row and then
        // again in turn (more than the table keeps): each read equals the closed form
        // computed for its own length, bit for bit; without a lag the reading is the
        // pressure.
        let tau = 2e-3;
        let lengths: Vec<f64> = (0..40).map(|k| 0.5e-3 * (1.0 + 1e-13 * k as f64)).collect();
        let mut factors = LagFactors::new(tau);
        for &h in lengths.iter().chain(&lengths).chain(lengths.iter().rev()) {
            let a = -(-h / tau).exp_m1();
            let expected = Step {
                a,
                b: 1.0 - tau * a / h,
            };
            assert_eq!(factors.at(h), expected, "{h:e}");
            assert_eq!(factors.at(h), expected, "{h:e} again");
        }
        // Against the exponential's series: for x = h/τ ≪ 1, a = x − x²/2 + x³/6 − … and
        // b = x/2 − x²/6 + x³/24 − …, each within its next term (alternating series).
        let mut fresh = LagFactors::new(1.0);
        let x = 1e-3;
        let step = fresh.at(x);
        assert!((step.a - (x - x * x / 2.0 + x * x * x / 6.0)).abs() < x.powi(4) / 24.0 + 1e-18);
        assert!((step.b - (x / 2.0 - x * x / 6.0)).abs() < x.powi(3) / 24.0 + 1e-15);
        let mut none = LagFactors::new(0.0);
        assert_eq!(none.at(0.5e-3).next(3.0, 5.0, 7.0), 7.0);
    }

    #[test]
    fn a_ramp_is_followed_as_the_lag_equation_solves_it_whatever_the_substeps() {
        // τ·ds/dt = p − s with p = p₀ + r·t and s(0) = p₀: s(t) = p(t) − r·τ·(1 − e^(−t/τ)).
        // Stepped with lengths from 0.05 to 2 τ in turn, the reading matches the solution
        // at every step to rounding.
        let (tau, p0, r) = (4e-3, 2e6, 3e8);
        let mut lags = LagFactors::new(tau);
        let (mut t, mut s) = (0.0, p0);
        for k in 0..400 {
            let h = tau * [0.05, 0.125, 0.5, 1.0, 2.0][k % 5];
            let (pa, pb) = (p0 + r * t, p0 + r * (t + h));
            s = lags.at(h).next(s, pa, pb);
            t += h;
            let exact = p0 + r * t - r * tau * (1.0 - (-t / tau).exp());
            assert!(
                (s - exact).abs() < 1e-9 * exact,
                "t {t}: {s} against {exact}"
            );
        }
    }
}
