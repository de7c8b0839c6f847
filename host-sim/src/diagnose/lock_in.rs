//! The angle-locked lines' least squares: a window's signals fitted by a cubic in time and
//! sin/cos of k·θ at the orders analysed, all at once (lock-in), read as each order's
//! complex amplitude Z (y ≈ Re(Z·e^{jkθ})).

use nalgebra::DMatrix;
use rustfft::num_complex::Complex64;

/// Terms of the polynomial in time fitted beside the lines: a cubic. A window's speed is
/// steady only within a band (a sine test's shaft accelerates through it), and the angle's
/// curvature left by a straight line would leak into the lines, most at the high orders
/// whose torque weighs the angle's line with J·(k·ω̄)².
pub const TREND_TERMS: usize = 4;

/// Complex amplitudes of `signals` at `orders` (ascending) over `rows` (each signal a slice
/// whose first element is the log's row given beside it), by one least-squares fit of a
/// cubic in time ([`TREND_TERMS`]) and sin/cos of k·θ for every order (the orders are
/// near-orthogonal over whole revolutions; fitting them together removes what leaks
/// between them).
pub fn lock_in(
    t: &[f64],
    theta: &[f64],
    rows: std::ops::Range<usize>,
    orders: &[u32],
    signals: &[(&[f64], usize)],
) -> Option<Vec<Vec<Complex64>>> {
    let x = trend_and_lines(t, theta, rows, orders, signals)?;
    Some(
        (0..signals.len())
            .map(|s| {
                (0..orders.len())
                    .map(|m| {
                        Complex64::new(
                            x[(TREND_TERMS + 2 * m, s)],
                            -x[(TREND_TERMS + 1 + 2 * m, s)],
                        )
                    })
                    .collect()
            })
            .collect(),
    )
}

/// The start time of the window `rows` and its span (never zero), which [`regressors`]
/// map onto [−1, 1]. [s]
pub fn window_clock(t: &[f64], rows: std::ops::Range<usize>) -> (f64, f64) {
    let t0 = t[rows.start];
    (t0, (t[rows.end - 1] - t0).max(f64::MIN_POSITIVE))
}

/// The regressors of the row at time `t` and angle `theta` of a window starting at `t0` and
/// `span` long: the Legendre polynomials of the window's time on [−1, 1] (well
/// conditioned), then cos and sin of k·θ for each of `orders` (ascending), written to `phi`.
/// The sinusoids are powers of one e^{jθ}, not a sine each.
pub fn regressors(t: f64, t0: f64, span: f64, theta: f64, orders: &[u32], phi: &mut [f64]) {
    let x = 2.0 * (t - t0) / span - 1.0;
    phi[..TREND_TERMS].copy_from_slice(&[1.0, x, 1.5 * x * x - 0.5, 2.5 * x * x * x - 1.5 * x]);
    let (s1, c1) = theta.sin_cos();
    let base = Complex64::new(c1, s1);
    let mut z = Complex64::new(1.0, 0.0);
    let mut last = 0;
    for (m, &order) in orders.iter().enumerate() {
        z *= base.powu(order - last);
        last = order;
        phi[TREND_TERMS + 2 * m] = z.re;
        phi[TREND_TERMS + 2 * m + 1] = z.im;
    }
}

/// The least-squares coefficients of [`regressors`] for each of `signals` over `rows`, a
/// column per signal, `None` for too few rows.
///
/// The fit is solved through its normal equations, accumulated in one pass over the rows:
/// the columns are Legendre polynomials and whole-revolution sinusoids, well conditioned,
/// and the pass costs n·c²/2 against the n·c² several times over of a decomposition of
/// the n×c design matrix.
pub fn trend_and_lines(
    t: &[f64],
    theta: &[f64],
    rows: std::ops::Range<usize>,
    orders: &[u32],
    signals: &[(&[f64], usize)],
) -> Option<DMatrix<f64>> {
    let n = rows.len();
    let cols = TREND_TERMS + 2 * orders.len();
    if n < 2 * cols {
        return None;
    }
    let (t0, span) = window_clock(t, rows.clone());
    let mut gram = DMatrix::<f64>::zeros(cols, cols);
    let mut rhs = DMatrix::<f64>::zeros(cols, signals.len());
    let mut phi = vec![0.0; cols];
    for k in rows.clone() {
        regressors(t[k], t0, span, theta[k], orders, &mut phi);
        for i in 0..cols {
            let pi = phi[i];
            for j in i..cols {
                gram[(i, j)] += pi * phi[j];
            }
        }
        for (s, (y, offset)) in signals.iter().enumerate() {
            let v = y[k - offset];
            for (i, p) in phi.iter().enumerate() {
                rhs[(i, s)] += p * v;
            }
        }
    }
    gram.fill_lower_triangle_with_upper_triangle();
    match gram.clone().cholesky() {
        Some(c) => Some(c.solve(&rhs)),
        None => gram.svd(true, true).solve(&rhs, 1e-12).ok(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lock_in_reads_amplitude_and_phase_of_a_line() {
        // y = 0.3·cos(18θ − 0.7) + a slope, θ turning at 7 rad/s: Z = 0.3·e^{−j0.7}.
        let n = 4000;
        let t: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
        let th: Vec<f64> = t.iter().map(|t| 7.0 * t).collect();
        let y: Vec<f64> = th
            .iter()
            .zip(&t)
            .map(|(a, t)| 0.3 * (18.0 * a - 0.7).cos() + 2.0 * t)
            .collect();
        let z = lock_in(&t, &th, 0..n, &[17, 18, 19], &[(&y, 0)]).unwrap();
        let want = Complex64::from_polar(0.3, -0.7);
        assert!((z[0][1] - want).norm() < 1e-9, "{:?}", z[0][1]);
        assert!(z[0][0].norm() < 1e-9 && z[0][2].norm() < 1e-9);
    }
}
