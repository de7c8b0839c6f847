//! The two linear blocks the exponential integrator solves exactly over a step: the winding
//! currents at the step's speed, driven by the inverter's voltage turning with the rotor, and
//! the port-A node against the absorber's inlet column.
//!
//! # Winding currents (eq. 2 at a known speed)
//! With ω_e(t) = ω_e0 + α_e·t over the step and the remainder r(t) = r_0 + r_1·t + r_2·t²
//! (magnet and harmonic back-EMF and the dead-time voltage, divided by L, extrapolated from
//! the last evaluations),
//!
//! ```text
//! i' = A·i + α_e·t·C·i + M·u(t) + r_0 + r_1·t + r_2·t²
//! A = [−R/L_d  ω_e0·L_q/L_d; −ω_e0·L_d/L_q  −R/L_q],  C = [0  L_q/L_d; −L_d/L_q  0],
//! M = diag(1/L_d, 1/L_q),  u' = ω_e(t)·(u_q, −u_d)
//! ```
//!
//! (A also changes within the step by a1·t, see below) where u is the inverter's held voltage
//! vector seen from the turning rotor frame (the
//! held α-β vector rotated back by the rotor's electrical angle), the magnet's fundamental
//! back-EMF −ω_e(t)·ψ_f/L_q on the q axis is part of the forcing, and A also carries the dead
//! time's voltage of the phases whose current is within its band (there it is a resistance,
//! the band's voltage over its current, seen in d-q as r·G(θ_e) with G = ⅔·Σ c_k·c_kᵀ over
//! those phases; it turns with the rotor, a1 = −M·r·G'(θ_e)·ω_e); outside the band the dead
//! time's voltage is constant in α-β and turns with u. Its Taylor coefficients
//! about the step's start follow from the equations themselves: with Z_k = i⁽ᵏ⁾(0)·τᵏ/k! and
//! W_k = u⁽ᵏ⁾(0)·τᵏ/k!,
//!
//! ```text
//! Z_{k+1} = τ/(k+1)·(A·Z_k + α_e·τ·C·Z_{k−1} + M·W_k + [k=j]·τʲ·r_j, j = 0, 1, 2)
//! W_{k+1} = τ/(k+1)·(ω_e0·J·W_k + α_e·τ·J·W_{k−1}),   J·(a, b) = (b, −a)
//! ```
//!
//! and i(f·τ) = Σ Z_k·fᵏ. This is the matrix exponential e^{τA} and its convolution with the
//! forcing applied by the series, summed until the next term is below rounding; the series
//! converges like (ν·τ)ᵏ/k! with ν = R/L + |ω_e|·√(L_q/L_d), so the step is cut into
//! sub-intervals of ν·τ ≤ ½ (one at any speed of the nominal rig: ν·τ ≤ 0.1 at 3000 rpm).
//! The torque, the input power and the copper loss over the step are integrated with
//! Simpson's rule on the series' values at the start, middle and end of each sub-interval
//! (the integrands are smooth within the step: its error is τ⁵/2880 of their fourth
//! derivative).
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

/// The winding's current equation over a step.
#[derive(Clone, Copy, Debug)]
pub(super) struct Winding {
    /// The matrix at the step's start: resistance (the winding's, and the dead time's
    /// within its current band) and the speed coupling, over L. [1/s]
    pub a: M2,
    /// Its rate of change within the piece (the band's resistance turning with the rotor),
    /// a(t) = a + a1·t. [1/s²]
    pub a1: M2,
    /// L_q/L_d, −L_d/L_q: the speed coupling's coefficients. [1]
    pub coupling: [f64; 2],
    /// 1/L_d, 1/L_q. [1/H]
    pub inv_l: [f64; 2],
}

/// What the winding series needs at the start of a sub-interval.
#[derive(Clone, Copy, Debug)]
pub(super) struct WindingStart {
    /// i_d, i_q. [A]
    pub i: [f64; 2],
    /// The inverter's voltage in the rotor frame. [V]
    pub u: [f64; 2],
    /// Electrical speed. [rad/s]
    pub omega_e: f64,
    /// Electrical acceleration. [rad/s²]
    pub alpha_e: f64,
    /// The electrical acceleration per ampere of i_d and i_q (the torque's gradient times
    /// p_n/J; zero for a shaft held by friction). [rad/s²/A]
    pub accel_gain: [f64; 2],
    /// The electrical acceleration's slope and curvature from the shaft's other torques
    /// (p_n/J times the load's). [rad/s³], [rad/s⁴]
    pub accel_load: [f64; 2],
    /// The back-EMF per electrical speed over L, E(t) = E_0 + E_1·t + E_2·t²: the magnet's
    /// flux and its harmonics, (ψ_q − ∂ψ_d/∂θ_e)/L_d and −(ψ_d + ∂ψ_q/∂θ_e)/L_q, along the
    /// angle the rotor turns. [A/(rad/s)/s], per s and s².
    pub emf: [[f64; 2]; 3],
}

/// Highest order of the winding series.
const MAX_ORDER: usize = 24;

/// 1/(k+1) for the series' orders.
const INV: [f64; MAX_ORDER + 1] = {
    let mut t = [0.0; MAX_ORDER + 1];
    let mut k = 0;
    while k <= MAX_ORDER {
        t[k] = 1.0 / (k + 1) as f64;
        k += 1;
    }
    t
};

/// The series stops after two successive terms below this fraction of the currents'
/// (and voltage's) scale: 1e-12 of an ampere-scale current per step, a nanoampere after a
/// million steps if it never cancelled, is far below anything the model resolves, and
/// summing on to rounding would cost orders for nothing.
const SERIES_TOLERANCE: f64 = 1e-12;

/// The winding at the middle and end of a sub-interval `tau`.
#[derive(Clone, Copy, Debug)]
pub(super) struct WindingPoints {
    /// Currents at τ/2 and τ. [A]
    pub i: [[f64; 2]; 2],
    /// Rotor-frame voltage at τ/2 and τ. [V]
    pub u: [[f64; 2]; 2],
    /// Electrical angle turned since the start, at τ/2 and τ. [rad]
    pub turned: [f64; 2],
    /// Electrical speed at τ/2 and τ, and acceleration at τ. [rad/s], [rad/s²]
    pub omega_e_mid: f64,
    pub omega_e: f64,
    pub alpha_e: f64,
}

/// The series of the module docs over `tau` (with ν·τ ≤ ½), the speed carried along to
/// third order: Ω_1 = α_e, (k+1)·Ω_{k+1} = g·i⁽ᵏ⁾/k! + the load's, so that the back-EMF, the
/// speed coupling and the voltage's rotation follow the speed as the torque changes within
/// the step (a current responding to a new duty changes the acceleration at once).
pub(super) fn winding_series(w: &Winding, s: &WindingStart, tau: f64) -> WindingPoints {
    let a = &w.a;
    // a1·t·i at order k is τ·a1·Z_{k−1}.
    let b = [
        [tau * w.a1[0][0], tau * w.a1[0][1]],
        [tau * w.a1[1][0], tau * w.a1[1][1]],
    ];
    let (cd, cq) = (w.coupling[0], w.coupling[1]);
    let (ld, lq) = (w.inv_l[0], w.inv_l[1]);
    let w0 = s.omega_e;
    // Scaled speed coefficients ŵ_j = Ω_j·τʲ; ŵ_2 and ŵ_3 follow from Z_1 and Z_2.
    let o1 = s.alpha_e * tau;
    let (mut o2, mut o3) = (0.0, 0.0);
    // The back-EMF per speed, scaled: Ê_m = E_m·τᵐ.
    let e0 = s.emf[0];
    let e1 = [s.emf[1][0] * tau, s.emf[1][1] * tau];
    let e2 = [s.emf[2][0] * tau * tau, s.emf[2][1] * tau * tau];
    // Z_k, Z_{k−1}, Z_{k−2}, Z_{k−3} and the same for W; ŵ_k, ŵ_{k−1}, ŵ_{k−2}.
    let (mut z, mut z1, mut z2, mut z3) = (s.i, [0.0; 2], [0.0; 2], [0.0; 2]);
    let (mut u, mut u1, mut u2, mut u3) = (s.u, [0.0; 2], [0.0; 2], [0.0; 2]);
    let (mut wk, mut wk1, mut wk2) = (w0, 0.0, 0.0);
    let (mut end, mut mid, mut u_end, mut u_mid) = (z, z, u, u);
    let mut half = 1.0;
    let scale_i = libm::fabs(z[0]) + libm::fabs(z[1]);
    let tol_u = SERIES_TOLERANCE * (libm::fabs(u[0]) + libm::fabs(u[1]));
    let mut tol_z = SERIES_TOLERANCE * scale_i;
    let mut small_before = false;
    for (k, inv) in INV.iter().enumerate().take(MAX_ORDER) {
        let c = tau * inv;
        let fd = ld * u[0] + wk * e0[0] + wk1 * e1[0] + wk2 * e2[0];
        let fq = lq * u[1] + wk * e0[1] + wk1 * e1[1] + wk2 * e2[1];
        let zn = [
            c * (a[0][0] * z[0]
                + a[0][1] * z[1]
                + cd * (o1 * z1[1] + o2 * z2[1] + o3 * z3[1])
                + b[0][0] * z1[0]
                + b[0][1] * z1[1]
                + fd),
            c * (a[1][0] * z[0]
                + a[1][1] * z[1]
                + cq * (o1 * z1[0] + o2 * z2[0] + o3 * z3[0])
                + b[1][0] * z1[0]
                + b[1][1] * z1[1]
                + fq),
        ];
        let un = [
            c * (w0 * u[1] + o1 * u1[1] + o2 * u2[1] + o3 * u3[1]),
            -c * (w0 * u[0] + o1 * u1[0] + o2 * u2[0] + o3 * u3[0]),
        ];
        // (k+2)·Ω_{k+2} = g·Y_{k+1} + load_k: ŵ_{k+2} = τ/(k+2)·(g·Z_{k+1} + load_k·τ^{k+1}).
        if k == 0 {
            o2 = 0.5
                * tau
                * (s.accel_gain[0] * zn[0] + s.accel_gain[1] * zn[1] + s.accel_load[0] * tau);
        } else if k == 1 {
            o3 = tau / 3.0
                * (s.accel_gain[0] * zn[0] + s.accel_gain[1] * zn[1] + s.accel_load[1] * tau * tau);
        }
        (z3, z2, z1, z) = (z2, z1, z, zn);
        (u3, u2, u1, u) = (u2, u1, u, un);
        wk2 = wk1;
        wk1 = wk;
        wk = match k {
            0 => o1,
            1 => o2,
            2 => o3,
            _ => 0.0,
        };
        half *= 0.5;
        end[0] += zn[0];
        end[1] += zn[1];
        mid[0] += half * zn[0];
        mid[1] += half * zn[1];
        u_end[0] += un[0];
        u_end[1] += un[1];
        u_mid[0] += half * un[0];
        u_mid[1] += half * un[1];
        if k == 0 {
            // The forcing's first term sets the scale of the change over the step.
            tol_z = SERIES_TOLERANCE * (scale_i + libm::fabs(zn[0]) + libm::fabs(zn[1]));
        }
        // Two successive terms below the tolerance (one small term can be a forcing's zero
        // crossing that the next order revives), past the speed's orders.
        let small = libm::fabs(zn[0]) + libm::fabs(zn[1]) <= tol_z
            && libm::fabs(un[0]) + libm::fabs(un[1]) <= tol_u;
        if k >= 3 && small && small_before {
            break;
        }
        small_before = small;
    }
    // The speed and the angle turned, from its series.
    let turned_end = tau * (w0 + o1 / 2.0 + o2 / 3.0 + o3 / 4.0);
    let turned_mid = tau * (w0 / 2.0 + o1 / 8.0 + o2 / 24.0 + o3 / 64.0);
    WindingPoints {
        i: [mid, end],
        u: [u_mid, u_end],
        turned: [turned_mid, turned_end],
        omega_e_mid: w0 + o1 / 2.0 + o2 / 4.0 + o3 / 8.0,
        omega_e: w0 + o1 + o2 + o3,
        alpha_e: (o1 + 2.0 * o2 + 3.0 * o3) / tau,
    }
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

    #[test]
    fn winding_series_is_the_locked_rotor_step_response() {
        // Locked rotor (ω = 0), voltage step on d: i_d = U/R·(1 − e^{−tR/L_d}).
        let (r, ld, lq) = (0.958, 5.25e-3, 12e-3);
        let w = Winding {
            a: [[-r / ld, 0.0], [0.0, -r / lq]],
            a1: [[0.0; 2]; 2],
            coupling: [lq / ld, -ld / lq],
            inv_l: [1.0 / ld, 1.0 / lq],
        };
        let start = WindingStart {
            i: [0.0, 0.0],
            u: [10.0, 0.0],
            omega_e: 0.0,
            alpha_e: 0.0,
            accel_gain: [0.0; 2],
            accel_load: [0.0; 2],
            emf: [[0.0; 2]; 3],
        };
        let tau = 2e-3;
        let p = winding_series(&w, &start, tau);
        for (k, t) in [(0, tau / 2.0), (1, tau)] {
            let exact = 10.0 / r * (1.0 - libm::exp(-t * r / ld));
            assert!(
                (p.i[k][0] - exact).abs() < 1e-13,
                "{} vs {exact}",
                p.i[k][0]
            );
            assert!(p.i[k][1].abs() < 1e-15);
        }
    }

    #[test]
    fn winding_series_and_phi_functions_agree_on_a_polynomial_forcing() {
        // Two independent routes to y' = A·y + r0 + r1·t + r2·t² at constant speed: the
        // series of the winding and e^{τA}, φ₁, φ₂, φ₃ from scaling and squaring.
        let (we, ld, lq, r) = (900.0, 5.25e-3, 12e-3, 0.958);
        let a = [[-r / ld, we * lq / ld], [-we * ld / lq, -r / lq]];
        let w = Winding {
            a,
            a1: [[0.0; 2]; 2],
            coupling: [lq / ld, -ld / lq],
            inv_l: [1.0 / ld, 1.0 / lq],
        };
        let (i0, r0, r1, r2) = ([2.0, -3.0], [500.0, -800.0], [4e5, 1e5], [-3e8, 2e8]);
        let tau = 50e-6;
        let series = winding_series(
            &w,
            &WindingStart {
                i: i0,
                u: [0.0; 2],
                omega_e: we,
                alpha_e: 0.0,
                accel_gain: [0.0; 2],
                accel_load: [0.0; 2],
                // The forcing ω_e·E(t) with E = r/ω_e.
                emf: [r0.map(|v| v / we), r1.map(|v| v / we), r2.map(|v| v / we)],
            },
            tau,
        );
        let p = phi(&a, tau);
        let terms = [
            mv(&p.e, i0),
            mv(&p.p1, r0).map(|v| tau * v),
            mv(&p.p2, r1).map(|v| tau * tau * v),
            mv(&p.p3, r2).map(|v| 2.0 * tau * tau * tau * v),
        ];
        for k in 0..2 {
            let y: f64 = terms.iter().map(|t| t[k]).sum();
            assert!(
                (series.i[1][k] - y).abs() < 1e-13,
                "{:?} vs {y}",
                series.i[1]
            );
        }
    }

    #[test]
    fn winding_series_turns_the_voltage_with_the_rotor() {
        // A held α-β vector seen from a rotor turning at ω_e: u(t) = R(−ω_e·t)·u(0).
        let (we, tau) = (700.0, 1e-4);
        let w = Winding {
            a: [[-100.0, 2.0 * we], [-0.5 * we, -50.0]],
            a1: [[0.0; 2]; 2],
            coupling: [2.0, -0.5],
            inv_l: [100.0, 50.0],
        };
        let start = WindingStart {
            i: [1.0, -2.0],
            u: [30.0, 40.0],
            omega_e: we,
            alpha_e: 0.0,
            accel_gain: [0.0; 2],
            accel_load: [0.0; 2],
            emf: [[0.0; 2]; 3],
        };
        let p = winding_series(&w, &start, tau);
        for (k, t) in [(0, tau / 2.0), (1, tau)] {
            let (s, c) = (libm::sin(we * t), libm::cos(we * t));
            let exact = [30.0 * c + 40.0 * s, -30.0 * s + 40.0 * c];
            assert!(
                (p.u[k][0] - exact[0]).abs() < 1e-12,
                "{:?} {exact:?}",
                p.u[k]
            );
            assert!(
                (p.u[k][1] - exact[1]).abs() < 1e-12,
                "{:?} {exact:?}",
                p.u[k]
            );
        }
    }
}
