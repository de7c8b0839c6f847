//! Parsers of the command line's numeric values, shared by the subcommands' arguments: each
//! names the text it rejects (an excerpt of a long one) and why, so clap reports it with
//! the flag (exit status 2); and numbers as messages show them.

use crate::bench_log::limits::excerpt;

/// A positive finite number.
pub fn positive_f64(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        Ok(_) => Err(format!("`{}` must be a positive finite number", excerpt(s))),
        Err(_) => Err(format!("`{}` is not a number", excerpt(s))),
    }
}

/// A finite number, not negative.
pub fn non_negative_f64(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v >= 0.0 => Ok(v),
        Ok(_) => Err(format!(
            "`{}` must be a finite number, not negative",
            excerpt(s)
        )),
        Err(_) => Err(format!("`{}` is not a number", excerpt(s))),
    }
}

/// A number as a message shows it: the shortest text that reads back to it, in exponent
/// notation when positional would spell out dozens of digits (`1e300`, not 301 digits).
pub fn show(v: f64) -> String {
    let mut s = String::new();
    crate::bench_log::format_value(&mut s, v);
    s
}

/// `text` with every word longer than a screen line cut to an excerpt: clap quotes a
/// rejected argument whole, and a 2 MB argument would fill the terminal.
pub fn shorten_long_words(text: &str) -> String {
    const LONGEST: usize = 80;
    let mut out = String::with_capacity(text.len().min(4096));
    for (i, line) in text.split('\n').enumerate() {
        if i > 0 {
            out.push('\n');
        }
        for (j, word) in line.split(' ').enumerate() {
            if j > 0 {
                out.push(' ');
            }
            if word.chars().count() > LONGEST {
                out.push_str(&excerpt(word));
            } else {
                out.push_str(word);
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn long_arguments_are_quoted_as_excerpts() {
        let arg = "7".repeat(2_000_000);
        let e = positive_f64(&format!("{arg}x")).unwrap_err();
        assert!(e.len() < 120, "{e}");
        let msg = shorten_long_words(&format!(
            "error: invalid value '{arg}' for '--duration <S>'"
        ));
        assert!(msg.len() < 160 && msg.contains("--duration"), "{msg}");
        assert_eq!(show(1e300), "1e300");
        assert_eq!(show(2e6), "2000000");
    }
}
