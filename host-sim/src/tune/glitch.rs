//! Lone bad samples in a step's response: a reading that leaves both its neighbours in the
//! same direction by more than the step could move it in one sample, while the neighbours
//! agree with each other — a dropped or corrupted sample (a transducer glitch, a logger
//! writing 0 for a missed reading), not the loop's response. The identification integrates
//! the response, so one such sample biases the identified plant; it is refused with its
//! time, for the engineer to repair or re-record.

/// The first lone spike of `y`: `|y[k] − y[k±1]| > threshold` on both sides with the same
/// sign, and `|y[k+1] − y[k−1]| < threshold / 4`.
pub fn lone_spike(y: &[f64], threshold: f64) -> Option<usize> {
    (1..y.len().saturating_sub(1)).find(|&k| {
        let (a, b) = (y[k] - y[k - 1], y[k] - y[k + 1]);
        a.abs() > threshold
            && b.abs() > threshold
            && a.signum() == b.signum()
            && (y[k + 1] - y[k - 1]).abs() < 0.25 * threshold
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_dropped_sample_is_found_and_a_step_is_not() {
        // A first-order rise from 3 to 5 (time constant 10 samples) with one reading of 0.
        let mut y: Vec<f64> = (0..200)
            .map(|k| 3.0 + 2.0 * (1.0 - (-(k as f64) / 10.0).exp()))
            .collect();
        assert_eq!(lone_spike(&y, 1.0), None);
        // A true step of the whole size in one sample is no spike either.
        let steps: Vec<f64> = (0..20).map(|k| if k < 10 { 3.0 } else { 5.0 }).collect();
        assert_eq!(lone_spike(&steps, 1.0), None);
        y[120] = 0.0;
        assert_eq!(lone_spike(&y, 1.0), Some(120));
    }
}
