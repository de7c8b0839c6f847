//! The feed-forward's state in the controller ([`Compensation`]): the table, whether it
//! is committed, a CAN load in progress, the gain and lead of the step, the flow-ripple
//! modulation, and why a table or a setting is refused ([`CompensationError`]).

use super::flow;
use super::record;
use super::table::{Exponent, Table, BINS, BINS_PER_RAD, CHANNELS};
use core::fmt;

/// Why a table or a setting of the feed-forward was refused.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CompensationError {
    /// The table's amplitude over the operating range times the scale exceeds the limit.
    Amplitude {
        /// The amplitude it would reach. [A]
        amplitude_a: f32,
        /// `compensation.max_current_a`. [A]
        limit_a: f32,
    },
    /// A table record or CAN load that does not decode ([`record::RecordError`]).
    Record(record::RecordError),
}

impl fmt::Display for CompensationError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CompensationError::Amplitude {
                amplitude_a,
                limit_a,
            } => write!(
                f,
                "feed-forward amplitude {amplitude_a} A over the operating range exceeds compensation.max_current_a = {limit_a} A"
            ),
            CompensationError::Record(e) => write!(f, "compensation table refused: {e}"),
        }
    }
}

/// The feed-forward's state in the controller: the table, whether it is committed (a
/// complete, checked table), a CAN load in progress, and the gain and lead of the step.
#[derive(Clone, Debug)]
pub struct Compensation {
    table: Table,
    committed: bool,
    loader: Option<record::Loader>,
    gain: f32,
    lead_s: f32,
    /// The lead in bins per rad/s of speed: t_lead·BINS/2π. [s·bins/rad]
    lead_bins: f32,
    p_max_pa: f32,
    i_max_a: f32,
    /// The speed modulation against the pump's flow ripple.
    flow: flow::FlowRipple,
}

impl Compensation {
    /// For `cfg`: an empty committed table (no effect until one is loaded and enabled).
    pub fn new(cfg: &crate::Config) -> Compensation {
        let mut c = Compensation {
            table: Table::ZERO,
            committed: true,
            loader: None,
            gain: 0.0,
            lead_s: 0.0,
            lead_bins: 0.0,
            p_max_pa: 0.0,
            i_max_a: 0.0,
            flow: flow::FlowRipple::OFF,
        };
        c.retune(cfg);
        c
    }

    /// Takes the gain, the lead and the operating range from `cfg`.
    pub fn retune(&mut self, cfg: &crate::Config) {
        let on = cfg.compensation.enabled
            && self.committed
            && self.loader.is_none()
            && !self.table.is_zero();
        self.gain = if on { cfg.compensation.scale } else { 0.0 };
        self.lead_s = cfg.motor.q_inductance_h / cfg.current.kp_q + 1.0 / cfg.rates.pwm_hz.max(1.0);
        self.lead_bins = self.lead_s * BINS_PER_RAD;
        self.p_max_pa = cfg.limits.over_pressure_pa;
        self.i_max_a = cfg.speed.iq_limit_a;
        self.flow = flow::FlowRipple::new(cfg, cfg.compensation.enabled, self.lead_s);
    }

    /// The speed modulation against the pump's flow ripple (off unless enabled with a
    /// piston count and a ratio; acts whether or not a table is loaded).
    pub fn flow(&self) -> &flow::FlowRipple {
        &self.flow
    }

    /// The q-current feed-forward [A] at shaft angle `theta_m` [rad] (in [0, 2π), the
    /// encoder's), speed `omega` [rad/s], port-A pressure `p_pa` [Pa] and q-current
    /// reference `iq_ref` [A]; and the per-current channel g·c_i, the flux harmonics'
    /// share of the magnet flux the current loop's decoupling takes for their back-EMF
    /// ([`crate::current_loop`]). [1]
    ///
    /// The same cost whether it acts or not (a zero gain multiplies a finite table), so the
    /// step's worst case is its every case. The bin comes from the angle in bins, a
    /// revolution ahead so it stays positive under any lead: the float-to-integer
    /// conversion then floors, and the fraction is the float remainder (no fixed-point
    /// mask and scale as in [`crate::angle_grid`], three instructions fewer).
    #[inline(always)]
    pub fn current(&self, theta_m: f32, omega: f32, p_pa: f32, iq_ref: f32) -> (f32, f32) {
        let bins = BINS as f32 + theta_m * BINS_PER_RAD + omega * self.lead_bins;
        let whole = bins as i32;
        let [c0, cp, ci] = self.table.interpolate(whole as usize, bins - whole as f32);
        let flux = self.gain * ci;
        (self.gain * (c0 + cp * p_pa) + flux * iq_ref, flux)
    }

    /// The table in use (or being loaded).
    pub fn table(&self) -> &Table {
        &self.table
    }

    /// True when the table is complete and checked (not loading, not refused).
    pub fn is_committed(&self) -> bool {
        self.committed && self.loader.is_none()
    }

    /// True when the feed-forward acts (outside Disabled and Calibrating).
    pub fn is_active(&self) -> bool {
        self.gain != 0.0
    }

    /// The lead time of the lookup angle. [s]
    pub fn lead_s(&self) -> f32 {
        self.lead_s
    }

    /// The amplitude `table` would reach under `cfg` (scale × bound over the operating
    /// range), refused above `compensation.max_current_a`.
    pub fn check_amplitude(table: &Table, cfg: &crate::Config) -> Result<(), CompensationError> {
        let c = &cfg.compensation;
        let bound = table.amplitude_bound(cfg.limits.over_pressure_pa, cfg.speed.iq_limit_a);
        let amplitude_a = c.scale * bound;
        if amplitude_a > c.max_current_a {
            Err(CompensationError::Amplitude {
                amplitude_a,
                limit_a: c.max_current_a,
            })
        } else {
            Ok(())
        }
    }

    /// The table's amplitude at unit scale over the operating range. [A]
    pub fn amplitude_bound(&self) -> f32 {
        self.table.amplitude_bound(self.p_max_pa, self.i_max_a)
    }

    /// Replaces the table with `table` if its amplitude under `cfg` is within the limit;
    /// otherwise the table is cleared (and the feed-forward stays off).
    pub fn install(&mut self, table: &Table, cfg: &crate::Config) -> Result<(), CompensationError> {
        self.loader = None;
        let result = Compensation::check_amplitude(table, cfg);
        match result {
            Ok(()) => self.table.clone_from(table),
            Err(_) => self.table = Table::ZERO,
        }
        self.committed = true;
        self.retune(cfg);
        result
    }

    /// Reads a stored or shipped record through `read` (see [`record::read`]) straight
    /// into the table, then checks its amplitude under `cfg`. On any refusal the table is
    /// left empty and the feed-forward off.
    pub fn load_record(
        &mut self,
        len: usize,
        read: impl FnMut(usize, &mut [u8]) -> bool,
        cfg: &crate::Config,
    ) -> Result<(), CompensationError> {
        self.loader = None;
        let result = record::read(len, read, &mut self.table).map_err(CompensationError::Record);
        self.settle(result, cfg)
    }

    /// Empties the table (committed, zero amplitude).
    pub fn clear(&mut self, cfg: &crate::Config) {
        self.table = Table::ZERO;
        self.loader = None;
        self.committed = true;
        self.retune(cfg);
    }

    /// A CAN load's header: the LSB exponents and the bin count; the feed-forward is off
    /// until the commit.
    pub fn begin(
        &mut self,
        exponents: [Exponent; CHANNELS],
        bins: u16,
        cfg: &crate::Config,
    ) -> Result<(), CompensationError> {
        self.committed = false;
        let result = match record::Loader::begin(&mut self.table, exponents, bins) {
            Ok(l) => {
                self.loader = Some(l);
                Ok(())
            }
            Err(e) => {
                self.loader = None;
                Err(CompensationError::Record(e))
            }
        };
        self.retune(cfg);
        result
    }

    /// A CAN load's next bin.
    pub fn bin(&mut self, bin: u16, raw: [i16; CHANNELS]) -> Result<(), CompensationError> {
        match &mut self.loader {
            Some(l) => l.bin(&mut self.table, bin, raw),
            None => Err(record::RecordError::NotLoading),
        }
        .map_err(CompensationError::Record)
    }

    /// A CAN load's commit: the record's CRC must match what arrived, then the amplitude
    /// must be within the limit. A refused commit leaves the table empty.
    pub fn commit(&mut self, crc: u32, cfg: &crate::Config) -> Result<(), CompensationError> {
        let Some(l) = self.loader.take() else {
            return Err(CompensationError::Record(record::RecordError::NotLoading));
        };
        let result = l.finish(crc).map_err(CompensationError::Record);
        self.settle(result, cfg)
    }

    /// Ends a load that arrived in place as `arrived`: its amplitude checked under `cfg`,
    /// the table emptied on any refusal, committed either way.
    fn settle(
        &mut self,
        arrived: Result<(), CompensationError>,
        cfg: &crate::Config,
    ) -> Result<(), CompensationError> {
        let result = arrived.and_then(|()| Compensation::check_amplitude(&self.table, cfg));
        if result.is_err() {
            self.table = Table::ZERO;
        }
        self.committed = true;
        self.retune(cfg);
        result
    }
}
