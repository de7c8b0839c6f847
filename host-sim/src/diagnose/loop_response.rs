//! The drive's current and speed loops as the line readings see them: the loops of the
//! rig's Table 1 design (through `closed_loop::controller_config`) as transfer functions at
//! one angular frequency. The q current's tracking of its reference
//! G_i = (K_p·s + K_i)/(L·s² + (R + K_p)·s + K_i), the speed loop's current reference per
//! unit angle line C_ω(jw)·jw with C_ω = K_p + B_a + K_i/(jw), and the current loops'
//! disturbance sensitivity H = s/(L·s² + (R + K_p)·s + K_i) that turns a voltage line
//! (a back-EMF's, a dead time's) into a current line. A bench's own loops differ from
//! Table 1's by up to [`LOOP_TOLERANCE`].

use plant_model::Rig;
use rustfft::num_complex::Complex64;

/// Relative uncertainty of the current and speed loops' responses computed from the rig's
/// Table 1 gains and inductances. [1]
pub const LOOP_TOLERANCE: f64 = 0.25;

/// The q current's closed-loop response to its reference on `rig` at angular frequency
/// `w`. [1]
pub fn current_tracking(rig: &Rig, w: f64) -> Complex64 {
    let c = closed_loop::controller_config(rig).current;
    let m = &rig.motor;
    let s = Complex64::new(0.0, w);
    let (kp, ki) = (c.kp_q as f64, c.ki_q as f64);
    (s * kp + ki) / (s * s * m.l_q_h + s * (m.r_s_ohm + kp) + ki)
}

/// The speed loop's q-current reference per unit angle line at `w`: C_ω(jw)·jw. [A/rad]
pub fn speed_reference_per_angle(rig: &Rig, w: f64) -> Complex64 {
    let c = closed_loop::controller_config(rig).speed;
    let s = Complex64::new(0.0, w);
    let pi = Complex64::new(c.kp as f64 + c.active_damping as f64, 0.0) + (c.ki as f64) / s;
    pi * s
}

/// The current loops' disturbance sensitivity on (d, q) at angular frequency `w` (signed:
/// a line turning backwards is the conjugate). [A/V]
pub fn disturbance_sensitivity(rig: &Rig, w: f64) -> (Complex64, Complex64) {
    let c = closed_loop::controller_config(rig).current;
    let m = &rig.motor;
    let s = Complex64::new(0.0, w);
    let h = |l: f64, kp: f64, ki: f64| s / (s * s * l + s * (m.r_s_ohm + kp) + ki);
    (
        h(m.l_d_h, c.kp_d as f64, c.ki_d as f64),
        h(m.l_q_h, c.kp_q as f64, c.ki_q as f64),
    )
}
