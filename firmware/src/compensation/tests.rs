//! The feed-forward's table, lookup, record and CAN load, checked against values written
//! out here (a sampled sine, the documented byte layout, hand-computed bounds).

use super::record::{self, RecordError, RECORD_LEN};
use super::*;
use crate::Config;
use core::f32::consts::TAU;
use std::vec::Vec;

/// A table whose constant channel is `amp`·cos(k·θ + φ) sampled at the bins (i16 with
/// exponent 20: ±0.031 A full scale), the other channels constant.
fn line_table(amp: f32, k: u32, phi: f32) -> Table {
    let e = 20;
    let mut raw = [[0i16; CHANNELS]; BINS];
    for (b, r) in raw.iter_mut().enumerate() {
        let th = b as f32 * TAU / BINS as f32;
        let v = amp * libm::cosf(k as f32 * th + phi);
        *r = [libm::roundf(v / lsb(e)) as i16, 1000, -2000];
    }
    Table::from_raw([e, 40, 24], &raw).unwrap()
}

#[test]
fn the_lsb_is_an_exact_power_of_two() {
    assert_eq!(lsb(0), 1.0);
    assert_eq!(lsb(10), 1.0 / 1024.0);
    assert_eq!(lsb(40), 1.0 / (1u64 << 40) as f32);
    assert!(lsb(MAX_EXPONENT) > 0.0 && lsb(MAX_EXPONENT).is_normal());
}

#[test]
fn the_lookup_interpolates_a_sampled_line_within_the_chord_bound() {
    // A line of order k sampled every h = 2π/512 of shaft angle: between samples linear
    // interpolation errs by at most amp·(k·h)²/8 (the chord's sag), plus the i16 rounding.
    let (amp, k) = (0.03, 24u32);
    let t = line_table(amp, k, 0.4);
    let h = TAU / BINS as f32;
    let bound = amp * (k as f32 * h) * (k as f32 * h) / 8.0 + lsb(20) + 1e-6;
    let mut worst = 0f32;
    for i in 0..20_000 {
        let th = i as f32 * 0.000_731 - 2.0;
        let want = amp * libm::cosf(k as f32 * th + 0.4);
        let [c0, cp, ci] = t.at(th);
        worst = worst.max((c0 - want).abs());
        assert_eq!(cp, 1000.0 * lsb(40));
        assert_eq!(ci, -2000.0 * lsb(24));
    }
    assert!(worst <= bound, "worst {worst} vs bound {bound}");
}

fn enabled(scale: f32) -> Config {
    let mut cfg = Config::nominal();
    cfg.compensation.enabled = true;
    cfg.compensation.scale = scale;
    cfg
}

#[test]
fn the_feed_forward_scales_each_channel_with_its_regressor() {
    // At a bin's angle, standing still: g·(c0 + cp·p + ci·iq) with the values written.
    let cfg = enabled(0.5);
    let mut c = Compensation::new(&cfg);
    let mut raw = [[0i16; CHANNELS]; BINS];
    raw[100] = [3000, 500, -700];
    let t = Table::from_raw([14, 36, 16], &raw).unwrap();
    c.install(&t, &cfg).unwrap();
    let th = 100.0 * TAU / BINS as f32;
    let (p, iq) = (5e6, 1.2);
    let want = 0.5 * (3000.0 * lsb(14) + 500.0 * lsb(36) * p - 700.0 * lsb(16) * iq);
    let (got, flux) = c.current(th, 0.0, p, iq);
    // The per-current channel times the gain: the flux harmonics' share.
    assert!((flux - 0.5 * -700.0 * lsb(16)).abs() < 1e-9, "{flux}");
    assert!(
        (got - want).abs() < 1e-6 * want.abs().max(1.0),
        "{got} vs {want}"
    );
    // The lookup leads by ω·t_lead: at speed, the value a lead-time later is used.
    let lead = c.lead_s();
    assert!((lead - (0.012 / 13.2 + 1.0 / 20e3)).abs() < 1e-7, "{lead}");
    let w = 50.0;
    let (ahead, _) = c.current(th - w * lead, w, p, iq);
    assert!((ahead - got).abs() < 2e-3 * got.abs(), "{ahead} vs {got}");
    // Off: zero whatever the table holds.
    let mut off = cfg;
    off.compensation.enabled = false;
    c.retune(&off);
    assert_eq!(c.current(th, 0.0, p, iq), (0.0, 0.0));
    assert!(!c.is_active());
}

#[test]
fn the_amplitude_bound_is_the_sum_of_the_channel_peaks_over_the_operating_range() {
    // Peaks 0.5 A, 1e-8 A/Pa, 0.01 A/A at the nominal trip pressure and q-current limit
    // (20 MPa, 30 A): 0.5 + 0.2 + 0.3 = 1.0 A at unit scale.
    let mut raw = [[0i16; CHANNELS]; BINS];
    raw[3] = [-16384, 0, 0];
    raw[7] = [0, 10_995, 0];
    raw[9] = [0, 0, 10_486];
    let t = Table::from_raw([15, 40, 20], &raw).unwrap();
    let cfg = Config::nominal();
    let bound = t.amplitude_bound(cfg.limits.over_pressure_pa, cfg.speed.iq_limit_a);
    let want = 0.5 + 10_995.0 / (1u64 << 40) as f32 * 20e6 + 10_486.0 / (1u64 << 20) as f32 * 30.0;
    assert!(
        (bound - want).abs() < 1e-5 && (bound - 1.0).abs() < 1e-3,
        "{bound}"
    );
    // The nominal 3 A limit: scale 2 (2.0 A) accepted; with the limit lowered to 1.5 A
    // refused naming it.
    assert_eq!(Compensation::check_amplitude(&t, &enabled(2.0)), Ok(()));
    let mut low = enabled(2.0);
    low.compensation.max_current_a = 1.5;
    match Compensation::check_amplitude(&t, &low) {
        Err(CompensationError::Amplitude {
            amplitude_a,
            limit_a,
        }) => {
            assert_eq!(limit_a, 1.5);
            assert!((amplitude_a - 2.0 * want).abs() < 1e-4);
        }
        other => panic!("{other:?}"),
    }
    // A refused install leaves an empty table: the drive runs uncompensated.
    let mut c = Compensation::new(&low);
    assert!(c.install(&t, &low).is_err());
    assert!(c.table().is_zero());
    assert_eq!(c.current(0.1, 0.0, 5e6, 1.0), (0.0, 0.0));
}

fn record_of(t: &Table) -> Vec<u8> {
    let mut out = [0u8; RECORD_LEN];
    record::Encoder::write_all(t, &mut out);
    out.to_vec()
}

#[test]
fn a_record_has_the_documented_layout_and_reads_back_exactly() {
    let t = line_table(0.02, 72, 1.0);
    let r = record_of(&t);
    assert_eq!(r.len(), 3096);
    assert_eq!(&r[0..4], b"EHCT");
    assert_eq!(u16::from_le_bytes([r[4], r[5]]), 1);
    assert_eq!(u16::from_le_bytes([r[6], r[7]]), 512);
    assert_eq!(r[8], 3);
    assert_eq!([r[10], r[11], r[12]], [20, 40, 24]);
    // Bin 5's constant channel at bytes 16 + 6·5.
    let raw5 = i16::from_le_bytes([r[46], r[47]]);
    assert_eq!(f32::from(raw5) * lsb(20), t.bin(5)[0]);
    // The CRC is CRC-32/ISO-HDLC of everything before it (the crate's table-driven
    // implementation, not the record's).
    let crc = crc::Crc::<u32>::new(&crc::CRC_32_ISO_HDLC).checksum(&r[..16 + 6 * 512]);
    assert_eq!(u32::from_le_bytes(r[3088..3092].try_into().unwrap()), crc);
    assert_eq!(record::crc_of(&t), crc);
    let mut back = Table::ZERO;
    assert_eq!(record::from_bytes(&r, &mut back), Ok(()));
    assert_eq!(back, t);
}

#[test]
fn a_record_of_the_wrong_size_version_sizes_or_crc_is_refused_and_leaves_no_table() {
    let good = record_of(&line_table(0.02, 72, 1.0));
    let refused = |bytes: &[u8]| {
        let mut t = line_table(0.01, 18, 0.0);
        let e = record::from_bytes(bytes, &mut t).unwrap_err();
        assert!(t.is_zero(), "{e:?} left a table");
        e
    };
    assert_eq!(
        refused(&good[..good.len() - 8]),
        RecordError::Length { found: 3088 }
    );
    let mut long = good.clone();
    long.extend_from_slice(&[0xFF; 8]);
    assert_eq!(refused(&long), RecordError::Length { found: 3104 });
    let mut bad = good.clone();
    bad[0] = b'X';
    assert_eq!(refused(&bad), RecordError::Magic);
    let mut bad = good.clone();
    bad[4] = 2;
    assert_eq!(refused(&bad), RecordError::Version { found: 2 });
    let mut bad = good.clone();
    bad[6..8].copy_from_slice(&1024u16.to_le_bytes());
    assert_eq!(refused(&bad), RecordError::Bins { found: 1024 });
    let mut bad = good.clone();
    bad[8] = 2;
    assert_eq!(refused(&bad), RecordError::Channels { found: 2 });
    let mut bad = good.clone();
    bad[11] = 120;
    assert_eq!(
        refused(&bad),
        RecordError::Exponent {
            channel: 1,
            found: 120
        }
    );
    let mut bad = good.clone();
    bad[1000] ^= 0x10;
    assert!(matches!(refused(&bad), RecordError::Crc { .. }));
}

#[test]
fn a_can_load_in_order_with_the_records_crc_installs_the_table() {
    let cfg = enabled(1.0);
    let t = line_table(0.03, 72, 0.3);
    let mut c = Compensation::new(&cfg);
    c.begin(t.exponents(), BINS as u16, &cfg).unwrap();
    assert!(!c.is_active(), "off while loading");
    for b in 0..BINS {
        c.bin(b as u16, t.raw(b)).unwrap();
    }
    assert!(!c.is_active());
    c.commit(record::crc_of(&t), &cfg).unwrap();
    assert!(c.is_active() && c.is_committed());
    assert_eq!(c.table(), &t);
}

#[test]
fn a_can_load_with_a_lost_frame_or_a_wrong_crc_is_refused() {
    let cfg = enabled(1.0);
    let t = line_table(0.03, 72, 0.3);
    let mut c = Compensation::new(&cfg);
    // A bin without a header.
    assert_eq!(
        c.bin(0, t.raw(0)),
        Err(CompensationError::Record(RecordError::NotLoading))
    );
    // Bin 7 lost: bin 8 is out of order, and the commit is incomplete.
    c.begin(t.exponents(), BINS as u16, &cfg).unwrap();
    for b in 0..7 {
        c.bin(b, t.raw(b as usize)).unwrap();
    }
    assert_eq!(
        c.bin(8, t.raw(8)),
        Err(CompensationError::Record(RecordError::OutOfOrder {
            expected: 7
        }))
    );
    assert_eq!(
        c.commit(record::crc_of(&t), &cfg),
        Err(CompensationError::Record(RecordError::Incomplete {
            received: 7
        }))
    );
    assert!(!c.is_active() && c.table().is_zero());
    // Every bin, one corrupted in transit: the record's CRC refuses it.
    c.begin(t.exponents(), BINS as u16, &cfg).unwrap();
    for b in 0..BINS {
        let mut raw = t.raw(b);
        if b == 300 {
            raw[0] ^= 1;
        }
        c.bin(b as u16, raw).unwrap();
    }
    assert!(matches!(
        c.commit(record::crc_of(&t), &cfg),
        Err(CompensationError::Record(RecordError::Crc { .. }))
    ));
    assert!(!c.is_active());
    // A header for another bin count or with a bad exponent.
    assert_eq!(
        c.begin(t.exponents(), 256, &cfg),
        Err(CompensationError::Record(RecordError::Bins { found: 256 }))
    );
    assert!(matches!(
        c.begin([0, -1, 0], BINS as u16, &cfg),
        Err(CompensationError::Record(RecordError::Exponent { .. }))
    ));
}
