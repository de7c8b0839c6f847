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
//! | command timeout | no command reached the drive for longer than the timeout, in an active mode | 10 | 2 |
//! | watchdog | the application reported an overrun | 11 | 1 |
//!
//! A deadline of 0 means the very call that read the cause returns the bridge off (one PWM
//! period from cause to gates off); 1, that the next call does (the break and the overrun
//! are reported between calls). The encoder's plausibility limits are the configured
//! plausible speed's step per call (⌈ω·N/(2π·f)⌉ + 2 counts) and that plus two for the
//! index.

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
        }
    }

    /// The overrun was reported before call `period`.
    pub fn overrun(&mut self, period: u64) {
        self.watchdog_at = Some(period);
    }

    /// Forgets the index history (the drive does so on ClearFaults).
    pub fn rearm(&mut self) {
        self.since_index = 0;
    }

    /// The rules that fire in this period.
    pub fn evaluate(&mut self, v: &PeriodView) -> Vec<Fired> {
        let mut out = Vec::new();
        let mut fire = |codes, deadline, rule| {
            out.push(Fired {
                period: v.period,
                codes,
                deadline,
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
        out
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
