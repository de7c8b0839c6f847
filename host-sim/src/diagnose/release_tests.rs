//! The release tests' searches on a hand-built log: a blocked cylinder's pressure raised
//! from 3 to 5 MPa by the pump into an absorber whose gas lost a third of its precharge,
//! integrated here from the volume balance (eq. 21) and the polytropic gas law (eq. 22)
//! alone.

use crate::bench_log::BenchLog;
use crate::diagnose::calibration::{calibrate, test_release, thinned, Release, MAX_FIT_S};
use crate::diagnose::facts::{rows_spanning, LogFacts};
use crate::diagnose::hydraulic::nominal_leakage;
use crate::diagnose::hydraulic_relation::{hyd, HydraulicRelation, HYDRAULIC_WINDOW_S};
use crate::diagnose::test_noise::gaussian;
use plant_model::accumulator::ATMOSPHERE_PA;
use plant_model::Rig;
use std::f64::consts::PI;

/// The precharge the log's absorber holds: 0.7 of the rig file's 3 MPa, below the
/// 3 MPa the log starts from. [Pa]
const PRECHARGE_PA: f64 = 2.1e6;
/// White noise on the logged pressure. [Pa]
const NOISE_PA: f64 = 2e3;

/// Oil the absorber holds at gauge pressure `p` (eq. 22): V₀·(1 − ((p₀+p_a)/(p+p_a))^(1/n)),
/// written out here rather than taken from `plant_model::accumulator::GasCharge`, which the
/// diagnosis's own hydraulic model calls.
fn absorber_oil(rig: &Rig, p: f64) -> f64 {
    let a = &rig.absorber;
    let ratio = (PRECHARGE_PA + ATMOSPHERE_PA) / (p + ATMOSPHERE_PA);
    if ratio >= 1.0 {
        0.0
    } else {
        a.shell_volume_m3 * (1.0 - ratio.powf(1.0 / a.polytropic_exponent))
    }
}

/// 0.5 s holding 3 MPa (the pump replacing the leakage), 200 rad/s until 5 MPa, then
/// holding again, at 1 kHz over 5 s: dp/dt = (D/2π·ω − G·(p − p_fill)) / (V/β + dV_abs/dp),
/// integrated with 20 substeps per row.
fn precharge_log(rig: &Rig) -> BenchLog {
    let d_per_rad = rig.pump.displacement_m3_per_rev / (2.0 * PI);
    let g = nominal_leakage(rig);
    let p_fill = rig.fill.pressure_pa;
    let c_oil = rig.cylinder.chamber_a_volume_m3 / rig.oil.bulk_modulus_pa;
    let holding = |p: f64| g * (p - p_fill) / d_per_rad;
    let (n, sub) = (5000, 20);
    let h = 1e-3 / sub as f64;
    let mut p = 3e6;
    let (mut t, mut pressure, mut speed) = (Vec::new(), Vec::new(), Vec::new());
    for k in 0..n {
        let tk = k as f64 * 1e-3;
        let w = if tk >= 0.5 && p < 5e6 {
            200.0
        } else {
            holding(p)
        };
        t.push(tk);
        pressure.push(p);
        speed.push(w);
        for _ in 0..sub {
            let dp = 1.0;
            let c_gas = (absorber_oil(rig, p + dp) - absorber_oil(rig, p)) / dp;
            p += h * (d_per_rad * w - g * (p - p_fill)) / (c_oil + c_gas);
        }
    }
    BenchLog {
        p_ref_pa: t.iter().map(|&t| if t < 0.5 { 3e6 } else { 5e6 }).collect(),
        p_pa: pressure
            .iter()
            .zip(gaussian(n, 29))
            .map(|(p, e)| p + NOISE_PA * e)
            .collect(),
        speed_rad_s: speed,
        iq_a: vec![0.0; n],
        id_a: vec![0.0; n],
        t_s: t,
        ..BenchLog::default()
    }
}

#[test]
fn a_precharge_below_the_starting_pressure_is_found_from_the_rig_files_values() {
    // The calibration mimics the lost gas within the bands (a smaller shell, a larger
    // displacement); from there the grid's 2.1 MPa fits worse than 3 MPa. Started also
    // from the rig file's values, the release finds the precharge the log was built with.
    let rig = Rig::nominal();
    let log = precharge_log(&rig);
    let facts = LogFacts::of(&log, &rig);
    let relation = HydraulicRelation {
        log: &log,
        facts: &facts,
        rig: &rig,
    };
    let rows = thinned(
        facts.windows(facts.identification(), HYDRAULIC_WINDOW_S),
        &log.p_pa,
        rows_spanning(MAX_FIT_S, facts.period_s, 1),
    );
    let base = calibrate(&relation, &rows);
    let test = test_release(&relation, &rows, Release::Precharge, &base);
    let found = test.fitted.values[hyd::PRECHARGE];
    assert!(
        (found / PRECHARGE_PA - 1.0).abs() < 0.03,
        "precharge {found} Pa, built with {PRECHARGE_PA} Pa"
    );
    assert!(test.lambda > 100.0, "Λ = {}", test.lambda);
}
