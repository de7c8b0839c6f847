//! The winding currents the exponential integrator solves exactly over a step (a
//! sub-interval of it): their Taylor series at the step's speed, driven by the inverter's
//! voltage turning with the rotor.
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
use super::blocks::M2;

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
    /// Electrical speed at τ/2. [rad/s]
    pub omega_e_mid: f64,
    /// Electrical speed at τ. [rad/s]
    pub omega_e: f64,
    /// Electrical acceleration at τ. [rad/s²]
    pub alpha_e: f64,
}

/// The series of the module docs over `tau` (with ν·τ ≤ ½), the speed carried along to
/// third order: Ω_1 = α_e, (k+1)·Ω_{k+1} = g·i⁽ᵏ⁾/k! + the load's, so that the back-EMF, the
/// speed coupling and the voltage's rotation follow the speed as the torque changes within
/// the step (a current responding to a new duty changes the acceleration at once).
pub(super) fn winding_series(w: &Winding, s: &WindingStart, tau: f64) -> WindingPoints {
    series::<true>(w, s, tau)
}

/// [`winding_series`] for a matrix that holds still within the sub-interval (`w.a1` zero:
/// no phase inside the dead time's band), its terms left out.
pub(super) fn winding_series_fixed(w: &Winding, s: &WindingStart, tau: f64) -> WindingPoints {
    series::<false>(w, s, tau)
}

/// The series, with the matrix's turning `a1` (`TURNING`) or without it.
#[inline(always)]
fn series<const TURNING: bool>(w: &Winding, s: &WindingStart, tau: f64) -> WindingPoints {
    let tol_u = SERIES_TOLERANCE * (libm::fabs(s.u[0]) + libm::fabs(s.u[1]));
    let mut st = Terms {
        // a1·t·i at order k is τ·a1·Z_{k−1}.
        b: [
            [tau * w.a1[0][0], tau * w.a1[0][1]],
            [tau * w.a1[1][0], tau * w.a1[1][1]],
        ],
        o: [s.alpha_e * tau, 0.0, 0.0],
        e: [
            s.emf[0],
            [s.emf[1][0] * tau, s.emf[1][1] * tau],
            [s.emf[2][0] * tau * tau, s.emf[2][1] * tau * tau],
        ],
        z: [s.i, [0.0; 2], [0.0; 2], [0.0; 2]],
        u: [s.u, [0.0; 2], [0.0; 2], [0.0; 2]],
        wk: [s.omega_e, 0.0, 0.0],
        end: s.i,
        mid: s.i,
        u_end: s.u,
        u_mid: s.u,
        half: 1.0,
        tol: [
            SERIES_TOLERANCE * (libm::fabs(s.i[0]) + libm::fabs(s.i[1])),
            tol_u,
        ],
        small_before: false,
    };
    // The first orders, where the older terms and the speed's later coefficients are still
    // zero, without them; then the rest until two successive terms are small.
    st.order::<TURNING, 0>(w, s, tau, 0);
    st.order::<TURNING, 1>(w, s, tau, 1);
    st.order::<TURNING, 2>(w, s, tau, 2);
    for k in 3..MAX_ORDER {
        if st.order::<TURNING, 3>(w, s, tau, k) {
            break;
        }
    }
    // The speed and the angle turned, from its series.
    let w0 = s.omega_e;
    let [o1, o2, o3] = st.o;
    let turned_end = tau * (w0 + o1 / 2.0 + o2 / 3.0 + o3 / 4.0);
    let turned_mid = tau * (w0 / 2.0 + o1 / 8.0 + o2 / 24.0 + o3 / 64.0);
    WindingPoints {
        i: [st.mid, st.end],
        u: [st.u_mid, st.u_end],
        turned: [turned_mid, turned_end],
        omega_e_mid: w0 + o1 / 2.0 + o2 / 4.0 + o3 / 8.0,
        omega_e: w0 + o1 + o2 + o3,
        alpha_e: (o1 + 2.0 * o2 + 3.0 * o3) / tau,
    }
}

/// The series' running sums and its last terms.
struct Terms {
    /// τ·a1. [1/s]
    b: M2,
    /// The speed's scaled coefficients ŵ_1, ŵ_2, ŵ_3 (ŵ_j = Ω_j·τʲ). [rad/s]
    o: [f64; 3],
    /// The back-EMF per speed, scaled: Ê_m = E_m·τᵐ. [A/(rad/s)/s]
    e: [[f64; 2]; 3],
    /// Z_k, Z_{k−1}, Z_{k−2}, Z_{k−3}. [A]
    z: [[f64; 2]; 4],
    /// W_k, W_{k−1}, W_{k−2}, W_{k−3}. [V]
    u: [[f64; 2]; 4],
    /// ŵ_k, ŵ_{k−1}, ŵ_{k−2}. [rad/s]
    wk: [f64; 3],
    /// The sums at τ and τ/2 of the currents [A] and the voltage [V].
    end: [f64; 2],
    mid: [f64; 2],
    u_end: [f64; 2],
    u_mid: [f64; 2],
    /// 2^−k. [1]
    half: f64,
    /// What a small term of the currents [A] and of the voltage [V] is.
    tol: [f64; 2],
    /// The last term was small.
    small_before: bool,
}

impl Terms {
    /// Adds the terms of order `k` + 1: `K` is `k` for the first three orders (the terms
    /// still zero there left out, so they cost nothing) and 3 for any later one. Returns
    /// whether the series has converged.
    #[inline(always)]
    fn order<const TURNING: bool, const K: usize>(
        &mut self,
        w: &Winding,
        s: &WindingStart,
        tau: f64,
        k: usize,
    ) -> bool {
        let c = tau * INV[k];
        let (fd, fq) = self.forcing::<K>(w, k);
        let (rd, rq) = self.coupled::<TURNING, K>(w);
        let zn = [c * (rd + fd), c * (rq + fq)];
        let un = self.turned_voltage::<K>(s.omega_e, c);
        self.o = self.speed_coefficients::<K>(s, tau, zn);
        self.shift::<K>(zn, un);
        self.add_to_sums(zn, un);
        if K == 0 {
            // The forcing's first term sets the scale of the change over the step.
            self.tol[0] = current_tolerance(s, zn);
        }
        self.converged::<K>(zn, un)
    }

    /// The forcing M·W_k + Σ ŵ_{k−m}·Ê_m of order `k` (nothing of the back-EMF past order
    /// 5: ŵ ends at order 3, Ê at 2).
    #[inline(always)]
    fn forcing<const K: usize>(&self, w: &Winding, k: usize) -> (f64, f64) {
        let (ld, lq) = (w.inv_l[0], w.inv_l[1]);
        let [e0, e1, e2] = self.e;
        let u = self.u[0];
        let [wk, wk1, wk2] = self.wk;
        match K {
            0 => (ld * u[0] + wk * e0[0], lq * u[1] + wk * e0[1]),
            1 => (
                ld * u[0] + wk * e0[0] + wk1 * e1[0],
                lq * u[1] + wk * e0[1] + wk1 * e1[1],
            ),
            _ if k < 6 => (
                ld * u[0] + wk * e0[0] + wk1 * e1[0] + wk2 * e2[0],
                lq * u[1] + wk * e0[1] + wk1 * e1[1] + wk2 * e2[1],
            ),
            _ => (ld * u[0], lq * u[1]),
        }
    }

    /// A·Z_k and the speed's change ŵ_j·C·Z_{k−j} (and τ·a1·Z_{k−1} when `TURNING`).
    #[inline(always)]
    fn coupled<const TURNING: bool, const K: usize>(&self, w: &Winding) -> (f64, f64) {
        let a = &w.a;
        let (cd, cq) = (w.coupling[0], w.coupling[1]);
        let [o1, o2, o3] = self.o;
        let [z, z1, z2, z3] = self.z;
        let (mut rd, mut rq) = (
            a[0][0] * z[0] + a[0][1] * z[1],
            a[1][0] * z[0] + a[1][1] * z[1],
        );
        let (hd, hq) = match K {
            0 => (0.0, 0.0),
            1 => (o1 * z1[1], o1 * z1[0]),
            2 => (o1 * z1[1] + o2 * z2[1], o1 * z1[0] + o2 * z2[0]),
            _ => (
                o1 * z1[1] + o2 * z2[1] + o3 * z3[1],
                o1 * z1[0] + o2 * z2[0] + o3 * z3[0],
            ),
        };
        if K > 0 {
            rd += cd * hd;
            rq += cq * hq;
            if TURNING {
                let b = &self.b;
                rd = rd + b[0][0] * z1[0] + b[0][1] * z1[1];
                rq = rq + b[1][0] * z1[0] + b[1][1] * z1[1];
            }
        }
        (rd, rq)
    }

    /// The voltage's next term W_{k+1} = c·(ω_e0·J·W_k + ŵ_j·J·W_{k−j}), turning with the
    /// rotor at `w0`, with `c` = τ/(k+1).
    #[inline(always)]
    fn turned_voltage<const K: usize>(&self, w0: f64, c: f64) -> [f64; 2] {
        let [o1, o2, o3] = self.o;
        let [u, u1, u2, u3] = self.u;
        let (vd, vq) = match K {
            0 => (w0 * u[1], w0 * u[0]),
            1 => (w0 * u[1] + o1 * u1[1], w0 * u[0] + o1 * u1[0]),
            2 => (
                w0 * u[1] + o1 * u1[1] + o2 * u2[1],
                w0 * u[0] + o1 * u1[0] + o2 * u2[0],
            ),
            _ => (
                w0 * u[1] + o1 * u1[1] + o2 * u2[1] + o3 * u3[1],
                w0 * u[0] + o1 * u1[0] + o2 * u2[0] + o3 * u3[0],
            ),
        };
        [c * vd, -c * vq]
    }

    /// The speed's scaled coefficients with the one the new current term `zn` sets:
    /// (k+2)·Ω_{k+2} = g·Y_{k+1} + load_k, ŵ_{k+2} = τ/(k+2)·(g·Z_{k+1} + load_k·τ^{k+1})
    /// for the first two orders; unchanged after them.
    #[inline(always)]
    fn speed_coefficients<const K: usize>(
        &self,
        s: &WindingStart,
        tau: f64,
        zn: [f64; 2],
    ) -> [f64; 3] {
        let g = s.accel_gain;
        let mut o = self.o;
        if K == 0 {
            o[1] = 0.5 * tau * (g[0] * zn[0] + g[1] * zn[1] + s.accel_load[0] * tau);
        } else if K == 1 {
            o[2] = tau / 3.0 * (g[0] * zn[0] + g[1] * zn[1] + s.accel_load[1] * tau * tau);
        }
        o
    }

    /// Moves the last terms down by one order with `zn` and `un` the newest, and the speed's
    /// coefficient ŵ_{k+1} in.
    #[inline(always)]
    fn shift<const K: usize>(&mut self, zn: [f64; 2], un: [f64; 2]) {
        let [z, z1, z2, _] = self.z;
        let [u, u1, u2, _] = self.u;
        let [wk, wk1, _] = self.wk;
        self.z = [zn, z, z1, z2];
        self.u = [un, u, u1, u2];
        self.wk = [
            match K {
                0 => self.o[0],
                1 => self.o[1],
                2 => self.o[2],
                _ => 0.0,
            },
            wk,
            wk1,
        ];
    }

    /// Adds the terms `zn` and `un` to the sums at τ, and at τ/2 with the next power of ½.
    #[inline(always)]
    fn add_to_sums(&mut self, zn: [f64; 2], un: [f64; 2]) {
        self.half *= 0.5;
        let half = self.half;
        self.end[0] += zn[0];
        self.end[1] += zn[1];
        self.mid[0] += half * zn[0];
        self.mid[1] += half * zn[1];
        self.u_end[0] += un[0];
        self.u_end[1] += un[1];
        self.u_mid[0] += half * un[0];
        self.u_mid[1] += half * un[1];
    }

    /// Whether the series has converged with the terms `zn` and `un`: two successive terms
    /// below the tolerance (one small term can be a forcing's zero crossing that the next
    /// order revives), past the speed's orders.
    #[inline(always)]
    fn converged<const K: usize>(&mut self, zn: [f64; 2], un: [f64; 2]) -> bool {
        let small = libm::fabs(zn[0]) + libm::fabs(zn[1]) <= self.tol[0]
            && libm::fabs(un[0]) + libm::fabs(un[1]) <= self.tol[1];
        let done = K >= 3 && small && self.small_before;
        self.small_before = small;
        done
    }
}

/// What a small term of the currents is, from the start's currents and the first term
/// `zn` of the series.
#[inline(always)]
fn current_tolerance(s: &WindingStart, zn: [f64; 2]) -> f64 {
    let scale_i = libm::fabs(s.i[0]) + libm::fabs(s.i[1]);
    SERIES_TOLERANCE * (scale_i + libm::fabs(zn[0]) + libm::fabs(zn[1]))
}

#[cfg(test)]
mod tests {
    use super::*;

    use super::super::blocks::{mv, phi};

    /// Both variants of the series: with the matrix's turning and without (`a1` is zero in
    /// these tests, so both must give the same exact answers).
    const SERIES: [fn(&Winding, &WindingStart, f64) -> WindingPoints; 2] =
        [winding_series, winding_series_fixed];

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
        for p in SERIES.map(|f| f(&w, &start, tau)) {
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
        for series in SERIES.map(|f| {
            f(
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
            )
        }) {
            check_against_phi(&a, i0, [r0, r1, r2], tau, series.i[1]);
        }
    }

    /// The end of y' = A·y + r0 + r1·t + r2·t² from `i0` by e^{τA}, φ₁, φ₂, φ₃ against
    /// `end`.
    fn check_against_phi(a: &M2, i0: [f64; 2], r: [[f64; 2]; 3], tau: f64, end: [f64; 2]) {
        let [r0, r1, r2] = r;
        let p = phi(a, tau);
        let terms = [
            mv(&p.e, i0),
            mv(&p.p1, r0).map(|v| tau * v),
            mv(&p.p2, r1).map(|v| tau * tau * v),
            mv(&p.p3, r2).map(|v| 2.0 * tau * tau * tau * v),
        ];
        for k in 0..2 {
            let y: f64 = terms.iter().map(|t| t[k]).sum();
            assert!((end[k] - y).abs() < 1e-13, "{end:?} vs {y}");
        }
    }

    #[test]
    fn winding_series_turns_the_voltage_with_the_rotor() {
        // A held α-β vector seen from a rotor turning at ω_e and accelerating at α_e (no
        // torque feedback): it turns by ω_e·t + α_e·t²/2, u(t) = R(−ω_e·t − α_e·t²/2)·u(0).
        let (we, tau) = (700.0, 1e-4);
        let w = Winding {
            a: [[-100.0, 2.0 * we], [-0.5 * we, -50.0]],
            a1: [[0.0; 2]; 2],
            coupling: [2.0, -0.5],
            inv_l: [100.0, 50.0],
        };
        for alpha in [0.0, 4e6] {
            let start = WindingStart {
                i: [1.0, -2.0],
                u: [30.0, 40.0],
                omega_e: we,
                alpha_e: alpha,
                accel_gain: [0.0; 2],
                accel_load: [0.0; 2],
                emf: [[0.0; 2]; 3],
            };
            for p in SERIES.map(|f| f(&w, &start, tau)) {
                for (k, t) in [(0, tau / 2.0), (1, tau)] {
                    let th = we * t + 0.5 * alpha * t * t;
                    assert!((p.turned[k] - th).abs() < 1e-15, "{} vs {th}", p.turned[k]);
                    let (s, c) = (libm::sin(th), libm::cos(th));
                    let exact = [30.0 * c + 40.0 * s, -30.0 * s + 40.0 * c];
                    for j in 0..2 {
                        assert!(
                            (p.u[k][j] - exact[j]).abs() < 1e-12,
                            "{:?} {exact:?}",
                            p.u[k]
                        );
                    }
                }
                assert!((p.omega_e - (we + alpha * tau)).abs() < 1e-9);
            }
        }
    }
}
