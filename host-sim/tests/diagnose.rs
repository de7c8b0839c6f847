//! `eha diagnose` on logs whose truth is known because the test chose it: the plant
//! simulated with one effect of the catalogue at a set value (or none), the diagnosis given
//! only the log file and the nominal rig. It must name the effect, fit its parameter within
//! 20 % of the value the test set, gain on the signal the effect shows in, and say `none`
//! for a nominal rig; the JSON has the contract's fields and `--report` its files.
//! (The blind suite in `tests/` does the same from seeds the diagnosis never sees.)

mod common;

use common::{edited, eha, rewritten, s, scratch};
use serde_json::Value;
use std::fs;
use std::path::PathBuf;

/// The log rate of every test here but the one on fast logs: the firmware's telemetry.
const ONE_KHZ: &[&str] = &["--log-rate", "1000"];

/// Simulates `scenario` with `effects` and the further arguments `extra` (a log rate, a
/// duration) into `run.csv` in a fresh folder, with the sensor noise of seed 21; the
/// folder and the log.
fn simulate(
    name: &str,
    scenario: &str,
    effects: Option<&str>,
    extra: &[&str],
) -> (PathBuf, PathBuf) {
    simulate_seeded(name, scenario, effects, extra, "21")
}

/// [`simulate`] with the sensor noise of `seed`.
fn simulate_seeded(
    name: &str,
    scenario: &str,
    effects: Option<&str>,
    extra: &[&str],
    seed: &str,
) -> (PathBuf, PathBuf) {
    let dir = scratch("diagnose", name);
    let log = dir.join("run.csv");
    let mut args = vec![
        "simulate",
        "--scenario",
        scenario,
        "--out",
        s(&log),
        "--seed",
        seed,
    ];
    args.extend(extra);
    if let Some(e) = effects {
        args.extend(["--effects", e]);
    }
    let o = eha(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    (dir, log)
}

/// Simulates as [`simulate`] into a log in a fresh folder, then diagnoses it.
fn diagnose(name: &str, scenario: &str, effects: Option<&str>, extra: &[&str]) -> (Value, PathBuf) {
    let (dir, log) = simulate(name, scenario, effects, extra);
    let json = dir.join("diagnosis.json");
    let report = dir.join("report");
    let o = eha(&[
        "diagnose",
        s(&log),
        "--json",
        s(&json),
        "--report",
        s(&report),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: Value = serde_json::from_str(&fs::read_to_string(&json).unwrap()).unwrap();
    (v, report)
}

fn lead(v: &Value) -> &str {
    v["causes"][0]["effect"].as_str().unwrap()
}

fn param(v: &Value, name: &str) -> f64 {
    v["causes"][0]["parameters"][name].as_f64().unwrap()
}

fn noise_ratio(v: &Value, model: &str, signal: &str) -> f64 {
    v[model]["noise_ratio_by_signal"][signal].as_f64().unwrap()
}

fn gain(v: &Value, signal: &str) -> f64 {
    v["extended"]["fit_percent_by_signal"][signal]
        .as_f64()
        .unwrap()
        - v["baseline"]["fit_percent_by_signal"][signal]
            .as_f64()
            .unwrap()
}

#[test]
fn a_nominal_rig_is_explained_by_the_nominal_model() {
    let (v, report) = diagnose("nominal", "pressure-hold", None, ONE_KHZ);
    assert_eq!(lead(&v), "none", "{v:#}");
    assert!(v["extended"]["effects"].as_array().unwrap().is_empty());
    // The contract's fields.
    assert_eq!(v["samples"].as_u64(), Some(3000));
    for key in ["identification_segment_s", "validation_segment_s"] {
        let seg = v[key].as_array().unwrap();
        assert!(seg[0].as_f64().unwrap() < seg[1].as_f64().unwrap(), "{key}");
    }
    // The validation segment follows the identification segment without overlap.
    assert!(
        v["validation_segment_s"][0].as_f64().unwrap()
            > v["identification_segment_s"][1].as_f64().unwrap()
    );
    for key in ["fit_percent", "rmse_pa", "fit_percent_by_signal"] {
        assert!(!v["baseline"][key].is_null(), "baseline.{key}");
        assert!(!v["extended"][key].is_null(), "extended.{key}");
    }
    for signal in ["p_pa", "speed_rad_s", "iq_a"] {
        assert!(
            v["baseline"]["fit_percent_by_signal"][signal].is_number(),
            "{signal}"
        );
    }
    assert!(v["gain"]["fit_points"].is_number());
    assert!(v["gain"]["rmse_reduction_percent"].is_number());
    // Every effect whose relation the log supports is ranked: the hydraulic ones (the
    // shaft angle and the pressure are logged), shaft friction (the torque balance), dead
    // time (the voltages are logged). The angle-locked lines need steady rotation, which
    // the holding's limit cycle around 1 rev/s does not give within 10 %.
    let ranked: Vec<&str> = v["causes"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|c| c["effect"].as_str())
        .collect();
    for effect in [
        "extra_leakage",
        "entrained_air",
        "accumulator_precharge",
        "pressure_sensor_lag",
        "shaft_friction",
        "dead_time",
    ] {
        assert!(ranked.contains(&effect), "{effect} not ranked: {ranked:?}");
    }
    assert!(report.join("report.md").exists());
}

#[test]
fn a_ten_kilohertz_log_is_read_as_a_one_kilohertz_log_is() {
    // The bench-log contract allows 1–10 kHz. The same run logged at 10 kHz is explained
    // about as well as at 1 kHz on every signal the model predicts (differences, start
    // fits, fit budgets and correlation times are spans of time, not of rows; rows
    // counted would differentiate the encoder's counts ten times harder). The bound
    // leaves room for the speed estimate, which the
    // controller updates at 2 kHz and the 10 kHz log holds for five rows, so its
    // second differences understate its noise.
    let run = |rate: &'static str| ["--log-rate", rate, "--duration", "6"];
    let (slow, _) = diagnose("nominal-1khz", "pressure-step", None, &run("1000"));
    let (fast, _) = diagnose("nominal-10khz", "pressure-step", None, &run("10000"));
    assert_eq!(lead(&fast), "none", "{fast:#}");
    let signals = ["p_pa", "iq_a", "speed_rad_s", "ud_v", "uq_v"];
    assert_explained_alike(&slow, &fast, &signals, 2.5, "at 10 kHz");
}

/// Asserts that the baseline explains each of `signals` in `other` within `bound` times
/// its residual over its noise in `reference`; `what` says how `other` was logged.
fn assert_explained_alike(
    reference: &Value,
    other: &Value,
    signals: &[&str],
    bound: f64,
    what: &str,
) {
    for signal in signals {
        let (a, b) = (
            noise_ratio(reference, "baseline", signal),
            noise_ratio(other, "baseline", signal),
        );
        assert!(
            b < bound * a,
            "{signal}: residual {b:.2}× its noise {what}, {a:.2}× as the reference"
        );
    }
}

#[test]
fn a_leakage_is_measured_on_a_ten_kilohertz_log_as_on_a_one_kilohertz_log() {
    // The diagnosis reads a log faster than about 2 kHz at that rate (every k-th row as
    // logged). The leak shows in the holding speed: 12 s, so that both segments hold (the
    // rise at the speed limit lasts 3 s); 5e-13 m³/(s·Pa) as the 1 kHz tests measure it.
    let leak = Some("extra_leakage:coefficient_m3_s_pa=5e-13");
    let long = ["--log-rate", "10000", "--duration", "12"];
    let (v, _) = diagnose("leakage-10khz", "pressure-step", leak, &long);
    assert_eq!(lead(&v), "extra_leakage", "{v:#}");
    // Named alone (no transducer lag accused on the tenfold rows), from the rows 0.45 ms
    // apart at least: every fifth of the 120 000, 24 000.
    assert_eq!(
        v["extended"]["effects"],
        serde_json::json!(["extra_leakage"]),
        "{v:#}"
    );
    assert_eq!(v["samples"], 24_000, "{v:#}");
    let c = param(&v, "coefficient_m3_s_pa");
    assert!((c / 5e-13 - 1.0).abs() < 0.2, "{c}");
}

#[test]
fn an_inverter_dead_time_is_named_and_measured() {
    // 1.5 µs: a voltage error of t_d·f_pwm·U_dc = 8.4 V per leg at full current.
    let (v, report) = diagnose(
        "dead-time",
        "pressure-hold",
        Some("dead_time:dead_time_s=1.5e-6"),
        ONE_KHZ,
    );
    assert_eq!(lead(&v), "dead_time", "{v:#}");
    let t_d = param(&v, "dead_time_s");
    assert!((t_d / 1.5e-6 - 1.0).abs() < 0.2, "{t_d}");
    assert!(gain(&v, "uq_v") >= 10.0, "{v:#}");
    let md = fs::read_to_string(report.join("report.md")).unwrap();
    assert!(md.contains("dead_time"));
    assert!(report.join("trace_uq_v.svg").exists());
}

#[test]
fn a_gas_loss_in_the_absorber_is_named_and_measured() {
    // Precharge 1.8 MPa where the rig file says 3 MPa: the absorber takes oil from lower
    // pressure on, and the 3 → 5 MPa step fills more slowly.
    let (v, _) = diagnose(
        "precharge",
        "pressure-step",
        Some("accumulator_precharge:precharge_pa=1.8e6"),
        ONE_KHZ,
    );
    assert_eq!(lead(&v), "accumulator_precharge", "{v:#}");
    let p0 = param(&v, "precharge_pa");
    assert!((p0 / 1.8e6 - 1.0).abs() < 0.2, "{p0}");
    // On the validation segment the extended model explains the pressure down to twice
    // its noise at most, and at least halves what the calibrated baseline leaves.
    let (base, ext) = (
        noise_ratio(&v, "baseline", "p_pa"),
        noise_ratio(&v, "extended", "p_pa"),
    );
    assert!(ext < 2.0 && ext < 0.5 * base, "{base} → {ext}");
    assert!(gain(&v, "p_pa") > 0.0, "{v:#}");
}

#[test]
#[ignore = "known regression: on a moving piston the hydraulic effects are not tested (the \
            volume balance multiplies the position's noise by the oil's stiffness), so the \
            lag is named `none`; run with --ignored"]
fn a_transducer_lag_shows_as_its_phase_delay_at_the_payload_resonance() {
    // A first-order lag τ delays a ringing at ω by atan(ω·τ)/ω. After a speed step the free
    // payload rings on the oil spring at ω_h = √(2·β·A²/(V·m)) = √(2·6.5e8·(71e-4)²/
    // (450e-6·2000)) = 270 rad/s (43 Hz): 7 ms of lag is 1.084/270 = 4.0 ms of delay there.
    let (_, log) = simulate(
        "lag-signature",
        "speed-step",
        Some("pressure_sensor_lag:time_constant_s=7e-3"),
        ONE_KHZ,
    );
    let bench = host_sim::bench_log::read(&log).expect("the simulated log reads back");
    let a = host_sim::diagnose::analysis::analyse(&bench, &plant_model::Rig::nominal())
        .expect("diagnosis");
    let p = a
        .signatures
        .iter()
        .find(|g| g.signal == "p_pa")
        .expect("the pressure's signature");
    let omega_h = (2.0 * 6.5e8 * 71e-4f64.powi(2) / (450e-6 * 2000.0)).sqrt();
    let delay = |tau: f64| (omega_h * tau).atan() / omega_h;
    // The baseline is calibrated with the transducer's own lag anywhere in its 0–2.5 ms
    // band, so its residual lags it by between delay(7 ms) − delay(2.5 ms) and delay(7 ms);
    // one log row (1 ms) of resolution either side.
    let (lo, hi) = (delay(7e-3) - delay(2.5e-3) - 1e-3, delay(7e-3) + 1e-3);
    assert!((lo..=hi).contains(&p.lag_s), "{} not in {lo}…{hi}", p.lag_s);
    // Released, the lag is named and measured.
    let first = &a.diagnosis.causes[0];
    assert_eq!(first.effect, "pressure_sensor_lag", "{}", first.evidence);
    let tau = first.parameters["time_constant_s"];
    assert!((tau / 7e-3 - 1.0).abs() < 0.2, "{tau}");
}

#[test]
fn a_transducer_lag_within_twice_its_band_is_measured_but_not_named() {
    // A healthy bench's snubbed transducer and its logger's filter lag by a few
    // milliseconds: 3.5 ms, past the 2.5 ms tolerance band but within twice it, is read
    // and reported, and not named as a fault (7 ms is: the phase-delay test above). The
    // staircase's steps make its signature plain.
    let lag = Some("pressure_sensor_lag:time_constant_s=3.5e-3");
    let (v, _) = diagnose("lag-under-floor", "staircase", lag, ONE_KHZ);
    assert_eq!(v["extended"]["effects"], serde_json::json!([]), "{v:#}");
    let causes = v["causes"].as_array().expect("the ranked causes");
    let c = causes
        .iter()
        .find(|c| c["effect"] == "pressure_sensor_lag")
        .expect("the lag is tested");
    let tau = c["parameters"]["time_constant_s"].as_f64().unwrap();
    assert!((tau / 3.5e-3 - 1.0).abs() < 0.2, "{tau}");
    let evidence = c["evidence"].as_str().unwrap();
    assert!(
        evidence.contains("twice its tolerance band's top"),
        "{evidence}"
    );
}

/// `log` rewritten without the columns named in `drop` (metadata kept), as a bench whose
/// drive does not log them writes it.
fn without_columns(log: &std::path::Path, drop: &[&str]) -> PathBuf {
    let text = fs::read_to_string(log).unwrap();
    let mut keep: Vec<bool> = Vec::new();
    let mut out = String::new();
    for line in text.lines() {
        if line.starts_with('#') {
            out.push_str(line);
        } else {
            let cells: Vec<&str> = line.split(',').collect();
            if keep.is_empty() {
                keep = cells.iter().map(|c| !drop.contains(c)).collect();
            }
            let kept: Vec<&str> = cells
                .iter()
                .zip(&keep)
                .filter(|(_, k)| **k)
                .map(|(c, _)| *c)
                .collect();
            out.push_str(&kept.join(","));
        }
        out.push('\n');
    }
    let path = log.with_file_name("without.csv");
    fs::write(&path, out).unwrap();
    path
}

fn diagnose_file(log: &std::path::Path) -> Value {
    let json = log.with_extension("json");
    let o = eha(&["diagnose", s(log), "--json", s(&json)]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_str(&fs::read_to_string(&json).unwrap()).unwrap()
}

#[test]
fn a_dead_time_is_measured_from_the_currents_alone() {
    // Without the stator voltages the dead time is read from the current lines at 6·p_n
    // the loops leave; the voltage it makes follows the logged phase currents, whose zero
    // crossings it moves. Within 15 % at 1, 2 and 3 µs on 20 s steps (its windows of
    // steady rotation are then mostly the hold's; on 12 s steps it reads 18–36 % high).
    for t_d in [1e-6, 2e-6, 3e-6] {
        let effect = format!("dead_time:dead_time_s={t_d}");
        let (_, log) = simulate(
            &format!("dead-time-no-voltage-{t_d}"),
            "pressure-step",
            Some(&effect),
            &["--log-rate", "1000", "--duration", "20"],
        );
        let bare = without_columns(&log, &["ud_v", "uq_v", "udc_v"]);
        let v = diagnose_file(&bare);
        let named = &v["extended"]["effects"];
        assert_eq!(named, &serde_json::json!(["dead_time"]), "{t_d}: {v:#}");
        let fit = param(&v, "dead_time_s");
        assert!((fit / t_d - 1.0).abs() < 0.15, "{t_d}: fitted {fit}");
    }
}

#[test]
fn a_dead_time_read_from_the_currents_weighs_the_q_line_by_its_loops_uncertainty() {
    // At holding speed the speed and pressure loops move the q current at the dead time's
    // sixth harmonic, and the q line's corrections for them are uncertain. Weighed by its
    // noise floor alone, the q line read this 1.5 µs (sensor noise of seed 1, a 20 s step
    // logged at 2 kHz, no voltages) 26 % high; with its corrections' variance it is read
    // within 10 %.
    let (_, log) = simulate_seeded(
        "dead-time-q-line",
        "pressure-step",
        Some("dead_time:dead_time_s=1.5e-6"),
        &["--log-rate", "2000", "--duration", "20"],
        "1",
    );
    let v = diagnose_file(&without_columns(&log, &["ud_v", "uq_v", "udc_v"]));
    assert_eq!(
        v["extended"]["effects"],
        serde_json::json!(["dead_time"]),
        "{v:#}"
    );
    let fit = param(&v, "dead_time_s");
    assert!((fit / 1.5e-6 - 1.0).abs() < 0.10, "fitted {fit}");
}

/// The pair of [`two_effects_at_once_are_both_named`]: a leaking pump (5e-13 m³/(s·Pa))
/// on a motor with a cogging torque (0.3 N·m), a 20 s pressure step logged at 1 kHz.
const PAIR: &str = "extra_leakage:coefficient_m3_s_pa=5e-13,cogging_torque:amplitude_nm=0.3";
const PAIR_LOG: &[&str] = &["--log-rate", "1000", "--duration", "20"];

/// Asserts that the diagnosis `v` of a [`PAIR`] log names both effects, nothing else, each
/// within 25 %; returns the cogging's cause.
fn assert_pair_named(v: &Value) -> &Value {
    let mut named: Vec<&str> = v["extended"]["effects"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e.as_str().unwrap())
        .collect();
    named.sort_unstable();
    assert_eq!(named, ["cogging_torque", "extra_leakage"], "{v:#}");
    let cause = |name: &str| {
        v["causes"]
            .as_array()
            .unwrap()
            .iter()
            .find(|c| c["effect"] == name)
            .unwrap()
    };
    let main = |name: &str, parameter: &str| cause(name)["parameters"][parameter].as_f64().unwrap();
    let leak = main("extra_leakage", "coefficient_m3_s_pa");
    assert!((leak / 5e-13 - 1.0).abs() < 0.25, "{leak}");
    let cogging = main("cogging_torque", "amplitude_nm");
    assert!((cogging / 0.3 - 1.0).abs() < 0.25, "{cogging}");
    cause("cogging_torque")
}

#[test]
fn two_effects_at_once_are_both_named() {
    // A leaking pump on a motor with a cogging torque: the leakage shows in the pressure's
    // relation, the cogging in the torque line at the slot order. Each judged against the
    // model extended by the other; both named, nothing else, each within 25 %.
    let (v, report) = diagnose("pair", "pressure-step", Some(PAIR), PAIR_LOG);
    assert_pair_named(&v);
    // The terminal says both, each with its evidence, as the JSON does.
    let log = report.parent().unwrap().join("run.csv");
    let o = eha(&["diagnose", s(&log)]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8_lossy(&o.stdout);
    let named = v["extended"]["effects"].as_array().unwrap();
    let label: Vec<&str> = named.iter().map(|e| e.as_str().unwrap()).collect();
    assert!(
        text.contains(&format!("named: {}\n", label.join(" + "))),
        "{text}"
    );
    for effect in label {
        assert!(
            text.contains(&format!("cause: {effect} — ")),
            "{effect}: {text}"
        );
    }
}

#[test]
fn a_leakage_is_measured_in_absolute_terms_on_a_pump_built_off_its_displacement() {
    // A pump built 4 % over its listed displacement on a motor 3 % under its flux, both
    // within the bands the diagnosis grants them, leaking 3e-13 m³/(s·Pa) more than the
    // rig file's pump. On the blocked cylinder the pressure fixes the leakage only relative
    // to the displacement (the holding speed is G·p/D), so read at a displacement anywhere
    // in its ±5 % band it could be off by a twentieth of the whole leakage, 6e-13: a tenth
    // of the extra. The torque balance gives D/ψ_f, the stator voltages ψ_f: their product
    // puts the extra leakage within 4 % of the truth.
    let dir = scratch("diagnose", "leakage-off-displacement");
    let mut plant = plant_model::Rig::nominal();
    plant.pump.displacement_m3_per_rev *= 1.04;
    plant.motor.psi_f_wb *= 0.97;
    let plant_file = dir.join("plant.toml");
    fs::write(&plant_file, host_sim::rig_file::to_toml(&plant)).unwrap();
    let log = dir.join("run.csv");
    let o = eha(&[
        "simulate",
        "--scenario",
        "pressure-step",
        "--plant-rig",
        s(&plant_file),
        "--effects",
        "extra_leakage:coefficient_m3_s_pa=3e-13",
        "--log-rate",
        "1000",
        "--duration",
        "12",
        "--seed",
        "21",
        "--out",
        s(&log),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v = diagnose_file(&log);
    assert_eq!(
        v["extended"]["effects"],
        serde_json::json!(["extra_leakage"]),
        "{v:#}"
    );
    let c = param(&v, "coefficient_m3_s_pa");
    assert!((c / 3e-13 - 1.0).abs() < 0.04, "{c}");
}

/// `log` as a bench logger without the angle writes it: the speed column replaced by the
/// encoder angle's difference over each row, (θ_k − θ_{k−1})/(t_k − t_{k−1}), and the
/// angle column dropped.
fn with_counted_speed(log: &std::path::Path) -> PathBuf {
    use host_sim::bench_log;
    use std::f64::consts::TAU;
    let mut b = bench_log::read(log).unwrap();
    let theta = b.theta_m_rad.take().unwrap();
    b.speed_rad_s = (0..b.len())
        .map(|k| {
            if k == 0 {
                return 0.0;
            }
            let d = theta[k] - theta[k - 1];
            (d - TAU * (d / TAU).round()) / (b.t_s[k] - b.t_s[k - 1])
        })
        .collect();
    let path = log.with_file_name("counted.csv");
    bench_log::write(&path, &b).unwrap();
    path
}

#[test]
fn a_log_without_the_angle_is_read_from_its_counted_speed() {
    // A bench logging the encoder's count difference as its speed and no angle: the speed
    // sums back to the counted angle, the cogging line stays phase-locked across windows,
    // and both effects are named within 25 % as with the angle.
    let (_, log) = simulate("counted-speed", "pressure-step", Some(PAIR), PAIR_LOG);
    let v = diagnose_file(&with_counted_speed(&log));
    let cogging = assert_pair_named(&v);
    let evidence = cogging["evidence"].as_str().unwrap();
    assert!(
        evidence.contains("counted back from the speed"),
        "{evidence}"
    );
}

/// `log` without the rows of `lost`, as a logger that dropped them writes it.
fn without_rows(log: &std::path::Path, lost: impl Fn(usize) -> bool) -> PathBuf {
    rewritten(log, "dropped.csv", |r, line| {
        (!lost(r)).then(|| line.to_string())
    })
}

#[test]
fn a_log_whose_logger_lost_rows_is_read_as_the_whole_log() {
    // The bench-log contract does not ask for even sampling. 20 rows lost every 0.4 s of a
    // 1 kHz log: at the rise's speed limit (180 rad/s) the shaft turns 3.8 rad across each
    // gap, more than half a revolution, so the logged angle alone cannot say how far it
    // went, and a speed taken from it would jump by a revolution over the gap.
    let lost = |log: &std::path::Path| without_rows(log, |r| r % 400 >= 380);
    assert_read_as_the_whole_log("lost-rows", lost, 1.5, "with rows lost");
}

/// Simulates a 6 s pressure step logged at 1 kHz on the nominal rig, rewrites its log with
/// `rewrite`, and asserts that both are explained alike within `bound` (`what` says how
/// the rewritten one differs) and the rewritten one is named `none`.
fn assert_read_as_the_whole_log(
    name: &str,
    rewrite: impl Fn(&std::path::Path) -> PathBuf,
    bound: f64,
    what: &str,
) {
    let one_khz = ["--log-rate", "1000", "--duration", "6"];
    let (dir, log) = simulate(name, "pressure-step", None, &one_khz);
    let whole = diagnose_file(&log);
    let rewritten = diagnose_file(&rewrite(&log));
    assert_eq!(lead(&rewritten), "none", "{rewritten:#}");
    let signals = ["p_pa", "iq_a", "speed_rad_s"];
    assert_explained_alike(&whole, &rewritten, &signals, bound, what);
    fs::remove_dir_all(dir).ok();
}

/// `log` with each row's time moved by up to ±`scatter` [s] (the first and last kept), as
/// a PC that stamps telemetry rows on arrival writes it; the rows themselves unchanged.
fn with_scattered_stamps(log: &std::path::Path, scatter: f64) -> PathBuf {
    let text = fs::read_to_string(log).unwrap();
    let rows = text.lines().filter(|l| !l.starts_with('#')).count() - 1;
    let mut x = 0x2545_f491_4f6c_dd1du64;
    edited(log, "stamped.csv", "t_s", |r, t| {
        if r == 0 || r + 1 == rows {
            return t.to_string();
        }
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        let u = (x >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
        let t: f64 = t.parse().unwrap();
        format!("{}", t + 2.0 * u * scatter)
    })
}

#[test]
fn rows_stamped_off_their_sampling_are_read_on_its_grid() {
    // A drive samples on its own clock; the PC that logs its telemetry stamps each row as
    // it arrives, ±0.2 ms about the millisecond it was taken. Read at those times the
    // angle jumps by ω·δt (36 mrad at 180 rad/s) and the shaft's relations take that for
    // motion; the logged angle turns smoothly only on the grid the rows were sampled on.
    let stamped = |log: &std::path::Path| with_scattered_stamps(log, 0.2e-3);
    assert_read_as_the_whole_log("scattered-stamps", stamped, 1.2, "with scattered stamps");
}
