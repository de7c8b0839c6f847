//! PMSM in the rotor d-q frame (amplitude-invariant), eq. 1–7, with the low-speed torque
//! disturbances of Section 4.1: cogging torque (eq. 16) and magnet-flux harmonics
//! (eq. 17–19).
//!
//! Flux linkage ψ_d = L_d·i_d + ψ_df(θ_e), ψ_q = L_q·i_q + ψ_qf(θ_e) (eq. 1, generalised): the
//! magnet flux seen in d-q is ψ_f plus the Park transform of the phase harmonics of eq. 17.
//! A harmonic of order k = 6j+1 in the phases is a positive sequence and appears at
//! (k−1)·θ_e in d-q; k = 6j−1 is a negative sequence and appears at (k+1)·θ_e — so the 5th
//! and 7th both give the 6th, the 11th and 13th the 12th (eq. 18). Voltage (eq. 2):
//!
//! ```text
//! L_d·di_d/dt = u_d − R_s·i_d − ω_e·∂ψ_df/∂θ_e + ω_e·(L_q·i_q + ψ_qf)
//! L_q·di_q/dt = u_q − R_s·i_q − ω_e·∂ψ_qf/∂θ_e − ω_e·(L_d·i_d + ψ_df)
//! ```
//!
//! Torque from the power balance (electrical power in = d/dt of the winding energy
//! ¾(L_d·i_d² + L_q·i_q²) + copper loss + T_e·ω_m), which is eq. 3 plus the harmonic terms:
//!
//! ```text
//! T_e = 1.5·p_n·[ψ_df·i_q − ψ_qf·i_d + i_d·∂ψ_df/∂θ_e + i_q·∂ψ_qf/∂θ_e + (L_d − L_q)·i_d·i_q]
//! ```
//!
//! With i_d = 0 and the 5th and 7th at the same phase φ this is
//! T_e = 1.5·p_n·i_q·[ψ_f + (7ψ_7 − 5ψ_5)·cos(6θ_e + φ)] (eq. 19's T_0 + T_6·cos 6θ_e).
//! Cogging (eq. 16) is a conservative torque −dW/dθ_m from the slotting energy W(θ_m).

use crate::rig::{MotorParams, MAX_COGGING_HARMONICS, MAX_FLUX_HARMONICS};

/// A unit phasor cos θ + j·sin θ; harmonics k·θ come from integer powers, so one `sincos`
/// of the shaft angle serves every harmonic of an evaluation without range reduction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Phasor {
    /// cos θ.
    pub cos: f64,
    /// sin θ.
    pub sin: f64,
}

impl core::ops::Mul for Phasor {
    type Output = Phasor;
    /// Product (angle sum).
    #[inline]
    fn mul(self, o: Phasor) -> Phasor {
        Phasor {
            cos: self.cos * o.cos - self.sin * o.sin,
            sin: self.sin * o.cos + self.cos * o.sin,
        }
    }
}

impl Phasor {
    /// The phasor of angle `theta` (one libm call). [rad]
    #[inline]
    pub fn of(theta: f64) -> Phasor {
        let (sin, cos) = libm::sincos(theta);
        Phasor { cos, sin }
    }

    /// The phasor of a small angle `delta` (an integration step's rotation) by its Taylor
    /// series, without range reduction: for |δ| ≤ 0.1 the first omitted terms, δ¹¹/11! and
    /// δ¹²/12!, are below 3e-19, under half an ulp; larger angles go through libm. [rad]
    #[inline]
    pub fn small(delta: f64) -> Phasor {
        if libm::fabs(delta) > 0.1 {
            return Phasor::of(delta);
        }
        let d2 = delta * delta;
        let sin =
            delta * (1.0 - d2 / 6.0 * (1.0 - d2 / 20.0 * (1.0 - d2 / 42.0 * (1.0 - d2 / 72.0))));
        let cos = 1.0
            - d2 / 2.0
                * (1.0 - d2 / 12.0 * (1.0 - d2 / 30.0 * (1.0 - d2 / 56.0 * (1.0 - d2 / 90.0))));
        Phasor { cos, sin }
    }

    /// The k-th power (angle k·θ) by binary exponentiation (⌊log₂ k⌋ squarings and one
    /// product per further set bit); rounding grows like k·ε.
    #[inline]
    pub fn pow(self, k: u32) -> Phasor {
        if k == 0 {
            return Phasor { cos: 1.0, sin: 0.0 };
        }
        let mut base = self;
        for _ in 0..k.trailing_zeros() {
            base = base * base;
        }
        let mut acc = base;
        let mut rest = k >> k.trailing_zeros() >> 1;
        while rest > 0 {
            base = base * base;
            if rest & 1 == 1 {
                acc = acc * base;
            }
            rest >>= 1;
        }
        acc
    }
}

/// The flux harmonics that appear in d-q at one multiple m of θ_e (the 5th and 7th at the
/// 6th): ψ_df += Σ a·cos(m·θ_e + φ) = Re(e^{jmθ_e}·D), ψ_qf += Σ s·a·sin(m·θ_e + φ) =
/// Im(e^{jmθ_e}·Q) with the complex amplitudes D = Σ a·e^{jφ} and Q = Σ s·a·e^{jφ}
/// (s = ±1 the sequence), so one power and two complex products serve every harmonic of
/// the group.
#[derive(Clone, Copy, Debug)]
struct DqFluxTerm {
    multiple: u32,
    /// D. [Wb]
    d: Phasor,
    /// Q. [Wb]
    q: Phasor,
}

/// The magnet flux in d-q at one rotor angle, with its angular derivatives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MagnetFlux {
    /// ψ_df. [Wb]
    pub d_wb: f64,
    /// ψ_qf. [Wb]
    pub q_wb: f64,
    /// ∂ψ_df/∂θ_e. [Wb/rad]
    pub d_slope_wb: f64,
    /// ∂ψ_qf/∂θ_e. [Wb/rad]
    pub q_slope_wb: f64,
    /// ∂²ψ_df/∂θ_e². [Wb/rad²]
    pub d_curvature_wb: f64,
    /// ∂²ψ_qf/∂θ_e². [Wb/rad²]
    pub q_curvature_wb: f64,
}

/// The motor's equations, precomputed from [`MotorParams`] (only active harmonics kept).
#[derive(Clone, Debug)]
pub struct Motor {
    /// Pole pairs p_n as a float. [1]
    pub pole_pairs: f64,
    /// R_s. [Ω]
    pub r_s_ohm: f64,
    /// L_d. [H]
    pub l_d_h: f64,
    /// L_q. [H]
    pub l_q_h: f64,
    /// ψ_f. [Wb]
    pub psi_f_wb: f64,
    flux_terms: [DqFluxTerm; MAX_FLUX_HARMONICS],
    n_flux_terms: usize,
    cogging: [(f64, u32, Phasor); MAX_COGGING_HARMONICS],
    n_cogging: usize,
}

impl Motor {
    /// Builds the equations from validated parameters.
    pub fn new(p: &MotorParams) -> Motor {
        let zero = Phasor { cos: 0.0, sin: 0.0 };
        let empty = DqFluxTerm {
            multiple: 0,
            d: zero,
            q: zero,
        };
        let mut flux_terms = [empty; MAX_FLUX_HARMONICS];
        let mut n_flux_terms = 0;
        for h in p.flux_harmonics.iter().filter(|h| h.amplitude_wb != 0.0) {
            // 6j+1: positive sequence, seen at (k−1)·θ_e; 6j−1: negative, at (k+1)·θ_e.
            let (multiple, sequence) = if h.order % 6 == 1 {
                (h.order - 1, 1.0)
            } else {
                (h.order + 1, -1.0)
            };
            let ph = Phasor::of(h.phase_rad);
            let a = h.amplitude_wb;
            let slot = match flux_terms
                .iter()
                .take(n_flux_terms)
                .position(|t| t.multiple == multiple)
            {
                Some(i) => i,
                None => {
                    n_flux_terms += 1;
                    n_flux_terms - 1
                }
            };
            if let Some(t) = flux_terms.get_mut(slot) {
                t.multiple = multiple;
                t.d.cos += a * ph.cos;
                t.d.sin += a * ph.sin;
                t.q.cos += sequence * a * ph.cos;
                t.q.sin += sequence * a * ph.sin;
            }
        }
        let mut cogging = [(0.0, 0, Phasor { cos: 1.0, sin: 0.0 }); MAX_COGGING_HARMONICS];
        let mut n_cogging = 0;
        for c in p.cogging.iter().filter(|c| c.amplitude_nm > 0.0) {
            cogging[n_cogging] = (c.amplitude_nm, c.order, Phasor::of(c.phase_rad));
            n_cogging += 1;
        }
        Motor {
            pole_pairs: p.pole_pairs as f64,
            r_s_ohm: p.r_s_ohm,
            l_d_h: p.l_d_h,
            l_q_h: p.l_q_h,
            psi_f_wb: p.psi_f_wb,
            flux_terms,
            n_flux_terms,
            cogging,
            n_cogging,
        }
    }

    /// Magnet flux in d-q at electrical angle `theta_e` (eq. 18).
    pub fn magnet_flux(&self, theta_e: f64) -> MagnetFlux {
        self.magnet_flux_at(Phasor::of(theta_e))
    }

    /// Magnet flux in d-q at the electrical-angle phasor `e` (eq. 18).
    #[inline]
    pub fn magnet_flux_at(&self, e: Phasor) -> MagnetFlux {
        let mut f = MagnetFlux {
            d_wb: self.psi_f_wb,
            q_wb: 0.0,
            d_slope_wb: 0.0,
            q_slope_wb: 0.0,
            d_curvature_wb: 0.0,
            q_curvature_wb: 0.0,
        };
        for t in self.flux_terms.iter().take(self.n_flux_terms) {
            let base = e.pow(t.multiple);
            let (d, q) = (base * t.d, base * t.q);
            let m = t.multiple as f64;
            f.d_wb += d.cos;
            f.q_wb += q.sin;
            f.d_slope_wb -= m * d.sin;
            f.q_slope_wb += m * q.cos;
            f.d_curvature_wb -= m * m * d.cos;
            f.q_curvature_wb -= m * m * q.sin;
        }
        f
    }

    /// Electromagnetic torque (eq. 3 with the flux harmonics). [N·m]
    #[inline]
    pub fn torque_nm(&self, i_d: f64, i_q: f64, flux: &MagnetFlux) -> f64 {
        1.5 * self.pole_pairs
            * (flux.d_wb * i_q - flux.q_wb * i_d
                + i_d * flux.d_slope_wb
                + i_q * flux.q_slope_wb
                + (self.l_d_h - self.l_q_h) * i_d * i_q)
    }

    /// di_d/dt and di_q/dt (eq. 2 with the harmonic back-EMF). [A/s]
    #[inline]
    pub fn current_derivatives(
        &self,
        u_d: f64,
        u_q: f64,
        i_d: f64,
        i_q: f64,
        omega_e: f64,
        flux: &MagnetFlux,
    ) -> (f64, f64) {
        let did = (u_d - self.r_s_ohm * i_d - omega_e * flux.d_slope_wb
            + omega_e * (self.l_q_h * i_q + flux.q_wb))
            / self.l_d_h;
        let diq = (u_q
            - self.r_s_ohm * i_q
            - omega_e * flux.q_slope_wb
            - omega_e * (self.l_d_h * i_d + flux.d_wb))
            / self.l_q_h;
        (did, diq)
    }

    /// Cogging torque at mechanical angle `theta_m` (eq. 16). [N·m]
    pub fn cogging_torque_nm(&self, theta_m: f64) -> f64 {
        self.cogging_torque_at(Phasor::of(theta_m))
    }

    /// Cogging torque at the mechanical-angle phasor `m` (eq. 16). [N·m]
    #[inline]
    pub fn cogging_torque_at(&self, m: Phasor) -> f64 {
        self.cogging
            .iter()
            .take(self.n_cogging)
            .map(|&(a, n, ph)| a * (m.pow(n) * ph).sin)
            .sum()
    }

    /// Slotting energy W(θ_m) whose negative slope is the cogging torque. [J]
    pub fn cogging_energy_j(&self, theta_m: f64) -> f64 {
        let m = Phasor::of(theta_m);
        self.cogging
            .iter()
            .take(self.n_cogging)
            .map(|&(a, n, ph)| a / n as f64 * (m.pow(n) * ph).cos)
            .sum()
    }

    /// Energy stored in the winding inductances, ¾(L_d·i_d² + L_q·i_q²). [J]
    pub fn winding_energy_j(&self, i_d: f64, i_q: f64) -> f64 {
        0.75 * (self.l_d_h * i_d * i_d + self.l_q_h * i_q * i_q)
    }

    /// Peak line-to-line back-EMF at electrical speed `omega_e`. [V]
    pub fn line_emf_peak_v(&self, omega_e: f64) -> f64 {
        libm::sqrt(3.0) * self.psi_f_wb * libm::fabs(omega_e)
    }
}
