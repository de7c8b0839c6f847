//! The commissioning sequence's state machine: alignment sweeps and holds (encoder offset
//! and direction), the two current levels (R_s), the spin (inertia and ψ_f) and the
//! result with its gains; the inductance pulses are in `pulses.rs`. The steps and their
//! equations are in the [`super`] documentation.

use super::config::CommissioningConfig;
use super::estimate::{angle_difference, CircularMean, Mean, SlopeFit};
use super::gains::{self, CurrentGains};
use super::interface::{Action, CommissioningResult, Input};
use crate::config::sections::Config;
use crate::supervisor::FaultCode;
use crate::transforms::{clarke, park, sin_cos, Dq};
use core::f32::consts::TAU;

/// Largest disagreement of the two alignment holds. [rad]
const HOLD_AGREEMENT_RAD: f32 = 20.0 * core::f32::consts::PI / 180.0;
/// Window of the open-phase check at the start of each sweep, from its first period
/// (from 5 ms, when the current loop has settled at τ = 0.9 ms, to 10 ms). [s]
const CURRENT_CHECK_S: (f32, f32) = (5e-3, 10e-3);
/// Settling time of the speed estimate before an acceleration is measured. [s]
const ACCEL_SETTLE_S: f32 = 6e-3;

#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Axis {
    D,
    Q,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Phase {
    Idle,
    Sweep {
        dir: f32,
        start: i64,
        current: Mean,
    },
    Hold {
        dir: f32,
        angle: CircularMean,
    },
    Level {
        high: bool,
        u: Mean,
        i: Mean,
        u_q: Mean,
    },
    Pulses {
        axis: Axis,
        /// Cycle 0 finds the pulse length and is not used.
        cycle: u32,
        /// 0: +U, 1: −U (twice as long), 2: +U.
        segment: u8,
        /// Periods in this segment so far.
        k: u32,
        fit: SlopeFit,
        flux: f32,
        i_start: f32,
        i_prev: f32,
        u_prev: f32,
    },
    Accelerate {
        sign: f32,
        w1: f32,
        i: Mean,
    },
    Spin {
        u_q: Mean,
        i_q: Mean,
        i_d: Mean,
        start: i64,
    },
    Stop,
    Done,
    Failed,
}

/// Sample counts of the configured times.
#[derive(Clone, Copy, Debug)]
pub(super) struct Periods {
    pub(super) t: f32,
    pub(super) settle: u32,
    pub(super) average: u32,
    pub(super) sweep: u32,
    pub(super) timeout: u32,
    pub(super) accel_settle: u32,
    pub(super) check: (u32, u32),
}

/// The sequence's state.
#[derive(Clone, Copy, Debug)]
pub struct Commissioning {
    pub(super) c: CommissioningConfig,
    pub(super) nameplate: [f32; 4],
    pub(super) pole_pairs: f32,
    pub(super) counts_per_rev: f32,
    pub(super) ba: f32,
    pub(super) p: Periods,
    pub(super) phase: Phase,
    /// Periods in the present phase.
    pub(super) n: u32,
    /// Periods since the start.
    pub(super) total: u32,
    pub(super) offsets: [CircularMean; 2],
    pub(super) offset: f32,
    pub(super) levels: [(f32, f32); 2],
    pub(super) u_hold: Dq,
    pub(super) r_s: f32,
    pub(super) l: [f32; 2],
    pub(super) psi_f: f32,
    pub(super) pulse_len: u32,
    pub(super) alpha: [(f32, f32); 2],
    pub(super) new_gains: Option<CurrentGains>,
    pub(super) result: Option<CommissioningResult>,
}

impl Commissioning {
    /// From a validated configuration; idle until [`Commissioning::start`].
    #[inline(never)]
    pub fn new(cfg: &Config) -> Commissioning {
        let pwm = cfg.rates.pwm_hz.max(1.0);
        let c = cfg.commissioning;
        let calls = |s: f32| ((s * pwm) as u32).max(1);
        let m = &cfg.motor;
        Commissioning {
            c,
            nameplate: [
                m.stator_resistance_ohm,
                m.d_inductance_h,
                m.q_inductance_h,
                m.flux_linkage_wb,
            ],
            pole_pairs: m.pole_pairs as f32,
            counts_per_rev: cfg.sensors.encoder_counts_per_rev as f32,
            ba: cfg.speed.active_damping,
            p: Periods {
                t: 1.0 / pwm,
                settle: calls(c.settle_time_s),
                average: calls(c.average_time_s),
                sweep: calls(c.sweep_time_s),
                timeout: calls(c.step_timeout_s),
                accel_settle: calls(ACCEL_SETTLE_S),
                check: (calls(CURRENT_CHECK_S.0), calls(CURRENT_CHECK_S.1)),
            },
            phase: Phase::Idle,
            n: 0,
            total: 0,
            offsets: [CircularMean::default(); 2],
            offset: 0.0,
            levels: [(0.0, 0.0); 2],
            u_hold: Dq::default(),
            r_s: 0.0,
            l: [0.0; 2],
            psi_f: 0.0,
            pulse_len: 1,
            alpha: [(0.0, 0.0); 2],
            new_gains: None,
            result: None,
        }
    }

    /// Starts (or restarts) the sequence.
    pub fn start(&mut self) {
        self.phase = Phase::Sweep {
            dir: 1.0,
            start: 0,
            current: Mean::default(),
        };
        self.n = 0;
        self.total = 0;
        self.offsets = [CircularMean::default(); 2];
        self.new_gains = None;
        self.result = None;
    }

    /// True while the sequence runs.
    pub fn is_running(&self) -> bool {
        !matches!(self.phase, Phase::Idle | Phase::Done | Phase::Failed)
    }

    /// The result of the last completed sequence.
    pub fn result(&self) -> Option<CommissioningResult> {
        self.result
    }

    /// Current gains designed during the sequence, once (the controller applies them).
    pub fn take_new_gains(&mut self) -> Option<CurrentGains> {
        self.new_gains.take()
    }

    /// Identified machine constants so far (L_d, L_q [H], ψ_f [Wb]) for the decoupling.
    pub fn machine(&self) -> (f32, f32, f32) {
        (self.l[0], self.l[1], self.psi_f)
    }

    /// The speed reference while the sequence runs the speed loop. [rad/s]
    pub fn speed_setpoint(&self) -> Option<f32> {
        match self.phase {
            Phase::Spin { .. } => Some(self.c.spin_speed_rad_s),
            Phase::Stop => Some(0.0),
            _ => None,
        }
    }

    pub(super) fn next(&mut self, phase: Phase) {
        self.phase = phase;
        self.n = 0;
    }

    pub(super) fn fail(&mut self, f: FaultCode) -> Action {
        self.next(Phase::Failed);
        Action::Fault(f)
    }

    /// True when `v` is finite and within the plausible window around nameplate `k`.
    pub(super) fn plausible(&self, v: f32, k: usize) -> bool {
        let nominal = self.nameplate.get(k).copied().unwrap_or(0.0);
        let r = self.c.plausible_ratio;
        v.is_finite() && v >= nominal / r && v <= nominal * r
    }

    /// Electrical travel since `start`. [rad]
    fn travel(&self, now: i64, start: i64) -> f32 {
        let counts = now.wrapping_sub(start).clamp(-(1 << 24), 1 << 24) as i32 as f32;
        counts * TAU * self.pole_pairs / self.counts_per_rev
    }

    /// One period of the sequence. Not inlined: the controller's ISR body stays as small
    /// as it was when commissioning is idle.
    #[inline(never)]
    pub fn step(&mut self, x: &Input) -> Action {
        self.n = self.n.saturating_add(1);
        self.total = self.total.saturating_add(1);
        match self.phase {
            Phase::Idle | Phase::Done => Action::Off,
            Phase::Failed => Action::Off,
            Phase::Sweep {
                dir,
                start,
                current,
            } => self.sweep_alignment(x, dir, start, current),
            Phase::Hold { dir, angle } => self.hold_alignment(x, dir, angle),
            Phase::Level { high, u, i, u_q } => self.measure_resistance(x, high, u, i, u_q),
            Phase::Pulses { .. } => self.pulse_step(x),
            Phase::Accelerate { sign, w1, i } => self.measure_acceleration(x, sign, w1, i),
            Phase::Spin {
                u_q,
                i_q,
                i_d,
                start,
            } => self.measure_flux(x, u_q, i_q, i_d, start),
            Phase::Stop => self.stop_and_finish(x),
        }
    }

    /// One period of an alignment sweep: the forced angle turns one electrical turn in `dir`;
    /// checks for an open phase early and, at the end, that the encoder followed (step 1).
    #[inline]
    fn sweep_alignment(&mut self, x: &Input, dir: f32, start: i64, mut current: Mean) -> Action {
        let n = self.n;
        let start = if n == 1 { x.position_counts } else { start };
        // The current vector's magnitude does not depend on the frame: over the
        // check window it must reach half the reference, or a phase (or the
        // motor, or the current sensing) is open. Checked early, before the
        // PI has sat at its voltage limit for long.
        let [a, b, c] = x.i_abc;
        let ab = clarke(a, b, c);
        if n > self.p.check.0 && n <= self.p.check.1 {
            current.add(libm::sqrtf(ab.alpha * ab.alpha + ab.beta * ab.beta));
        }
        if n == self.p.check.1 && current.value() < 0.4 * self.c.current_a {
            return self.fail(FaultCode::CommissioningCurrent);
        }
        self.phase = Phase::Sweep {
            dir,
            start,
            current,
        };
        if n >= self.p.sweep {
            // About one electrical turn in the sweep's direction (less the rotor's
            // initial snap of up to half a turn).
            // Backwards (reversed encoder) or hardly at all (no movement).
            let moved = dir * self.travel(x.position_counts, start);
            if moved < 0.25 * TAU {
                return self.fail(FaultCode::CommissioningEncoder);
            }
            self.next(Phase::Hold {
                dir,
                angle: CircularMean::default(),
            });
        }
        let theta = dir * TAU * n as f32 / self.p.sweep as f32;
        self.align(theta, x)
    }

    /// One period of an alignment hold at θ_e = 0: averages the encoder's angle; after the
    /// backward hold, checks the two holds agree and sets the encoder offset (step 1).
    #[inline]
    fn hold_alignment(&mut self, x: &Input, dir: f32, mut angle: CircularMean) -> Action {
        let n = self.n;
        if n > self.p.settle {
            angle.add(x.theta_e_raw);
        }
        self.phase = Phase::Hold { dir, angle };
        if n >= self.p.settle + self.p.average {
            let k = if dir > 0.0 { 0 } else { 1 };
            self.offsets[k] = angle;
            if dir > 0.0 {
                self.next(Phase::Sweep {
                    dir: -1.0,
                    start: 0,
                    current: Mean::default(),
                });
            } else {
                let [a, b] = self.offsets;
                if angle_difference(a.value(), b.value()).abs() > HOLD_AGREEMENT_RAD {
                    return self.fail(FaultCode::CommissioningEncoder);
                }
                let mut both = CircularMean::default();
                both.add_direction(&a);
                both.add_direction(&b);
                self.offset = crate::transforms::wrap_2pi(both.value());
                self.next(Phase::Level {
                    high: false,
                    u: Mean::default(),
                    i: Mean::default(),
                    u_q: Mean::default(),
                });
            }
        }
        self.align(0.0, x)
    }

    /// One period at a d-current level: averages the voltage and current; after the high
    /// level, R_s from the two levels and the hold voltages for the pulses (step 2).
    #[inline]
    fn measure_resistance(
        &mut self,
        x: &Input,
        high: bool,
        mut u: Mean,
        mut i: Mean,
        mut u_q: Mean,
    ) -> Action {
        let i_max = self.c.current_a;
        let n = self.n;
        let i_ref = if high { 0.8 * i_max } else { 0.4 * i_max };
        if n > self.p.settle {
            u.add(x.u_dq_prev.d);
            u_q.add(x.u_dq_prev.q);
            i.add(forced_dq(x).d);
        }
        self.phase = Phase::Level { high, u, i, u_q };
        if n >= self.p.settle + self.p.average {
            let (u, i) = (u.value(), i.value());
            if (i - i_ref).abs() > 0.1 * i_ref {
                return self.fail(FaultCode::CommissioningCurrent);
            }
            if !high {
                self.levels[0] = (u, i);
                self.next(Phase::Level {
                    high: true,
                    u: Mean::default(),
                    i: Mean::default(),
                    u_q: Mean::default(),
                });
            } else {
                self.levels[1] = (u, i);
                self.u_hold = Dq {
                    d: u,
                    q: u_q.value(),
                };
                let (u1, i1) = self.levels[0];
                self.r_s = (u - u1) / (i - i1);
                if !self.plausible(self.r_s, 0) {
                    return self.fail(FaultCode::CommissioningImplausible);
                }
                self.next(Commissioning::pulses(Axis::D));
            }
        }
        Action::Current {
            theta_e: 0.0,
            rotor_frame: false,
            i_ref: Dq {
                d: i_ref,
                q: self.damping(x, i_ref),
            },
        }
    }

    /// One period at constant q-current (`sign`): the acceleration and its mean current once
    /// the target speed is reached, or a fault if the shaft does not follow (step 5).
    #[inline]
    fn measure_acceleration(&mut self, x: &Input, sign: f32, w1: f32, mut i: Mean) -> Action {
        let n = self.n;
        let theta_e = x.theta_e_raw - self.offset;
        let w = x.speed_rad_s;
        let w1 = if n == self.p.accel_settle { w } else { w1 };
        if n > self.p.accel_settle {
            i.add(self.encoder_dq(x).q);
        }
        self.phase = Phase::Accelerate { sign, w1, i };
        let target = if sign > 0.0 { 1.0 } else { 0.3 } * self.c.spin_speed_rad_s;
        if n > 2 * self.p.accel_settle && sign * (w - target) >= 0.0 {
            let dt = (n - self.p.accel_settle) as f32 * self.p.t;
            let k = if sign > 0.0 { 0 } else { 1 };
            self.alpha[k] = ((w - w1) / dt, i.value());
            if sign > 0.0 {
                self.next(Phase::Spin {
                    u_q: Mean::default(),
                    i_q: Mean::default(),
                    i_d: Mean::default(),
                    start: 0,
                });
            } else {
                self.next(Phase::Stop);
            }
        } else if n >= self.p.timeout
            || (sign > 0.0 && w < -0.3 * self.c.spin_speed_rad_s)
            || (sign < 0.0 && w > 1.5 * self.c.spin_speed_rad_s)
        {
            // No speed, or speed the wrong way round: the shaft does not follow.
            return self.fail(FaultCode::CommissioningEncoder);
        }
        Action::Current {
            theta_e,
            rotor_frame: true,
            i_ref: Dq {
                d: 0.0,
                q: sign * self.c.spin_current_a,
            },
        }
    }

    /// One period of speed control at the spin speed: averages u_q, i_q, i_d and the
    /// encoder's travel, then ψ_f (step 5).
    #[inline]
    fn measure_flux(
        &mut self,
        x: &Input,
        mut u_q: Mean,
        mut i_q: Mean,
        mut i_d: Mean,
        start: i64,
    ) -> Action {
        let n = self.n;
        let theta_e = x.theta_e_raw - self.offset;
        let start = if n == self.p.settle {
            x.position_counts
        } else {
            start
        };
        if n > self.p.settle {
            let i = self.encoder_dq(x);
            u_q.add(x.u_dq_prev.q);
            i_q.add(i.q);
            i_d.add(i.d);
        }
        self.phase = Phase::Spin {
            u_q,
            i_q,
            i_d,
            start,
        };
        if n >= self.p.settle + self.p.average {
            let w_e =
                self.travel(x.position_counts, start) / ((n - self.p.settle) as f32 * self.p.t);
            self.psi_f =
                (u_q.value() - self.r_s * i_q.value() - w_e * self.l[0] * i_d.value()) / w_e;
            if !self.plausible(self.psi_f, 3) {
                return self.fail(FaultCode::CommissioningImplausible);
            }
            self.next(Phase::Accelerate {
                sign: -1.0,
                w1: 0.0,
                i: Mean::default(),
            });
        }
        Action::Speed {
            theta_e,
            rad_s: self.c.spin_speed_rad_s,
        }
    }

    /// One period of speed control at standstill, then the result with its gains.
    #[inline]
    fn stop_and_finish(&mut self, x: &Input) -> Action {
        let n = self.n;
        let theta_e = x.theta_e_raw - self.offset;
        if n >= self.p.settle + self.p.average {
            return self.finish();
        }
        Action::Speed {
            theta_e,
            rad_s: 0.0,
        }
    }

    /// Alignment at the forced angle `theta` [rad]: d-current plus speed damping on q.
    fn align(&self, theta: f32, x: &Input) -> Action {
        let i_d = 0.8 * self.c.current_a;
        Action::Current {
            theta_e: theta,
            rotor_frame: false,
            i_ref: Dq {
                d: i_d,
                q: self.damping(x, i_d),
            },
        }
    }

    /// Damping q-current for a rotor locked by the d-current `i_d` [A]: opposes the speed,
    /// limited to ±`i_d`. [A]
    fn damping(&self, x: &Input, i_d: f32) -> f32 {
        crate::pi::saturate(
            -self.c.alignment_damping_a_per_rad_s * x.speed_rad_s,
            -i_d,
            i_d,
        )
    }

    /// d-q currents in the encoder's frame with the identified offset. [A]
    #[inline(never)]
    fn encoder_dq(&self, x: &Input) -> Dq {
        let [a, b, c] = x.i_abc;
        park(clarke(a, b, c), sin_cos(x.theta_e_raw - self.offset))
    }

    fn finish(&mut self) -> Action {
        let k_t = gains::torque_constant(self.pole_pairs, self.psi_f);
        let [(a_up, i_up), (a_down, i_down)] = self.alpha;
        let j = k_t * (i_up - i_down) / (a_up - a_down);
        if !(j.is_finite() && j > 0.0) {
            return self.fail(FaultCode::CommissioningImplausible);
        }
        let c = &self.c;
        self.result = Some(CommissioningResult {
            stator_resistance_ohm: self.r_s,
            d_inductance_h: self.l[0],
            q_inductance_h: self.l[1],
            flux_linkage_wb: self.psi_f,
            encoder_offset_rad: self.offset,
            inertia_kg_m2: j,
            current_gains: gains::current_gains(
                self.r_s,
                self.l[0],
                self.l[1],
                c.current_bandwidth_rad_s,
            ),
            speed_gains: gains::speed_gains(
                j,
                k_t,
                c.speed_natural_frequency_rad_s,
                c.speed_damping_ratio,
                self.ba,
            ),
            duration_s: self.total as f32 * self.p.t,
        });
        self.next(Phase::Done);
        Action::Done
    }
}

/// d-q currents at the forced angle θ_e = 0 (α-β itself). [A]
pub(super) fn forced_dq(x: &Input) -> Dq {
    let [a, b, c] = x.i_abc;
    let ab = clarke(a, b, c);
    Dq {
        d: ab.alpha,
        q: ab.beta,
    }
}
