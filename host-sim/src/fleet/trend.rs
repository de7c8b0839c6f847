//! The trend of one parameter of one drive over time: a straight line fitted to the
//! diagnoses' estimates by weighted least squares, the weights from each estimate's
//! standard error and from the scatter between logs that the standard errors do not
//! explain.
//!
//! Model: y_i = a + b·(t_i − t̄) + e_i with e_i ~ N(0, s_i² + τ²), where s_i is the log's
//! own standard error and τ² the between-log variance (what changes from one log to the
//! next beyond the sensor noise the diagnosis accounts for: the day's oil temperature, the
//! fit's own model error). τ² is the Paule–Mandel estimate: the τ² ≥ 0 at which the
//! weighted residual sum of squares Σ w_i·r_i², w_i = 1/(s_i² + τ²), equals its expectation
//! n − 2 (zero when the standard errors explain the scatter already). With those weights,
//! b and a (at the weighted mean time t̄, where they are uncorrelated) have variances
//! 1/Σ w_i·(t_i − t̄)² and 1/Σ w_i.
//!
//! A drift is flagged when b/SE(b), referred to Student's t with n_eff − 2 degrees of
//! freedom (τ² is estimated from the same points; n_eff = (Σw)²/Σw², Kish's effective
//! number of points, is n when the weights are equal), is significant at the two-sided level
//! [`FALSE_ALARM`]. The line crosses a limit L at t_c = t̄ + (L − a)/b, with the standard
//! error (delta method) √(Var a + (t_c − t̄)²·Var b)/|b|.

use statrs::distribution::{ContinuousCDF, StudentsT};

/// Two-sided false-alarm probability of one drift test (one parameter of one drive): the
/// diagnosis's own per-test rate, so a fleet of hundreds of drive-parameter pairs raises
/// a false drift about once in a hundred runs. [1]
pub const FALSE_ALARM: f64 = 1e-4;

/// The fewest logs a trend is fitted to: two degrees of freedom for the scatter.
pub const MIN_POINTS: usize = 4;

/// One estimate: when, what, how well.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Point {
    /// When the log was recorded. [day since the Unix epoch]
    pub t_days: f64,
    /// The parameter's estimate. [parameter unit]
    pub value: f64,
    /// Its standard error, finite and positive. [parameter unit]
    pub se: f64,
}

/// A fitted trend.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Trend {
    /// Points fitted.
    pub points: usize,
    /// The weighted mean time the line is centred on. [day since the Unix epoch]
    pub t_centre_days: f64,
    /// The line's value at the centre, a. [parameter unit]
    pub value_at_centre: f64,
    /// Standard error of a. [parameter unit]
    pub value_at_centre_se: f64,
    /// Rate of change, b. [parameter unit per day]
    pub rate_per_day: f64,
    /// Standard error of b. [parameter unit per day]
    pub rate_se_per_day: f64,
    /// Between-log scatter beyond the standard errors, τ. [parameter unit]
    pub scatter: f64,
    /// b / SE(b). [1]
    pub t_statistic: f64,
    /// Two-sided probability of a |t| this large without drift. [1]
    pub p_value: f64,
}

/// Where a parameter must stay.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Limit {
    /// The parameter must stay above this value. [parameter unit]
    Lower(f64),
    /// The parameter must stay below this value. [parameter unit]
    Upper(f64),
}

impl Limit {
    /// The limit's value. [parameter unit]
    pub fn value(self) -> f64 {
        match self {
            Limit::Lower(v) | Limit::Upper(v) => v,
        }
    }
}

/// Weighted least-squares line through `points` with weights `w`: (t̄, a, b, Σw,
/// Σw·(t − t̄)², Σw·r²).
fn weighted_line(points: &[Point], w: &[f64]) -> (f64, f64, f64, f64, f64, f64) {
    let sw: f64 = w.iter().sum();
    let t_bar = points.iter().zip(w).map(|(p, w)| w * p.t_days).sum::<f64>() / sw;
    let a = points.iter().zip(w).map(|(p, w)| w * p.value).sum::<f64>() / sw;
    let stt: f64 = points
        .iter()
        .zip(w)
        .map(|(p, w)| w * (p.t_days - t_bar).powi(2))
        .sum();
    let sty: f64 = points
        .iter()
        .zip(w)
        .map(|(p, w)| w * (p.t_days - t_bar) * (p.value - a))
        .sum();
    let b = sty / stt;
    let q = points
        .iter()
        .zip(w)
        .map(|(p, w)| w * (p.value - a - b * (p.t_days - t_bar)).powi(2))
        .sum();
    (t_bar, a, b, sw, stt, q)
}

fn weights(points: &[Point], tau2: f64) -> Vec<f64> {
    points.iter().map(|p| 1.0 / (p.se * p.se + tau2)).collect()
}

/// The Paule–Mandel between-log variance τ²: the root of Q(τ²) = n − 2, Q decreasing in
/// τ², by bisection (zero when Q(0) ≤ n − 2).
fn between_log_variance(points: &[Point]) -> f64 {
    let target = (points.len() - 2) as f64;
    let q = |tau2: f64| weighted_line(points, &weights(points, tau2)).5;
    if q(0.0) <= target {
        return 0.0;
    }
    // An upper end: the unweighted residual variance grows until Q falls below n − 2.
    let ones = vec![1.0; points.len()];
    let mut hi = (weighted_line(points, &ones).5 / target).max(f64::MIN_POSITIVE);
    let mut guard = 0;
    while q(hi) > target && guard < 200 {
        hi *= 4.0;
        guard += 1;
    }
    let mut lo = 0.0;
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if q(mid) > target {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo <= 1e-12 * hi {
            break;
        }
    }
    0.5 * (lo + hi)
}

/// Kish's effective number of points of weights `w`, (Σw)²/Σw²: n for equal weights, about
/// k when k points outweigh the rest.
fn effective_points(w: &[f64]) -> f64 {
    let (s1, s2) = w.iter().fold((0.0, 0.0), |(a, b), w| (a + w, b + w * w));
    s1 * s1 / s2
}

/// Fits the trend; `None` with fewer than [`MIN_POINTS`] usable points (finite value and
/// time, finite positive standard error), when they all share one time, or when their
/// weights leave fewer than [`MIN_POINTS`] effective points ([`effective_points`]): a
/// parameter most logs cannot tell apart (standard errors of 1e9 and more beside a few of
/// 1e5) would otherwise be a line through its two or three sharpest estimates, tested as
/// if it stood on them all. The drift test's degrees of freedom are the effective points
/// less two.
pub fn fit(points: &[Point]) -> Option<Trend> {
    let points: Vec<Point> = points
        .iter()
        .copied()
        .filter(|p| p.t_days.is_finite() && p.value.is_finite() && p.se.is_finite() && p.se > 0.0)
        .collect();
    if points.len() < MIN_POINTS {
        return None;
    }
    let t0 = points[0].t_days;
    if points.iter().all(|p| p.t_days == t0) {
        return None;
    }
    let tau2 = between_log_variance(&points);
    let w = weights(&points, tau2);
    let effective = effective_points(&w);
    // (Equal weights give n up to rounding.)
    if effective < MIN_POINTS as f64 * (1.0 - 1e-9) {
        return None;
    }
    let (t_bar, a, b, sw, stt, _) = weighted_line(&points, &w);
    let rate_se = (1.0 / stt).sqrt();
    let t_statistic = b / rate_se;
    let dof = effective - 2.0;
    let p_value = StudentsT::new(0.0, 1.0, dof)
        .map(|d| 2.0 * d.sf(t_statistic.abs()))
        .unwrap_or(f64::NAN);
    Some(Trend {
        points: points.len(),
        t_centre_days: t_bar,
        value_at_centre: a,
        value_at_centre_se: (1.0 / sw).sqrt(),
        rate_per_day: b,
        rate_se_per_day: rate_se,
        scatter: tau2.sqrt(),
        t_statistic,
        p_value,
    })
}

impl Trend {
    /// Whether the rate is significant at [`FALSE_ALARM`].
    pub fn drifting(&self) -> bool {
        self.p_value < FALSE_ALARM
    }

    /// The line's value at `t_days` and its standard error. [parameter unit]
    pub fn value_at(&self, t_days: f64) -> (f64, f64) {
        let dt = t_days - self.t_centre_days;
        let v = self.value_at_centre + self.rate_per_day * dt;
        let se = (self.value_at_centre_se.powi(2) + (dt * self.rate_se_per_day).powi(2)).sqrt();
        (v, se)
    }

    /// When the line crosses `limit` moving towards its wrong side, and the standard error
    /// of that time (days); `None` when the line moves away from it or is flat.
    pub fn crossing(&self, limit: Limit) -> Option<(f64, f64)> {
        let b = self.rate_per_day;
        let towards = match limit {
            Limit::Lower(_) => b < 0.0,
            Limit::Upper(_) => b > 0.0,
        };
        if !towards || !b.is_finite() {
            return None;
        }
        let dt = (limit.value() - self.value_at_centre) / b;
        let t_c = self.t_centre_days + dt;
        let se = (self.value_at_centre_se.powi(2) + (dt * self.rate_se_per_day).powi(2)).sqrt()
            / b.abs();
        (t_c.is_finite() && se.is_finite()).then_some((t_c, se))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand_core::{RngCore, SeedableRng};
    use rand_xoshiro::Xoshiro256PlusPlus;

    fn point(t_days: f64, value: f64, se: f64) -> Point {
        Point { t_days, value, se }
    }

    #[test]
    fn exact_line_with_equal_errors_is_ordinary_least_squares() {
        // y = 10 − 0.5 t at t = 0, 1, 2, 3, 4; s = 0.2 everywhere, no scatter.
        // Σ(t − t̄)² = 10, so SE(b) = 0.2/√10; at t̄ = 2, a = 9, SE(a) = 0.2/√5.
        let pts: Vec<Point> = (0..5)
            .map(|k| point(k as f64, 10.0 - 0.5 * k as f64, 0.2))
            .collect();
        let t = fit(&pts).unwrap();
        assert!((t.rate_per_day + 0.5).abs() < 1e-12);
        assert!((t.t_centre_days - 2.0).abs() < 1e-12);
        assert!((t.value_at_centre - 9.0).abs() < 1e-12);
        assert!((t.rate_se_per_day - 0.2 / 10f64.sqrt()).abs() < 1e-12);
        assert!((t.value_at_centre_se - 0.2 / 5f64.sqrt()).abs() < 1e-12);
        assert_eq!(t.scatter, 0.0);
        // Student's t with 3 degrees of freedom in closed form: the two-sided tail beyond
        // |t| is 1 − (2/π)·(θ + sin θ·cos θ), θ = atan(|t|/√3).
        let th = (t.t_statistic.abs() / 3f64.sqrt()).atan();
        let p = 1.0 - 2.0 / std::f64::consts::PI * (th + th.sin() * th.cos());
        assert!((t.p_value - p).abs() < 1e-9 * p, "{} vs {p}", t.p_value);
        // |t| = 7.9 on 3 degrees of freedom: p ≈ 0.004, no drift at 1e-4.
        assert!(!t.drifting());
        // Crossing 6 (lower limit) at t = 8: Var = SE(a)² + 36·SE(b)², over |b| = 0.5.
        let (tc, se) = t.crossing(Limit::Lower(6.0)).unwrap();
        assert!((tc - 8.0).abs() < 1e-12);
        let want = ((0.04 / 5.0) + 36.0 * 0.04 / 10.0_f64).sqrt() / 0.5;
        assert!((se - want).abs() < 1e-12, "{se} vs {want}");
        // An upper limit is never crossed by a falling line.
        assert_eq!(t.crossing(Limit::Upper(12.0)), None);
    }

    #[test]
    fn equal_errors_give_the_closed_form_between_log_variance() {
        // With equal s the weights are equal whatever τ², the line is the OLS line and
        // Paule–Mandel's condition RSS/(s² + τ²) = n − 2 gives τ² = RSS/(n − 2) − s².
        let ys = [1.0, 3.5, 1.8, 4.9, 3.1, 6.2, 4.4];
        let pts: Vec<Point> = ys
            .iter()
            .enumerate()
            .map(|(k, &y)| point(k as f64 * 30.0, y, 0.1))
            .collect();
        // OLS by hand: t̄ = 90, Σ(t − t̄)² = 900·28 = 25 200.
        let n = ys.len() as f64;
        let y_bar = ys.iter().sum::<f64>() / n;
        let sty: f64 = ys
            .iter()
            .enumerate()
            .map(|(k, y)| (k as f64 * 30.0 - 90.0) * (y - y_bar))
            .sum();
        let b = sty / 25_200.0;
        let rss: f64 = ys
            .iter()
            .enumerate()
            .map(|(k, y)| (y - y_bar - b * (k as f64 * 30.0 - 90.0)).powi(2))
            .sum();
        let tau2 = rss / (n - 2.0) - 0.01;
        let t = fit(&pts).unwrap();
        assert!(
            (t.scatter.powi(2) - tau2).abs() < 1e-9 * tau2,
            "{}",
            t.scatter
        );
        assert!((t.rate_per_day - b).abs() < 1e-12);
        // SE(b) = √((s² + τ²)/Σ(t − t̄)²) = √(RSS/(n − 2)/Σ(t − t̄)²): the OLS standard error.
        let ols_se = (rss / (n - 2.0) / 25_200.0).sqrt();
        assert!((t.rate_se_per_day - ols_se).abs() < 1e-9 * ols_se);
    }

    #[test]
    fn too_few_or_unusable_points_give_no_trend() {
        let pts = [
            point(0.0, 1.0, 0.1),
            point(1.0, 2.0, f64::INFINITY),
            point(2.0, 3.0, 0.0),
            point(3.0, f64::NAN, 0.1),
            point(4.0, 5.0, 0.1),
            point(5.0, 6.0, 0.1),
        ];
        assert_eq!(fit(&pts), None);
        let same_day: Vec<Point> = (0..6).map(|k| point(1.0, k as f64, 0.1)).collect();
        assert_eq!(fit(&same_day), None);
    }

    /// Standard normal deviates (Box–Muller) from a seeded stream.
    struct Normal(Xoshiro256PlusPlus);
    impl Normal {
        fn unit(&mut self) -> f64 {
            ((self.0.next_u64() >> 11) as f64 + 0.5) / (1u64 << 53) as f64
        }
        fn draw(&mut self) -> f64 {
            let (u, v) = (self.unit(), self.unit());
            (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
        }
    }

    #[test]
    fn a_line_carried_by_two_sharp_estimates_is_no_trend() {
        // 28 logs that cannot tell the parameter (standard error 1e9 about 6.9e8) and two,
        // two years apart, that claim 2e5 and differ by 7e6: by weight the line stands on
        // two points (Kish: (Σw)²/Σw² ≈ 2), which cannot show a drift.
        let mut pts: Vec<Point> = (0..30)
            .map(|k| point(30.4 * k as f64, 6.9e8, 1e9))
            .collect();
        pts[2] = point(60.8, 6.91e8, 2e5);
        pts[26] = point(790.4, 6.84e8, 2e5);
        assert!(fit(&pts).is_none());
        // The same values with equal errors are 30 points and a fit.
        for p in &mut pts {
            p.se = 2e5;
        }
        assert_eq!(fit(&pts).unwrap().points, 30);
    }

    #[test]
    fn rate_intervals_cover_and_false_alarms_stay_at_their_rate() {
        // 30 monthly logs with standard errors varying threefold and a between-log
        // scatter twice the typical error: the 95 % interval of the rate must cover the
        // true rate in about 95 % of 2000 fleets, and a drift-free parameter must be
        // called significant at 5 % in about 5 % of them (binomial 3σ bands).
        let mut g = Normal(Xoshiro256PlusPlus::seed_from_u64(7));
        let (runs, rate) = (2000, -2.0);
        let (mut covered, mut alarms) = (0, 0);
        for _ in 0..runs {
            let mut pts = Vec::new();
            let mut flat = Vec::new();
            for k in 0..30 {
                let t = 30.4 * k as f64 + 5.0 * g.unit();
                let se = 10.0 * (1.0 + 2.0 * g.unit());
                let e = se * g.draw() + 20.0 * g.draw();
                pts.push(point(t, 3000.0 + rate * t + e, se));
                flat.push(point(t, 3000.0 + e, se));
            }
            let t = fit(&pts).unwrap();
            let q = StudentsT::new(0.0, 1.0, (t.points - 2) as f64)
                .unwrap()
                .inverse_cdf(0.975);
            if (t.rate_per_day - rate).abs() <= q * t.rate_se_per_day {
                covered += 1;
            }
            if fit(&flat).unwrap().p_value < 0.05 {
                alarms += 1;
            }
        }
        let sigma = (0.05f64 * 0.95 / runs as f64).sqrt();
        let coverage = covered as f64 / runs as f64;
        let alarm_rate = alarms as f64 / runs as f64;
        assert!((coverage - 0.95).abs() < 3.0 * sigma, "coverage {coverage}");
        assert!(
            (alarm_rate - 0.05).abs() < 3.0 * sigma,
            "false alarms {alarm_rate}"
        );
    }
}
