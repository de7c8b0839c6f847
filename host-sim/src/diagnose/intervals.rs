//! A log interval's integration in the hydraulic relation: the substeps it is cut into,
//! their length h, and the pressure transducer's first-order lag over each (τ·dp_s/dt =
//! p − p_s, solved exactly for p moving linearly from p₀ to p₁ over the substep:
//! p_s ← p_s + a·(p₀ − p_s) + b·(p₁ − p₀), a = 1 − e^(−h/τ), b = 1 − τ·a/h — the ramp's
//! own response, so the reading trails a ramp of rate r by r·τ whatever h), computed once
//! for each interval met.

/// The integration of the last few log intervals met, each computed once. A logged time
/// column's intervals differ in their last bits from row to row (times written to a tenth
/// of a millisecond and read back take a dozen or so distinct differences, changing on most
/// rows), so one remembered interval would miss on most rows; a handful, matched exactly,
/// hits on nearly all, and every interval's values are those computed for it.
pub struct Intervals {
    /// Time constant τ. [s]
    tau: f64,
    /// The substeps an interval [s] is cut into.
    cut: fn(f64) -> usize,
    /// Intervals [s] and their integration; unused slots hold NaN, which matches nothing.
    seen: [(f64, Interval); Intervals::KEPT],
    /// The slot the next new interval takes.
    next: usize,
}

/// One log interval's integration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interval {
    /// Substeps the interval is cut into. [1]
    pub steps: usize,
    /// Their length h. [s]
    pub h: f64,
    /// 1/h, known before a substep starts. [1/s]
    pub per_h: f64,
    /// The transducer's factors over a substep.
    pub lag: Step,
}

/// The transducer's factors over one substep length. [1]
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

impl Intervals {
    /// Intervals kept.
    const KEPT: usize = 16;

    /// The integration of time constant `tau` [s] with intervals cut by `cut`, none
    /// computed yet.
    pub fn new(tau: f64, cut: fn(f64) -> usize) -> Intervals {
        let unused = Interval {
            steps: 1,
            h: f64::NAN,
            per_h: f64::NAN,
            lag: Step { a: 1.0, b: 1.0 },
        };
        Intervals {
            tau,
            cut,
            seen: [(f64::NAN, unused); Intervals::KEPT],
            next: 0,
        }
    }

    /// The integration of log interval `dt` [s].
    #[inline]
    pub fn at(&mut self, dt: f64) -> Interval {
        if let Some((_, f)) = self.seen.iter().find(|(seen, _)| *seen == dt) {
            return *f;
        }
        let steps = (self.cut)(dt).max(1);
        let h = dt / steps as f64;
        let lag = if self.tau > 0.0 && h > 0.0 {
            // −expm1 keeps a's digits where h ≪ τ; b = 1 − τ·a/h ≈ h/(2τ) there.
            let a = -(-h / self.tau).exp_m1();
            Step {
                a,
                b: 1.0 - self.tau * a / h,
            }
        } else {
            Step { a: 1.0, b: 1.0 }
        };
        let f = Interval {
            steps,
            h,
            per_h: 1.0 / h,
            lag,
        };
        self.seen[self.next] = (dt, f);
        self.next = (self.next + 1) % Intervals::KEPT;
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
        let mut factors = Intervals::new(tau, |_| 1);
        for &h in lengths.iter().chain(&lengths).chain(lengths.iter().rev()) {
            let a = -(-h / tau).exp_m1();
            let expected = Step {
                a,
                b: 1.0 - tau * a / h,
            };
            assert_eq!(factors.at(h).lag, expected, "{h:e}");
            assert_eq!(factors.at(h).lag, expected, "{h:e} again");
        }
        // Against the exponential's series: for x = h/τ ≪ 1, a = x − x²/2 + x³/6 − … and
        // b = x/2 − x²/6 + x³/24 − …, each within its next term (alternating series).
        let mut fresh = Intervals::new(1.0, |_| 1);
        let x = 1e-3;
        let step = fresh.at(x).lag;
        assert!((step.a - (x - x * x / 2.0 + x * x * x / 6.0)).abs() < x.powi(4) / 24.0 + 1e-18);
        assert!((step.b - (x / 2.0 - x * x / 6.0)).abs() < x.powi(3) / 24.0 + 1e-15);
        let mut none = Intervals::new(0.0, |_| 1);
        assert_eq!(none.at(0.5e-3).lag.next(3.0, 5.0, 7.0), 7.0);
    }

    #[test]
    fn a_ramp_is_followed_as_the_lag_equation_solves_it_whatever_the_substeps() {
        // τ·ds/dt = p − s with p = p₀ + r·t and s(0) = p₀: s(t) = p(t) − r·τ·(1 − e^(−t/τ)).
        // Stepped with lengths from 0.05 to 2 τ in turn, the reading matches the solution
        // at every step to rounding.
        let (tau, p0, r) = (4e-3, 2e6, 3e8);
        let mut lags = Intervals::new(tau, |_| 1);
        let (mut t, mut s) = (0.0, p0);
        for k in 0..400 {
            let h = tau * [0.05, 0.125, 0.5, 1.0, 2.0][k % 5];
            let (pa, pb) = (p0 + r * t, p0 + r * (t + h));
            s = lags.at(h).lag.next(s, pa, pb);
            t += h;
            let exact = p0 + r * t - r * tau * (1.0 - (-t / tau).exp());
            assert!(
                (s - exact).abs() < 1e-9 * exact,
                "t {t}: {s} against {exact}"
            );
        }
    }

    #[test]
    fn an_interval_is_cut_as_its_rule_says_and_remembered_as_first_computed() {
        // Cut into substeps of at most 1 ms: 2.5 ms into 3 of 5/6 ms, 1 ms into 1, and a
        // zero-substep rule still takes one; each read again is the same, bit for bit.
        let mut cut = Intervals::new(2e-3, |dt| (dt / 1e-3).ceil() as usize);
        for (dt, steps) in [(2.5e-3, 3), (1e-3, 1), (0.4e-3, 1), (2.5e-3, 3)] {
            let i = cut.at(dt);
            assert_eq!(i.steps, steps, "{dt}");
            assert!((i.h * steps as f64 - dt).abs() < 1e-18, "{dt}: h {}", i.h);
            assert!((i.h * i.per_h - 1.0).abs() < 1e-15, "{dt}");
            assert_eq!(cut.at(dt), i);
        }
        let mut none = Intervals::new(2e-3, |_| 0);
        assert_eq!(none.at(1e-3).steps, 1);
    }
}
