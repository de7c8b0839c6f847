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
pub mod feedforward;
pub mod flow;
pub mod record;
pub mod table;

pub use config::CompensationConfig;
pub use feedforward::{Compensation, CompensationError};
pub use table::{lsb, Channel, Exponent, Table, BINS, BINS_LOG2, CHANNELS, MAX_EXPONENT};

#[cfg(test)]
mod tests;
