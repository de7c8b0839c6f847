//! Times of bench logs and of predictions: RFC 3339 timestamps (`# recorded_at:` in a
//! bench log, the `recorded_at` column of a fleet manifest) read with the `time` crate, held
//! for arithmetic as days since the Unix epoch (1970-01-01T00:00:00Z, UTC), and written
//! back as RFC 3339 timestamps or calendar dates (UTC).

use crate::bench_log::limits::excerpt;
use time::format_description::well_known::Rfc3339;
use time::OffsetDateTime;

/// Seconds per day. [s/day]
pub const SECONDS_PER_DAY: f64 = 86_400.0;

/// Days since the Unix epoch of an RFC 3339 timestamp (`2026-11-30T14:05:00Z`,
/// `2026-11-30T15:05:00+01:00`, fractions of a second allowed). [day]
pub fn parse_days(text: &str) -> Result<f64, String> {
    let t = OffsetDateTime::parse(text.trim(), &Rfc3339).map_err(|e| {
        format!(
            "`{}` is not an RFC 3339 timestamp like 2026-11-30T14:05:00Z ({e})",
            excerpt(text)
        )
    })?;
    Ok(t.unix_timestamp_nanos() as f64 / 1e9 / SECONDS_PER_DAY)
}

/// The clap parser of an RFC 3339 argument: the text as given, once it parses.
pub fn rfc3339_arg(text: &str) -> Result<String, String> {
    parse_days(text).map(|_| text.trim().to_string())
}

/// The instant `days` after the Unix epoch (UTC), `None` beyond the years 1–9999.
fn instant(days: f64) -> Option<OffsetDateTime> {
    if !days.is_finite() {
        return None;
    }
    let nanos = (days * SECONDS_PER_DAY * 1e9).round();
    // ±3e5 years of nanoseconds fit an i128 easily; `time` refuses what it cannot hold.
    OffsetDateTime::from_unix_timestamp_nanos(nanos as i128).ok()
}

/// The UTC calendar date `days` after the Unix epoch (`2026-11-30`), `None` when it is not
/// finite or beyond the years 1–9999.
pub fn date(days: f64) -> Option<String> {
    instant(days).map(|t| t.date().to_string())
}

/// The RFC 3339 timestamp (UTC, whole seconds) `days` after the Unix epoch.
pub fn rfc3339(days: f64) -> Option<String> {
    let t = instant(days)?.replace_nanosecond(0).ok()?;
    t.format(&Rfc3339).ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn timestamps_are_days_since_the_epoch() {
        // 2000-03-01 is day 11 017: 30 years of 365 days, 7 leap days (1972–1996), and
        // 31 + 29 days of January and February 2000.
        assert_eq!(parse_days("2000-03-01T00:00:00Z").unwrap(), 11_017.0);
        assert_eq!(parse_days("1970-01-01T12:00:00Z").unwrap(), 0.5);
        // An offset is the same instant in UTC.
        assert_eq!(
            parse_days("2026-11-30T15:05:00+01:00").unwrap(),
            parse_days("2026-11-30T14:05:00Z").unwrap()
        );
        assert_eq!(date(11_017.0).as_deref(), Some("2000-03-01"));
        assert_eq!(date(11_016.99).as_deref(), Some("2000-02-29"));
        assert_eq!(rfc3339(11_017.25).as_deref(), Some("2000-03-01T06:00:00Z"));
        assert_eq!(date(f64::NAN), None);
        assert_eq!(date(1e12), None);
    }

    #[test]
    fn what_is_not_rfc_3339_is_refused_by_name() {
        for bad in [
            "2026-11-30",
            "30/11/2026 14:05",
            "2026-13-01T00:00:00Z",
            "",
            "now",
        ] {
            let e = parse_days(bad).unwrap_err();
            assert!(e.contains("RFC 3339"), "{bad}: {e}");
        }
    }
}
