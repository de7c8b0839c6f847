//! Quadrature-encoder decoding: electrical angle, unwrapped shaft position, speed over a
//! window, the reference of the counter to the index pulse, and the plausibility checks of
//! the supervisor's encoder fault (implausible jump, lost or misplaced index).
//!
//! The counter wraps once per revolution (ARR = N − 1). The electrical offset the
//! configuration and the parameter table hold is relative to the index:
//! θ_e = p_n·2π·(count − c_index)/N − offset, where c_index is the counter value at the
//! index (eq. 1–3 are written at θ_e). An absolute counter (or the simulated one) reads 0 at
//! the index from the first sample, so c_index = 0 ([`Encoder::new`]). An incremental
//! counter zeroed at power-up, as the board's TIM2 is, starts at an arbitrary angle
//! ([`Encoder::with_unknown_reference`]): the first index pulse's captured count becomes
//! c_index, and until then the angle is unknown — unless an alignment (or commissioning)
//! has measured the offset in the counter's own frame in this power cycle; that offset is
//! then converted to the index-relative one when the index is first seen
//! ([`Encoder::take_learned_offset`]). The reference is folded into one counter-frame
//! offset, so the per-sample angle costs what it did without it.
//!
//! The difference between two samples is taken modulo N into [−N/2, N/2): valid while the
//! shaft turns less than half a revolution per current-loop period, which the configuration
//! enforces with margin. Each index pulse is checked twice: the count sampled in the same
//! period must be within one period's travel of the captured count (a counter and a
//! capture that disagree), and the capture must repeat the first one within the index
//! pulse's width (counts lost or gained since).

use crate::transforms::wrap_2pi;
use core::num::NonZeroU32;

/// Width of the widest index pulse (one line: four quadrature counts). Turning backwards,
/// the capture sees the pulse's rising edge at its other end, so captures of the same
/// index differ by up to this much. [counts]
pub const INDEX_WIDTH_COUNTS: i32 = 4;

/// What one encoder sample revealed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EncoderEvent {
    /// Plausible.
    Ok,
    /// The count moved more than the plausible speed allows in one period.
    Jump,
    /// The shaft travelled more than a revolution without an index, or an index came
    /// elsewhere than the counter or the first index says.
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
    /// Electrical offset relative to the index. [rad]
    offset_rad: f32,
    /// What the electrical angle subtracts from p_n·2π·count/N: `offset_rad` moved to the
    /// index's count, or an alignment's counter-frame measurement. [rad]
    counter_offset_rad: f32,
    /// Counter value at the index (c_index), once known.
    index_count: Option<u32>,
    /// The counter reads 0 at the index from the first sample (absolute counter).
    absolute: bool,
    /// `counter_offset_rad` was measured by an alignment before the index was seen.
    aligned_unreferenced: bool,
    /// `offset_rad` changed through the index or an alignment and has not been taken.
    learned: bool,
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
    /// and the largest plausible step `max_step` [counts per sample], on a counter that
    /// reads 0 at the index from the first sample.
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
            counter_offset_rad: offset_rad,
            index_count: Some(0),
            absolute: true,
            aligned_unreferenced: false,
            learned: false,
            max_step,
            index_margin: max_step + 2,
            last_count: 0,
            position: 0,
            since_index: 0,
            index_seen: false,
            primed: false,
        }
    }

    /// The same on a counter that started at an arbitrary angle: the angle is known once
    /// the index has been seen or an alignment has run.
    pub fn with_unknown_reference(mut self) -> Encoder {
        self.absolute = false;
        self.index_count = None;
        self
    }

    /// Mechanical angle per count. [rad]
    pub fn rad_per_count(&self) -> f32 {
        self.rad_per_count
    }

    /// Sets the index-relative electrical offset (live parameter, stored table); it
    /// supersedes an alignment not yet tied to the index. [rad]
    pub fn set_offset(&mut self, offset_rad: f32) {
        self.offset_rad = offset_rad;
        self.aligned_unreferenced = false;
        self.learned = false;
        self.counter_offset_rad = match self.index_count {
            Some(c) => offset_rad + self.raw_electrical_angle(c),
            None => offset_rad,
        };
    }

    /// Takes an offset measured in the counter's own frame (an alignment or commissioning
    /// found the rotor's d axis at counter-frame angle `counter_offset_rad`): the angle is
    /// valid from now on; the index-relative offset follows at once if the index is known,
    /// else at the first index ([`Encoder::take_learned_offset`]). [rad]
    pub fn align(&mut self, counter_offset_rad: f32) {
        self.counter_offset_rad = counter_offset_rad;
        match self.index_count {
            Some(c) => {
                self.offset_rad = wrap_2pi(counter_offset_rad - self.raw_electrical_angle(c));
                self.learned = true;
            }
            None => self.aligned_unreferenced = true,
        }
    }

    /// The index-relative offset, once, after the index or an alignment changed it (for
    /// the live parameter table). [rad]
    pub fn take_learned_offset(&mut self) -> Option<f32> {
        core::mem::take(&mut self.learned).then_some(self.offset_rad)
    }

    /// Index-relative electrical offset (what the parameter table holds). [rad]
    pub fn offset(&self) -> f32 {
        self.offset_rad
    }

    /// True when the electrical angle is known: the counter is tied to the index, or an
    /// alignment has measured the offset in the counter's frame.
    pub fn angle_known(&self) -> bool {
        self.index_count.is_some() || self.aligned_unreferenced
    }

    /// Counter value at the index, once known. [counts]
    pub fn index_count(&self) -> Option<u32> {
        self.index_count
    }

    /// Forgets the counter's reference after an encoder fault (counts may have been lost):
    /// an incremental counter needs the index or an alignment again; an absolute one keeps
    /// its reference.
    pub fn forget_reference(&mut self) {
        if !self.absolute {
            self.index_count = None;
            self.aligned_unreferenced = false;
            self.counter_offset_rad = self.offset_rad;
        }
    }

    /// Electrical angle of a count, not wrapped (sin/cos take any angle). [rad]
    #[inline]
    pub fn electrical_angle(&self, count: u32) -> f32 {
        self.raw_electrical_angle(count) - self.counter_offset_rad
    }

    /// p_n·2π·count/N, the electrical angle in the counter's own frame (no offset). [rad]
    #[inline]
    pub fn raw_electrical_angle(&self, count: u32) -> f32 {
        self.within_rev(count) as f32 * self.elec_rad_per_count
    }

    /// Mechanical angle of a count in [0, 2π), from the index once it is known (from the
    /// counter's zero before). [rad]
    #[inline]
    pub fn mechanical_angle(&self, count: u32) -> f32 {
        let n = self.counts_per_rev.get();
        let c = self.within_rev(count);
        let from_index = match self.index_count {
            Some(i) if c >= i => c - i,
            Some(i) => c + (n - i),
            None => c,
        };
        from_index as f32 * self.rad_per_count
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

    /// `x` modulo N into [−N/2, N/2).
    #[inline]
    fn wrapped(&self, x: i32) -> i32 {
        let n = self.counts_per_rev.get() as i32;
        if x >= self.half {
            x - n
        } else if x < -self.half {
            x + n
        } else {
            x
        }
    }

    /// `count` modulo the counts per revolution. A timer counting modulo N (its reload at
    /// N − 1) already reads below N, and then no division is taken: the ISR reads three
    /// angles of each sample, and a division is the longest instruction of its chain.
    #[inline]
    fn within_rev(&self, count: u32) -> u32 {
        if count < self.counts_per_rev.get() {
            count
        } else {
            count % self.counts_per_rev
        }
    }

    /// Takes one sample: the counter `count`, whether an index pulse was captured since
    /// the previous sample, and the captured counter value `index_count`; returns what it
    /// revealed.
    #[inline]
    pub fn update(&mut self, count: u32, index: bool, index_count: u32) -> EncoderEvent {
        let count = self.within_rev(count);
        if !self.primed {
            self.primed = true;
            self.last_count = count;
        }
        let delta = self.wrapped(count as i32 - self.last_count as i32);
        self.last_count = count;
        self.position += delta as i64;
        let mut event = EncoderEvent::Ok;
        if delta.abs() > self.max_step {
            event = EncoderEvent::Jump;
        }
        if index {
            self.on_index(count, self.within_rev(index_count), &mut event);
        } else {
            self.since_index = self.since_index.saturating_add(delta);
            let n = self.counts_per_rev.get() as i32;
            if self.since_index.abs() > n + self.index_margin && event == EncoderEvent::Ok {
                event = EncoderEvent::IndexLost;
                // Report once per lost revolution.
                self.since_index = 0;
            }
        }
        event
    }

    /// An index pulse captured at `captured` while the counter now reads `count`.
    fn on_index(&mut self, count: u32, captured: u32, event: &mut EncoderEvent) {
        // The shaft moved at most one period's travel since the edge.
        let since = self.wrapped(count as i32 - captured as i32);
        let consistent = since.abs() <= self.index_margin;
        let repeats = match self.index_count {
            Some(first) => {
                self.wrapped(captured as i32 - first as i32).abs() <= INDEX_WIDTH_COUNTS + 1
            }
            None => true,
        };
        if !(consistent && repeats) {
            if *event == EncoderEvent::Ok {
                *event = EncoderEvent::IndexLost;
            }
        } else if self.index_count.is_none() {
            // First index of the power cycle: tie the counter to it.
            self.index_count = Some(captured);
            let at_index = self.raw_electrical_angle(captured);
            if self.aligned_unreferenced {
                self.aligned_unreferenced = false;
                self.offset_rad = wrap_2pi(self.counter_offset_rad - at_index);
                self.learned = true;
            } else {
                self.counter_offset_rad = self.offset_rad + at_index;
            }
        }
        self.since_index = since;
        self.index_seen = true;
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
    use core::f32::consts::TAU;

    #[test]
    fn unwraps_across_the_wrap_both_ways() {
        let mut e = Encoder::new(10_000, 4, 0.0, 50);
        assert_eq!(e.update(9_990, false, 0), EncoderEvent::Ok);
        assert_eq!(e.update(5, true, 0), EncoderEvent::Ok);
        assert_eq!(e.position(), 15);
        assert_eq!(e.update(9_995, true, 0), EncoderEvent::Ok);
        assert_eq!(e.position(), 5);
    }

    #[test]
    fn a_free_running_counter_reads_as_its_count_within_the_revolution() {
        // A 16-bit timer that is not reset at N: 65 535 and 5 535 are the same place of a
        // 10 000-count shaft (65 535 = 6·10 000 + 5 535), and a step from 65 530 to 65 535
        // is five counts.
        let wrapped = Encoder::new(10_000, 4, 0.3, 50);
        let mut free = Encoder::new(10_000, 4, 0.3, 50);
        assert_eq!(free.update(65_530, false, 0), EncoderEvent::Ok);
        assert_eq!(free.update(65_535, false, 0), EncoderEvent::Ok);
        assert_eq!(free.position(), 5);
        assert_eq!(
            free.mechanical_angle(65_535),
            wrapped.mechanical_angle(5_535)
        );
        assert_eq!(
            free.electrical_angle(65_535),
            wrapped.electrical_angle(5_535)
        );
    }

    #[test]
    fn jump_and_lost_index() {
        let mut e = Encoder::new(10_000, 4, 0.0, 20);
        e.update(100, false, 0);
        assert_eq!(e.update(200, false, 0), EncoderEvent::Jump);
        // An index captured at 0 while the counter reads 5010: the two disagree.
        let mut e = Encoder::new(10_000, 4, 0.0, 20);
        e.update(5_000, false, 0);
        assert_eq!(e.update(5_010, true, 0), EncoderEvent::IndexLost);
        // Counter and capture agree, but the index is not where it was (counts lost).
        let mut e = Encoder::new(10_000, 4, 0.0, 20);
        e.update(4_995, false, 0);
        assert_eq!(e.update(5_010, true, 5_000), EncoderEvent::IndexLost);
        // More than a revolution without an index.
        let mut e = Encoder::new(10_000, 4, 0.0, 20);
        let mut c = 0u32;
        e.update(c, false, 0);
        let mut lost = false;
        for _ in 0..600 {
            c = (c + 20) % 10_000;
            if e.update(c, false, 0) == EncoderEvent::IndexLost {
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
        assert!((e.electrical_angle(2_500) - (TAU - 0.5)).abs() < 1e-5);
        assert_eq!(max_step_counts(600.0, 20e3, 10_000), 50);
    }

    /// xorshift32: arbitrary boot angles and offsets without a dependency.
    fn next(state: &mut u32) -> u32 {
        *state ^= *state << 13;
        *state ^= *state >> 17;
        *state ^= *state << 5;
        *state
    }

    const N: u32 = 10_000;
    const POLE_PAIRS: u32 = 4;
    const MAX_STEP: u32 = 50;

    /// A quadrature encoder whose disk has the index at disk count 0, one line (four
    /// counts) wide, read by a counter zeroed at power-up: the truth the decoder is
    /// checked against, written from the disk's point of view.
    struct Shaft {
        /// Disk count (0 = index), unwrapped.
        disk: i64,
        /// Disk count at power-up.
        boot: i64,
    }

    impl Shaft {
        fn counter(&self) -> u32 {
            (self.disk - self.boot).rem_euclid(N as i64) as u32
        }
        /// True electrical angle for the index-relative offset `offset`. [rad]
        fn theta_e(&self, offset: f32) -> f32 {
            let d = self.disk.rem_euclid(N as i64) as f32;
            POLE_PAIRS as f32 * TAU * d / N as f32 - offset
        }
        /// Moves by `step` counts; returns (index seen, captured counter value). Forwards
        /// the pulse's rising edge is at disk count 0, backwards at its far end, 3.
        fn turn(&mut self, step: i64) -> (bool, u32) {
            let (from, to) = (self.disk, self.disk + step);
            let n = N as i64;
            let crosses = |edge: i64| {
                let lo = from.min(to);
                let hi = from.max(to);
                // An edge position e + k·N strictly passed between from and to.
                (lo.div_euclid(n)..=hi.div_euclid(n) + 1).any(|k| {
                    let at = edge + k * n;
                    if step > 0 {
                        from < at && at <= to
                    } else {
                        to <= at && at < from
                    }
                })
            };
            self.disk = to;
            let edge = if step > 0 { 0 } else { 3 };
            if step != 0 && crosses(edge) {
                (true, (edge - self.boot).rem_euclid(n) as u32)
            } else {
                (false, 0)
            }
        }
    }

    fn wrapped_error(a: f32, b: f32) -> f32 {
        let d = (a - b).rem_euclid(TAU);
        d.min(TAU - d)
    }

    #[test]
    fn an_incremental_counter_is_tied_to_the_index_wherever_it_booted() {
        let mut rng = 0x2545_f491u32;
        let k_e = POLE_PAIRS as f32 * TAU / N as f32;
        for case in 0..200 {
            let boot = (next(&mut rng) % N) as i64;
            let offset = (next(&mut rng) % 6283) as f32 * 1e-3;
            let mut shaft = Shaft { disk: boot, boot };
            let mut e = Encoder::new(N, POLE_PAIRS, offset, MAX_STEP).with_unknown_reference();
            assert!(!e.angle_known(), "case {case}: known before the index");
            // Turn one way or the other at 1..=MAX_STEP counts per sample until the index.
            let dir = if next(&mut rng) % 2 == 0 { 1 } else { -1 };
            let speed = 1 + (next(&mut rng) % MAX_STEP) as i64;
            let mut seen = false;
            for _ in 0..(2 * N as i64 / speed + 2) {
                let (index, captured) = shaft.turn(dir * speed);
                let event = e.update(shaft.counter(), index, captured);
                assert_eq!(event, EncoderEvent::Ok, "case {case}");
                if index {
                    seen = true;
                    break;
                }
                assert!(!e.angle_known(), "case {case}");
            }
            assert!(seen, "case {case}: no index in a revolution");
            assert!(e.angle_known());
            // The learned reference: within the index pulse's width of the truth, in
            // either direction, then tracked sample by sample.
            let tol = (INDEX_WIDTH_COUNTS as f32 + 0.5) * k_e;
            for _ in 0..300 {
                let (index, captured) = shaft.turn(dir * speed);
                assert_eq!(e.update(shaft.counter(), index, captured), EncoderEvent::Ok);
                let err = wrapped_error(e.electrical_angle(shaft.counter()), shaft.theta_e(offset));
                assert!(err <= tol, "case {case}: {err} rad off");
                let mech = shaft.disk.rem_euclid(N as i64) as f32 * TAU / N as f32;
                let err_m = wrapped_error(e.mechanical_angle(shaft.counter()), mech);
                assert!(
                    err_m <= tol / POLE_PAIRS as f32,
                    "case {case}: θ_m {err_m} off"
                );
            }
            // The stored offset is untouched: nothing was learned, only the reference.
            assert_eq!(e.take_learned_offset(), None);
            assert_eq!(e.offset(), offset);
        }
    }

    #[test]
    fn an_alignment_before_the_index_is_carried_to_the_index_and_survives_a_reboot() {
        let mut rng = 0x1234_5678u32;
        let k_e = POLE_PAIRS as f32 * TAU / N as f32;
        for case in 0..100 {
            // The rotor's true offset from the index, unknown to the drive (its table holds
            // a stale 1.0 rad).
            let truth = (next(&mut rng) % 6283) as f32 * 1e-3;
            let boot = (next(&mut rng) % N) as i64;
            // The alignment pulls the rotor to θ_e = 0: a disk count where p·2π·d/N = truth
            // (one of the p_n such positions).
            let pair = (next(&mut rng) % POLE_PAIRS) as f32;
            let d_align = libm::roundf((truth + pair * TAU) / k_e) as i64 % N as i64;
            let mut shaft = Shaft {
                disk: d_align,
                boot,
            };
            let mut e = Encoder::new(N, POLE_PAIRS, 1.0, MAX_STEP).with_unknown_reference();
            e.update(shaft.counter(), false, 0);
            e.align(wrap_2pi(e.raw_electrical_angle(shaft.counter())));
            assert!(e.angle_known(), "case {case}: aligned");
            let align_err =
                wrapped_error(e.electrical_angle(shaft.counter()), shaft.theta_e(truth));
            assert!(align_err <= 0.6 * k_e, "case {case}: {align_err}");
            // Index later, turning forwards: the offset becomes index-relative.
            let mut learned = None;
            for _ in 0..(N / 20 + 2) {
                let (index, captured) = shaft.turn(20);
                assert_eq!(e.update(shaft.counter(), index, captured), EncoderEvent::Ok);
                if let Some(o) = e.take_learned_offset() {
                    learned = Some(o);
                }
                let err = wrapped_error(e.electrical_angle(shaft.counter()), shaft.theta_e(truth));
                assert!(
                    err <= 0.6 * k_e,
                    "case {case}: {err} rad off after the index"
                );
            }
            let learned = learned.expect("the offset is learned at the index");
            assert!(wrapped_error(learned, truth) <= 0.6 * k_e, "case {case}");
            // Reboot elsewhere with the learned offset in the table: after the index the
            // angle is right again.
            let boot2 = (next(&mut rng) % N) as i64;
            let mut shaft = Shaft {
                disk: boot2,
                boot: boot2,
            };
            let mut e = Encoder::new(N, POLE_PAIRS, learned, MAX_STEP).with_unknown_reference();
            let mut turns = 0;
            while !e.angle_known() {
                let (index, captured) = shaft.turn(-17);
                e.update(shaft.counter(), index, captured);
                turns += 1;
                assert!(turns < 1000, "case {case}: no index");
            }
            let (index, captured) = shaft.turn(-17);
            e.update(shaft.counter(), index, captured);
            let err = wrapped_error(e.electrical_angle(shaft.counter()), shaft.theta_e(truth));
            assert!(
                err <= (INDEX_WIDTH_COUNTS as f32 + 0.6) * k_e,
                "case {case}: {err}"
            );
        }
    }

    #[test]
    fn counts_lost_after_the_reference_trip_the_index_check_and_clear_the_reference() {
        let mut shaft = Shaft {
            disk: 7_000,
            boot: 7_000,
        };
        let mut e = Encoder::new(N, POLE_PAIRS, 0.3, MAX_STEP).with_unknown_reference();
        for _ in 0..200 {
            let (index, captured) = shaft.turn(30);
            e.update(shaft.counter(), index, captured);
        }
        assert!(e.angle_known());
        // The counter slips 40 counts (noise on A/B): the next index is captured elsewhere.
        shaft.boot -= 40;
        let mut lost = false;
        for _ in 0..400 {
            let (index, captured) = shaft.turn(30);
            lost |= e.update(shaft.counter(), index, captured) == EncoderEvent::IndexLost;
        }
        assert!(lost);
        e.forget_reference();
        assert!(!e.angle_known());
        // An absolute counter keeps its reference.
        let mut a = Encoder::new(N, POLE_PAIRS, 0.3, MAX_STEP);
        a.forget_reference();
        assert!(a.angle_known());
    }
}
