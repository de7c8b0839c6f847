//! What the drive must see, and by when: the campaign's rules, evaluated every PWM period on
//! what the drive was given (its ADC results and encoder count) and on the plant's truth,
//! independently of the control core's code. Each rule names the fault codes that answer
//! it and its deadline in current-loop calls after the period it fires in:
//!
//! | rule | fires when | codes | deadline |
//! |---|---|---|---|
//! | over-current (truth) | a bridge current at the sampling instant above the trip level plus the reading's noise | 1, 17 | 0 |
//! | over-current (reading) | a phase-current reading above the trip level | 1 | 0 |
//! | hardware break | the plant's break switched the gates off during the period | 17, 1 | 1 |
//! | DC link | the DC-link reading beyond the under- or over-voltage level | 3 / 2 | 0 |
//! | transducer | the reading below the open-wire or above the short level, or a pressure above the over-pressure level | 5 / 6 / 4 | 0 |
//! | encoder | a count step beyond the plausible speed's, an index far from count 0, a revolution and its margin without an index | 7, 8 | 0 |
//! | over-speed (truth) | the shaft above the over-speed level by 2 % | 9 | two speed-loop periods |
//! | current sum | the three phase-current readings sum beyond the plausible level (plus the offsets' tolerance until they are measured, and while a calibration measures them again) | 19 | 0 |
//! | stall (truth) | the bridge has driven 90 % of the q-current limit into a shaft turning below a tenth of the speed limit for 90 % of the stall time | 20 | 30 % of the stall time |
//! | command timeout | no command reached the drive for longer than the timeout, in an active mode | 10 | 2 |
//! | watchdog | the application reported an overrun | 11 | 1 |
//!
//! A deadline of 0 means the very call that read the cause returns the bridge off (one PWM
//! period from cause to gates off); 1, that the next call does (the break and the overrun
//! are reported between calls). The encoder's plausibility limits are the configured
//! plausible speed's step per call (⌈ω·N/(2π·f)⌉ + 2 counts) and that plus two for the
//! index; "the shaft measured" is the encoder's count travel over a speed-loop period.
//! The current sum is taken with the offsets the drive calibrated.
//!
//! Two rules permit a code without requiring it: over-speed as the encoder reads it (the
//! drive's speed estimate filters the counts, so a burst of spurious counts may or may not
//! carry it over the level) permits 9; a fault injected during the commissioning sequence
//! permits the sequence's own checks (12–15).

use firmware::{Config, FaultCode, Measurements, Mode};

/// A rule that fired: when, which codes answer it, by when.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fired {
    /// The period it fired in (since the injection). [calls]
    pub period: u64,
    /// The codes that answer it.
    pub codes: &'static [FaultCode],
    /// Calls after `period` by which one must be latched. [calls]
    pub deadline: u64,
    /// A code must answer it (else the rule only permits one).
    pub must: bool,
    /// Its name.
    pub rule: &'static str,
}

const OC: &[FaultCode] = &[FaultCode::PhaseOverCurrent, FaultCode::HardwareBreak];
const OC_READ: &[FaultCode] = &[FaultCode::PhaseOverCurrent];
const BREAK: &[FaultCode] = &[FaultCode::HardwareBreak, FaultCode::PhaseOverCurrent];
const UV: &[FaultCode] = &[FaultCode::DcLinkUnderVoltage];
const OV: &[FaultCode] = &[FaultCode::DcLinkOverVoltage];
const OPEN: &[FaultCode] = &[FaultCode::PressureSensorOpenWire];
const SHORT: &[FaultCode] = &[FaultCode::PressureSensorShort];
const OP: &[FaultCode] = &[FaultCode::OverPressure];
const ENC: &[FaultCode] = &[FaultCode::EncoderJump, FaultCode::EncoderIndexLost];
const OS: &[FaultCode] = &[FaultCode::OverSpeed];
const TIMEOUT: &[FaultCode] = &[FaultCode::CommandTimeout];
const WATCHDOG: &[FaultCode] = &[FaultCode::Watchdog];
const SUM: &[FaultCode] = &[FaultCode::PhaseCurrentSum];
const STALL: &[FaultCode] = &[FaultCode::Stall];
const COMMISSIONING: &[FaultCode] = &[
    FaultCode::CurrentOffset,
    FaultCode::CommissioningCurrent,
    FaultCode::CommissioningImplausible,
    FaultCode::CommissioningEncoder,
];

/// What one period gives the rules.
#[derive(Clone, Copy, Debug)]
pub struct PeriodView<'a> {
    /// Calls since the injection.
    pub period: u64,
    /// What the controller was given.
    pub m: &'a Measurements,
    /// The bridge currents at the sampling instant. [A]
    pub i_bridge_a: [f64; 3],
    /// The shaft speed. [rad/s]
    pub omega_rad_s: f64,
    /// The break switched the gates off during this period.
    pub broke: bool,
    /// Time since a command last reached the drive. [s]
    pub silent_s: f64,
    /// The mode the controller was in during the call.
    pub mode: Mode,
    /// The motor's d-q currents at the sampling instant. [A]
    pub i_dq_a: (f64, f64),
    /// The controller has measured its current offsets.
    pub calibrated: bool,
    /// The zero-current ADC results the controller uses. [counts]
    pub offsets_lsb: [f32; 3],
}

/// The rules' state (the encoder's history) and limits.
#[derive(Clone, Debug)]
pub struct Spec {
    cfg: Config,
    max_step: i64,
    index_margin: i64,
    last_count: Option<u32>,
    since_index: i64,
    watchdog_at: Option<u64>,
    stall_calls: u64,
    /// The unwrapped count at the last speed-loop period's calls. [counts]
    positions: std::collections::VecDeque<i64>,
    position: i64,
    injected: bool,
}

impl Spec {
    /// The rules for the controller configuration `cfg`.
    pub fn new(cfg: &Config) -> Spec {
        let n = f64::from(cfg.sensors.encoder_counts_per_rev);
        let per_call = f64::from(cfg.limits.encoder_plausible_speed_rad_s) * n
            / (std::f64::consts::TAU * f64::from(cfg.rates.pwm_hz));
        let max_step = per_call.ceil() as i64 + 2;
        Spec {
            cfg: *cfg,
            max_step,
            index_margin: max_step + 2,
            last_count: None,
            since_index: 0,
            watchdog_at: None,
            stall_calls: 0,
            positions: std::collections::VecDeque::new(),
            position: 0,
            injected: false,
        }
    }

    /// The overrun was reported before call `period`.
    pub fn overrun(&mut self, period: u64) {
        self.watchdog_at = Some(period);
    }

    /// A fault was injected before the next call.
    pub fn injected(&mut self) {
        self.injected = true;
    }

    /// Forgets the index history (the drive does so on ClearFaults).
    pub fn rearm(&mut self) {
        self.since_index = 0;
    }

    /// The rules that fire in this period.
    pub fn evaluate(&mut self, v: &PeriodView) -> Vec<Fired> {
        let speed = self.count_speed(v.m);
        let mut out = Vec::new();
        let mut fire = |codes, deadline, rule| {
            out.push(Fired {
                period: v.period,
                codes,
                deadline,
                must: true,
                rule,
            })
        };
        let encoder = self.encoder(v.m);
        let s = &self.cfg.sensors;
        let l = &self.cfg.limits;
        let oc = f64::from(l.over_current_a);
        // The reading's own error at the trip level: four noise rms and one count.
        let margin = 4.0 * 0.02 + f64::from(s.current_a_per_lsb);
        if v.i_bridge_a.iter().any(|i| i.abs() > oc + margin) {
            fire(OC, 0, "over-current (truth)");
        }
        let amps = |c: u16| (f32::from(c) - s.current_zero_lsb) * s.current_a_per_lsb;
        if v.m
            .adc_phase_current
            .iter()
            .any(|c| amps(*c).abs() > l.over_current_a)
        {
            fire(OC_READ, 0, "over-current (reading)");
        }
        if v.broke {
            fire(BREAK, 1, "hardware break");
        }
        let u = f32::from(v.m.adc_dc_link) * s.dc_link_v_per_lsb;
        if u < l.under_voltage_v {
            fire(UV, 0, "under-voltage");
        }
        if u > l.over_voltage_v {
            fire(OV, 0, "over-voltage");
        }
        let p = v.m.adc_pressure;
        let pa = (f32::from(p) - s.pressure_zero_lsb) * s.pressure_pa_per_lsb;
        if p < s.pressure_open_wire_lsb {
            fire(OPEN, 0, "transducer open");
        } else if p > s.pressure_short_lsb {
            fire(SHORT, 0, "transducer short");
        } else if pa > l.over_pressure_pa {
            fire(OP, 0, "over-pressure");
        }
        if let Some(rule) = encoder {
            fire(ENC, 0, rule);
        }
        let speed_calls = (self.cfg.rates.pwm_hz / self.cfg.rates.speed_loop_hz).round() as u64;
        if v.omega_rad_s.abs() > 1.02 * f64::from(l.over_speed_rad_s) {
            fire(OS, 2 * speed_calls, "over-speed (truth)");
        }
        if v.mode.is_active() && v.silent_s > f64::from(l.command_timeout_s) {
            fire(TIMEOUT, 2, "command timeout");
        }
        if self.watchdog_at == Some(v.period) {
            fire(WATCHDOG, 1, "overrun");
        }
        let sum: f32 =
            v.m.adc_phase_current
                .iter()
                .zip(v.offsets_lsb)
                .map(|(c, o)| (f32::from(*c) - o) * s.current_a_per_lsb)
                .sum();
        let allowance = if v.calibrated && v.mode != Mode::Calibrating {
            0.0
        } else {
            3.0 * self.cfg.calibration.offset_max_lsb * s.current_a_per_lsb
        };
        // A margin for the f32 arithmetic's order.
        if sum.abs() > l.current_sum_a + allowance + 1e-3 {
            fire(SUM, 0, "current sum");
        }
        let calls = |t: f32| (t * self.cfg.rates.pwm_hz).round() as u64;
        let sp = &self.cfg.speed;
        let driving = (v.i_dq_a.0.hypot(v.i_dq_a.1)) >= 0.9 * f64::from(sp.iq_limit_a);
        let at_rest = speed.abs() < 0.1 * f64::from(sp.speed_limit_rad_s);
        let running = matches!(v.mode, Mode::Speed | Mode::Pressure);
        self.stall_calls = if running && driving && at_rest {
            self.stall_calls + 1
        } else {
            0
        };
        if self.stall_calls == calls(0.9 * l.stall_time_s) {
            fire(STALL, calls(0.3 * l.stall_time_s), "stall");
        }
        let mut permit = |codes, rule| {
            out.push(Fired {
                period: v.period,
                codes,
                deadline: u64::MAX,
                must: false,
                rule,
            })
        };
        if speed.abs() > f64::from(l.over_speed_rad_s) {
            permit(OS, "over-speed (counts)");
        }
        if std::mem::take(&mut self.injected) && v.mode == Mode::Calibrating {
            permit(COMMISSIONING, "commissioning's checks");
        }
        out
    }

    /// The shaft's speed as the encoder's counts give it over the last speed-loop period.
    /// [rad/s]
    fn count_speed(&mut self, m: &Measurements) -> f64 {
        let n = i64::from(self.cfg.sensors.encoder_counts_per_rev);
        let count = i64::from(m.encoder_count) % n;
        if let Some(last) = self.last_count {
            let mut delta = count - i64::from(last);
            if delta >= n / 2 {
                delta -= n;
            } else if delta < -n / 2 {
                delta += n;
            }
            self.position += delta;
        }
        let window = (self.cfg.rates.pwm_hz / self.cfg.rates.speed_loop_hz).round() as usize;
        self.positions.push_back(self.position);
        if self.positions.len() > window + 1 {
            self.positions.pop_front();
        }
        let travel = self.position - self.positions.front().copied().unwrap_or(self.position);
        let span = (self.positions.len().saturating_sub(1)).max(1) as f64;
        travel as f64 * std::f64::consts::TAU / n as f64 * f64::from(self.cfg.rates.pwm_hz) / span
    }

    /// The encoder's plausibility: a step beyond the plausible speed's, an index far from
    /// count 0, a revolution and its margin without an index.
    fn encoder(&mut self, m: &Measurements) -> Option<&'static str> {
        let n = i64::from(self.cfg.sensors.encoder_counts_per_rev);
        let count = i64::from(m.encoder_count) % n;
        let last = self.last_count.replace(count as u32)?;
        let mut delta = count - i64::from(last);
        if delta >= n / 2 {
            delta -= n;
        } else if delta < -n / 2 {
            delta += n;
        }
        if delta.abs() > self.max_step {
            return Some("encoder jump");
        }
        if m.encoder_index {
            let from_zero = if count < n / 2 { count } else { count - n };
            self.since_index = from_zero;
            if from_zero.abs() > self.index_margin {
                return Some("index far from 0");
            }
        } else {
            self.since_index += delta;
            if self.since_index.abs() > n + self.index_margin {
                self.since_index = 0;
                return Some("index missing");
            }
        }
        None
    }
}
