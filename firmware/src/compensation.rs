//! Angle-indexed torque feed-forward: the periodic low-speed torques the model explains
//! (cogging, eq. 16; the 6th-harmonic torque of the flux harmonics, eq. 17–19; the pump's
//! torque ripple, eq. 20; the torque a phase-current offset hides), cancelled at their
//! source by an extra q-current reference looked up at the shaft's mechanical angle.
//!
//! # The table
//!
//! [`BINS`] = 512 bins per mechanical revolution, each with three channels, one per
//! scaling law of the effects:
//!
//! ```text
//!   i_q,ff(θ) = g · ( c₀(θ) + c_p(θ)·p + c_i(θ)·i_q,ref )
//! ```
//!
//! - `c₀` [A]: cogging and a current offset's image, load-independent (the low-side
//!   pressure's share of the pump ripple is folded in here, so `p` is the measured gauge
//!   pressure of port A);
//! - `c_p` [A/Pa]: the pump's torque ripple over K_t, proportional to the pressure
//!   difference across the pump;
//! - `c_i` [A/A]: the flux harmonics' torque ripple, proportional to the mean torque, i.e.
//!   to the q-current reference (before the feed-forward);
//! - `g` = `compensation.scale` while `compensation.enabled` and a table is committed,
//!   0 otherwise, and always 0 outside Speed and Pressure (the controller's business).
//!
//! Between bins the channels are interpolated linearly (a line of order k comes out
//! attenuated by sinc²(πk/512), 6 % at the cogging's 72/rev: the host pre-emphasises each
//! order it writes). The lookup angle leads the measured one by ω·t_lead, with t_lead the
//! closed current loop's time constant L_q/Kp_q plus one PWM period (the step's sample and
//! hold), so the torque arrives at the angle it was computed for. About 40 instructions on
//! the Cortex-M4F, f32 throughout (an f32 table costs 6 KiB of RAM; i16 would halve it
//! but add a conversion per value in the step).
//!
//! # Bounds
//!
//! The table's amplitude over the operating range, `g·(max|c₀| + max|c_p|·p_trip +
//! max|c_i|·I_lim)` with the over-pressure trip level and the q-current limit (the speed
//! loop's output, which the reference never exceeds), must stay at or below
//! `compensation.max_current_a`: a committed table, a scale, a limit or a q-current limit
//! that would break it is refused naming the bound ([`Compensation::check_amplitude`]), so
//! the step needs no clamp of its own.
//!
//! # Loading
//!
//! Over CAN, bin by bin in order after a header, then a commit carrying the CRC of the
//! whole record ([`record::Loader`]); from flash or a file as one record
//! ([`record::read`]): magic, version, bin and channel counts, per-channel LSBs, i16
//! values, CRC-32. While a table loads, or after a refused one, the feed-forward is off.

pub mod config;
pub mod flow;
pub mod record;

pub use config::CompensationConfig;

use crate::angle_grid::position;
use core::fmt;

/// Bins per mechanical revolution, as a power of two. [1]
pub const BINS_LOG2: u32 = 9;
/// Bins per mechanical revolution. [1]
pub const BINS: usize = 1 << BINS_LOG2;
/// Channels per bin: constant, per pressure, per current. [1]
pub const CHANNELS: usize = 3;
/// Bins per radian of shaft angle. [1/rad]
const BINS_PER_RAD: f32 = BINS as f32 / core::f32::consts::TAU;

/// A table channel: what its values multiply.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Channel {
    /// Load-independent q current. [A]
    Constant = 0,
    /// q current per pascal of port-A pressure. [A/Pa]
    PerPressure = 1,
    /// q current per ampere of q-current reference. [A/A]
    PerCurrent = 2,
}

impl Channel {
    /// Every channel, in record order.
    pub const ALL: [Channel; CHANNELS] =
        [Channel::Constant, Channel::PerPressure, Channel::PerCurrent];

    /// Unit of the channel's values.
    pub fn unit(self) -> &'static str {
        match self {
            Channel::Constant => "A",
            Channel::PerPressure => "A/Pa",
            Channel::PerCurrent => "A/A",
        }
    }
}

/// Exponent e of a channel's LSB 2^−e: values are i16 · 2^−e. [1]
pub type Exponent = i8;

/// Largest LSB exponent a table may use (2^−100: far below any physical value, still a
/// normal f32). [1]
pub const MAX_EXPONENT: Exponent = 100;

/// 2^−e exactly, for e in 0‥=[`MAX_EXPONENT`]. [1]
pub fn lsb(e: Exponent) -> f32 {
    let e = e.clamp(0, MAX_EXPONENT) as u32;
    f32::from_bits((127 - e) << 23)
}

/// The table in RAM: per bin the three channels as f32 (i16 · LSB, exact), the first bin
/// repeated at the end so interpolation never wraps, and each channel's largest magnitude.
#[derive(Clone, Debug, PartialEq)]
pub struct Table {
    bins: [[f32; CHANNELS]; BINS + 1],
    exponents: [Exponent; CHANNELS],
    peak: [f32; CHANNELS],
}

impl Table {
    /// All zero.
    pub const ZERO: Table = Table {
        bins: [[0.0; CHANNELS]; BINS + 1],
        exponents: [0; CHANNELS],
        peak: [0.0; CHANNELS],
    };

    /// A table from i16 values `raw[bin][channel]` with LSB exponents `exponents`; `None`
    /// when an exponent is outside 0‥=[`MAX_EXPONENT`].
    pub fn from_raw(
        exponents: [Exponent; CHANNELS],
        raw: &[[i16; CHANNELS]; BINS],
    ) -> Option<Table> {
        let mut t = Table::ZERO;
        t.start(exponents).ok()?;
        for (k, r) in raw.iter().enumerate() {
            t.set_bin(k, *r);
        }
        Some(t)
    }

    /// Zeroes the table and sets the LSB exponents (0‥=[`MAX_EXPONENT`]; the index of the
    /// first one out of range otherwise).
    fn start(&mut self, exponents: [Exponent; CHANNELS]) -> Result<(), usize> {
        if let Some(bad) = exponents
            .iter()
            .position(|e| !(0..=MAX_EXPONENT).contains(e))
        {
            return Err(bad);
        }
        *self = Table::ZERO;
        self.exponents = exponents;
        Ok(())
    }

    /// Writes bin `k` (< [`BINS`]) from its i16 values.
    fn set_bin(&mut self, k: usize, raw: [i16; CHANNELS]) {
        let Some(bin) = self.bins.get_mut(k) else {
            return;
        };
        for c in 0..CHANNELS {
            let v = f32::from(raw[c]) * lsb(self.exponents[c]);
            bin[c] = v;
            if v.abs() > self.peak[c] {
                self.peak[c] = v.abs();
            }
        }
        if k == 0 {
            self.bins[BINS] = self.bins[0];
        }
    }

    /// The LSB exponents. [1]
    pub fn exponents(&self) -> [Exponent; CHANNELS] {
        self.exponents
    }

    /// Bin `k`'s values in the channels' units (`k` < [`BINS`]; zero beyond).
    pub fn bin(&self, k: usize) -> [f32; CHANNELS] {
        if k < BINS {
            self.bins[k]
        } else {
            [0.0; CHANNELS]
        }
    }

    /// Bin `k`'s i16 values (exact: every value is an i16 times its LSB).
    pub fn raw(&self, k: usize) -> [i16; CHANNELS] {
        let b = self.bin(k);
        core::array::from_fn(|c| (b[c] / lsb(self.exponents[c])) as i16)
    }

    /// Each channel's largest magnitude. [A, A/Pa, A/A]
    pub fn peak(&self) -> [f32; CHANNELS] {
        self.peak
    }

    /// True when every value is zero.
    pub fn is_zero(&self) -> bool {
        self.peak.iter().all(|p| *p == 0.0)
    }

    /// Largest feed-forward at unit gain for pressures up to `p_max_pa` [Pa] and q-current
    /// references up to `i_max_a` [A] in magnitude. [A]
    pub fn amplitude_bound(&self, p_max_pa: f32, i_max_a: f32) -> f32 {
        self.peak[0] + self.peak[1] * p_max_pa + self.peak[2] * i_max_a
    }

    /// The three channels interpolated at `theta_m` [rad] (any angle, wrapped).
    #[inline(always)]
    pub fn at(&self, theta_m: f32) -> [f32; CHANNELS] {
        let (k, f) = position(theta_m, BINS_LOG2);
        self.interpolate(k, f)
    }

    /// The three channels a fraction `f` [0, 1) of the way from bin `k` to the next.
    #[inline(always)]
    fn interpolate(&self, k: usize, f: f32) -> [f32; CHANNELS] {
        let k = k & (BINS - 1);
        // k < BINS by its mask: both bins exist, no bounds check.
        let (a, b) = (self.bins[k], self.bins[k + 1]);
        core::array::from_fn(|c| a[c] + f * (b[c] - a[c]))
    }
}

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

#[cfg(test)]
mod tests;
