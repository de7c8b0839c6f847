//! Parsers of the command line's numeric values, shared by the subcommands' arguments: each
//! names the text it rejects and why, so clap reports it with the flag (exit status 2).

/// A positive finite number.
pub fn positive_f64(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        Ok(_) => Err(format!("`{s}` must be a positive finite number")),
        Err(_) => Err(format!("`{s}` is not a number")),
    }
}

/// A finite number, not negative.
pub fn non_negative_f64(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v >= 0.0 => Ok(v),
        Ok(_) => Err(format!("`{s}` must be a finite number, not negative")),
        Err(_) => Err(format!("`{s}` is not a number")),
    }
}
