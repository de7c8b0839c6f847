//! Linear least squares for the identifications: `A·x ≈ b` solved by singular value
//! decomposition (`nalgebra`), the columns scaled to unit norm first so that parameters of
//! very different units (kg·m² next to N·m) weigh alike, with the fit measure MATLAB's
//! `compare` uses.

use nalgebra::{DMatrix, DVector};

/// A least-squares solution and how well it fits.
#[derive(Clone, Debug, PartialEq)]
pub struct Fit {
    /// The parameters, in the units of their columns' inverse.
    pub x: Vec<f64>,
    /// `100·(1 − ‖A·x − b‖/‖b − mean b‖)`. [%]
    pub fit_percent: f64,
    /// `‖A·x − b‖²`.
    pub residual_ss: f64,
}

/// Solves `A·x ≈ b` for `A` of `n` rows and `m` columns given row by row in `rows`.
pub fn least_squares(n: usize, m: usize, rows: &[f64], rhs: &[f64]) -> Result<Fit, String> {
    if n < m || rows.len() != n * m || rhs.len() != n {
        return Err(format!(
            "least squares needs at least {m} rows of {m} values and one right-hand side each"
        ));
    }
    let mut a = DMatrix::from_row_slice(n, m, rows);
    let b = DVector::from_column_slice(rhs);
    let scale: Vec<f64> = (0..m)
        .map(|j| {
            let s = a.column(j).norm();
            if s > 0.0 {
                s
            } else {
                1.0
            }
        })
        .collect();
    for (j, s) in scale.iter().enumerate() {
        a.column_mut(j).unscale_mut(*s);
    }
    let y = a
        .clone()
        .svd(true, true)
        .solve(&b, 1e-12)
        .map_err(|e| format!("least squares: {e}"))?;
    let r = &a * &y - &b;
    let mean = b.mean();
    let spread = b.map(|v| v - mean).norm();
    Ok(Fit {
        x: y.iter().zip(&scale).map(|(v, s)| v / s).collect(),
        fit_percent: 100.0 * (1.0 - r.norm() / spread.max(f64::MIN_POSITIVE)),
        residual_ss: r.norm_squared(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recovers_a_line_through_noise_free_points_of_disparate_scale() {
        // b = 2e-3·u + 5e2·v exactly: both parameters back, fit 100 %.
        let pts: Vec<(f64, f64)> = (0..50)
            .map(|k| (k as f64 * 1e3, (k as f64 * 0.37).sin()))
            .collect();
        let rows: Vec<f64> = pts.iter().flat_map(|&(u, v)| [u, v]).collect();
        let rhs: Vec<f64> = pts.iter().map(|&(u, v)| 2e-3 * u + 5e2 * v).collect();
        let f = least_squares(50, 2, &rows, &rhs).unwrap();
        assert!(
            (f.x[0] - 2e-3).abs() < 1e-12 && (f.x[1] - 5e2).abs() < 1e-9,
            "{f:?}"
        );
        assert!(f.fit_percent > 99.999);
        assert!(least_squares(1, 2, &rows[..2], &rhs[..1]).is_err());
    }
}
