//! The hydraulic block the exponential integrator solves exactly over a step: the port-A
//! node against the absorber's inlet column and, while the piston is free, port B with the
//! payload, by their matrix functions e^{τA}, φ₁, φ₂, φ₃ (the winding currents, the other
//! linear block, are the series of [`super::series`]); and the small matrix helpers both use.
//!
//! # The nodes, the absorber inlet and the payload (eq. 11, 12, 22–26)
//! y = (p_A, q, p_B, v) with q the absorber's inlet flow and v the piston's velocity obeys
//! y' = A_h·y + f(t),
//!
//! ```text
//!       [ 0     −k_A   0     −k_A·A ]      k_A = β/V_1, k_B = β/V_2,
//! A_h = [ 1/I   −R/I   0      0     ]      A the piston area, m the payload,
//!       [ 0      0     0     +k_B·A ]      B_p its viscous damping
//!       [ A/m    0    −A/m   −B_p/m ]
//! ```
//!
//! — the oil column of the absorber's inlet against chamber 1 (≈ 300 Hz at the nominal rig,
//! damping ratio 0.02) and the payload on the oil springs of both chambers (≈ 43 Hz, damping
//! ratio 1e-4): the two lightly damped modes whose phase an explicit scheme would lose over a
//! stroke. A shut poppet zeroes q's row, a blocked or stuck piston v's (and the block is then
//! the 2×2 of p_A and q). f holds the other flows, the gas pressure and the other forces,
//! extrapolated as f_0 + f_1·t + f_2·t²:
//!
//! ```text
//! y(τ) = e^{τA_h}·y(0) + τ·φ₁(τA_h)·f_0 + τ²·φ₂(τA_h)·f_1 + 2τ³·φ₃(τA_h)·f_2
//! ```
//!
//! with φ_k(z) = Σ_j zʲ/(j + k)! (∫₀^τ e^{A(τ−s)}·sⁿ ds = n!·τⁿ⁺¹·φ_{n+1}(τA)). The matrix
//! functions come from their Taylor series on τ·A_h/2ˢ (ν·τ/2ˢ ≤ ¼, ν Gershgorin's bound of
//! the eigenvalues in the basis that balances each coupled pair, 14 terms: truncation below
//! 1e-19) and s doublings,
//! e(2τ) = e(τ)², φ₁(2τ) = (e·φ₁ + φ₁)/2, φ₂(2τ) = (e·φ₂ + φ₁ + φ₂)/4,
//! φ₃(2τ) = (e·φ₃ + φ₃)/8 + φ₁/16 + φ₂/8 (the right sides at τ).

/// A 2×2 matrix, row-major.
pub(super) type M2 = [[f64; 2]; 2];

/// An n×n matrix, row-major.
pub(super) type Mat<const N: usize> = [[f64; N]; N];

fn identity<const N: usize>() -> Mat<N> {
    let mut m = [[0.0; N]; N];
    for (k, row) in m.iter_mut().enumerate() {
        row[k] = 1.0;
    }
    m
}

#[inline]
fn mul<const N: usize>(a: &Mat<N>, b: &Mat<N>) -> Mat<N> {
    let mut c = [[0.0; N]; N];
    for r in 0..N {
        for k in 0..N {
            let v = a[r][k];
            if v != 0.0 {
                for col in 0..N {
                    c[r][col] += v * b[k][col];
                }
            }
        }
    }
    c
}

/// Matrix times vector.
#[inline]
pub(super) fn mv<const N: usize>(a: &Mat<N>, v: [f64; N]) -> [f64; N] {
    let mut out = [0.0; N];
    for (o, row) in out.iter_mut().zip(a) {
        *o = row.iter().zip(&v).map(|(a, b)| a * b).sum();
    }
    out
}

fn lin<const N: usize>(a: &Mat<N>, ka: f64, b: &Mat<N>, kb: f64) -> Mat<N> {
    let mut c = [[0.0; N]; N];
    for r in 0..N {
        for col in 0..N {
            c[r][col] = ka * a[r][col] + kb * b[r][col];
        }
    }
    c
}

/// e^{τA}, φ₁(τA), φ₂(τA) and φ₃(τA) of an n×n matrix A.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Phi<const N: usize> {
    /// e^{τA}.
    pub e: Mat<N>,
    /// φ₁(τA).
    pub p1: Mat<N>,
    /// φ₂(τA).
    pub p2: Mat<N>,
    /// φ₃(τA).
    pub p3: Mat<N>,
}

/// Terms of the Taylor series in [`phi`].
const PHI_TERMS: usize = 14;

/// A bound of the spectral radius of `a` robust to the badly scaled units of the nodes
/// (pascals against cubic metres per second): the largest over the rows of |a_ii| plus the
/// geometric means √|a_ij·a_ji| of the off-diagonal pairs, Gershgorin's bound in the basis
/// that balances each pair.
// The pairs a_rc, a_cr are read by index from both sides.
#[allow(clippy::needless_range_loop)]
fn size<const N: usize>(a: &Mat<N>) -> f64 {
    let mut worst = 0.0f64;
    for r in 0..N {
        let mut s = libm::fabs(a[r][r]);
        for c in 0..N {
            if c != r {
                s += libm::sqrt(libm::fabs(a[r][c] * a[c][r]));
                // A one-way coupling (the other entry zero) adds no eigenvalue; it scales
                // with the step like the diagonal and is covered by the doublings below.
            }
        }
        worst = worst.max(s);
    }
    worst
}

/// The matrix functions of `a` at step `tau` (see the module docs).
pub(super) fn phi<const N: usize>(a: &Mat<N>, tau: f64) -> Phi<N> {
    let nu = tau * size(a);
    let mut doublings = 0u32;
    let mut scaled = tau;
    let mut left = nu;
    while left > 0.25 && doublings < 60 {
        left *= 0.5;
        scaled *= 0.5;
        doublings += 1;
    }
    let z = lin(a, scaled, &identity(), 0.0);
    let zero = [[0.0; N]; N];
    let mut out = Phi {
        e: zero,
        p1: zero,
        p2: zero,
        p3: zero,
    };
    let mut fact = [1.0f64; PHI_TERMS + 3];
    for k in 1..PHI_TERMS + 3 {
        fact[k] = fact[k - 1] * k as f64;
    }
    let mut power = identity();
    for k in 0..PHI_TERMS {
        out.e = lin(&out.e, 1.0, &power, 1.0 / fact[k]);
        out.p1 = lin(&out.p1, 1.0, &power, 1.0 / fact[k + 1]);
        out.p2 = lin(&out.p2, 1.0, &power, 1.0 / fact[k + 2]);
        out.p3 = lin(&out.p3, 1.0, &power, 1.0 / fact[k + 3]);
        power = mul(&power, &z);
    }
    for _ in 0..doublings {
        let Phi { e, p1, p2, p3 } = out;
        out.e = mul(&e, &e);
        out.p1 = lin(&mul(&e, &p1), 0.5, &p1, 0.5);
        out.p2 = lin(&lin(&mul(&e, &p2), 0.25, &p1, 0.25), 1.0, &p2, 0.25);
        let a = lin(&mul(&e, &p3), 0.125, &p3, 0.125);
        out.p3 = lin(&lin(&a, 1.0, &p1, 1.0 / 16.0), 1.0, &p2, 0.125);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// e^{τA} of a 2×2 matrix with complex eigenvalues σ ± jω in closed form:
    /// e^{στ}·(cos ωτ·I + sin ωτ/ω·(A − σI)).
    fn closed_form(a: &M2, tau: f64) -> M2 {
        let sigma = 0.5 * (a[0][0] + a[1][1]);
        let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
        let omega = libm::sqrt(det - sigma * sigma);
        let (s, c) = (libm::sin(omega * tau), libm::cos(omega * tau));
        let g = libm::exp(sigma * tau);
        let b = lin(a, 1.0, &identity(), -sigma);
        lin(&identity(), g * c, &b, g * s / omega)
    }

    #[test]
    fn matrix_exponential_matches_the_closed_form_at_any_step() {
        // The absorber port of the nominal rig: β/V1 = 6.5e8/450e-6, I = 3.85e5, R = 3e7.
        let a = [[0.0, -6.5e8 / 450e-6], [1.0 / 3.85e5, -3e7 / 3.85e5]];
        for tau in [1e-6, 50e-6, 2e-3, 0.05] {
            let p = phi(&a, tau);
            let e = closed_form(&a, tau);
            for r in 0..2 {
                for c in 0..2 {
                    // Compare in the balanced basis (entries scaled by the node's ratio).
                    let b = libm::sqrt(6.5e8 / 450e-6 * 3.85e5);
                    let scale = [[1.0, 1.0 / b], [b, 1.0]][r][c];
                    let d = (p.e[r][c] - e[r][c]) * scale;
                    assert!(d.abs() < 1e-12, "τ {tau}: e[{r}][{c}] off by {d:e}");
                }
            }
        }
    }

    #[test]
    fn phi_functions_solve_a_ramp_forcing() {
        // y' = A·y + f0 + f1·t from y(0) = 0 has the steady ramp solution
        // y_s(t) = −A⁻¹(f0 + f1·t) − A⁻²·f1 once the transient e^{tA}·(−y_s(0)) is added.
        let a = [[-300.0, 900.0], [-400.0, -50.0]];
        let (f0, f1) = ([3.0, -1.0], [200.0, 50.0]);
        let tau = 4e-3;
        let p = phi(&a, tau);
        let y = {
            let e1 = mv(&p.p1, f0);
            let e2 = mv(&p.p2, f1);
            [
                tau * e1[0] + tau * tau * e2[0],
                tau * e1[1] + tau * tau * e2[1],
            ]
        };
        let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
        let inv = [
            [a[1][1] / det, -a[0][1] / det],
            [-a[1][0] / det, a[0][0] / det],
        ];
        let ys = |t: f64| {
            let f = [f0[0] + f1[0] * t, f0[1] + f1[1] * t];
            let a1 = mv(&inv, f);
            let a2 = mv(&inv, mv(&inv, f1));
            [-a1[0] - a2[0], -a1[1] - a2[1]]
        };
        let e = closed_form(&a, tau);
        let tr = mv(&e, ys(0.0));
        let exact = [ys(tau)[0] - tr[0], ys(tau)[1] - tr[1]];
        for k in 0..2 {
            assert!(
                (y[k] - exact[k]).abs() < 1e-12 * exact[k].abs().max(1e-3),
                "{y:?} vs {exact:?}"
            );
        }
    }
}
