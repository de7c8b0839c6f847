//! How well a prediction follows a measured signal: the contract's fit percentage (the
//! normalised root-mean-square error, 100·(1 − ‖y − ŷ‖₂ / ‖y − mean(y)‖₂)) and the
//! residual row by row.

/// Goodness of fit in percent, 100·(1 − ‖y − ŷ‖₂ / ‖y − mean(y)‖₂), of `simulated` (ŷ)
/// against `measured` (y): 100 is a perfect match, 0 is no better than the measured mean,
/// and it is unbounded below.
///
/// `None` when it is undefined: the two differ in length, are empty, hold a non-finite
/// value, or `measured` is constant.
pub fn fit_percent(measured: &[f64], simulated: &[f64]) -> Option<f64> {
    if measured.len() != simulated.len() || measured.is_empty() {
        return None;
    }
    if measured.iter().chain(simulated).any(|v| !v.is_finite()) {
        return None;
    }
    let mean = measured.iter().sum::<f64>() / measured.len() as f64;
    let spread = measured
        .iter()
        .map(|y| (y - mean) * (y - mean))
        .sum::<f64>();
    if spread <= 0.0 {
        return None;
    }
    let error = measured
        .iter()
        .zip(simulated)
        .map(|(y, s)| (y - s) * (y - s))
        .sum::<f64>();
    Some(100.0 * (1.0 - (error / spread).sqrt()))
}

/// Residual, measured − simulated, row by row (the shorter length when they differ).
pub fn residual(measured: &[f64], simulated: &[f64]) -> Vec<f64> {
    measured.iter().zip(simulated).map(|(y, s)| y - s).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fit_of_a_perfect_match_is_100_and_of_the_mean_is_0() {
        let y = [1.0, 2.0, 4.0, 8.0];
        assert_eq!(fit_percent(&y, &y), Some(100.0));
        assert_eq!(fit_percent(&y, &[3.75; 4]), Some(0.0));
    }

    #[test]
    fn fit_follows_the_normalised_error_norm() {
        // y − mean = (−1, 1), ‖·‖ = √2; error (0.5, 0.5), ‖·‖ = √0.5: fit = 100·(1 − 1/2).
        let fit = fit_percent(&[1.0, 3.0], &[0.5, 2.5]).unwrap();
        assert!((fit - 50.0).abs() < 1e-12, "{fit}");
        // The mirror image about the mean errs by twice the spread: −100 %.
        let fit = fit_percent(&[1.0, 3.0], &[3.0, 1.0]).unwrap();
        assert!((fit + 100.0).abs() < 1e-12, "{fit}");
    }

    #[test]
    fn fit_is_undefined_for_constant_or_mismatched_data() {
        assert_eq!(fit_percent(&[2.0; 3], &[2.0; 3]), None);
        assert_eq!(fit_percent(&[1.0, 2.0], &[1.0]), None);
        assert_eq!(fit_percent(&[], &[]), None);
        assert_eq!(fit_percent(&[1.0, f64::NAN], &[1.0, 2.0]), None);
    }

    #[test]
    fn residual_is_measured_minus_simulated() {
        assert_eq!(residual(&[3.0, 1.0], &[1.0, 2.0]), vec![2.0, -1.0]);
    }
}
