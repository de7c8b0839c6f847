//! The simulator's study results against what the rig predicts independently: pulsation lines
//! at the orders of their physical causes, and no absorption from an absorber that holds no
//! oil.

use closed_loop::by_name;
use host_sim::pulsation::{amplitude_spectrum, dominant_line, sources};
use host_sim::run::{run, RunOptions};
use plant_model::{Effect, Rig};
use std::f64::consts::PI;
use std::process::Command;

/// Holding at 5 MPa without absorber, controller configured for no absorber, one effect on;
/// returns (dominant frequency, shaft revolutions per second).
fn dominant_with(effect: &str) -> (f64, f64) {
    let mut rig = Rig::nominal();
    rig.absorber.enabled = false;
    let controller = rig.clone();
    Effect::parse(effect).unwrap().apply(&mut rig);
    let scenario = by_name("pressure-hold").unwrap();
    let r = run(
        &rig,
        &controller,
        scenario,
        &RunOptions {
            duration_s: 3.0,
            log_rate_hz: 2000.0,
            seed: 3,
            progress: false,
            metadata: vec![],
            compensation: None,
            integrator: Default::default(),
        },
    )
    .unwrap();
    let first = r.log.t_s.iter().position(|t| *t >= 1.0).unwrap();
    let p = &r.p_true_pa[first..];
    let w = &r.speed_true_rad_s[first..];
    let rev_s = w.iter().sum::<f64>() / w.len() as f64 / (2.0 * PI);
    let spectrum = amplitude_spectrum(p, 1.0 / 2000.0);
    // Lines above twice the shaft frequency: below it sits the pressure loop's own
    // regulation of the slow leakage balance.
    let (f, _, _) = dominant_line(&spectrum, 2.0 * rev_s, rev_s, &sources(&rig)).unwrap();
    (f, rev_s)
}

#[test]
fn pulsation_lines_sit_at_the_orders_the_rig_predicts() {
    let rig = Rig::nominal();
    // Independent of the code: z = 9 pistons (odd) ripple 2z per revolution; 5th/7th flux
    // harmonics give the 6th electrical = 6·p_n per revolution; cogging at LCM(9 slots, 8 poles).
    let cases = [
        ("piston_ripple:amplitude_ratio=0.05", 2.0 * 9.0),
        (
            "flux_harmonics:t6_ratio=0.05",
            6.0 * rig.motor.pole_pairs as f64,
        ),
        ("cogging_torque:amplitude_nm=0.2", 72.0),
    ];
    for (effect, order) in cases {
        let (f, rev_s) = dominant_with(effect);
        let expected = order * rev_s;
        // One bin of the 2 s window is 0.5 Hz; the shaft speed itself wobbles a few percent.
        assert!(
            (f - expected).abs() <= (0.05 * expected).max(0.75),
            "{effect}: dominant line {f:.2} Hz, expected order {order} × {rev_s:.3} rev/s = {expected:.2} Hz"
        );
    }
}

#[test]
fn an_absorber_above_the_working_pressure_absorbs_nothing() {
    // Precharged above the 5 MPa holding pressure the bladder fills the shell: no oil, no
    // capacitance (C_acc = 0 below precharge), so the pulsation equals the no-absorber run's.
    let out = Command::new(env!("CARGO_BIN_EXE_eha"))
        .args([
            "sweep-precharge",
            "--values",
            "4e6,10e6,13e6",
            "--json",
            "-",
        ])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let points = v["points"].as_array().unwrap();
    let reference = v["reference_pulsation_pp_pa"].as_f64().unwrap();
    assert!(reference > 0.0);
    for p in points {
        let p0 = p["precharge_pa"].as_f64().unwrap();
        let absorption = p["absorption_percent"].as_f64().unwrap();
        if p0 > 5e6 {
            assert!(
                absorption.abs() < 1.0,
                "precharge {p0}: absorption {absorption} %"
            );
            assert_eq!(p["natural_frequency_hz"].as_f64().unwrap(), 0.0);
        } else {
            // Below the working pressure the absorber holds oil and absorbs.
            assert!(
                absorption > 50.0,
                "precharge {p0}: absorption {absorption} %"
            );
            assert!(p["natural_frequency_hz"].as_f64().unwrap() > 0.0);
        }
    }
}
