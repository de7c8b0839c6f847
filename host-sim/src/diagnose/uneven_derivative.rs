//! The second derivative of a signal logged at uneven times: at each row, the curvature of
//! the quadratic fitted by least squares to the rows within a half-width in time of it.
//! This is the Savitzky–Golay filter of [`super::mechanical::savgol_second_derivative`]
//! (which assumes rows at one period) with the logged times in place of the row numbers;
//! on even rows the two coincide.

use nalgebra::{Matrix3, Vector3};

/// y″ at each row of `t` from the quadratic fitted to the rows within `half_width_s` of it
/// (at least one on each side); a row with fewer than three such rows (an end) takes its
/// neighbour's value. [unit of y per s²]
pub fn second_derivative_at_times(t: &[f64], y: &[f64], half_width_s: f64) -> Vec<f64> {
    let n = t.len().min(y.len());
    let mut out: Vec<Option<f64>> = vec![None; n];
    // The times' printed rounding must not drop a row at the window's edge.
    let reach = half_width_s * (1.0 + 1e-9);
    for k in 1..n.saturating_sub(1) {
        // Every row within the half-width, and a neighbour on each side.
        let (mut a, mut b) = (k - 1, k + 1);
        while a > 0 && t[k] - t[a - 1] <= reach {
            a -= 1;
        }
        while b + 1 < n && t[b + 1] - t[k] <= reach {
            b += 1;
        }
        out[k] = curvature(&t[a..=b], &y[a..=b], t[k]);
    }
    // The ends (and any row without a fit) repeat the nearest fitted value.
    let first = out.iter().flatten().next().copied().unwrap_or(0.0);
    let mut last = first;
    out.into_iter()
        .map(|v| {
            if let Some(v) = v {
                last = v;
            }
            last
        })
        .collect()
}

/// Twice the quadratic coefficient of the least-squares quadratic through (t, y) about
/// `t0`; `None` when the times do not fix a quadratic.
fn curvature(t: &[f64], y: &[f64], t0: f64) -> Option<f64> {
    // Scaled abscissae keep the normal equations well conditioned.
    let h = t
        .iter()
        .map(|t| (t - t0).abs())
        .fold(0.0, f64::max)
        .max(f64::MIN_POSITIVE);
    let mut normal = Matrix3::zeros();
    let mut rhs = Vector3::zeros();
    for (ti, yi) in t.iter().zip(y) {
        let u = (ti - t0) / h;
        let row = Vector3::new(1.0, u, u * u);
        normal += row * row.transpose();
        rhs += row * *yi;
    }
    let c = normal.lu().solve(&rhs)?;
    Some(2.0 * c[2] / (h * h))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_parabola_logged_at_uneven_times_has_its_curvature_everywhere() {
        // θ = 3 + 2·t + 7.5·t², θ″ = 15, at times 1 ms apart with every seventh row missing.
        let t: Vec<f64> = (0..400)
            .filter(|k| k % 7 != 3)
            .map(|k| k as f64 * 1e-3)
            .collect();
        let y: Vec<f64> = t.iter().map(|t| 3.0 + 2.0 * t + 7.5 * t * t).collect();
        for (k, a) in second_derivative_at_times(&t, &y, 3e-3).iter().enumerate() {
            assert!((a - 15.0).abs() < 1e-6, "row {k}: {a}");
        }
    }

    #[test]
    fn on_even_rows_a_sinusoid_comes_out_with_the_quadratic_fits_gain() {
        // y = sin(ω·t) on rows 1 ms apart, fitted over ±3 rows. On a symmetric window the
        // least-squares quadratic's coefficient is Σ c_j·y_j / Σ c_j² with c_j = j² − ⟨j²⟩
        // (orthogonal to 1 and j), so the curvature at row k is
        // sin(ω·t_k) · 2·Σ c_j·cos(ω·j·T) / (Σ c_j²·T²): the exact −ω² scaled by the fit's gain.
        let (w, period, m) = (40.0, 1e-3, 3i32);
        let t: Vec<f64> = (0..300).map(|k| k as f64 * period).collect();
        let y: Vec<f64> = t.iter().map(|t| (w * t).sin()).collect();
        let mean_j2 = (m * (m + 1)) as f64 / 3.0;
        let c = |j: i32| (j * j) as f64 - mean_j2;
        let num: f64 = (-m..=m).map(|j| c(j) * (w * j as f64 * period).cos()).sum();
        let den: f64 = (-m..=m).map(|j| c(j) * c(j)).sum::<f64>() * period * period;
        let gain = 2.0 * num / den;
        assert!((gain / -(w * w) - 1.0).abs() < 0.01, "{gain}");
        let a = second_derivative_at_times(&t, &y, m as f64 * period);
        for k in 3..297 {
            let exact = (w * t[k]).sin() * gain;
            assert!(
                (a[k] - exact).abs() < 1e-6 * w * w,
                "row {k}: {} vs {exact}",
                a[k]
            );
        }
    }
}
