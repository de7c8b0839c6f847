//! Commissioning: identifies the motor the drive is connected to and derives the
//! loop gains, as a state machine the controller steps once per PWM period in mode
//! Calibrating after the current offsets are measured.
//!
//! The steps, in order, each with its current limit, its time limit and a plausibility
//! check that faults instead of producing nonsense:
//!
//! 1. **Encoder offset and direction** — the current vector (0.8·I_max on d) is swept one
//!    electrical turn forward at a forced angle and held at θ_e = 0, then one turn back and
//!    held again; the rotor follows and settles on the d axis (q-current proportional to
//!    speed damps its ringing). The offset is the circular mean of the encoder's electrical
//!    angle over both holds, so friction and load torque, which displace the rotor opposite
//!    ways in the two directions, cancel. The encoder must travel about one electrical turn
//!    in the sweep's direction: opposite means reversed, little means no movement (fault
//!    15); the two holds must agree within 20°.
//! 2. **R_s** — d-current at 0.4·I_max and 0.8·I_max with the rotor locked on d, the PI's
//!    mean voltage at each: R_s = ΔU/ΔI, which cancels the inverter's dead-time voltage
//!    error (a constant once every phase current is beyond the dead-time band). A level the
//!    loop cannot reach is an open phase (fault 13).
//! 3. **L_d, L_q** — open-loop voltage pulses ±U_p on one axis around the bias (0.8·I_max
//!    on d, the hold voltages of step 2 on both axes): +U_p until the current has risen by
//!    0.4·I_max (this sets the pulse length n), then cycles of +U_p for n, −U_p for 2n,
//!    +U_p for n periods, which swing the current ±0.4·I_max and leave no net torque
//!    impulse on q. Per segment, eq. 2 at standstill integrated exactly over the held
//!    voltages gives L·Δi = Σ(u − u_hold)·T − R_s·∫(i − i_bias)dt; L is the least-squares
//!    slope over all segments. A pulse that does not reach its current in time is fault 13.
//! 4. **Current gains** — Kp = L·ω_c, Ki = R_s·ω_c ([`gains`]); the current loop uses them
//!    from here on.
//! 5. **Inertia and ψ_f** — with the identified offset: constant +i_q until the spin speed,
//!    speed control there, constant −i_q down to 30 %. ψ_f = (ū_q − R_s·ī_q −
//!    ω̄_e·L_d·ī_d)/ω̄_e (eq. 2 in steady state) over the speed-controlled window, ω̄_e from
//!    the encoder's travel. J = K_t·(ī₊ − ī₋)/(α₊ − α₋) from the two accelerations, so a
//!    load torque common to both cancels. No speed reached in time, or the wrong sign, is
//!    fault 15.
//!
//! Any identified value outside [nameplate / r, nameplate · r] (`plausible_ratio`) or not
//! finite is fault 14.
//!
//! Accuracy on the plant model with noise and quantisation (`tests/tests/commissioning.rs`,
//! 20 rigs with R_s, L_d, L_q, ψ_f off by up to ±30 %): R_s, L_d, ψ_f within 0.1 %, L_q
//! biased low by up to 1.1 % (the back-EMF of the rotor's small motion under the q pulses,
//! see [`CommissioningConfig::pulse_voltage_v`]), the offset within 0.2° electrical, J
//! about +1.5 %. Known limit: with inverter dead time the spin's small q-current sits in
//! the dead-time band, whose voltage error reads as extra back-EMF (ψ_f +1.6 % at 1 µs)
//! and as torque error in J (+8 %); R_s and the inductances are unaffected.

pub mod config;
pub mod estimate;
pub mod gains;

pub use config::CommissioningConfig;
pub use gains::{CurrentGains, SpeedGains};

use crate::config::Config;
use crate::supervisor::FaultCode;
use crate::transforms::{clarke, park, sin_cos, Dq};
use core::f32::consts::TAU;
use estimate::{angle_difference, CircularMean, Mean, SlopeFit};

/// Largest disagreement of the two alignment holds. [rad]
const HOLD_AGREEMENT_RAD: f32 = 20.0 * core::f32::consts::PI / 180.0;
/// Window of the open-phase check at the start of each sweep, from its first period
/// (from 5 ms, when the current loop has settled at τ = 0.9 ms, to 10 ms). [s]
const CURRENT_CHECK_S: (f32, f32) = (5e-3, 10e-3);
/// Settling time of the speed estimate before an acceleration is measured. [s]
const ACCEL_SETTLE_S: f32 = 6e-3;

/// What the controller gives the sequence each period.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Input {
    /// Phase currents of this sample. [A]
    pub i_abc: [f32; 3],
    /// The d-q voltage commanded in the previous period (applied since). [V]
    pub u_dq_prev: Dq,
    /// Encoder electrical angle without any offset, p_n·2π·count/N. [rad]
    pub theta_e_raw: f32,
    /// Unwrapped encoder position. [counts]
    pub position_counts: i64,
    /// Shaft speed, low-pass filtered but updated every period (the speed observer's
    /// integrator: under constant acceleration it lags by a constant, which cancels in the
    /// acceleration measurement). [rad/s]
    pub speed_rad_s: f32,
}

/// What the controller does this period.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Action {
    /// Bridge off.
    Off,
    /// Current loop to `i_ref` [A] at the electrical angle `theta_e` [rad].
    Current {
        /// Angle of the d-q frame. [rad]
        theta_e: f32,
        /// The frame is the rotor's (encoder angle), so the speed-voltage decoupling
        /// applies; false for a forced angle, where the frame does not turn with the shaft
        /// and ω_e·(L_d·i_d + ψ_f) fed forward would push a q-current in phase with the
        /// speed: negative damping of the locked rotor.
        rotor_frame: bool,
        /// Current reference. [A]
        i_ref: Dq,
    },
    /// Open-loop voltage `u` [V] at `theta_e` [rad].
    Voltage {
        /// Angle of the d-q frame. [rad]
        theta_e: f32,
        /// Voltage. [V]
        u: Dq,
    },
    /// Speed loop to `rad_s` [rad/s] (i_d = 0) at the electrical angle `theta_e` [rad].
    Speed {
        /// Angle of the d-q frame. [rad]
        theta_e: f32,
        /// Speed reference. [rad/s]
        rad_s: f32,
    },
    /// Finished: the result is in [`Commissioning::result`].
    Done,
    /// Failed with a fault code (13, 14 or 15).
    Fault(FaultCode),
}

/// What commissioning identified (SI) and the gains derived from it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CommissioningResult {
    /// Stator resistance R_s. [Ω]
    pub stator_resistance_ohm: f32,
    /// d-axis inductance L_d. [H]
    pub d_inductance_h: f32,
    /// q-axis inductance L_q. [H]
    pub q_inductance_h: f32,
    /// Magnet flux linkage ψ_f. [Wb]
    pub flux_linkage_wb: f32,
    /// Encoder offset: θ_e = p_n·θ_count − offset, in [0, 2π). [rad]
    pub encoder_offset_rad: f32,
    /// Shaft inertia (motor and pump). [kg·m²]
    pub inertia_kg_m2: f32,
    /// Current-loop gains for the configured bandwidth.
    pub current_gains: CurrentGains,
    /// Speed-loop gains for the configured natural frequency and damping.
    pub speed_gains: SpeedGains,
    /// Time the sequence took (from its first sample, current offsets excluded). [s]
    pub duration_s: f32,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Axis {
    D,
    Q,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Phase {
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
struct Periods {
    t: f32,
    settle: u32,
    average: u32,
    sweep: u32,
    timeout: u32,
    accel_settle: u32,
    check: (u32, u32),
}

/// The sequence's state.
#[derive(Clone, Copy, Debug)]
pub struct Commissioning {
    c: CommissioningConfig,
    nameplate: [f32; 4],
    pole_pairs: f32,
    counts_per_rev: f32,
    ba: f32,
    p: Periods,
    phase: Phase,
    /// Periods in the present phase.
    n: u32,
    /// Periods since the start.
    total: u32,
    offsets: [CircularMean; 2],
    offset: f32,
    levels: [(f32, f32); 2],
    u_hold: Dq,
    r_s: f32,
    l: [f32; 2],
    psi_f: f32,
    pulse_len: u32,
    alpha: [(f32, f32); 2],
    new_gains: Option<CurrentGains>,
    result: Option<CommissioningResult>,
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

    fn next(&mut self, phase: Phase) {
        self.phase = phase;
        self.n = 0;
    }

    fn fail(&mut self, f: FaultCode) -> Action {
        self.next(Phase::Failed);
        Action::Fault(f)
    }

    /// True when `v` is finite and within the plausible window around nameplate `k`.
    fn plausible(&self, v: f32, k: usize) -> bool {
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
        let i_max = self.c.current_a;
        let n = self.n;
        match self.phase {
            Phase::Idle | Phase::Done => Action::Off,
            Phase::Failed => Action::Off,
            Phase::Sweep {
                dir,
                start,
                mut current,
            } => {
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
            Phase::Hold { dir, mut angle } => {
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
            Phase::Level {
                high,
                mut u,
                mut i,
                mut u_q,
            } => {
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
            Phase::Pulses { .. } => self.pulse_step(x),
            Phase::Accelerate { sign, w1, mut i } => {
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
            Phase::Spin {
                mut u_q,
                mut i_q,
                mut i_d,
                start,
            } => {
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
                    let w_e = self.travel(x.position_counts, start)
                        / ((n - self.p.settle) as f32 * self.p.t);
                    self.psi_f =
                        (u_q.value() - self.r_s * i_q.value() - w_e * self.l[0] * i_d.value())
                            / w_e;
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
            Phase::Stop => {
                let theta_e = x.theta_e_raw - self.offset;
                if n >= self.p.settle + self.p.average {
                    return self.finish();
                }
                Action::Speed {
                    theta_e,
                    rad_s: 0.0,
                }
            }
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

    /// The pulse phase for `axis`.
    fn pulses(axis: Axis) -> Phase {
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

    /// d-q currents in the encoder's frame with the identified offset. [A]
    #[inline(never)]
    fn encoder_dq(&self, x: &Input) -> Dq {
        let [a, b, c] = x.i_abc;
        park(clarke(a, b, c), sin_cos(x.theta_e_raw - self.offset))
    }

    /// One period of the inductance pulses (see the module documentation, step 3).
    fn pulse_step(&mut self, x: &Input) -> Action {
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
fn forced_dq(x: &Input) -> Dq {
    let [a, b, c] = x.i_abc;
    let ab = clarke(a, b, c);
    Dq {
        d: ab.alpha,
        q: ab.beta,
    }
}
