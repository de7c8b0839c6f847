//! Quadrature-encoder decoding: electrical angle, unwrapped shaft position, speed over a
//! window, and the plausibility checks of the supervisor's encoder fault (implausible jump,
//! lost or misplaced index).
//!
//! The counter wraps once per revolution (ARR = N − 1) with the index at count 0. The
//! electrical angle is θ_e = p_n·2π·count/N − offset (eq. 1–3 are written at θ_e). The
//! difference between two samples is taken modulo N into [−N/2, N/2): valid while the shaft
//! turns less than half a revolution per current-loop period, which the configuration
//! enforces with margin.

use core::num::NonZeroU32;

/// What one encoder sample revealed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EncoderEvent {
    /// Plausible.
    Ok,
    /// The count moved more than the plausible speed allows in one period.
    Jump,
    /// The shaft travelled more than a revolution without an index, or an index came far
    /// from count 0.
    IndexLost,
}

/// Encoder decoder state.
#[derive(Clone, Copy, Debug)]
pub struct Encoder {
    /// Non-zero by type, so `count % counts_per_rev` has no division-by-zero panic path in
    /// the ISR.
    counts_per_rev: NonZeroU32,
    half: i32,
    rad_per_count: f32,
    elec_rad_per_count: f32,
    offset_rad: f32,
    max_step: i32,
    index_margin: i32,
    last_count: u32,
    position: i64,
    since_index: i32,
    index_seen: bool,
    primed: bool,
}

impl Encoder {
    /// For `counts_per_rev` counts, `pole_pairs`, the electrical offset `offset_rad` [rad]
    /// and the largest plausible step `max_step` [counts per sample].
    pub fn new(counts_per_rev: u32, pole_pairs: u32, offset_rad: f32, max_step: u32) -> Encoder {
        // The wrapped difference below works in i32.
        let n = counts_per_rev.clamp(4, 1 << 24);
        let rad_per_count = core::f32::consts::TAU / n as f32;
        let max_step = (max_step.min(n / 4)) as i32;
        Encoder {
            counts_per_rev: NonZeroU32::new(n).unwrap_or(NonZeroU32::MIN),
            half: (n / 2) as i32,
            rad_per_count,
            elec_rad_per_count: rad_per_count * pole_pairs as f32,
            offset_rad,
            max_step,
            index_margin: max_step + 2,
            last_count: 0,
            position: 0,
            since_index: 0,
            index_seen: false,
            primed: false,
        }
    }

    /// Mechanical angle per count. [rad]
    pub fn rad_per_count(&self) -> f32 {
        self.rad_per_count
    }

    /// Sets the electrical offset (after alignment). [rad]
    pub fn set_offset(&mut self, offset_rad: f32) {
        self.offset_rad = offset_rad;
    }

    /// Electrical offset. [rad]
    pub fn offset(&self) -> f32 {
        self.offset_rad
    }

    /// Electrical angle of a count, not wrapped (sin/cos take any angle). [rad]
    #[inline]
    pub fn electrical_angle(&self, count: u32) -> f32 {
        (count % self.counts_per_rev) as f32 * self.elec_rad_per_count - self.offset_rad
    }

    /// Mechanical angle of a count in [0, 2π). [rad]
    #[inline]
    pub fn mechanical_angle(&self, count: u32) -> f32 {
        (count % self.counts_per_rev) as f32 * self.rad_per_count
    }

    /// Unwrapped position since start. [counts]
    pub fn position(&self) -> i64 {
        self.position
    }

    /// Forgets the index history (after a fault is cleared, or on start).
    pub fn rearm(&mut self) {
        self.since_index = 0;
        self.index_seen = false;
    }

    /// Takes one sample; returns what it revealed.
    #[inline]
    pub fn update(&mut self, count: u32, index: bool) -> EncoderEvent {
        let count = count % self.counts_per_rev;
        if !self.primed {
            self.primed = true;
            self.last_count = count;
            return EncoderEvent::Ok;
        }
        let n = self.counts_per_rev.get() as i32;
        let mut delta = count as i32 - self.last_count as i32;
        if delta >= self.half {
            delta -= n;
        } else if delta < -self.half {
            delta += n;
        }
        self.last_count = count;
        self.position += delta as i64;
        let mut event = EncoderEvent::Ok;
        if delta.abs() > self.max_step {
            event = EncoderEvent::Jump;
        }
        if index {
            // The index is at count 0: the count must be within what the shaft can have
            // moved since it passed.
            let from_zero = if (count as i32) < self.half {
                count as i32
            } else {
                count as i32 - n
            };
            if from_zero.abs() > self.index_margin && event == EncoderEvent::Ok {
                event = EncoderEvent::IndexLost;
            }
            self.since_index = from_zero;
            self.index_seen = true;
        } else {
            self.since_index = self.since_index.saturating_add(delta);
            if self.since_index.abs() > n + self.index_margin && event == EncoderEvent::Ok {
                event = EncoderEvent::IndexLost;
                // Report once per lost revolution.
                self.since_index = 0;
            }
        }
        event
    }

    /// True once an index has been seen since start or the last [`Encoder::rearm`].
    pub fn index_seen(&self) -> bool {
        self.index_seen
    }
}

/// Largest plausible encoder step per sample for `speed_rad_s` at `sample_hz` with
/// `counts_per_rev`, with two counts of margin. [counts]
pub fn max_step_counts(speed_rad_s: f32, sample_hz: f32, counts_per_rev: u32) -> u32 {
    let per_sample =
        speed_rad_s / core::f32::consts::TAU / sample_hz.max(1.0) * counts_per_rev as f32;
    (per_sample.max(0.0) + 0.999) as u32 + 2
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unwraps_across_the_wrap_both_ways() {
        let mut e = Encoder::new(10_000, 4, 0.0, 50);
        assert_eq!(e.update(9_990, false), EncoderEvent::Ok);
        assert_eq!(e.update(5, true), EncoderEvent::Ok);
        assert_eq!(e.position(), 15);
        assert_eq!(e.update(9_995, true), EncoderEvent::Ok);
        assert_eq!(e.position(), 5);
    }

    #[test]
    fn jump_and_lost_index() {
        let mut e = Encoder::new(10_000, 4, 0.0, 20);
        e.update(100, false);
        assert_eq!(e.update(200, false), EncoderEvent::Jump);
        // Index far from count 0.
        let mut e = Encoder::new(10_000, 4, 0.0, 20);
        e.update(5_000, false);
        assert_eq!(e.update(5_010, true), EncoderEvent::IndexLost);
        // More than a revolution without an index.
        let mut e = Encoder::new(10_000, 4, 0.0, 20);
        let mut c = 0u32;
        e.update(c, false);
        let mut lost = false;
        for _ in 0..600 {
            c = (c + 20) % 10_000;
            if e.update(c, false) == EncoderEvent::IndexLost {
                lost = true;
            }
        }
        assert!(lost);
    }

    #[test]
    fn angles() {
        let e = Encoder::new(10_000, 4, 0.5, 20);
        // A quarter revolution = 4 quarter electrical turns = 2π electrical.
        assert!((e.mechanical_angle(2_500) - core::f32::consts::FRAC_PI_2).abs() < 1e-6);
        assert!((e.electrical_angle(2_500) - (core::f32::consts::TAU - 0.5)).abs() < 1e-5);
        assert_eq!(max_step_counts(600.0, 20e3, 10_000), 50);
    }
}
