//! A setpoint profile: what the bench PC streams to the drive during a test that is not a
//! few fixed commands — a staircase of pressures, a sinusoidal pressure, a speed that
//! ramps, runs and reverses. The setpoint is piecewise linear through knots (a step is two
//! knots at the same instant), plus an optional sine from a given instant, and it is sent
//! as one `SetPressure` or `SetSpeed` command every [`Profile::period_s`], as a bench PC
//! sends its setpoints over CAN (the drive holds the last one between messages).
//!
//! `no_std` and `Copy` like the scenarios that carry it: the named defaults are `const`,
//! and a generator builds its own with [`Profile::new`] and [`Profile::with_knot`].

use firmware::Command;

/// Most knots a profile holds (a staircase of five levels needs ten).
pub const MAX_KNOTS: usize = 12;

/// The bench PC's streaming period: 100 setpoints per second. [s]
pub const STREAM_PERIOD_S: f64 = 0.01;

/// Which reference a profile streams.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Setpoint {
    /// The pressure setpoint (`SetPressure`), pressure control. [Pa]
    Pressure,
    /// The speed setpoint (`SetSpeed`), speed control. [rad/s]
    Speed,
}

/// A sinusoid added to the knots' line from `from_s` on, starting at phase 0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sine {
    /// When it starts. [s]
    pub from_s: f64,
    /// Amplitude (half the peak-to-peak). [Pa or rad/s]
    pub amplitude: f64,
    /// Frequency. [Hz]
    pub frequency_hz: f64,
}

/// Why a knot or sine was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ProfileError {
    /// More than [`MAX_KNOTS`] knots.
    TooManyKnots,
    /// A knot earlier than the one before it, or not finite.
    KnotOutOfOrder,
    /// A sine with a negative or non-finite amplitude, start or frequency.
    BadSine,
}

/// A streamed setpoint: piecewise linear through its knots (held before the first and
/// after the last), plus its [`Sine`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Profile {
    /// What is streamed.
    pub setpoint: Setpoint,
    /// Time between two streamed setpoints. [s]
    pub period_s: f64,
    knots: [(f64, f64); MAX_KNOTS],
    len: usize,
    /// The sinusoid on top of the knots' line, if any.
    pub sine: Option<Sine>,
}

impl Profile {
    /// An empty profile of `setpoint`, streamed every [`STREAM_PERIOD_S`].
    pub const fn new(setpoint: Setpoint) -> Profile {
        Profile {
            setpoint,
            period_s: STREAM_PERIOD_S,
            knots: [(0.0, 0.0); MAX_KNOTS],
            len: 0,
            sine: None,
        }
    }

    /// The profile with the knot (`t_s` [s], `value` [Pa or rad/s]) appended; a knot at the
    /// same instant as the previous one makes a step.
    pub const fn with_knot(mut self, t_s: f64, value: f64) -> Result<Profile, ProfileError> {
        if self.len == MAX_KNOTS {
            return Err(ProfileError::TooManyKnots);
        }
        if !t_s.is_finite()
            || !value.is_finite()
            || (self.len > 0 && t_s < self.knots[self.len - 1].0)
        {
            return Err(ProfileError::KnotOutOfOrder);
        }
        self.knots[self.len] = (t_s, value);
        self.len += 1;
        Ok(self)
    }

    /// The profile with `sine` added.
    pub const fn with_sine(mut self, sine: Sine) -> Result<Profile, ProfileError> {
        let ok = sine.from_s.is_finite()
            && sine.amplitude.is_finite()
            && sine.frequency_hz.is_finite()
            && sine.amplitude >= 0.0
            && sine.frequency_hz >= 0.0;
        if !ok {
            return Err(ProfileError::BadSine);
        }
        self.sine = Some(sine);
        Ok(self)
    }

    /// `with_knot` for the named defaults, where a refusal is a programming error caught
    /// at compile time.
    pub const fn knot(self, t_s: f64, value: f64) -> Profile {
        match self.with_knot(t_s, value) {
            Ok(p) => p,
            Err(_) => panic!("a named profile's knots are in order and within MAX_KNOTS"),
        }
    }

    /// The knots, in order. [(s, Pa or rad/s)]
    pub fn knots(&self) -> &[(f64, f64)] {
        &self.knots[..self.len]
    }

    /// The setpoint at `t_s` [s]. [Pa or rad/s]
    pub fn value_at(&self, t_s: f64) -> f64 {
        let knots = self.knots();
        let line = match knots.iter().rposition(|(t, _)| *t <= t_s) {
            None => knots.first().map_or(0.0, |k| k.1),
            Some(i) => match knots.get(i + 1) {
                Some(&(t1, v1)) if t1 > knots[i].0 => {
                    let (t0, v0) = knots[i];
                    v0 + (v1 - v0) * (t_s - t0) / (t1 - t0)
                }
                _ => knots[i].1,
            },
        };
        let wave = match self.sine {
            Some(s) if t_s >= s.from_s => {
                s.amplitude
                    * libm::sin(2.0 * core::f64::consts::PI * s.frequency_hz * (t_s - s.from_s))
            }
            _ => 0.0,
        };
        line + wave
    }

    /// The command that sends the setpoint at `t_s` [s] (values out of the drive's range
    /// are the drive's to refuse, as on a bench).
    pub fn command_at(&self, t_s: f64) -> Command {
        let v = self.value_at(t_s) as f32;
        match self.setpoint {
            Setpoint::Pressure => Command::SetPressure { pa: v },
            Setpoint::Speed => Command::SetSpeed { rad_s: v },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn knots_interpolate_step_and_hold() {
        let p = Profile::new(Setpoint::Pressure)
            .knot(1.0, 0.5e6)
            .knot(3.0, 4.5e6)
            .knot(5.0, 4.5e6)
            .knot(5.0, 6e6);
        // Held before the first knot, linear on the ramp (halfway: 2.5 MPa), held, stepped
        // at 5 s, held after the last knot.
        assert_eq!(p.value_at(0.0), 0.5e6);
        assert_eq!(p.value_at(2.0), 2.5e6);
        assert_eq!(p.value_at(4.9), 4.5e6);
        assert_eq!(p.value_at(5.0), 6e6);
        assert_eq!(p.value_at(100.0), 6e6);
        assert_eq!(p.with_knot(4.0, 1.0), Err(ProfileError::KnotOutOfOrder));
    }

    #[test]
    fn the_sine_starts_at_zero_phase_on_top_of_the_line() {
        let p = Profile::new(Setpoint::Pressure)
            .knot(0.0, 5e6)
            .with_sine(Sine {
                from_s: 2.0,
                amplitude: 1e5,
                frequency_hz: 0.25,
            })
            .expect("a valid sine");
        // A quarter period (1 s) after its start the sine is at its crest, half a period
        // after it is back at zero.
        assert_eq!(p.value_at(1.9), 5e6);
        assert!((p.value_at(3.0) - 5.1e6).abs() < 1e-6);
        assert!((p.value_at(4.0) - 5e6).abs() < 1e-6);
    }

    #[test]
    fn a_full_profile_refuses_another_knot() {
        let mut p = Profile::new(Setpoint::Speed);
        for k in 0..MAX_KNOTS {
            p = p.knot(k as f64, 0.0);
        }
        assert_eq!(
            p.with_knot(MAX_KNOTS as f64, 0.0),
            Err(ProfileError::TooManyKnots)
        );
    }
}
