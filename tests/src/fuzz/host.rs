//! Host-side readers: the bench-log CSV, the telemetry line and its compact record, `eha
//! ingest` over a decoder's output, and the rig file.

use firmware::telemetry::{parse_line, TelemetryFrame, COMPACT_LEN};
use host_sim::bench_log::{self, limits::LineLimited, BenchLog};
use host_sim::rig_file;
use plant_model::Rig;
use std::io::BufReader;
use std::path::Path;

/// Two logs hold the same bits (NaN cannot occur: the reader refuses it).
fn same_log(a: &BenchLog, b: &BenchLog) -> bool {
    a.metadata == b.metadata
        && a.columns().count() == b.columns().count()
        && a.columns().zip(b.columns()).all(|((sa, ca), (sb, cb))| {
            sa == sb
                && ca.len() == cb.len()
                && ca.iter().zip(cb).all(|(x, y)| x.to_bits() == y.to_bits())
        })
}

/// Written and read back, a log the reader accepted is the same log.
fn round_trips(log: &BenchLog) {
    let bytes = match bench_log::to_bytes(log) {
        Ok(b) => b,
        Err(e) => panic!("the reader accepted a log the writer refuses: {e}"),
    };
    match bench_log::parse(bytes.as_slice(), Path::new("rewritten.csv")) {
        Ok(back) => assert!(same_log(log, &back), "the log changed on a round trip"),
        Err(e) => panic!("a written log does not read back: {e}"),
    }
}

/// The bench-log reader: any bytes; an accepted log passes the writer's checks, round
/// trips bit for bit, and can be asked whether it replays on the nominal rig.
pub fn bench_log(data: &[u8]) {
    let path = Path::new("fuzz.csv");
    if let Ok(log) = bench_log::parse(data, path) {
        assert!(log.check(path).is_ok(), "accepted but fails its own check");
        round_trips(&log);
        let _ = bench_log::replayable::check(&log, &Rig::nominal(), path);
    }
}

/// The telemetry line parser and the compact record: a parsed line written again parses to
/// the same frame; a decoded record encodes to a record that decodes to the same frame.
pub fn telemetry(data: &[u8]) {
    let text = String::from_utf8_lossy(data);
    for line in text.lines() {
        if let Ok(f) = parse_line(line) {
            let mut again = String::new();
            f.write_line(&mut again).expect("writing to a String");
            match parse_line(&again) {
                Ok(g) => assert!(same_frame(&f, &g), "{line:?} → {again:?}"),
                Err(e) => panic!("{again:?} written from {line:?} does not parse: {e}"),
            }
        }
    }
    if let Some(record) = data.get(..COMPACT_LEN) {
        let mut r = [0u8; COMPACT_LEN];
        r.copy_from_slice(record);
        if let Ok(f) = TelemetryFrame::from_compact(&r) {
            let g = TelemetryFrame::from_compact(&f.to_compact()).expect("re-encoded record");
            assert!(same_frame(&f, &g), "compact record not stable");
        }
    }
}

/// Two frames with the same bits (NaN equal to NaN).
fn same_frame(a: &TelemetryFrame, b: &TelemetryFrame) -> bool {
    let fa = [
        a.p_ref_pa,
        a.p_pa,
        a.speed_rad_s,
        a.iq_a,
        a.id_a,
        a.theta_m_rad,
    ];
    let fb = [
        b.p_ref_pa,
        b.p_pa,
        b.speed_rad_s,
        b.iq_a,
        b.id_a,
        b.theta_m_rad,
    ];
    let ga = [a.speed_ref_rad_s, a.iq_ref_a, a.ud_v, a.uq_v, a.udc_v];
    let gb = [b.speed_ref_rad_s, b.iq_ref_a, b.ud_v, b.uq_v, b.udc_v];
    a.t_s.to_bits() == b.t_s.to_bits()
        && fa.iter().zip(fb).all(|(x, y)| x.to_bits() == y.to_bits())
        && ga.iter().zip(gb).all(|(x, y)| x.to_bits() == y.to_bits())
        && (a.mode, a.fault, a.command_status) == (b.mode, b.fault, b.command_status)
}

/// `eha ingest` without the files: a decoder's output to a bench log; what it accepts is a
/// valid bench log that round trips.
pub fn ingest(data: &[u8]) {
    let path = Path::new("fuzz.log");
    let input = BufReader::new(LineLimited::new(data));
    if let Ok((ingested, lines)) = host_sim::ingest::read(input, path) {
        assert!(ingested.malformed.len() <= host_sim::ingest::KEPT);
        assert!(ingested.malformed.len() <= ingested.malformed_count);
        if host_sim::ingest::check(&ingested, lines, path).is_ok() {
            assert!(
                ingested.log.check(path).is_ok(),
                "ingest built an invalid log"
            );
            round_trips(&ingested.log);
        } else if ingested.malformed_count == 0 && ingested.frames() > 0 {
            let t = &ingested.log.t_s;
            if (t[t.len() - 1] - t[0] + 1e-3) * bench_log::MIN_ROWS as f64 > 1e8 {
                return; // the copies would leave the time column's range
            }
            // Too few frames for a bench log: the frames repeated (time shifted on) up to
            // the minimum must still make one, so that small inputs test what ingest keeps
            // of a frame's values without a 100-line input each time.
            let log = repeated(&ingested.log, bench_log::MIN_ROWS);
            assert!(
                log.check(path).is_ok(),
                "ingested frames make an invalid log"
            );
            round_trips(&log);
        }
    }
}

/// `log`'s rows repeated until it has at least `rows`, its time restarted at 0 and each
/// copy shifted past the previous one.
fn repeated(log: &BenchLog, rows: usize) -> BenchLog {
    let n = log.len();
    let (t0, span) = (log.t_s[0], log.t_s[n - 1] - log.t_s[0] + 1e-3);
    let mut out = BenchLog::default();
    let mut k = 0usize;
    while out.len() < rows {
        for (signal, column) in log.columns() {
            let c = out.column_mut(signal);
            if signal == bench_log::Signal::Time {
                // Shifted copies of times one ulp apart may round together: each time at
                // least the next float after the one before (time is not under test).
                for t in column {
                    let shifted = t - t0 + k as f64 * span;
                    let after = c
                        .last()
                        .map_or(f64::NEG_INFINITY, |p: &f64| f64::from_bits(p.to_bits() + 1));
                    c.push(shifted.max(after));
                }
            } else {
                c.extend_from_slice(column);
            }
        }
        k += 1;
    }
    out
}

/// The rig file: any text; an accepted rig is valid, prints as a rig file that loads to the
/// same rig, and a plant can be built on it and stepped.
pub fn rig_file(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let path = Path::new("fuzz.toml");
    let Ok(rig) = rig_file::from_toml(text, path) else {
        return;
    };
    assert_eq!(rig.validate(), Ok(()));
    match rig_file::from_toml(&rig_file::to_toml(&rig), path) {
        Ok(back) => assert!(back == rig, "the rig changed on a round trip"),
        Err(e) => panic!("a printed rig does not load: {e}"),
    }
    // A valid rig builds a plant that steps (a PWM period at 30 % duty on one phase).
    let init = plant_model::InitialConditions::at_rest(&rig);
    let mut plant = plant_model::Plant::new(&rig, &init, 0).expect("a valid rig builds a plant");
    let inputs = plant_model::Inputs::duties([0.65, 0.5, 0.35], true);
    plant.advance(1.0 / rig.inverter.pwm_frequency_hz, &inputs);
    let _ = plant.sample();
}
