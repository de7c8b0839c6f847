//! The bench-log reader and writer against the contract's rules.

use super::*;
use std::path::Path;

fn log_text(rows: usize, header: &str, row: impl Fn(usize) -> String) -> String {
    let mut s = String::from("# source: test\n# rig: nominal\n");
    s.push_str(header);
    s.push('\n');
    for i in 0..rows {
        s.push_str(&row(i));
        s.push('\n');
    }
    s
}

const HEADER: &str = "t_s,p_ref_pa,p_pa,speed_rad_s,iq_a,id_a";

fn good_row(i: usize) -> String {
    format!("{},5e6,{},6.0,1.5,0", i as f64 * 1e-3, 5e6 + i as f64)
}

fn parse_str(s: &str) -> Result<BenchLog, BenchLogError> {
    parse(s.as_bytes(), Path::new("test.csv"))
}

fn content_error(s: &str) -> (usize, String, Problem) {
    match parse_str(s).unwrap_err() {
        BenchLogError::Content {
            line,
            column,
            problem,
            ..
        } => (line, column, problem),
        e => panic!("expected a content error, got {e}"),
    }
}

#[test]
fn reads_metadata_and_columns_by_name() {
    let text = log_text(
        100,
        "id_a,iq_a, speed_rad_s ,p_pa,p_ref_pa,t_s,mode,x_m",
        |i| format!("0,{},6,{},5e6,{},hold,1.5E-3", i, 1e6 + i as f64, i),
    );
    let log = parse_str(&text).unwrap();
    assert_eq!(log.len(), 100);
    assert_eq!(log.meta("source"), Some("test"));
    assert_eq!(log.meta("rig"), Some("nominal"));
    assert_eq!(log.t_s[99], 99.0);
    assert_eq!(log.p_pa[3], 1e6 + 3.0);
    assert_eq!(log.iq_a[7], 7.0);
    assert_eq!(log.speed_rad_s[0], 6.0);
    assert_eq!(log.x_m.as_ref().unwrap()[0], 1.5e-3);
    assert!(log.theta_m_rad.is_none());
}

#[test]
fn each_contract_violation_names_line_and_column() {
    // Lines: 1–2 metadata, 3 header, data from line 4.
    let (l, c, p) = content_error(&log_text(100, "t_s,p_ref_pa,p_pa,iq_a,id_a", |i| {
        format!("{i},0,0,0,0")
    }));
    assert_eq!(
        (l, c.as_str(), p),
        (3, "speed_rad_s", Problem::MissingColumn)
    );

    let (l, c, p) = content_error(&log_text(100, &format!("{HEADER},p_pa"), |i| {
        format!("{},0", good_row(i))
    }));
    assert_eq!(
        (l, c.as_str(), p),
        (
            3,
            "p_pa",
            Problem::DuplicateColumn {
                first: 3,
                second: 7
            }
        )
    );

    let (l, c, p) = content_error(&log_text(100, HEADER, |i| {
        if i == 10 {
            "0.01,5e6,abc,6,1.5,0".into()
        } else {
            good_row(i)
        }
    }));
    assert_eq!(
        (l, c.as_str(), p),
        (14, "p_pa", Problem::NotANumber { text: "abc".into() })
    );

    let (l, c, _) = content_error(&log_text(100, HEADER, |i| {
        if i == 50 {
            "0.05,5e6,1,NaN,1.5,0".into()
        } else {
            good_row(i)
        }
    }));
    assert_eq!((l, c.as_str()), (54, "speed_rad_s"));

    let (l, c, p) = content_error(&log_text(100, HEADER, |i| {
        if i == 20 {
            "0.019,5e6,1,6,1.5,0".into()
        } else {
            good_row(i)
        }
    }));
    assert_eq!(
        (l, c.as_str(), p),
        (
            24,
            "t_s",
            Problem::TimeNotIncreasing {
                previous: 0.019,
                value: 0.019
            }
        )
    );

    let (l, c, p) = content_error(&log_text(99, HEADER, good_row));
    assert_eq!(
        (l, c.as_str(), p),
        (102, "t_s", Problem::TooFewRows { rows: 99 })
    );

    let (l, c, p) = content_error(&log_text(100, HEADER, |i| {
        if i == 30 {
            "0.03,5e6,1,6,1.5".into()
        } else {
            good_row(i)
        }
    }));
    assert_eq!(
        (l, c.as_str(), p),
        (
            34,
            "id_a",
            Problem::WrongFieldCount {
                expected: 6,
                found: 5
            }
        )
    );
    let (l, c, _) = content_error(&log_text(100, HEADER, |i| {
        if i == 31 {
            format!("{},9", good_row(i))
        } else {
            good_row(i)
        }
    }));
    assert_eq!((l, c.as_str()), (35, "field 7"));

    let (l, _, p) = content_error("# only: metadata\n");
    assert_eq!((l, p), (2, Problem::NoHeader));
}

#[test]
fn message_names_file_line_and_column() {
    let text = log_text(100, HEADER, |i| {
        if i == 0 {
            "0,5e6,inf,6,1.5,0".into()
        } else {
            good_row(i)
        }
    });
    let msg = parse(text.as_bytes(), Path::new("runs/a.csv"))
        .unwrap_err()
        .to_string();
    assert!(msg.contains("runs/a.csv"), "{msg}");
    assert!(msg.contains("line 4"), "{msg}");
    assert!(msg.contains("column `p_pa`"), "{msg}");
}

#[test]
fn write_then_read_is_identity_including_awkward_values() {
    let mut log = BenchLog {
        metadata: vec![("source".into(), "sim".into()), ("x".into(), "".into())],
        ..BenchLog::default()
    };
    for i in 0..150 {
        let t = i as f64 * 1e-4 + 0.1; // not exactly representable sums
        log.t_s.push(t);
        log.p_ref_pa.push(5e6);
        log.p_pa
            .push(5e6 + (i as f64 * 0.7).sin() * 1.234_567_890_123e4);
        log.speed_rad_s.push(1.0 / 3.0 + i as f64);
        log.iq_a.push(-1e-300 * i as f64);
        log.id_a.push(if i % 2 == 0 { 0.0 } else { -0.0 });
        // Largest in its physical range, and awkward quotients of it.
        log.column_mut(Signal::OilTemp).push(1e4 / (i + 1) as f64);
    }
    let dir = std::env::temp_dir().join(format!("eha-bench-log-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("rt.csv");
    write(&path, &log).unwrap();
    let back = read(&path).unwrap();
    assert_eq!(back.len(), log.len());
    for (s, c) in log.columns() {
        let b = back.column(s).unwrap();
        assert!(
            c.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits()),
            "{} differs",
            s.name()
        );
    }
    assert_eq!(back.metadata, log.metadata);
    assert!(back.x_m.is_none());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn write_refuses_a_log_the_reader_would_reject_and_leaves_no_file() {
    let dir = std::env::temp_dir().join(format!("eha-bench-log-bad-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("bad.csv");
    let mut log = parse_str(&log_text(100, HEADER, good_row)).unwrap();
    log.p_pa[5] = f64::NAN;
    assert!(matches!(
        write(&path, &log),
        Err(BenchLogError::Content { line: 9, .. })
    ));
    log.p_pa[5] = 0.0;
    log.speed_rad_s.pop();
    assert!(matches!(
        write(&path, &log),
        Err(BenchLogError::Content {
            problem: Problem::ColumnLength { .. },
            ..
        })
    ));
    assert!(!path.exists());
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn format_is_shortest_round_trip() {
    let f = |v: f64| {
        let mut s = String::new();
        format_value(&mut s, v);
        s
    };
    assert_eq!(f(5e6), "5000000");
    assert_eq!(f(0.1), "0.1");
    assert_eq!(f(1e-13), "1e-13");
    assert_eq!(f(-2.5e20), "-2.5e20");
    assert_eq!(f(0.0), "0");
}

#[test]
fn metadata_the_writer_cannot_write_is_refused_on_reading() {
    // Found by fuzzing: a carriage return inside a value was read, and the log could not
    // be written back.
    let body = log_text(100, HEADER, good_row);
    let cr = format!("# source: a\rb\n{body}");
    let (l, c, p) = content_error(&cr);
    assert_eq!((l, c.as_str(), p), (1, "source", Problem::BadMetadata));
    let (l, _, p) = content_error(&format!("#: value\n{body}"));
    assert_eq!((l, p), (1, Problem::BadMetadata));
    // A bare `#` line is skipped like a blank one; a CRLF line end is no carriage return
    // inside.
    let ok = parse_str(&format!("#\r\n# rig: x\r\n{body}")).unwrap();
    assert_eq!(ok.meta("rig"), Some("x"));
    assert!(ok.check(Path::new("t.csv")).is_ok());
}

#[test]
fn drive_and_recorded_at_are_kept_and_read_alone_from_the_head() {
    let text = format!(
        "# drive: press-07\n# recorded_at: 2026-11-30T14:05:00Z\n{}",
        log_text(120, HEADER, good_row)
    );
    let log = parse_str(&text).unwrap();
    assert_eq!(log.drive(), Some("press-07"));
    assert_eq!(log.recorded_at(), Some("2026-11-30T14:05:00Z"));
    // Written back, both lines come first and read back the same.
    let bytes = to_bytes(&log).unwrap();
    assert!(String::from_utf8_lossy(&bytes).starts_with("# drive: press-07\n"));
    // The head alone: the metadata without reading the rows (which here are broken).
    let dir = crate::output::scratch::scratch_dir("bench-log-meta");
    let path = dir.join("head.csv");
    let head = "# drive: press-07\n# recorded_at: 2026-11-30T14:05:00Z\nt_s,oops\nnot,a,row\n";
    std::fs::write(&path, head).unwrap();
    let meta = read_metadata(&path).unwrap();
    assert_eq!(
        meta,
        vec![
            ("drive".to_string(), "press-07".to_string()),
            (
                "recorded_at".to_string(),
                "2026-11-30T14:05:00Z".to_string()
            )
        ]
    );
    assert!(read(&path).is_err());
    // A missing file names itself.
    let e = read_metadata(&dir.join("absent.csv")).unwrap_err();
    assert!(e.to_string().contains("absent.csv"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_log_at_the_thinning_rate_with_scattered_stamps_is_read_whole() {
    // 2 kHz rows (0.5 ms) stamped ±0.1 ms off their grid: a quarter of the intervals fall
    // under 0.45 ms, but the log is no faster than the rows the diagnosis reads, so none is
    // skipped.
    let scatter = |i: usize| [0.0, 0.9e-4, -0.8e-4, 0.6e-4, -0.9e-4][i % 5];
    let stamped = |i: usize| {
        let t = if i == 0 {
            0.0
        } else {
            i as f64 * 5e-4 + scatter(i)
        };
        format!("{t},5e6,{},6.0,1.5,0", 5e6 + i as f64)
    };
    let dir = std::env::temp_dir().join(format!("eha-thin-2k-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("stamped.csv");
    std::fs::write(&path, log_text(1000, HEADER, stamped)).unwrap();
    let whole = read(&path).unwrap();
    let intervals = whole
        .t_s
        .windows(2)
        .filter(|w| w[1] - w[0] < 0.45e-3)
        .count();
    assert!(intervals > 100, "{intervals} intervals under 0.45 ms");
    let (log, rows) = read_thinned(&path, 0.45e-3).unwrap();
    assert_eq!((rows, log.len()), (1000, 1000));
    assert_eq!(whole.thinned(0.45e-3), None);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_thinned_read_keeps_rows_the_interval_apart_and_still_checks_every_row() {
    // 10 kHz rows (0.1 ms) read at 0.45 ms at least: every fifth row, as logged.
    let fast = |i: usize| format!("{},5e6,{},6.0,1.5,0", i as f64 * 1e-4, 5e6 + i as f64);
    let dir = std::env::temp_dir().join(format!("eha-thin-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("fast.csv");
    std::fs::write(&path, log_text(1000, HEADER, fast)).unwrap();
    let (log, rows) = read_thinned(&path, 0.45e-3).unwrap();
    assert_eq!(rows, 1000);
    assert_eq!(log.len(), 200);
    for (k, (&t, &p)) in log.t_s.iter().zip(&log.p_pa).enumerate() {
        assert!((t - k as f64 * 5e-4).abs() < 1e-12, "row {k}: t = {t}");
        assert_eq!(
            p,
            5e6 + (5 * k) as f64,
            "row {k}: the logged value, unfiltered"
        );
    }
    // The same rows as thinning the whole log, and a 1 kHz log is left whole.
    let whole = read(&path).unwrap();
    assert_eq!(whole.thinned(0.45e-3).as_ref(), Some(&log));
    assert_eq!(log.thinned(0.45e-3), None);
    // A fault in a row the thinning skips (row 3, not a fifth) is still reported there.
    let bad = log_text(1000, HEADER, |i| {
        if i == 3 {
            "3e-4,5e6,x,6,1.5,0".into()
        } else {
            fast(i)
        }
    });
    std::fs::write(&path, bad).unwrap();
    match read_thinned(&path, 0.45e-3).unwrap_err() {
        BenchLogError::Content { line, column, .. } => {
            assert_eq!((line, column.as_str()), (7, "p_pa"))
        }
        e => panic!("expected a content error, got {e}"),
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_column_let_go_passes_only_where_the_reader_names_it_unread() {
    // The setpoint emptied after reading: the full check refuses the log (the column is
    // shorter than the time's), the check for a reader that never reads it passes, and a
    // thinning keeps it empty while it thins the others.
    let mut log = parse_str(&log_text(1000, HEADER, good_row)).unwrap();
    log.p_ref_pa = Vec::new();
    let file = Path::new("t.csv");
    match log.check(file).unwrap_err() {
        BenchLogError::Content {
            column, problem, ..
        } => {
            assert_eq!(column, "p_ref_pa");
            assert_eq!(
                problem,
                Problem::ColumnLength {
                    expected: 1000,
                    found: 0
                }
            );
        }
        e => panic!("expected a content error, got {e}"),
    }
    assert!(log.check_holding(file, &[Signal::PressureRef]).is_ok());
    // Another column emptied is refused whatever is named unread.
    let mut short = log.clone();
    short.iq_a = Vec::new();
    assert!(short.check_holding(file, &[Signal::PressureRef]).is_err());
    let thin = log.thinned(2.5e-3).unwrap();
    assert_eq!((thin.len(), thin.p_ref_pa.len()), (334, 0));
    assert!(thin.check_holding(file, &[Signal::PressureRef]).is_ok());
}

#[test]
fn an_optional_column_is_removed_and_a_required_one_is_not() {
    // Every column of the contract's tables: the six required stay, the nine optional go,
    // and the log then reads as one written without them.
    let header = Signal::ALL.map(Signal::name).join(",");
    let text = log_text(100, &header, |i| {
        let mut v = vec![format!("{}", i as f64 * 1e-3)];
        v.extend((1..Signal::ALL.len()).map(|_| "1".to_string()));
        v.join(",")
    });
    let mut log = parse_str(&text).unwrap();
    let required = ["t_s", "p_ref_pa", "p_pa", "speed_rad_s", "iq_a", "id_a"];
    for s in Signal::ALL {
        assert_eq!(log.remove(s), !required.contains(&s.name()), "{}", s.name());
    }
    let kept: Vec<&str> = log.columns().map(|(s, _)| s.name()).collect();
    assert_eq!(kept, required);
}
