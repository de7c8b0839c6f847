//! The blind identification suite: over [`SUITE_SEEDS`] seeds and the mended
//! [`tests::blind::REGRESSION_SEEDS`] the generator ([`tests::blind`]) hides one
//! catalogue effect or none in a closed-loop bench log of a
//! tolerance-perturbed rig; the diagnosis (`host_sim::diagnose::diagnose`) gets only the log
//! read back from its CSV file and the NOMINAL rig, and must
//! - name the hidden effect first (`none` first when none was hidden);
//! - fit each of its parameters within 25 % of the truth — integer parameters (`pistons`,
//!   `order`) exactly, phases within 0.35 rad modulo 2π (a negative fitted amplitude with
//!   the phase turned by π is the same harmonic and is normalised first); the shaft's
//!   breakaway torque, which no scenario makes observable
//!   ([`tests::blind::UNOBSERVABLE_PARAMETERS`]), is shown but not held to it;
//! - not make the validation-segment fit worse on the signal where the effect shows most
//!   (the extension's gain there is what the diagnosis validates on; how large it can be
//!   depends on the scenario and the noise, not on the diagnosis);
//! - call every log of the false-alarm set ([`NOTHING_HIDDEN_SEEDS`], nothing hidden)
//!   `none`: the rate is printed, and more than one false alarm in 20 fails.
//!
//! Every log is drawn with structure, not only parameters ([`tests::blind::Structure`]):
//! the line volume, the absorber inlet, the fill pressure, the leakage's path, the
//! transducer's zero, the controller's tuning and the columns the bench logged vary.
//!
//! One pair is indistinguishable on some logs, and the suite says which: piston ripple of
//! 1–3× kinematic is a torque of 0.01–0.03 N·m at the holding's 5 MPa, a line in the q
//! current below its noise per sample. Where even a model that has the ripple exactly,
//! added to a perfect model of the drawn rig and fitted on the very rows it is scored on,
//! gains less than the 10 points ([`tests::blind::line_fit_bound`], computed by the
//! generator's side from the truth), the log does not tell the ripple from `none` at the
//! suite's standard: `none` is as right as the ripple, and no gain or amplitude is owed
//! (every amplitude between none and the truth is equally indistinguishable). Where the
//! bound reaches 10 points, the ripple is held to everything above. A third test shows that
//! no other scenario or signal would do better.
//!
//! The diagnosis is read only through the contract's JSON (`shared/contracts/eha-cli.md`):
//! the suite depends on the contract, not on the diagnosis's Rust types. The truth numbers
//! come from the generator's draw, never from the diagnosis.
//!
//! A second test checks the generator itself, independently of the diagnosis: every hidden
//! effect's noise-free signature on its signal stands above the sensor noise.

use closed_loop::{by_name, SCENARIOS};
use host_sim::bench_log;
use host_sim::diagnose::diagnose;
use plant_model::pump::kinematic_ripple_ratio;
use plant_model::{Effect, Rig};
use rayon::prelude::*;
use serde_json::Value;
use std::f64::consts::{PI, TAU};
use std::path::PathBuf;
use tests::blind::{
    angle_locked_fit_bound, draw, generate, identification_seeds, line_below_noise, line_fit_bound,
    ripple_orders, signature, Truth, LOGGED, NOTHING_HIDDEN_SEEDS, SUITE_SEEDS,
    UNOBSERVABLE_PARAMETERS,
};

/// Relative tolerance on a fitted continuous parameter. [1]
const PARAMETER_TOLERANCE: f64 = 0.25;
/// Tolerance on a fitted phase, modulo 2π. [rad]
const PHASE_TOLERANCE_RAD: f64 = 0.35;
/// Least validation-fit gain on the truth's signal when an effect was hidden. [points]
const MIN_FIT_GAIN: f64 = 0.0;
/// The suite's standard of distinguishability: a piston ripple no model could gain this
/// much with is as well called `none` ([`tests::blind::line_fit_bound`]). [points]
const DISTINGUISHABLE_GAIN: f64 = 10.0;
/// False alarms allowed in the false-alarm set. [1]
const MAX_FALSE_ALARMS: usize = 1;

/// Where the generated logs go.
fn log_dir() -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("blind");
    std::fs::create_dir_all(&dir).expect("create the blind-log directory");
    dir
}

/// What the diagnosis said about one log, read from its contract JSON.
struct Said {
    /// `causes[0].effect`.
    effect: String,
    /// `causes[0].parameters`.
    parameters: Vec<(String, f64)>,
    /// `baseline.fit_percent_by_signal[signal]`. [%]
    baseline_fit: Option<f64>,
    /// `extended.fit_percent_by_signal[signal]`. [%]
    extended_fit: Option<f64>,
}

fn read_said(json: &Value, signal: &str) -> Result<Said, String> {
    let first = json
        .pointer("/causes/0")
        .ok_or("the diagnosis names no cause (`causes` is empty)")?;
    let effect = first
        .get("effect")
        .and_then(Value::as_str)
        .ok_or("`causes[0].effect` is not a string")?
        .to_string();
    let parameters = first
        .get("parameters")
        .and_then(Value::as_object)
        .map(|m| {
            m.iter()
                .filter_map(|(k, v)| v.as_f64().map(|v| (k.clone(), v)))
                .collect()
        })
        .unwrap_or_default();
    let fit = |model: &str| {
        json.pointer(&format!("/{model}/fit_percent_by_signal/{signal}"))
            .and_then(Value::as_f64)
    };
    Ok(Said {
        effect,
        parameters,
        baseline_fit: fit("baseline"),
        extended_fit: fit("extended"),
    })
}

/// One seed: what was hidden, what the diagnosis said.
struct SeedRun {
    seed: u64,
    truth: Truth,
    /// The piston ripple's fit bound ([`line_fit_bound`]) when the seed hides one.
    /// [percentage points]
    bound: Option<f64>,
    said: Result<Said, String>,
}

/// Generates, reads back and diagnoses one seed.
fn run_seed(seed: u64) -> SeedRun {
    let bound = line_fit_bound(&draw(seed))
        .unwrap_or_else(|e| panic!("seed {seed}: the ripple's bound failed: {e}"));
    let (path, truth) = match generate(seed, &log_dir()) {
        Ok(g) => g,
        Err(e) => panic!("seed {seed}: the generator failed: {e}"),
    };
    let said = bench_log::read(&path)
        .map_err(|e| format!("reading back the generated log: {e}"))
        .and_then(|log| {
            diagnose(&log, &Rig::nominal()).map_err(|e| format!("diagnose failed: {e}"))
        })
        .and_then(|d| serde_json::to_value(&d).map_err(|e| format!("to JSON: {e}")))
        .and_then(|json| read_said(&json, truth.signal));
    SeedRun {
        seed,
        truth,
        bound,
        said,
    }
}

/// A parameter's value as the plant understands it: `amplitude_ratio = 0` is the kinematic
/// ripple of the pistons, `order = 0` the cogging fundamental LCM(slots, 2·pole pairs).
fn effective(name: &str, value: f64, params: &[(String, f64)]) -> f64 {
    match (name, value) {
        ("amplitude_ratio", 0.0) => {
            let z = params
                .iter()
                .find(|(k, _)| k == "pistons")
                .map_or(0.0, |(_, z)| *z);
            kinematic_ripple_ratio(z as u32)
        }
        ("order", 0.0) => Rig::nominal().motor.cogging_fundamental_order() as f64,
        (_, v) => v,
    }
}

/// The fitted parameters with a negative harmonic amplitude turned positive and its phase
/// by π (the same harmonic).
fn normalised(params: &[(String, f64)]) -> Vec<(String, f64)> {
    let flip = params
        .iter()
        .any(|(k, v)| (k == "amplitude_nm" || k == "t6_ratio") && *v < 0.0);
    params
        .iter()
        .map(|(k, v)| match k.as_str() {
            "amplitude_nm" | "t6_ratio" if flip => (k.clone(), -v),
            "phase_rad" if flip => (k.clone(), v + PI),
            _ => (k.clone(), *v),
        })
        .collect()
}

/// Distance of two angles modulo 2π. [rad]
fn angle_distance(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(TAU);
    d.min(TAU - d)
}

/// Each truth parameter against the fitted one; the failures, described.
fn parameter_failures(truth: &Truth, fitted: &[(String, f64)]) -> Vec<String> {
    let truth_params: Vec<(String, f64)> = truth
        .parameters
        .iter()
        .map(|(k, v)| (k.to_string(), *v))
        .collect();
    let fitted = normalised(fitted);
    let mut out = Vec::new();
    for (name, t) in &truth_params {
        if UNOBSERVABLE_PARAMETERS.contains(&(truth.effect_name, name.as_str())) {
            continue;
        }
        let t = effective(name, *t, &truth_params);
        let Some((_, f)) = fitted.iter().find(|(k, _)| k == name) else {
            out.push(format!("parameter `{name}` not fitted"));
            continue;
        };
        let f = effective(name, *f, &fitted);
        let ok = match name.as_str() {
            "pistons" | "order" => f == t,
            "phase_rad" => angle_distance(f, t) <= PHASE_TOLERANCE_RAD,
            _ => (f - t).abs() <= PARAMETER_TOLERANCE * t.abs(),
        };
        if !ok {
            out.push(format!("`{name}` fitted {f:.4e}, truth {t:.4e}"));
        }
    }
    out
}

/// What the suite asks of every seed: the right name, its parameters, the fit gain when
/// an effect was hidden; the failures, described.
fn strict_failures(truth: &Truth, s: &Said) -> Vec<String> {
    let mut out = Vec::new();
    if s.effect == truth.effect_name {
        out.extend(parameter_failures(truth, &s.parameters));
    } else {
        out.push(format!("named `{}`", s.effect));
    }
    if truth.effect_name != "none" {
        match (s.baseline_fit, s.extended_fit) {
            (Some(b), Some(e)) if e - b >= MIN_FIT_GAIN => {}
            (Some(b), Some(e)) => out.push(format!(
                "fit gain on {} is {:.1} points < {MIN_FIT_GAIN}",
                truth.signal,
                e - b
            )),
            _ => out.push(format!("no fit reported for {}", truth.signal)),
        }
    }
    out
}

fn show_params(p: &[(String, f64)]) -> String {
    if p.is_empty() {
        return "—".into();
    }
    p.iter()
        .map(|(k, v)| format!("{k}={v:.3e}"))
        .collect::<Vec<_>>()
        .join(", ")
}

fn show_fit(f: Option<f64>) -> String {
    f.map_or("—".into(), |f| format!("{f:.1}"))
}

#[test]
fn the_diagnosis_finds_every_hidden_effect() {
    let seeds = identification_seeds();
    let results: Vec<SeedRun> = seeds.par_iter().map(|s| run_seed(*s)).collect();

    println!(
        "| seed | hidden effect | scenario | signal | truth parameters | named | fitted parameters | baseline fit [%] | extended fit [%] | gain [points] | attainable [points] | verdict |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|");
    let mut failures = Vec::new();
    for SeedRun {
        seed,
        truth,
        bound,
        said,
    } in &results
    {
        // A ripple no model could gain the 10 points with on this log is, at the suite's
        // standard, indistinguishable from none: either answer is right, and neither a
        // gain nor an amplitude is owed (every amplitude between none and the truth is
        // equally indistinguishable).
        let indistinguishable = bound.is_some_and(|b| b < DISTINGUISHABLE_GAIN);
        let truth_params: Vec<(String, f64)> = truth
            .parameters
            .iter()
            .map(|(k, v)| (k.to_string(), *v))
            .collect();
        // Everything the suite asks of a seed, then what an indistinguishable one is excused.
        let mut strict = Vec::new();
        let (named, fitted, base, ext) = match said {
            Err(e) => {
                strict.push(e.clone());
                ("—".to_string(), "—".to_string(), None, None)
            }
            Ok(s) => {
                strict.extend(strict_failures(truth, s));
                (
                    s.effect.clone(),
                    show_params(&s.parameters),
                    s.baseline_fit,
                    s.extended_fit,
                )
            }
        };
        let excused = indistinguishable
            && said
                .as_ref()
                .is_ok_and(|s| s.effect == "none" || s.effect == truth.effect_name);
        let gain = match (base, ext) {
            (Some(b), Some(e)) => format!("{:.1}", e - b),
            _ => "—".into(),
        };
        let verdict = match (strict.is_empty(), excused) {
            (true, _) => "ok".to_string(),
            (false, true) => format!(
                "ok: indistinguishable from none at {DISTINGUISHABLE_GAIN} points (strictly: {})",
                strict.join("; ")
            ),
            (false, false) => strict.join("; "),
        };
        let wrong = !strict.is_empty() && !excused;
        println!(
            "| {seed} | {} | {} | {} | {} | {named} | {fitted} | {} | {} | {gain} | {} | {verdict} |",
            truth.effect_name,
            truth.scenario,
            truth.signal,
            show_params(&truth_params),
            show_fit(base),
            show_fit(ext),
            show_fit(*bound),
        );
        if wrong {
            failures.push(format!("seed {seed} ({}): {verdict}", truth.effect_name));
        }
    }
    println!(
        "right or excused: {} of {}",
        seeds.len() - failures.len(),
        seeds.len()
    );
    if !failures.is_empty() {
        println!("missed:\n{}", failures.join("\n"));
    }
    // Every seed right, or excused by the computed bound; `docs/diagnosis.md` says what
    // each kind of log tells.
    assert!(
        failures.is_empty(),
        "{} of {} seeds failed:\n{}",
        failures.len(),
        seeds.len(),
        failures.join("\n")
    );
}

#[test]
fn the_suite_covers_every_effect_twice_and_none() {
    let mut count = std::collections::BTreeMap::new();
    for seed in 0..SUITE_SEEDS {
        *count.entry(draw(seed).truth.effect_name).or_insert(0) += 1;
    }
    for name in plant_model::effects::EFFECT_NAMES {
        let n = count.get(name).copied().unwrap_or(0);
        assert!(
            n >= 2,
            "effect {name} drawn {n} times in {SUITE_SEEDS} seeds"
        );
    }
    const { assert!(SUITE_SEEDS >= 30) };
}

/// The generator's scenario and signal for piston ripple are where an angle-locked model
/// could gain most, and everywhere else even the strong end of its range (three times
/// kinematic) leaves any such model below the 10 points: for every suite seed that hides
/// the ripple, with its own tolerances and noise, in every scenario, the upper bound of
/// [`angle_locked_fit_bound`] on every logged signal.
#[test]
fn piston_ripple_shows_most_where_the_generator_puts_it() {
    let cases: Vec<(u64, &str)> = (0..SUITE_SEEDS)
        .filter(|&s| draw(s).truth.effect_name == "piston_ripple")
        .flat_map(|s| SCENARIOS.iter().map(move |sc| (s, sc.name)))
        .collect();
    assert!(!cases.is_empty(), "the suite hides no piston ripple");
    let rows: Vec<(u64, &str, &str, Vec<f64>)> = cases
        .into_par_iter()
        .map(|(seed, scenario)| {
            let mut d = draw(seed);
            let drawn_scenario = d.truth.scenario;
            let Effect::PistonRipple { pistons, .. } = d.effect else {
                unreachable!("filtered on the effect's name")
            };
            d.effect = Effect::PistonRipple {
                pistons,
                amplitude_ratio: 3.0 * kinematic_ripple_ratio(pistons),
            };
            d.scenario = *by_name(scenario).expect("a listed scenario");
            let bound = angle_locked_fit_bound(
                &d,
                &LOGGED,
                d.scenario.duration_s / 2.0,
                &ripple_orders(pistons),
            )
            .unwrap_or_else(|e| panic!("seed {seed}, {scenario}: {e}"));
            (seed, scenario, drawn_scenario, bound)
        })
        .collect();
    let names: Vec<&str> = LOGGED.iter().map(|s| s.name()).collect();
    println!("| seed | scenario | {} |", names.join(" | "));
    let mut failures = Vec::new();
    for (seed, scenario, drawn_scenario, bound) in &rows {
        let cells: Vec<String> = bound.iter().map(|g| format!("{g:.1}")).collect();
        println!("| {seed} | {scenario} | {} |", cells.join(" | "));
        // The drawn scenario is the best place: its best signal (q current or speed,
        // depending on the controller's tuning) beats every signal of every other scenario.
        let best_of = |sc: &str| {
            rows.iter()
                .filter(|(s, r, _, _)| s == seed && *r == sc)
                .flat_map(|(_, _, _, b)| b.iter().copied())
                .fold(f64::NEG_INFINITY, f64::max)
        };
        let here = best_of(drawn_scenario);
        let best_elsewhere = SCENARIOS
            .iter()
            .filter(|sc| sc.name != *drawn_scenario)
            .map(|sc| best_of(sc.name))
            .fold(f64::NEG_INFINITY, f64::max);
        if scenario == drawn_scenario && here < best_elsewhere {
            failures.push(format!(
                "seed {seed}: {scenario} bounds {here:.1} points, another scenario \
                 {best_elsewhere:.1}"
            ));
        }
        if scenario != drawn_scenario {
            for (g, n) in bound.iter().zip(&names) {
                if *g >= DISTINGUISHABLE_GAIN {
                    failures.push(format!("seed {seed}, {scenario}, {n}: {g:.1} points"));
                }
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn every_hidden_effect_stands_above_the_sensor_noise() {
    let rows: Vec<(u64, Truth, f64, f64)> = (0..SUITE_SEEDS)
        .into_par_iter()
        .map(|seed| {
            let d = draw(seed);
            let signal = host_sim::bench_log::Signal::from_name(d.truth.signal)
                .expect("the truth's signal is a bench-log column");
            // The second half of the log: where a diagnosis would validate.
            let g = match signature(&d, signal, d.truth.duration_s / 2.0) {
                Ok(g) => g,
                Err(e) => panic!("seed {seed}: {e}"),
            };
            (seed, d.truth, g.ratio(), g.attainable_fit_gain())
        })
        .collect();
    println!("| seed | effect | scenario | signal | effect RMS / noise RMS | attainable fit gain [points] |");
    println!("|---|---|---|---|---|---|");
    let mut failures = Vec::new();
    for (seed, t, ratio, gain) in &rows {
        println!(
            "| {seed} | {} | {} | {} | {ratio:.2} | {gain:.1} |",
            t.effect_name, t.scenario, t.signal
        );
        if t.effect_name == "none" {
            // Nothing hidden: the truth and the effect-free plant are the same.
            if *ratio != 0.0 {
                failures.push(format!("seed {seed}: `none` differs from itself ({ratio})"));
            }
        } else if !line_below_noise(&draw(*seed)) && *ratio <= 1.0 {
            failures.push(format!(
                "seed {seed}: {} in {} shows {ratio:.2}× the noise on {}",
                t.effect_name, t.scenario, t.signal
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn the_judge_accepts_the_same_harmonic_and_refuses_a_wrong_parameter() {
    let truth = Truth {
        effect_name: "cogging_torque",
        parameters: vec![("amplitude_nm", 0.1), ("order", 72.0), ("phase_rad", 6.2)],
        scenario: "pressure-hold",
        duration_s: 3.0,
        signal: "iq_a",
    };
    let fitted = |a: f64, o: f64, ph: f64| {
        vec![
            ("amplitude_nm".to_string(), a),
            ("order".to_string(), o),
            ("phase_rad".to_string(), ph),
        ]
    };
    // 6.2 rad and 0.1 rad are 0.183 rad apart across 2π; order 0 is LCM(9, 8) = 72;
    // −0.11 N·m at phase 6.2 − π is +0.11 N·m at 6.2 (10 % off).
    assert!(parameter_failures(&truth, &fitted(0.085, 72.0, 0.1)).is_empty());
    assert!(parameter_failures(&truth, &fitted(0.1, 0.0, 6.2)).is_empty());
    assert!(parameter_failures(&truth, &fitted(-0.11, 72.0, 6.2 - PI)).is_empty());
    // 30 % off, order 36, 0.5 rad off, a parameter missing: each refused.
    assert_eq!(
        parameter_failures(&truth, &fitted(0.13, 72.0, 6.2)).len(),
        1
    );
    assert_eq!(parameter_failures(&truth, &fitted(0.1, 36.0, 6.2)).len(), 1);
    assert_eq!(parameter_failures(&truth, &fitted(0.1, 72.0, 5.7)).len(), 1);
    assert_eq!(
        parameter_failures(&truth, &fitted(0.1, 72.0, 6.2)[..2]).len(),
        1
    );
    // Kinematic ripple of 9 pistons: (π/18)·tan(π/36) = 1.527 %; `amplitude_ratio = 0` is it.
    let ripple = Truth {
        effect_name: "piston_ripple",
        parameters: vec![("pistons", 9.0), ("amplitude_ratio", 0.01527)],
        ..truth
    };
    let said = vec![
        ("pistons".to_string(), 9.0),
        ("amplitude_ratio".to_string(), 0.0),
    ];
    assert!(parameter_failures(&ripple, &said).is_empty());
}

#[test]
fn the_log_tells_nothing_but_its_source() {
    for seed in [5, 9] {
        let (path, truth) = generate(seed, &log_dir()).expect("generate");
        let log = bench_log::read(&path).expect("the generated log reads back");
        assert_eq!(
            log.metadata,
            vec![("source".to_string(), "blind-suite".to_string())]
        );
        let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
        // `blind-` and 16 hex digits drawn from the stream: no seed, no effect name.
        let token = name
            .strip_prefix("blind-")
            .and_then(|n| n.strip_suffix(".csv"));
        assert!(
            token.is_some_and(|t| t.len() == 16 && t.chars().all(|c| c.is_ascii_hexdigit())),
            "{name}"
        );
        // 1 kHz for the drawn length, every required and simulated column present.
        let rows = (truth.duration_s * 1e3).ceil() as usize;
        assert!(
            log.len().abs_diff(rows) <= 1,
            "{} rows, {rows} expected",
            log.len()
        );
        // The optional columns the draw dropped are absent, the others present.
        let dropped = &draw(seed).structure.dropped;
        for (name, present) in [
            ("ud_v", log.ud_v.is_some()),
            ("uq_v", log.uq_v.is_some()),
            ("x_m", log.x_m.is_some()),
            ("p_low_pa", log.p_low_pa.is_some()),
        ] {
            assert_eq!(present, !dropped.contains(&name), "seed {seed}: {name}");
        }
        assert!(log.theta_m_rad.is_some());
    }
}

/// The false-alarm rate: every log of [`NOTHING_HIDDEN_SEEDS`] hides nothing on a rig drawn
/// like the suite's (tolerances, structure, controller, columns); the diagnosis must call
/// it `none`.
#[test]
fn nothing_hidden_is_called_none() {
    let results: Vec<SeedRun> = NOTHING_HIDDEN_SEEDS.into_par_iter().map(run_seed).collect();
    println!("| seed | scenario | length [s] | dropped columns | named |");
    println!("|---|---|---|---|---|");
    let mut alarms = Vec::new();
    for r in &results {
        assert_eq!(r.truth.effect_name, "none", "seed {}", r.seed);
        let named = match &r.said {
            Ok(s) => s.effect.clone(),
            Err(e) => panic!("seed {}: {e}", r.seed),
        };
        println!(
            "| {} | {} | {:.1} | {} | {named} |",
            r.seed,
            r.truth.scenario,
            r.truth.duration_s,
            draw(r.seed).structure.dropped.join(" ")
        );
        if named != "none" {
            alarms.push(format!("seed {}: named {named}", r.seed));
        }
    }
    let n = results.len();
    println!(
        "false alarms: {} of {n} ({:.0} %)",
        alarms.len(),
        100.0 * alarms.len() as f64 / n as f64
    );
    assert!(n >= 20, "the false-alarm set has {n} logs");
    assert!(
        alarms.len() <= MAX_FALSE_ALARMS,
        "{} false alarms in {n}:\n{}",
        alarms.len(),
        alarms.join("\n")
    );
}
