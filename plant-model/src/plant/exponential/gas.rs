//! The absorber's and the fill's gas over one segment of the exponential integrator: the
//! polytropic law p·Vⁿ = const (eq. 22) as the pressure factor of an oil volume change, by
//! its binomial series where the change is small against the gas volume.

/// The binomial coefficients C(n + k − 1, k), k = 2…5, of a gas's polytropic series
/// (1 − e)^(−n) = 1 + n·e + Σ C(n + k − 1, k)·eᵏ, for the exponent `n` they were taken at.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct GasSeries {
    /// The polytropic exponent. [1]
    pub(super) n: f64,
    /// C(n + 1, 2) … C(n + 4, 5). [1]
    pub(super) c: [f64; 4],
}

impl GasSeries {
    /// The coefficients for exponent `n`.
    pub(super) fn new(n: f64) -> GasSeries {
        let c2 = n * (n + 1.0) / 2.0;
        let c3 = c2 * (n + 2.0) / 3.0;
        let c4 = c3 * (n + 3.0) / 4.0;
        let c5 = c4 * (n + 4.0) / 5.0;
        GasSeries {
            n,
            c: [c2, c3, c4, c5],
        }
    }
}

/// The factor p_1/p_0 of a polytropic gas of exponent `n` in a shell of `shell` whose oil
/// goes from `oil` to `oil + d_oil`: (V_g/(V_g − ΔV))ⁿ with V_g floored at a thousandth of the
/// shell, by its binomial series for small changes (exact to rounding below 1e-3 of V_g;
/// `kept` its coefficients when taken at `n`). [1]
pub(super) fn gas_growth(d_oil: f64, oil: f64, shell: f64, n: f64, kept: &GasSeries) -> f64 {
    let vg = (shell - oil).max(1e-3 * shell);
    let e = d_oil / vg;
    if libm::fabs(e) < 1e-3 {
        let [c2, c3, c4, c5] = if kept.n == n {
            kept.c
        } else {
            GasSeries::new(n).c
        };
        1.0 + e * (n + e * (c2 + e * (c3 + e * (c4 + e * c5))))
    } else {
        let after = (shell - oil - d_oil).max(1e-3 * shell);
        libm::pow(vg / after, n)
    }
}
