//! Loop gains from the identified motor.
//!
//! Current loops: pole–zero cancellation on the stator's R-L (Section 3.1, eq. 6, the
//! design behind Table 1): Kp = L·ω_c, Ki = R_s·ω_c, so each closed current loop is the
//! first-order 1/(1 + s/ω_c). On the nominal motor at ω_c = 1100 rad/s this gives Table
//! 1's 5.775 (d), 13.2 (q) and 1053.8.
//!
//! Speed loop: with an ideal current loop the mechanics are J·dω/dt = K_t·i_q − T_L with
//! K_t = 1.5·p_n·ψ_f (eq. 3 at i_d = 0), and the PI with active damping Ba (see
//! [`crate::speed_loop`]) closes J s² + K_t(Kp + Ba) s + K_t·Ki = 0. Placing it at ω_n, ζ:
//! Ki = ω_n²·J/K_t, Kp = 2ζω_n·J/K_t − Ba.

/// Current PI gains for both axes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CurrentGains {
    /// d-axis proportional gain. [V/A]
    pub kp_d: f32,
    /// q-axis proportional gain. [V/A]
    pub kp_q: f32,
    /// Integral gain of both axes. [V/(A·s)]
    pub ki: f32,
    /// The bandwidth they are designed for. [rad/s]
    pub bandwidth_rad_s: f32,
}

/// Speed PI gains.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpeedGains {
    /// Proportional gain. [A/(rad/s)]
    pub kp: f32,
    /// Integral gain. [A/rad]
    pub ki: f32,
    /// Active damping Ba kept from the configuration. [A/(rad/s)]
    pub active_damping: f32,
}

/// Current gains for resistance `r_s` [Ω], inductances `l_d`, `l_q` [H] at bandwidth
/// `omega_c` [rad/s].
pub fn current_gains(r_s: f32, l_d: f32, l_q: f32, omega_c: f32) -> CurrentGains {
    CurrentGains {
        kp_d: l_d * omega_c,
        kp_q: l_q * omega_c,
        ki: r_s * omega_c,
        bandwidth_rad_s: omega_c,
    }
}

/// Torque constant K_t = 1.5·p_n·ψ_f of `pole_pairs` and flux linkage `psi_f` [Wb].
/// [N·m/A]
pub fn torque_constant(pole_pairs: f32, psi_f: f32) -> f32 {
    1.5 * pole_pairs * psi_f
}

/// Speed gains for inertia `j` [kg·m²], torque constant `k_t` [N·m/A], natural frequency
/// `omega_n` [rad/s], damping ratio `zeta` and active damping `ba` [A/(rad/s)].
pub fn speed_gains(j: f32, k_t: f32, omega_n: f32, zeta: f32, ba: f32) -> SpeedGains {
    let per_a = if k_t > 0.0 { j / k_t } else { 0.0 };
    SpeedGains {
        kp: 2.0 * zeta * omega_n * per_a - ba,
        ki: omega_n * omega_n * per_a,
        active_damping: ba,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nominal_motor_gives_table_1() {
        // Table 1 (paper): Pi-Id Kp 5.775, Pi-Iq Kp 13.2, Ki 1053.8 at 1100 rad/s.
        let g = current_gains(0.958, 5.25e-3, 12e-3, 1100.0);
        assert!((g.kp_d - 5.775).abs() < 1e-3);
        assert!((g.kp_q - 13.2).abs() < 1e-3);
        assert!((g.ki - 1053.8).abs() < 0.05);
        // Table 1 speed PI: Kp 0.14, Ki 7.0 with Ba 0.013 on J = 8.0e-4 kg·m².
        let s = speed_gains(8.0e-4, torque_constant(4.0, 0.1827), 97.9, 1.07, 0.013);
        assert!((s.kp - 0.14).abs() < 0.002, "{s:?}");
        assert!((s.ki - 7.0).abs() < 0.02, "{s:?}");
    }
}
