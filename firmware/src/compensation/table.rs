//! The feed-forward's table in RAM: 512 bins per mechanical revolution, three channels
//! per bin (constant, per pressure, per current), i16 values with a per-channel LSB of
//! 2^−e, and its lookup at the shaft's angle with linear interpolation between bins (see
//! the [`super`] documentation for the model `i_q,ff(θ) = g·(c₀ + c_p·p + c_i·i_q,ref)`).

use crate::angle_grid::position;

/// Bins per mechanical revolution, as a power of two. [1]
pub const BINS_LOG2: u32 = 9;
/// Bins per mechanical revolution. [1]
pub const BINS: usize = 1 << BINS_LOG2;
/// Channels per bin: constant, per pressure, per current. [1]
pub const CHANNELS: usize = 3;
/// Bins per radian of shaft angle. [1/rad]
pub(super) const BINS_PER_RAD: f32 = BINS as f32 / core::f32::consts::TAU;

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
    pub(super) fn start(&mut self, exponents: [Exponent; CHANNELS]) -> Result<(), usize> {
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
    pub(super) fn set_bin(&mut self, k: usize, raw: [i16; CHANNELS]) {
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
    pub(super) fn interpolate(&self, k: usize, f: f32) -> [f32; CHANNELS] {
        let k = k & (BINS - 1);
        // k < BINS by its mask: both bins exist, no bounds check.
        let (a, b) = (self.bins[k], self.bins[k + 1]);
        core::array::from_fn(|c| a[c] + f * (b[c] - a[c]))
    }
}
