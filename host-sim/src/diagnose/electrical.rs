//! Electrical replay: the d-q voltages the controller must have commanded, predicted from the
//! logged currents and shaft motion with the stator equations (eq. 1–2) and the inverter's
//! dead-time error (Section 4.1 (2)), for comparison with the logged `ud_v`/`uq_v`.
//!
//! u_d = R_s·i_d + L_d·di_d/dt − ω_e·L_q·i_q,   u_q = R_s·i_q + L_q·di_q/dt + ω_e·(L_d·i_d + ψ_f)
//!
//! are the voltages the motor needs; the inverter loses, per leg, 2·t_d·f_pwm·U_dc·sign(i_x)
//! (faded linearly within the rig's current band), whose common mode the floating star point
//! removes. The controller regulates the currents, so its command is the motor's need plus
//! that loss: a dead time the model lacks shows in the residual as a voltage vector along the
//! current with a sixth-harmonic ripple, while a current-sensor offset or a torque ripple
//! barely moves it. The derivative is the central difference of the logged currents.
//!
//! This replay is algebraic (no state), so it costs one pass over the log.

use crate::bench_log::BenchLog;
use plant_model::inverter::{dq_to_abc, pole_to_dq, Inverter};
use plant_model::rig::InverterParams;
use plant_model::Rig;

/// Predicted commanded voltages, row for row. [V]
#[derive(Clone, Debug, PartialEq)]
pub struct ElectricalReplay {
    /// d-axis voltage. [V]
    pub ud_v: Vec<f64>,
    /// q-axis voltage. [V]
    pub uq_v: Vec<f64>,
}

/// Predicts `ud_v`, `uq_v` for the first `rows` rows of `log` on `rig`; `None` when the log
/// has no shaft angle (the dead-time pattern needs the electrical angle).
pub fn replay_electrical(log: &BenchLog, rig: &Rig, rows: usize) -> Option<ElectricalReplay> {
    let theta = log.theta_m_rad.as_deref()?;
    let n = rows.min(log.len());
    let m = &rig.motor;
    let pp = m.pole_pairs as f64;
    let u_dc = log.udc_v.as_deref().map_or(rig.inverter.u_dc_v, |u| {
        u.iter().sum::<f64>() / u.len() as f64
    });
    // The plant's own inverter model at the logged DC link: its pole voltages at zero duty
    // are minus the dead-time loss of each leg.
    let inverter = Inverter::new(&InverterParams {
        u_dc_v: u_dc,
        ..rig.inverter.clone()
    });
    let t = &log.t_s;
    let deriv = |y: &[f64], k: usize| {
        let (a, b) = (k.saturating_sub(1), (k + 1).min(log.len() - 1));
        if b > a {
            (y[b] - y[a]) / (t[b] - t[a])
        } else {
            0.0
        }
    };
    let mut out = ElectricalReplay {
        ud_v: Vec::with_capacity(n),
        uq_v: Vec::with_capacity(n),
    };
    for (k, &theta_k) in theta.iter().enumerate().take(n) {
        let (i_d, i_q) = (log.id_a[k], log.iq_a[k]);
        let w_e = pp * log.speed_rad_s[k];
        let mut u_d = m.r_s_ohm * i_d + m.l_d_h * deriv(&log.id_a, k) - w_e * m.l_q_h * i_q;
        let mut u_q =
            m.r_s_ohm * i_q + m.l_q_h * deriv(&log.iq_a, k) + w_e * (m.l_d_h * i_d + m.psi_f_wb);
        if inverter.has_dead_time() {
            let (s, c) = (pp * theta_k).sin_cos();
            let i_abc = dq_to_abc(i_d, i_q, s, c);
            // The star point removes the common mode; the controller adds the loss back.
            let (loss_d, loss_q) = pole_to_dq(&inverter.pole_voltages(&[0.0; 3], &i_abc), s, c);
            u_d -= loss_d;
            u_q -= loss_q;
        }
        out.ud_v.push(u_d);
        out.uq_v.push(u_q);
    }
    Some(out)
}
