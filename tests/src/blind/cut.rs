//! A share of a bench log's rows, the way a bench records a test other than in full: its
//! first rows (a shorter log of the same test) or its last ones (a recorder started late,
//! after the ramp). The scoring tables read foreign logs cut so, to see how the diagnosis
//! holds on logs drawn in other ways than the development sets.

use host_sim::bench_log::BenchLog;

/// Which rows of each log are kept.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Cut {
    /// The first share of the rows, in (0, 1]. [1]
    First(f64),
    /// The last share of the rows, in (0, 1]. [1]
    Last(f64),
}

impl Cut {
    /// Reads `first:SHARE` or `last:SHARE`, the share in (0, 1].
    pub fn parse(text: &str) -> Result<Cut, String> {
        let bad = || format!("`{text}`: expected first:SHARE or last:SHARE, SHARE in (0, 1]");
        let (side, share) = text.split_once(':').ok_or_else(bad)?;
        let share: f64 = share.trim().parse().map_err(|_| bad())?;
        if !(share > 0.0 && share <= 1.0) {
            return Err(bad());
        }
        match side.trim() {
            "first" => Ok(Cut::First(share)),
            "last" => Ok(Cut::Last(share)),
            _ => Err(bad()),
        }
    }

    /// The rows of `log` this cut keeps (`share·rows` rounded down, at least two), with their
    /// logged times and the log's metadata ([`BenchLog::rows`]).
    pub fn apply(self, log: &BenchLog) -> BenchLog {
        let n = log.len();
        let keep = |share: f64| ((share * n as f64) as usize).clamp(2.min(n), n);
        log.rows(match self {
            Cut::First(s) => 0..keep(s),
            Cut::Last(s) => n - keep(s)..n,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use host_sim::bench_log::Signal;

    fn ten_rows() -> BenchLog {
        let mut log = BenchLog::default();
        for signal in [Signal::Time, Signal::Pressure, Signal::ThetaM] {
            *log.column_mut(signal) = (0..10).map(|k| k as f64).collect();
        }
        log
    }

    #[test]
    fn a_cut_keeps_the_first_or_the_last_rows_as_logged() {
        let log = ten_rows();
        let first = Cut::parse("first:0.45").unwrap().apply(&log);
        assert_eq!(first.t_s, [0.0, 1.0, 2.0, 3.0]);
        assert_eq!(first.p_pa, [0.0, 1.0, 2.0, 3.0]);
        let last = Cut::parse("last:0.3").unwrap().apply(&log);
        assert_eq!(last.t_s, [7.0, 8.0, 9.0]);
        assert_eq!(last.theta_m_rad.as_deref(), Some(&[7.0, 8.0, 9.0][..]));
        // An absent optional column stays absent.
        assert!(last.x_m.is_none());
        // However small the share, two rows.
        assert_eq!(Cut::First(0.01).apply(&log).len(), 2);
        // Rows past the log's end are not there to keep.
        assert_eq!(log.rows(8..20).t_s, [8.0, 9.0]);
        assert!(log.rows(12..20).is_empty());
    }

    #[test]
    fn a_cut_is_first_or_last_with_a_share_in_the_unit_interval() {
        for bad in [
            "first",
            "middle:0.5",
            "first:0",
            "last:1.5",
            "last:x",
            "first:-0.2",
        ] {
            assert!(Cut::parse(bad).is_err(), "{bad}");
        }
        assert_eq!(Cut::parse("last:1"), Ok(Cut::Last(1.0)));
    }
}
