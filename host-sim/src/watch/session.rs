//! What `eha watch` knows of the stream so far: the counts (lines, frames, other lines,
//! malformed telemetry), the drive's latest mode and latched fault, a rolling window of
//! frames for the traces, and the pulsation over the last second.
//!
//! Lines are classified by the same reader as `eha ingest` ([`LineReader`]: the firmware's
//! own line parser, then the bench log's rules). A malformed line is counted and the first
//! one is kept to show; it never stops the session. A controller reset (time starting over)
//! shows as a run of frames whose time does not increase: after [`RESET_RUN`] of them the
//! view starts over from the new time base, and the session reports the reset so the log
//! (whose time must increase) can be closed.
//!
//! Pulsation: the measured pressure over the last [`PULSATION_WINDOW_S`] with its mean and
//! linear trend removed, its peak-to-peak (the transducer's noise included: it is what the
//! bench measures), and the strongest line of its amplitude spectrum
//! ([`crate::pulsation`]) up to half again the rig's highest source order (above it is
//! the transducer's noise), as an order of the mean shaft speed, named by the rig's
//! sources (piston ripple, cogging, flux harmonics) when it matches one.

use crate::ingest::{Line, LineProblem, LineReader};
use crate::pulsation::{amplitude_spectrum, dominant_line, Source};
use firmware::{FaultCode, Mode, TelemetryFrame};
use std::collections::VecDeque;

/// The span the pulsation is measured over. [s]
pub const PULSATION_WINDOW_S: f64 = 1.0;
/// Frames in a row whose time does not increase that mean the controller restarted.
pub const RESET_RUN: usize = 20;
/// Most frames kept for the traces, whatever the window (bounds the memory at full rate).
pub const MAX_WINDOW_FRAMES: usize = 400_000;
/// Lowest frequency taken as pulsation rather than drift. [Hz]
const MIN_PULSATION_HZ: f64 = 2.0;
/// Fewest samples the pulsation is computed from.
const MIN_PULSATION_SAMPLES: usize = 32;
/// Slowest shaft whose orders the pulsation is read in. [rev/s]
const MIN_REV_PER_S: f64 = 1e-3;
/// How far above the rig's highest source order the dominant line is looked for.
const ORDER_MARGIN: f64 = 1.5;

/// What one line did to the session.
#[derive(Clone, Debug, PartialEq)]
pub enum Outcome {
    /// A frame, for the log.
    Frame(TelemetryFrame),
    /// Not telemetry, or malformed telemetry (counted).
    Nothing,
    /// The controller restarted: the frames from here on start a new time base.
    Reset,
}

/// The pulsation over the last second.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pulsation {
    /// Peak-to-peak of the detrended pressure. [Pa]
    pub peak_to_peak_pa: f64,
    /// The mean shaft speed over the span. [rev/s]
    pub shaft_rev_per_s: f64,
    /// The strongest line: frequency [Hz] and amplitude [Pa], if any.
    pub line: Option<(f64, f64)>,
    /// The line's source by its order, if it matches one.
    pub source: Option<Source>,
}

impl Pulsation {
    /// The dominant line's order (cycles per revolution), when the shaft turns.
    pub fn order(&self) -> Option<f64> {
        let (f, _) = self.line?;
        (self.shaft_rev_per_s.abs() > MIN_REV_PER_S).then(|| f / self.shaft_rev_per_s.abs())
    }
}

/// The stream so far.
#[derive(Debug)]
pub struct Session {
    reader: LineReader,
    /// Lines read.
    pub lines: usize,
    /// Telemetry frames taken.
    pub frames: usize,
    /// Lines without the telemetry tag.
    pub skipped: usize,
    /// Telemetry lines that were malformed (too long ones included).
    pub malformed: usize,
    /// The first malformed line: its number and what was wrong.
    pub first_malformed: Option<(usize, String)>,
    /// Frames that carried a latched fault.
    pub faulted_frames: usize,
    /// Controller restarts seen.
    pub resets: usize,
    /// Frames in a row whose time did not increase.
    back_in_time: usize,
    /// The traces' span. [s]
    window_s: f64,
    /// The frames within the window, oldest first.
    window: VecDeque<TelemetryFrame>,
    /// The rig's pulsation sources, to name a line by its order.
    sources: Vec<Source>,
}

impl Session {
    /// An empty session with a trace window of `window_s` seconds.
    pub fn new(window_s: f64, sources: Vec<Source>) -> Session {
        Session {
            reader: LineReader::default(),
            lines: 0,
            frames: 0,
            skipped: 0,
            malformed: 0,
            first_malformed: None,
            faulted_frames: 0,
            resets: 0,
            back_in_time: 0,
            window_s: window_s.max(PULSATION_WINDOW_S),
            window: VecDeque::new(),
            sources,
        }
    }

    /// Takes one line of the decoder's output.
    pub fn line(&mut self, text: &str) -> Outcome {
        self.lines += 1;
        match self.reader.classify(text) {
            Line::Frame(f) => {
                self.back_in_time = 0;
                self.take(f);
                Outcome::Frame(f)
            }
            Line::Other => {
                self.skipped += 1;
                Outcome::Nothing
            }
            Line::Malformed(problem) => {
                let restart = matches!(problem, LineProblem::TimeNotIncreasing { .. });
                self.note_malformed(problem.to_string());
                if restart {
                    self.back_in_time += 1;
                    if self.back_in_time >= RESET_RUN {
                        return self.restart();
                    }
                }
                Outcome::Nothing
            }
        }
    }

    /// Counts a line longer than any decoder prints.
    pub fn too_long(&mut self) {
        self.lines += 1;
        self.note_malformed("longer than any decoder prints; dropped".into());
    }

    fn note_malformed(&mut self, what: String) {
        self.malformed += 1;
        if self.first_malformed.is_none() {
            self.first_malformed = Some((self.lines, what));
        }
    }

    fn take(&mut self, f: TelemetryFrame) {
        self.frames += 1;
        if f.fault.is_some() {
            self.faulted_frames += 1;
        }
        self.window.push_back(f);
        while self.window.len() > MAX_WINDOW_FRAMES
            || self
                .window
                .front()
                .is_some_and(|o| f.t_s - o.t_s > self.window_s)
        {
            self.window.pop_front();
        }
    }

    /// A new time base: the frames of the run that went back in time were counted as
    /// malformed; from the next one on they are taken again.
    fn restart(&mut self) -> Outcome {
        self.resets += 1;
        self.back_in_time = 0;
        self.reader = LineReader::default();
        self.window.clear();
        Outcome::Reset
    }

    /// The frames in the window, oldest first.
    pub fn window(&self) -> &VecDeque<TelemetryFrame> {
        &self.window
    }

    /// The traces' span. [s]
    pub fn window_s(&self) -> f64 {
        self.window_s
    }

    /// The latest frame.
    pub fn latest(&self) -> Option<&TelemetryFrame> {
        self.window.back()
    }

    /// The drive's mode, by the firmware's name.
    pub fn mode(&self) -> Option<Mode> {
        self.latest().map(|f| f.mode)
    }

    /// The latched fault, if any.
    pub fn fault(&self) -> Option<FaultCode> {
        self.latest().and_then(|f| f.fault)
    }

    /// The pulsation over the last [`PULSATION_WINDOW_S`], once that much is in view.
    pub fn pulsation(&self) -> Option<Pulsation> {
        let last = self.latest()?.t_s;
        let recent: Vec<&TelemetryFrame> = self
            .window
            .iter()
            .filter(|f| last - f.t_s <= PULSATION_WINDOW_S)
            .collect();
        let n = recent.len();
        if n < MIN_PULSATION_SAMPLES {
            return None;
        }
        let span = last - recent[0].t_s;
        let dt = span / (n - 1) as f64;
        if dt.is_nan() || dt <= 0.0 {
            return None;
        }
        let p: Vec<f64> = recent.iter().map(|f| f64::from(f.p_pa)).collect();
        let peak_to_peak_pa = crate::pulsation::peak_to_peak(&detrended(&p));
        let shaft_rev_per_s = recent.iter().map(|f| f64::from(f.speed_rad_s)).sum::<f64>()
            / n as f64
            / std::f64::consts::TAU;
        // Above the highest order a source of the rig can have, the spectrum is the
        // transducer's noise and quantisation, not pulsation.
        let top_order = self.sources.iter().map(|s| s.order).fold(0.0, f64::max);
        let max_hz = if shaft_rev_per_s.abs() > MIN_REV_PER_S && top_order > 0.0 {
            ORDER_MARGIN * top_order * shaft_rev_per_s.abs()
        } else {
            f64::INFINITY
        };
        let mut spectrum = amplitude_spectrum(&p, dt);
        spectrum.retain(|(f, _)| *f <= max_hz);
        let found = dominant_line(
            &spectrum,
            MIN_PULSATION_HZ,
            shaft_rev_per_s.abs(),
            &self.sources,
        );
        Some(Pulsation {
            peak_to_peak_pa,
            shaft_rev_per_s,
            line: found.map(|(f, a, _)| (f, a)),
            source: found.and_then(|(_, _, s)| s),
        })
    }
}

/// `x` less its least-squares straight line (a ramping setpoint is not pulsation).
fn detrended(x: &[f64]) -> Vec<f64> {
    let n = x.len() as f64;
    let tm = (n - 1.0) / 2.0;
    let xm = x.iter().sum::<f64>() / n;
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for (i, v) in x.iter().enumerate() {
        let t = i as f64 - tm;
        sxy += t * (v - xm);
        sxx += t * t;
    }
    let slope = if sxx > 0.0 { sxy / sxx } else { 0.0 };
    x.iter()
        .enumerate()
        .map(|(i, v)| v - xm - slope * (i as f64 - tm))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pulsation::sources;
    use plant_model::Rig;

    fn frame(t_s: f64, p_pa: f32, speed: f32) -> TelemetryFrame {
        TelemetryFrame {
            t_s,
            p_ref_pa: 5e6,
            p_pa,
            speed_rad_s: speed,
            iq_a: 0.5,
            id_a: 0.0,
            theta_m_rad: 0.0,
            speed_ref_rad_s: speed,
            iq_ref_a: 0.5,
            ud_v: 0.0,
            uq_v: 1.0,
            udc_v: 280.0,
            mode: Mode::Pressure,
            fault: None,
            command_status: 0,
        }
    }

    fn text(f: &TelemetryFrame) -> String {
        let mut s = String::from("INFO  ");
        f.write_line(&mut s).unwrap();
        s
    }

    #[test]
    fn a_known_ripple_gives_its_peak_to_peak_and_order() {
        // A 2 kPa peak-to-peak line at 18 cycles per revolution on a ramp, shaft at
        // 2 rev/s (36 Hz), sampled at 1 kHz for 1.5 s: the nominal pump's piston ripple.
        let rig = Rig::nominal();
        let mut s = Session::new(5.0, sources(&rig));
        let w = 2.0 * std::f64::consts::TAU;
        for i in 0..1500 {
            let t = i as f64 * 1e-3;
            let p = 5e6 + 2e5 * t + 1e3 * (18.0 * w * t).sin();
            assert!(matches!(
                s.line(&text(&frame(t, p as f32, w as f32))),
                Outcome::Frame(_)
            ));
        }
        let pulse = s.pulsation().unwrap();
        // The straight line fitted over 36 periods takes up a little of the sine (its
        // slope error grows the ends by about A·3/(π·36) each): within 3 %.
        assert!((pulse.peak_to_peak_pa - 2e3).abs() < 60.0, "{pulse:?}");
        assert!((pulse.order().unwrap() - 18.0).abs() < 0.5, "{pulse:?}");
        assert_eq!(pulse.source.unwrap().cause, "piston ripple");
    }

    #[test]
    fn lines_are_counted_and_a_reset_starts_a_new_time_base() {
        let mut s = Session::new(2.0, Vec::new());
        for i in 0..50 {
            s.line(&text(&frame(1.0 + i as f64 * 1e-3, 5e6, 1.0)));
        }
        s.line("INFO  boot");
        s.line("EHA1 t_s=garbage");
        s.too_long();
        assert_eq!((s.frames, s.skipped, s.malformed, s.lines), (50, 1, 2, 53));
        assert_eq!(s.first_malformed.as_ref().unwrap().0, 52);
        // The controller restarts at t = 0: RESET_RUN frames are malformed, then a reset.
        let mut outcomes = Vec::new();
        for i in 0..RESET_RUN + 5 {
            outcomes.push(s.line(&text(&frame(i as f64 * 1e-3, 5e6, 1.0))));
        }
        assert_eq!(outcomes[RESET_RUN - 1], Outcome::Reset);
        assert!(outcomes[RESET_RUN..]
            .iter()
            .all(|o| matches!(o, Outcome::Frame(_))));
        assert_eq!(s.resets, 1);
        assert_eq!(s.malformed, 2 + RESET_RUN);
        assert_eq!(s.window().len(), 5);
        assert_eq!(s.mode(), Some(Mode::Pressure));
    }
}
