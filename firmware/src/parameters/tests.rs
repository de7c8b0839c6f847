//! Table tests: the documented table equals the code, names are the real configuration
//! field paths, defaults lie inside their bounds, and every out-of-range value is refused
//! with the bound it violates.

use super::*;
use crate::config::{Config, ConfigError};

/// A number as written in the module's table: plain decimal, or `e` notation below 1e-7
/// (where plain decimals become unreadable).
fn doc_number(x: f32) -> std::string::String {
    if x != 0.0 && x.abs() < 1e-7 {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

fn doc_row(p: ParamId) -> std::string::String {
    format!(
        "//! | {} | `{}` | {} | {} | {} | {} |",
        p.code(),
        p.name(),
        p.unit(),
        doc_number(p.min()),
        doc_number(p.max()),
        doc_number(p.default_value())
    )
}

#[test]
fn the_documented_table_is_the_code() {
    let source = include_str!("../parameters.rs");
    let documented: std::vec::Vec<&str> = source
        .lines()
        .filter(|l| {
            l.strip_prefix("//! | ")
                .is_some_and(|r| r.starts_with(|c: char| c.is_ascii_digit()))
        })
        .collect();
    let expected: std::vec::Vec<std::string::String> = ParamId::ALL.map(doc_row).to_vec();
    assert_eq!(
        documented,
        expected,
        "module table out of date; the rows should read:\n{}",
        expected.join("\n")
    );
}

#[test]
fn ids_and_names_are_unique_and_round_trip() {
    for (i, p) in ParamId::ALL.iter().enumerate() {
        assert_eq!(ParamId::from_code(p.code()), Some(*p));
        assert_eq!(ParamId::from_name(p.name()), Some(*p));
        for q in &ParamId::ALL[i + 1..] {
            assert!(p.code() < q.code(), "ALL must be in id order: {p} {q}");
            assert_ne!(p.name(), q.name());
        }
    }
    assert_eq!(ParamId::from_code(0), None);
    assert_eq!(ParamId::from_name("speed.kp "), None);
    // The names the tune helper codes against.
    assert_eq!(ParamId::SpeedKp.name(), "speed.kp");
    assert_eq!(
        ParamId::AbsorberPrechargePa.name(),
        "hydraulics.absorber_precharge_pa"
    );
}

#[test]
fn names_are_the_configuration_field_paths() {
    // Corrupt exactly the field a parameter writes: the validator, which names fields by
    // their path independently of this table, must name the parameter's name.
    // An action has no field; `compensation.enabled` is a bool, which holds no bad value.
    let has_bad_value = |p: &ParamId| !p.is_action() && *p != ParamId::CompensationEnabled;
    for p in ParamId::ALL.into_iter().filter(has_bad_value) {
        let mut cfg = Config::nominal();
        let bad = if p.is_integer() {
            p.max() + 1.0
        } else {
            f32::NAN
        };
        p.write(&mut cfg, bad);
        let e = cfg.validate().expect_err(p.name());
        assert_eq!(e.field, p.name(), "{p}: {e}");
    }
}

#[test]
fn defaults_are_the_nominal_rig_and_inside_their_bounds() {
    // Table 1 and contracts/nominal-rig.md values, written out here.
    assert_eq!(ParamId::SpeedKp.default_value(), 0.14);
    assert_eq!(ParamId::SpeedKi.default_value(), 7.0);
    assert_eq!(ParamId::SpeedActiveDamping.default_value(), 0.013);
    assert_eq!(ParamId::CurrentKpQ.default_value(), 13.2);
    assert_eq!(ParamId::AbsorberPrechargePa.default_value(), 3e6);
    assert_eq!(ParamId::TelemetryDecimation.default_value(), 20.0);
    for p in ParamId::ALL {
        let v = p.default_value();
        assert!(p.min() <= v && v <= p.max(), "{p}: default {v}");
        let mut cfg = Config::nominal();
        assert_eq!(p.set(&mut cfg, v), Ok(()), "{p}");
        assert_eq!(cfg, Config::nominal());
    }
}

#[test]
fn every_out_of_range_value_is_refused_with_its_bound() {
    for p in ParamId::ALL {
        let mut cfg = Config::nominal();
        let below = if p.min() == 0.0 {
            -1e-30
        } else {
            p.min() * 0.99
        };
        assert_eq!(
            p.set(&mut cfg, below),
            Err(ParamError::BelowMinimum {
                id: p,
                min: p.min()
            })
        );
        assert_eq!(
            p.set(&mut cfg, p.max() * 1.01),
            Err(ParamError::AboveMaximum {
                id: p,
                max: p.max()
            })
        );
        assert_eq!(
            p.set(&mut cfg, f32::INFINITY),
            Err(ParamError::AboveMaximum {
                id: p,
                max: p.max()
            })
        );
        assert_eq!(
            p.set(&mut cfg, f32::NAN),
            Err(ParamError::NotANumber { id: p })
        );
        assert_eq!(cfg, Config::nominal(), "{p}: refused value was written");
    }
    let mut cfg = Config::nominal();
    assert_eq!(
        ParamId::TelemetryDecimation.set(&mut cfg, 2.5),
        Err(ParamError::NotWhole {
            id: ParamId::TelemetryDecimation
        })
    );
}

#[test]
fn values_in_conflict_with_another_parameter_are_refused_naming_the_rule() {
    // Within its own bounds, but the feedback filter must stay ≥ 2× the bandwidth
    // (150 rad/s now): 100 rad/s crossover would need 200 rad/s.
    let mut cfg = Config::nominal();
    let e = ParamId::PressureBandwidth.set(&mut cfg, 100.0);
    assert!(
        matches!(
            e,
            Err(ParamError::Inconsistent {
                id: ParamId::PressureBandwidth,
                field: "pressure.feedback_filter_rad_s",
                ..
            })
        ),
        "{e:?}"
    );
    assert_eq!(cfg, Config::nominal());
}

#[test]
fn a_snapshot_applies_back_and_a_bad_one_changes_nothing() {
    let mut cfg = Config::nominal();
    ParamId::SpeedKp.set(&mut cfg, 0.2).unwrap();
    let values = snapshot(&cfg);
    let mut back = Config::nominal();
    assert_eq!(apply_all(&mut back, &values), Ok(()));
    assert_eq!(back, cfg);

    let mut bad = values;
    bad[0] = 1e6; // current.kp_d above 200 V/A
    let mut untouched = Config::nominal();
    assert_eq!(
        apply_all(&mut untouched, &bad),
        Err(TableError::Value(ParamError::AboveMaximum {
            id: ParamId::CurrentKpD,
            max: 200.0
        }))
    );
    assert_eq!(untouched, Config::nominal());
    // Each value within its bounds, together inconsistent: filter below 2× bandwidth.
    let mut clash = values;
    clash[11] = 100.0; // pressure.bandwidth_rad_s with the 150 rad/s filter
    assert_eq!(ParamId::ALL[11], ParamId::PressureBandwidth);
    assert!(matches!(
        apply_all(&mut untouched, &clash),
        Err(TableError::Inconsistent(ConfigError {
            field: "pressure.feedback_filter_rad_s",
            ..
        }))
    ));
    assert_eq!(untouched, Config::nominal());
}

/// xorshift64: a fixed pseudo-random sequence for the equivalence test.
fn next(state: &mut u64) -> u64 {
    *state ^= *state << 13;
    *state ^= *state >> 7;
    *state ^= *state << 17;
    *state
}

fn unit(state: &mut u64) -> f32 {
    (next(state) >> 40) as f32 / (1u64 << 24) as f32
}

/// A value within the parameter's bounds: the default, a bound, uniform, or log-uniform
/// (so small and large magnitudes are both visited).
fn in_bounds(p: ParamId, state: &mut u64) -> f32 {
    let (lo, hi) = (p.min(), p.max());
    let v = match next(state) % 6 {
        0 | 1 => p.default_value(),
        2 => lo,
        3 => hi,
        4 => lo + (hi - lo) * unit(state),
        _ => {
            let a = libm::logf(lo.max(hi * 1e-12));
            libm::expf(a + (libm::logf(hi) - a) * unit(state))
        }
    };
    let v = v.clamp(lo, hi);
    if p.is_integer() {
        libm::roundf(v)
    } else {
        v
    }
}

#[test]
fn bounds_and_cross_check_accept_exactly_what_the_validator_accepts() {
    let mut state = 0x9E37_79B9_7F4A_7C15u64;
    let (mut accepted, mut refused) = (0, 0);
    for _ in 0..200_000 {
        let mut cfg = Config::nominal();
        for p in ParamId::ALL {
            // Change a few parameters per draw, so single rules decide often.
            if next(&mut state) % 4 == 0 {
                let v = in_bounds(p, &mut state);
                assert_eq!(p.check(v), Ok(()), "{p} = {v}");
                p.write(&mut cfg, v);
            }
        }
        let full = cfg.validate();
        let cross = cross_check(&cfg);
        assert_eq!(full.is_ok(), cross.is_ok(), "{full:?} vs {cross:?}");
        if full.is_ok() {
            accepted += 1;
        } else {
            refused += 1;
        }
    }
    // Both outcomes visited often: the comparison is not vacuous.
    assert!(
        accepted > 10_000 && refused > 10_000,
        "{accepted} / {refused}"
    );
}

#[test]
fn the_added_parameters_constant_defaults_are_the_nominal_ones() {
    for (p, d) in ParamId::ALL[LEGACY_COUNT..].iter().zip(ADDED_DEFAULTS) {
        assert_eq!(p.default_value(), d, "{p}");
    }
}
