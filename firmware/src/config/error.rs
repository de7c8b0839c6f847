//! The one error a configuration check gives: the dotted path of the first offending
//! field and what is wrong with it. Every section's `validate` returns it, so it sits
//! below all of them.

use core::fmt;

/// A configuration field that failed validation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ConfigError {
    /// Dotted field path, e.g. `rates.pwm_hz`.
    pub field: &'static str,
    /// What is wrong with it.
    pub problem: &'static str,
}

impl fmt::Display for ConfigError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "config field `{}`: {}", self.field, self.problem)
    }
}

impl core::error::Error for ConfigError {}
