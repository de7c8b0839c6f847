//! Supervisor: the operating modes and the latched faults of the drive.
//!
//! Every current-loop call the controller hands the supervisor the conditions it measured;
//! the first fault condition seen in an active mode latches its [`FaultCode`], drops the
//! mode to [`Mode::Disabled`] and the controller returns disabled PWM from that same call.
//! A latched fault is cleared only by command ([`Supervisor::clear`]), and only once its
//! cause is gone; event faults (encoder jump, command timeout, watchdog) have no lasting
//! cause, so the clear command itself is enough.
//!
//! Conditions are evaluated in every mode (so telemetry and the clear check see them) but
//! latch only while the bridge is on (Calibrating, Speed, Pressure): a drive at rest with
//! the DC link off is not faulted, and entering an active mode is refused while any
//! condition is present.
//!
//! Entering an active mode also needs the drive to be ready ([`Readiness`]): the phase-
//! current offsets measured since power-up (every active mode), and the rotor angle known
//! — the encoder tied to its index, or an alignment run — in this power cycle (Speed and
//! Pressure; Calibrating is how the angle is found).

use core::fmt;

/// Operating mode.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
#[repr(u8)]
pub enum Mode {
    /// Bridge off.
    #[default]
    Disabled = 0,
    /// Current-offset calibration (bridge off) then encoder alignment (d-axis current).
    Calibrating = 1,
    /// Speed control from the speed setpoint.
    Speed = 2,
    /// Pressure control from the pressure setpoint.
    Pressure = 3,
}

impl Mode {
    /// Wire/telemetry code.
    pub fn code(self) -> u8 {
        self as u8
    }

    /// Every mode, in code order.
    pub const ALL: [Mode; 4] = [
        Mode::Disabled,
        Mode::Calibrating,
        Mode::Speed,
        Mode::Pressure,
    ];

    /// From the wire/telemetry code.
    pub fn from_code(code: u8) -> Option<Mode> {
        Mode::ALL.into_iter().find(|m| m.code() == code)
    }

    /// The mode's name as tools show it (`disabled`, `calibrating`, `speed`, `pressure`).
    pub fn name(self) -> &'static str {
        match self {
            Mode::Disabled => "disabled",
            Mode::Calibrating => "calibrating",
            Mode::Speed => "speed",
            Mode::Pressure => "pressure",
        }
    }

    /// True when the bridge may be on.
    pub fn is_active(self) -> bool {
        self != Mode::Disabled
    }
}

/// Latched fault codes (telemetry code in brackets; 0 = no fault).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum FaultCode {
    /// A phase current above `limits.over_current_a`. (1)
    PhaseOverCurrent = 1,
    /// DC link above `limits.over_voltage_v`. (2)
    DcLinkOverVoltage = 2,
    /// DC link below `limits.under_voltage_v`. (3)
    DcLinkUnderVoltage = 3,
    /// Pressure above `limits.over_pressure_pa`. (4)
    OverPressure = 4,
    /// Pressure ADC below the open-wire threshold. (5)
    PressureSensorOpenWire = 5,
    /// Pressure ADC above the short-circuit threshold. (6)
    PressureSensorShort = 6,
    /// Encoder count moved implausibly far in one period. (7)
    EncoderJump = 7,
    /// Encoder index missing for more than a revolution, or far from count 0. (8)
    EncoderIndexLost = 8,
    /// Speed magnitude above `limits.over_speed_rad_s`. (9)
    OverSpeed = 9,
    /// No command within `limits.command_timeout_s` in an active mode. (10)
    CommandTimeout = 10,
    /// The application reported a control-loop overrun, or the previous run ended in an
    /// independent-watchdog reset (a stalled loop, a panic or a HardFault). (11)
    Watchdog = 11,
    /// Calibrated current offsets out of range. (12)
    CurrentOffset = 12,
    /// Commissioning: a current step not reached (open phase, disconnected motor). (13)
    CommissioningCurrent = 13,
    /// Commissioning: an identified value not finite or outside the plausible window
    /// around the nameplate. (14)
    CommissioningImplausible = 14,
    /// Commissioning: the encoder moved backwards (reversed), not at all, or the shaft did
    /// not follow the current vector. (15)
    CommissioningEncoder = 15,
    /// The stored parameter table was corrupt, of another version or inconsistent: the
    /// defaults were loaded instead. (16)
    ParameterStoreInvalid = 16,
    /// The power stage's hardware break cut the bridge: the gate driver's fault line, a
    /// phase-current comparator (short circuit, within microseconds) or a break forced by
    /// the firmware itself (a stalled loop). (17)
    HardwareBreak = 17,
    /// The flash is not in the dual-bank layout the parameter store lives in (option bit
    /// DBANK cleared): nothing was loaded, the defaults are in use and saves are refused.
    /// (18)
    ParameterFlashLayout = 18,
    /// The three phase currents do not sum to zero within `limits.current_sum_a`: a current
    /// channel stuck, off in gain or clipping, or current leaving the star through a short
    /// to a rail or earth. (19)
    PhaseCurrentSum = 19,
    /// The q-current reference at its limit for `limits.stall_time_s` with the shaft
    /// measured below a tenth of the speed limit: a locked rotor, or an encoder that does
    /// not see the shaft turn (stuck, reversed). (20)
    Stall = 20,
    /// The stored torque feed-forward table was refused (wrong size, format version or
    /// CRC, or an amplitude above `compensation.max_current_a`): the drive runs
    /// uncompensated. (21)
    CompensationTableInvalid = 21,
}

impl FaultCode {
    /// All codes, in bit order.
    pub const ALL: [FaultCode; 21] = [
        FaultCode::PhaseOverCurrent,
        FaultCode::DcLinkOverVoltage,
        FaultCode::DcLinkUnderVoltage,
        FaultCode::OverPressure,
        FaultCode::PressureSensorOpenWire,
        FaultCode::PressureSensorShort,
        FaultCode::EncoderJump,
        FaultCode::EncoderIndexLost,
        FaultCode::OverSpeed,
        FaultCode::CommandTimeout,
        FaultCode::Watchdog,
        FaultCode::CurrentOffset,
        FaultCode::CommissioningCurrent,
        FaultCode::CommissioningImplausible,
        FaultCode::CommissioningEncoder,
        FaultCode::ParameterStoreInvalid,
        FaultCode::HardwareBreak,
        FaultCode::ParameterFlashLayout,
        FaultCode::PhaseCurrentSum,
        FaultCode::Stall,
        FaultCode::CompensationTableInvalid,
    ];

    /// Largest telemetry code.
    pub const MAX_CODE: u8 = FaultCode::CompensationTableInvalid as u8;

    /// Telemetry code (1..=[`FaultCode::MAX_CODE`]).
    pub fn code(self) -> u8 {
        self as u8
    }

    /// From the telemetry code.
    pub fn from_code(code: u8) -> Option<FaultCode> {
        FaultCode::ALL.iter().copied().find(|f| f.code() == code)
    }

    /// Bit in a [`Conditions`] mask.
    pub fn bit(self) -> u32 {
        1 << (self as u8 - 1)
    }

    /// True for faults that are events without a lasting cause.
    pub fn is_event(self) -> bool {
        matches!(
            self,
            FaultCode::EncoderJump
                | FaultCode::EncoderIndexLost
                | FaultCode::CommandTimeout
                | FaultCode::Watchdog
                | FaultCode::CurrentOffset
                | FaultCode::CommissioningCurrent
                | FaultCode::CommissioningImplausible
                | FaultCode::CommissioningEncoder
                | FaultCode::ParameterStoreInvalid
                | FaultCode::HardwareBreak
                | FaultCode::ParameterFlashLayout
                | FaultCode::Stall
                | FaultCode::CompensationTableInvalid
        )
    }
}

impl FaultCode {
    /// What the fault means, in a few words (`phase over-current`).
    pub fn description(self) -> &'static str {
        match self {
            FaultCode::PhaseOverCurrent => "phase over-current",
            FaultCode::DcLinkOverVoltage => "DC-link over-voltage",
            FaultCode::DcLinkUnderVoltage => "DC-link under-voltage",
            FaultCode::OverPressure => "over-pressure",
            FaultCode::PressureSensorOpenWire => "pressure sensor open wire",
            FaultCode::PressureSensorShort => "pressure sensor short",
            FaultCode::EncoderJump => "encoder jump",
            FaultCode::EncoderIndexLost => "encoder index lost",
            FaultCode::OverSpeed => "over-speed",
            FaultCode::CommandTimeout => "command timeout",
            FaultCode::Watchdog => "watchdog (control-loop overrun)",
            FaultCode::CurrentOffset => "current offset out of range",
            FaultCode::CommissioningCurrent => "commissioning: current not reached (open phase?)",
            FaultCode::CommissioningImplausible => "commissioning: implausible identified value",
            FaultCode::CommissioningEncoder => {
                "commissioning: encoder reversed or shaft not moving"
            }
            FaultCode::ParameterStoreInvalid => "stored parameters invalid, defaults loaded",
            FaultCode::HardwareBreak => {
                "hardware break (gate-driver fault, comparator over-current or forced)"
            }
            FaultCode::ParameterFlashLayout => {
                "flash not dual-bank (DBANK option bit): parameter store unavailable"
            }
            FaultCode::PhaseCurrentSum => {
                "phase currents do not sum to zero (current sensor or earth fault)"
            }
            FaultCode::Stall => "stall: current at its limit, shaft not turning",
            FaultCode::CompensationTableInvalid => {
                "stored torque feed-forward table refused, running uncompensated"
            }
        }
    }
}

impl fmt::Display for FaultCode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "fault {}: {}", self.code(), self.description())
    }
}

/// Set of fault conditions present in one sample (bit = [`FaultCode::bit`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Conditions(pub u32);

impl Conditions {
    /// Adds `f` when `present`.
    #[inline]
    pub fn set(&mut self, f: FaultCode, present: bool) {
        if present {
            self.0 |= f.bit();
        }
    }

    /// True when `f` is present.
    pub fn has(self, f: FaultCode) -> bool {
        self.0 & f.bit() != 0
    }

    /// The present condition with the lowest code (the most basic cause first): the lowest
    /// set bit, since [`FaultCode::ALL`] is in bit order (none when no bit, or only bits no
    /// code has, are set).
    #[inline]
    pub fn first(self) -> Option<FaultCode> {
        FaultCode::ALL
            .get(self.0.trailing_zeros() as usize)
            .copied()
    }
}

/// What an active mode waits for besides the absence of faults.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Readiness {
    /// The phase-current offsets have been measured since power-up.
    pub current_offsets: bool,
    /// The electrical angle is known: the encoder is tied to its index, or an alignment
    /// ran, in this power cycle.
    pub rotor_angle: bool,
}

impl Readiness {
    /// Nothing to wait for.
    pub const READY: Readiness = Readiness {
        current_offsets: true,
        rotor_angle: true,
    };

    /// What `mode` still waits for, if anything.
    pub fn missing_for(self, mode: Mode) -> Option<NotReady> {
        if mode.is_active() && !self.current_offsets {
            Some(NotReady::CurrentOffsets)
        } else if matches!(mode, Mode::Speed | Mode::Pressure) && !self.rotor_angle {
            Some(NotReady::RotorAngle)
        } else {
            None
        }
    }
}

impl Default for Readiness {
    fn default() -> Self {
        Readiness::READY
    }
}

/// Why a drive is not ready for a mode (the wire code in brackets).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum NotReady {
    /// The phase-current offsets are still being measured (bridge off, for
    /// `calibration.offset_time_s` after power-up). (1)
    CurrentOffsets = 1,
    /// No encoder index since power-up and no alignment: the electrical angle is unknown.
    /// Turn the shaft past the index, or run Calibrating. (2)
    RotorAngle = 2,
}

impl NotReady {
    /// Wire code.
    pub fn code(self) -> u8 {
        self as u8
    }
}

impl fmt::Display for NotReady {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            NotReady::CurrentOffsets => "current offsets not measured yet",
            NotReady::RotorAngle => {
                "rotor angle unknown (no encoder index and no alignment since power-up)"
            }
        })
    }
}

/// Mode and latched-fault state.
#[derive(Clone, Copy, Debug, Default)]
pub struct Supervisor {
    mode: Mode,
    fault: Option<FaultCode>,
    present: Conditions,
    readiness: Readiness,
}

impl Supervisor {
    /// Disabled, no fault.
    pub fn new() -> Supervisor {
        Supervisor::default()
    }

    /// Current mode.
    pub fn mode(&self) -> Mode {
        self.mode
    }

    /// Latched fault.
    pub fn fault(&self) -> Option<FaultCode> {
        self.fault
    }

    /// Conditions of the last sample.
    pub fn conditions(&self) -> Conditions {
        self.present
    }

    /// Takes one sample's conditions; latches the first one while active. Returns true when
    /// the bridge may stay on after this call.
    #[inline]
    pub fn check(&mut self, conditions: Conditions) -> bool {
        self.present = conditions;
        if self.mode.is_active() {
            if let Some(f) = conditions.first() {
                self.trip(f);
            }
        }
        self.fault.is_none() && self.mode.is_active()
    }

    /// Latches `f` (keeps an earlier fault) and disables the bridge.
    pub fn trip(&mut self, f: FaultCode) {
        if self.fault.is_none() {
            self.fault = Some(f);
        }
        self.mode = Mode::Disabled;
    }

    /// Sets what the drive is ready for (the controller's measurements of this power cycle).
    pub fn set_readiness(&mut self, readiness: Readiness) {
        self.readiness = readiness;
    }

    /// What the drive is ready for.
    pub fn readiness(&self) -> Readiness {
        self.readiness
    }

    /// Clears the latched fault if its cause is gone (event faults: always). On refusal,
    /// returns the fault whose cause is still present.
    pub fn clear(&mut self) -> Result<(), FaultCode> {
        match self.fault {
            Some(f) if !f.is_event() && self.present.has(f) => Err(f),
            _ => {
                self.fault = None;
                Ok(())
            }
        }
    }

    /// Requests `mode`. Disabled is always granted; an active mode needs no latched fault,
    /// no present condition and the drive ready for it ([`Readiness`]); Calibrating is
    /// entered only from Disabled; Speed and Pressure switch between each other directly.
    pub fn request(&mut self, mode: Mode) -> Result<(), ModeRefusal> {
        if mode == Mode::Disabled {
            self.mode = mode;
            return Ok(());
        }
        if let Some(f) = self.fault {
            return Err(ModeRefusal::Faulted(f));
        }
        if let Some(f) = self.present.first() {
            return Err(ModeRefusal::ConditionPresent(f));
        }
        if let Some(r) = self.readiness.missing_for(mode) {
            return Err(ModeRefusal::NotReady(r));
        }
        let ok = matches!(
            (self.mode, mode),
            (Mode::Disabled, _)
                | (Mode::Calibrating, Mode::Calibrating)
                | (Mode::Speed | Mode::Pressure, Mode::Speed | Mode::Pressure)
        );
        if ok {
            self.mode = mode;
            Ok(())
        } else {
            Err(ModeRefusal::Transition {
                from: self.mode,
                to: mode,
            })
        }
    }
}

/// Why a mode request was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ModeRefusal {
    /// A fault is latched.
    Faulted(FaultCode),
    /// A fault condition is present now.
    ConditionPresent(FaultCode),
    /// The drive is not ready for the mode yet.
    NotReady(NotReady),
    /// The transition is not allowed (go through Disabled).
    Transition {
        /// Current mode.
        from: Mode,
        /// Requested mode.
        to: Mode,
    },
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_condition_is_the_lowest_code_present() {
        // Every pair of codes, and each with a bit no code has above it: the lower code of
        // the pair, whatever else is set; nothing from no bit or from unknown bits alone.
        assert_eq!(Conditions(0).first(), None);
        assert_eq!(Conditions(1 << 31 | 1 << 25).first(), None);
        for a in FaultCode::ALL {
            let alone = Conditions(a.bit() | 1 << 30);
            assert_eq!(alone.first(), Some(a));
            for b in FaultCode::ALL {
                let mut c = Conditions::default();
                c.set(a, true);
                c.set(b, true);
                let lower = if a.code() < b.code() { a } else { b };
                assert_eq!(c.first(), Some(lower), "{a:?} and {b:?}");
            }
        }
    }

    #[test]
    fn codes_round_trip_and_bits_are_distinct() {
        let mut seen = 0u32;
        for f in FaultCode::ALL {
            assert_eq!(FaultCode::from_code(f.code()), Some(f));
            assert_eq!(seen & f.bit(), 0);
            seen |= f.bit();
        }
        assert_eq!(FaultCode::from_code(0), None);
        // Code 16 is the documented parameter-store fault, 17 the hardware break.
        assert_eq!(
            FaultCode::from_code(16),
            Some(FaultCode::ParameterStoreInvalid)
        );
        // The codes are 1..=MAX_CODE without a gap, in enumeration order.
        for (k, f) in FaultCode::ALL.iter().enumerate() {
            assert_eq!(usize::from(f.code()), k + 1);
        }
        assert_eq!(usize::from(FaultCode::MAX_CODE), FaultCode::ALL.len());
        assert_eq!(FaultCode::from_code(FaultCode::MAX_CODE + 1), None);
        assert_eq!(FaultCode::from_code(17), Some(FaultCode::HardwareBreak));
        assert_eq!(FaultCode::from_code(20), Some(FaultCode::Stall));
        for m in [
            Mode::Disabled,
            Mode::Calibrating,
            Mode::Speed,
            Mode::Pressure,
        ] {
            assert_eq!(Mode::from_code(m.code()), Some(m));
        }
    }

    #[test]
    fn latches_and_clears_only_when_the_cause_is_gone() {
        let mut s = Supervisor::new();
        s.request(Mode::Speed).unwrap();
        let mut c = Conditions::default();
        c.set(FaultCode::OverPressure, true);
        assert!(!s.check(c));
        assert_eq!(s.fault(), Some(FaultCode::OverPressure));
        assert_eq!(s.mode(), Mode::Disabled);
        // Still present: refused, and mode requests too.
        assert_eq!(s.clear(), Err(FaultCode::OverPressure));
        assert_eq!(
            s.request(Mode::Speed),
            Err(ModeRefusal::Faulted(FaultCode::OverPressure))
        );
        // Gone: the fault stays latched until cleared.
        assert!(!s.check(Conditions::default()));
        assert_eq!(s.fault(), Some(FaultCode::OverPressure));
        assert_eq!(s.clear(), Ok(()));
        assert_eq!(s.fault(), None);
        assert_eq!(s.mode(), Mode::Disabled);
    }

    #[test]
    fn a_hardware_break_latches_its_own_code_until_cleared() {
        use crate::{Command, Config, Controller, Measurements};
        let healthy = Measurements {
            adc_phase_current: [2048; 3],
            adc_dc_link: 2800,
            adc_pressure: 6554 + 6291, // 3 MPa
            ..Measurements::default()
        };
        let mut c = Controller::new(&Config::nominal());
        // Power-up: the offsets measured at rest, then the encoder index passes.
        for _ in 0..1000 {
            c.on_current_sample(&healthy);
        }
        c.on_current_sample(&Measurements {
            encoder_index: true,
            ..healthy
        });
        c.command(Command::SetMode(Mode::Speed)).unwrap();
        assert!(c.on_current_sample(&healthy).pwm_enabled);
        // The break interrupt between two current-loop calls.
        c.report_hardware_break();
        assert_eq!(c.fault(), Some(FaultCode::HardwareBreak));
        assert_eq!(c.telemetry().fault.map(FaultCode::code), Some(17));
        for _ in 0..10 {
            assert!(!c.on_current_sample(&healthy).pwm_enabled);
            c.command(Command::Heartbeat).unwrap();
        }
        assert_eq!(
            c.command(Command::SetMode(Mode::Speed)),
            Err(crate::CommandError::Mode(ModeRefusal::Faulted(
                FaultCode::HardwareBreak
            )))
        );
        // The comparators' cause is not visible to the core: the clear is the operator's.
        c.command(Command::ClearFaults).unwrap();
        c.command(Command::SetMode(Mode::Speed)).unwrap();
        assert!(c.on_current_sample(&healthy).pwm_enabled);
    }

    #[test]
    fn transitions() {
        let mut s = Supervisor::new();
        assert!(s.request(Mode::Pressure).is_ok());
        assert!(s.request(Mode::Speed).is_ok());
        assert_eq!(
            s.request(Mode::Calibrating),
            Err(ModeRefusal::Transition {
                from: Mode::Speed,
                to: Mode::Calibrating
            })
        );
        let mut c = Conditions::default();
        c.set(FaultCode::DcLinkUnderVoltage, true);
        s.request(Mode::Disabled).unwrap();
        // Disabled: the condition is seen but does not latch; entering a mode is refused.
        assert!(!s.check(c));
        assert_eq!(s.fault(), None);
        assert_eq!(
            s.request(Mode::Speed),
            Err(ModeRefusal::ConditionPresent(FaultCode::DcLinkUnderVoltage))
        );
    }

    #[test]
    fn active_modes_wait_for_offsets_and_speed_and_pressure_for_the_angle() {
        let mut s = Supervisor::new();
        s.set_readiness(Readiness {
            current_offsets: false,
            rotor_angle: false,
        });
        for m in [Mode::Calibrating, Mode::Speed, Mode::Pressure] {
            assert_eq!(
                s.request(m),
                Err(ModeRefusal::NotReady(NotReady::CurrentOffsets))
            );
        }
        assert_eq!(s.request(Mode::Disabled), Ok(()));
        s.set_readiness(Readiness {
            current_offsets: true,
            rotor_angle: false,
        });
        for m in [Mode::Speed, Mode::Pressure] {
            assert_eq!(
                s.request(m),
                Err(ModeRefusal::NotReady(NotReady::RotorAngle))
            );
        }
        // Calibrating is how the angle is found.
        assert_eq!(s.request(Mode::Calibrating), Ok(()));
        s.request(Mode::Disabled).unwrap();
        s.set_readiness(Readiness::READY);
        assert_eq!(s.request(Mode::Pressure), Ok(()));
        // A latched fault is named before readiness.
        s.set_readiness(Readiness {
            current_offsets: false,
            rotor_angle: false,
        });
        s.trip(FaultCode::Watchdog);
        assert_eq!(
            s.request(Mode::Speed),
            Err(ModeRefusal::Faulted(FaultCode::Watchdog))
        );
    }
}
