//! Step 3 of commissioning: the open-loop voltage pulses on one axis around the bias
//! current and the least-squares fit of L_d or L_q over their segments (eq. 2 at
//! standstill integrated exactly over the held voltages; see the [`super`] documentation).

use super::estimate::{Mean, SlopeFit};
use super::gains;
use super::interface::{Action, Input};
use super::sequence::forced_dq;
use super::sequence::{Axis, Commissioning, Phase};
use crate::supervisor::FaultCode;
use crate::transforms::Dq;

impl Commissioning {
    /// The pulse phase for `axis`.
    pub(super) fn pulses(axis: Axis) -> Phase {
        Phase::Pulses {
            axis,
            cycle: 0,
            segment: 0,
            k: 0,
            fit: SlopeFit::default(),
            flux: 0.0,
            i_start: 0.0,
            i_prev: 0.0,
            u_prev: 0.0,
        }
    }

    /// One period of the inductance pulses (see the module documentation, step 3).
    pub(super) fn pulse_step(&mut self, x: &Input) -> Action {
        let Phase::Pulses {
            axis,
            mut cycle,
            mut segment,
            mut k,
            mut fit,
            mut flux,
            mut i_start,
            i_prev,
            u_prev,
        } = self.phase
        else {
            return Action::Off;
        };
        let i_dq = forced_dq(x);
        let (bias, hold) = match axis {
            Axis::D => (self.levels[1].1, self.u_hold.d),
            Axis::Q => (0.0, self.u_hold.q),
        };
        let i = match axis {
            Axis::D => i_dq.d,
            Axis::Q => i_dq.q,
        } - bias;
        let swing = 0.4 * self.c.current_a;
        if self.n == 1 {
            i_start = i;
        } else {
            // The voltage held over the last period and the trapezoid of its currents.
            let t = self.p.t;
            flux += (u_prev - hold) * t - self.r_s * t * 0.5 * (i_prev + i);
            k += 1;
            let length = match (cycle, segment) {
                (0, 0) => {
                    if i >= swing {
                        self.pulse_len = k;
                        k
                    } else if k >= self.p.timeout {
                        return self.fail(FaultCode::CommissioningCurrent);
                    } else {
                        u32::MAX
                    }
                }
                (_, 1) => 2 * self.pulse_len,
                _ => self.pulse_len,
            };
            if k >= length {
                if cycle > 0 {
                    fit.add(i - i_start, flux);
                }
                flux = 0.0;
                i_start = i;
                k = 0;
                segment += 1;
                if segment > 2 {
                    segment = 0;
                    cycle += 1;
                }
                if cycle > self.c.pulse_cycles {
                    return self.pulses_done(axis, fit.value());
                }
            }
        }
        let sign = if segment == 1 { -1.0 } else { 1.0 };
        let u_axis = hold + sign * self.c.pulse_voltage_v;
        self.phase = Phase::Pulses {
            axis,
            cycle,
            segment,
            k,
            fit,
            flux,
            i_start,
            i_prev: i,
            u_prev: u_axis,
        };
        let u = match axis {
            Axis::D => Dq {
                d: u_axis,
                q: self.u_hold.q,
            },
            Axis::Q => Dq {
                d: self.u_hold.d,
                q: u_axis,
            },
        };
        Action::Voltage { theta_e: 0.0, u }
    }

    /// The inductance of `axis` is `l` [H]: check it, go on to the next step.
    fn pulses_done(&mut self, axis: Axis, l: f32) -> Action {
        let k = match axis {
            Axis::D => 0,
            Axis::Q => 1,
        };
        if !self.plausible(l, 1 + k) {
            return self.fail(FaultCode::CommissioningImplausible);
        }
        self.l[k] = l;
        let hold = Action::Current {
            theta_e: 0.0,
            rotor_frame: false,
            i_ref: Dq {
                d: self.levels[1].1,
                q: 0.0,
            },
        };
        if axis == Axis::D {
            self.next(Commissioning::pulses(Axis::Q));
            return hold;
        }
        self.new_gains = Some(gains::current_gains(
            self.r_s,
            self.l[0],
            self.l[1],
            self.c.current_bandwidth_rad_s,
        ));
        self.next(Phase::Accelerate {
            sign: 1.0,
            w1: 0.0,
            i: Mean::default(),
        });
        hold
    }
}
