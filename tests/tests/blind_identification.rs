//! The blind identification suite. Over the coverage seeds ([`COVERAGE`]) the generator
//! ([`tests::blind`]) records one of four bench tests (a pressure step, a staircase, a
//! sine, a stroke of the free payload) at 500 Hz to 10 kHz for 15 to 40 s, on a
//! tolerance-perturbed rig with drawn structure, and hides one catalogue effect or two at
//! once, each at a magnitude that shows at least five times the noise on some logged
//! signal and scales with the effect; the false-alarm seeds ([`NOTHING_HIDDEN_SEEDS`])
//! hide nothing, three in each test. The diagnosis (`host_sim::diagnose::diagnose`) gets
//! only the log read back from its CSV file and the NOMINAL rig, and must
//! - name in `extended.effects` exactly the hidden effects (a pair: both and nothing else;
//!   nothing hidden: an empty list, no false alarm at all);
//! - fit each hidden effect's parameters, as its cause gives them, within the standard of
//!   [`tests::blind::judge`] (every parameter: 25 %, integers exactly, phases 0.35 rad;
//!   the shaft's breakaway torque, which no test makes observable, shown but not held);
//! - not make the validation-segment fit worse on the signal where each effect shows most,
//!   when the diagnosis scores that signal.
//!
//! CI runs a part of it (`the_diagnosis_holds_on_the_ci_seeds`: one coverage seed and one
//! nothing-hidden log per test); the whole suite is an ignored test:
//!
//! ```text
//! cargo test -p tests --test blind_identification -- --ignored --nocapture
//! ```
//!
//! The held-out part of the generator ([`tests::blind::HELD_OUT_SEEDS`]) is never run here:
//! `cargo run --release -p tests --example blind_table -- DIR FROM N` writes and scores it.
//!
//! The diagnosis is read only through the contract's JSON; the truth numbers come from the
//! generator's draw, never from the diagnosis. A failing seed is printed with everything
//! needed to mend the diagnosis: the test, rate, length, columns, hidden effects and their
//! parameters, and what the diagnosis named with its causes' evidence
//! (`cargo run --release -p tests --example blind_log -- DIR SEED` writes its log).
//!
//! Other tests check the generator itself, independently of the diagnosis: the coverage
//! (every effect on the tests where it shows, pairs of both kinds, every test and rate), a
//! negligible effect taken to show nowhere (the rule measures the effect, not the closed
//! loop's own divergence), and a log that tells nothing but its source.

use host_sim::bench_log;
use host_sim::diagnose::diagnose;
use plant_model::Rig;
use rayon::prelude::*;
use std::collections::{BTreeMap, BTreeSet};
use std::path::PathBuf;
use tests::blind::judge::{failures, read_said, Named, Said, Standard};
use tests::blind::table::Tally;
use tests::blind::{
    draw, generate, halfway, identification_seeds, noise_by_signal, outline, shown, Truth,
    COVERAGE, FAST_RATES_HZ, HYDRAULIC, MOTOR, NOTHING_HIDDEN_SEEDS, RATES_HZ, TESTS,
};

/// The coverage seeds CI runs: one per test, pairs and single effects in turn, chosen by
/// their place in [`COVERAGE`] before any was diagnosed.
const CI_SEEDS: [u64; 4] = [9, 14, 31, 35];

/// Seeds of the CI part the diagnosis gets wrong today (none): the suite reports them
/// and fails when one of them is right (take it out) or any other seed fails.
const KNOWN_MISSES: [u64; 0] = [];

/// Least validation-fit gain on a hidden effect's signal. [points]
const MIN_FIT_GAIN: f64 = 0.0;
/// False alarms allowed in the false-alarm set. [1]
const MAX_FALSE_ALARMS: usize = 0;
/// The signals the contract's `fit_percent_by_signal` must score.
const CONTRACT_SIGNALS: [&str; 3] = ["p_pa", "speed_rad_s", "iq_a"];

/// Where the generated logs go.
fn log_dir() -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("blind");
    std::fs::create_dir_all(&dir).expect("create the blind-log directory");
    dir
}

/// One seed: what was hidden, what the diagnosis said.
struct SeedRun {
    seed: u64,
    truth: Truth,
    said: Result<Said, String>,
}

/// Generates, reads back and diagnoses one seed.
fn run_seed(seed: u64) -> SeedRun {
    run_seed_as(seed, &[&|_| {}]).remove(0)
}

/// Generates and reads back one seed's log once, then diagnoses it as changed by each of
/// `edits` in turn: one run per edit.
fn run_seed_as(seed: u64, edits: &[&dyn Fn(&mut bench_log::BenchLog)]) -> Vec<SeedRun> {
    let read = generate(seed, &log_dir())
        .map_err(|e| format!("the generator failed: {e}"))
        .and_then(|(path, truth)| {
            let log = bench_log::read(&path)
                .map_err(|e| format!("reading back the generated log: {e}"))?;
            Ok((log, truth))
        });
    edits
        .iter()
        .map(|edit| {
            let (truth, said) = match &read {
                Ok((log, truth)) => {
                    let mut log = log.clone();
                    edit(&mut log);
                    let said = diagnose(&log, &Rig::nominal())
                        .map_err(|e| format!("diagnose failed: {e}"))
                        .and_then(|d| serde_json::to_value(&d).map_err(|e| format!("to JSON: {e}")))
                        .and_then(|json| read_said(&json));
                    (truth.clone(), said)
                }
                Err(e) => (outline(seed), Err(e.clone())),
            };
            let run = SeedRun { seed, truth, said };
            // Each run as soon as it is judged: a long run shows its results as they come.
            eprintln!("{}", row(&run).0);
            run
        })
        .collect()
}

/// The hidden effects as the judge takes them.
fn hidden(truth: &Truth) -> Vec<Named> {
    truth
        .effects
        .iter()
        .map(|h| Named {
            effect: h.name.to_string(),
            parameters: h
                .parameters
                .iter()
                .map(|(k, v)| (k.to_string(), *v))
                .collect(),
        })
        .collect()
}

/// The fit gains owed: on each hidden effect's signal, when the diagnosis scores it (and
/// always on the contract's signals); the failures, described.
fn fit_failures(truth: &Truth, s: &Said) -> Vec<String> {
    let mut out = Vec::new();
    for h in &truth.effects {
        match (s.baseline_fit.get(h.signal), s.extended_fit.get(h.signal)) {
            (Some(b), Some(e)) if e - b >= MIN_FIT_GAIN => {}
            (Some(b), Some(e)) => out.push(format!(
                "{}: fit gain on {} is {:.1} points < {MIN_FIT_GAIN}",
                h.name,
                h.signal,
                e - b
            )),
            _ if CONTRACT_SIGNALS.contains(&h.signal) => {
                out.push(format!("{}: no fit reported for {}", h.name, h.signal))
            }
            _ => {}
        }
    }
    out
}

fn show_params<K: std::fmt::Display>(p: &[(K, f64)]) -> String {
    if p.is_empty() {
        return "—".into();
    }
    p.iter()
        .map(|(k, v)| format!("{k}={v:.3e}"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// One line of the log's conditions: test, rate, length, dropped columns.
fn conditions(t: &Truth) -> String {
    format!(
        "{} | {} Hz | {:.1} s | {}",
        t.test,
        t.log_rate_hz,
        t.duration_s,
        if t.dropped.is_empty() {
            "—".into()
        } else {
            t.dropped.join(" ")
        }
    )
}

/// The hidden effects with their parameters and where each shows.
fn show_hidden(t: &Truth) -> String {
    if t.effects.is_empty() {
        return "none".into();
    }
    t.effects
        .iter()
        .map(|h| {
            format!(
                "{} ({}; {:.1}× noise on {})",
                h.name,
                show_params(&h.parameters),
                h.ratio,
                h.signal
            )
        })
        .collect::<Vec<_>>()
        .join(" + ")
}

/// What the diagnosis named, with each cause's parameters.
fn show_said(s: &Said) -> String {
    let named = if s.effects.is_empty() {
        "none".to_string()
    } else {
        s.effects.join("+")
    };
    let causes: Vec<String> = s
        .causes
        .iter()
        .map(|c| {
            let amb = if c.ambiguous_with.is_empty() {
                String::new()
            } else {
                format!(" ambiguous_with {:?}", c.ambiguous_with)
            };
            format!(
                "{} ({}){amb}",
                c.named.effect,
                show_params(&c.named.parameters)
            )
        })
        .collect();
    format!("{named}: causes {}", causes.join("; "))
}

/// The detailed account of a failed seed: the log and what the diagnosis said, evidence
/// lines included.
fn account(r: &SeedRun, verdict: &str) -> String {
    let mut out = format!(
        "seed {}: {verdict}\n  log: {} | hidden {}\n",
        r.seed,
        conditions(&r.truth),
        show_hidden(&r.truth)
    );
    match &r.said {
        Err(e) => out += &format!("  diagnosis: {e}\n"),
        Ok(s) => {
            out += &format!("  named: {}\n", show_said(s));
            for c in &s.causes {
                out += &format!("  evidence {}: {}\n", c.named.effect, c.evidence);
            }
        }
    }
    out
}

/// One seed's table row and its failures.
fn row(r: &SeedRun) -> (String, Vec<String>) {
    let wrong = match &r.said {
        Err(e) => vec![e.clone()],
        Ok(s) => {
            let mut w = failures(&hidden(&r.truth), s, Standard::Every);
            w.extend(fit_failures(&r.truth, s));
            w
        }
    };
    let verdict = if wrong.is_empty() {
        "ok".to_string()
    } else {
        wrong.join("; ")
    };
    let named = r.said.as_ref().map_or("—".into(), show_said);
    let line = format!(
        "| {} | {} | {} | {named} | {verdict} |",
        r.seed,
        conditions(&r.truth),
        show_hidden(&r.truth)
    );
    (line, wrong)
}

/// Judges `runs`: prints one row per seed, returns the failed seeds with their accounts.
fn judge(runs: &[SeedRun]) -> Vec<(u64, String)> {
    println!("| seed | test | rate | length | dropped | hidden | named | verdict |");
    println!("|---|---|---|---|---|---|---|---|");
    let mut failed = Vec::new();
    for r in runs {
        let (line, wrong) = row(r);
        println!("{line}");
        if !wrong.is_empty() {
            failed.push((r.seed, account(r, &wrong.join("; "))));
        }
    }
    failed
}

/// Runs `seeds` (in parallel), judges them, prints the table and the tally by test,
/// nothing hidden, one effect and pairs; returns the seeds that failed with their accounts.
fn run_and_judge(seeds: &[u64]) -> Vec<(u64, String)> {
    let runs: Vec<SeedRun> = seeds.par_iter().map(|s| run_seed(*s)).collect();
    let failed = judge(&runs);
    let mut tally = Tally::default();
    for r in &runs {
        let right = !failed.iter().any(|(s, _)| *s == r.seed);
        tally.add(r.truth.test, r.truth.effects.len(), right);
    }
    println!("\n{}", tally.markdown());
    failed
}

/// The suite's part CI runs: one coverage seed per test (two single effects, two pairs)
/// and one nothing-hidden log per test. Every seed must be judged right except the diagnosis's
/// known misses ([`KNOWN_MISSES`]), and a known miss that is now right must leave that
/// list, so the list says what fails today.
#[test]
fn the_diagnosis_holds_on_the_ci_seeds() {
    let seeds: Vec<u64> = CI_SEEDS
        .iter()
        .copied()
        .chain(NOTHING_HIDDEN_SEEDS.take(TESTS.len()))
        .collect();
    let failed = run_and_judge(&seeds);
    let unexpected: Vec<&str> = failed
        .iter()
        .filter(|(s, _)| !KNOWN_MISSES.contains(s))
        .map(|(_, a)| a.as_str())
        .collect();
    let mended: Vec<u64> = KNOWN_MISSES
        .iter()
        .copied()
        .filter(|k| seeds.contains(k) && !failed.iter().any(|(s, _)| s == k))
        .collect();
    for (_, a) in &failed {
        println!("{a}");
    }
    assert!(
        unexpected.is_empty(),
        "{} seeds failed that are not known misses:\n{}",
        unexpected.len(),
        unexpected.join("\n")
    );
    assert!(
        mended.is_empty(),
        "known misses now right, take them out of KNOWN_MISSES: {mended:?}"
    );
}

/// The whole suite, the issue's standard: every coverage seed right (exactly the hidden
/// effects, every parameter within the judge's standard) and no false alarm on any
/// nothing-hidden log. Slow (about 50 logs simulated and diagnosed):
/// `cargo test --release -p tests --test blind_identification -- --ignored --nocapture`.
#[test]
#[ignore = "the full blind suite: run with --ignored (minutes)"]
fn the_diagnosis_finds_every_hidden_effect() {
    let seeds: Vec<u64> = identification_seeds().chain(NOTHING_HIDDEN_SEEDS).collect();
    let failed = run_and_judge(&seeds);
    let false_alarms = failed
        .iter()
        .filter(|(s, _)| NOTHING_HIDDEN_SEEDS.contains(s))
        .count();
    println!(
        "false alarms: {false_alarms} of {} (at most {MAX_FALSE_ALARMS})",
        NOTHING_HIDDEN_SEEDS.count()
    );
    assert!(
        failed.is_empty(),
        "{} of {} seeds failed:\n{}",
        failed.len(),
        seeds.len(),
        failed
            .iter()
            .map(|(_, a)| a.as_str())
            .collect::<Vec<_>>()
            .join("\n")
    );
}

/// Coverage seeds that hide entrained air on a stroke of the free payload, with a Coulomb
/// cylinder friction (40) or a current offset (39) beside it: the oil's compliance shows
/// in the piston's position where the port pressure moves (the reversal, the friction's
/// stick-slip), which the volume balance read for the position measures. Seed 36, air
/// alone on a stroke, is left out: its only reversal falls in the validation segment,
/// and the identification segment's port pressure never moves.
const AIR_ON_A_STROKE_SEEDS: [u64; 2] = [39, 40];

/// Entrained air on a stroke named, with its bulk modulus, beside the other effect.
#[test]
fn air_on_a_stroke_is_read_from_the_position() {
    for seed in AIR_ON_A_STROKE_SEEDS {
        let t = outline(seed);
        assert_eq!(t.test, "stroke", "seed {seed}");
        assert!(
            t.effects.iter().any(|e| e.name == "entrained_air"),
            "seed {seed} hides no air"
        );
    }
    all_right(&AIR_ON_A_STROKE_SEEDS);
}

/// A shaft friction (0.195 N·m Coulomb, 0.266 N·m breakaway) on a 10 kHz sine test whose
/// release has a second, shallower basin near half the Coulomb torque, which a search from
/// the grid's best point alone reached or not by the log's last bits.
const SHAFT_FRICTION_BASIN_SEED: u64 = 25;

/// The shaft friction read in its deeper basin, within the judge's standard, on the log
/// as generated (its row times sums of PWM periods) and on the same log with each row's
/// time recounted as a whole number of PWM periods over the PWM frequency (the same
/// instants within 10⁻¹⁰ s). From the grid's best point alone both read 0.100 N·m.
#[test]
fn a_shaft_friction_is_read_in_its_deeper_basin() {
    let seed = SHAFT_FRICTION_BASIN_SEED;
    let t = outline(seed);
    assert!(
        t.effects.iter().any(|e| e.name == "shaft_friction"),
        "seed {seed} hides no shaft friction"
    );
    let pwm_hz = Rig::nominal().inverter.pwm_frequency_hz;
    let recount = |log: &mut bench_log::BenchLog| {
        for t in &mut log.t_s {
            let periods = (*t * pwm_hz).round();
            assert!(
                (periods / pwm_hz - *t).abs() < 1e-10,
                "row at {t} s off the grid"
            );
            *t = periods / pwm_hz;
        }
    };
    let runs = run_seed_as(seed, &[&|_| {}, &recount]);
    assert_none_failed(&judge(&runs));
}

/// Freely drawn pressure tests whose absorber's precharge (4.23–4.40 MPa) lies above every
/// pressure of their identification segment: the absorber never takes oil there, every
/// higher precharge fits as well, and the fit stops on that flat stretch (6.0 MPa, 36–42 %
/// off). The log bounds the precharge from below only, and it is read at that bound.
const PRECHARGE_ABOVE_THE_TEST_SEEDS: [u64; 3] = [4_302_112, 4_305_405, 4_318_304];

/// Every one of `seeds` judged right, or the judge's account of each that is not.
fn all_right(seeds: &[u64]) {
    assert_none_failed(&run_and_judge(seeds));
}

/// No run in `failed` (the judge's failed seeds with their accounts), or the accounts.
fn assert_none_failed(failed: &[(u64, String)]) {
    assert!(
        failed.is_empty(),
        "{}",
        failed
            .iter()
            .map(|(_, a)| a.as_str())
            .collect::<Vec<_>>()
            .join("\n")
    );
}

/// A precharge above the test's pressures named, and read within the judge's standard.
#[test]
fn a_precharge_above_the_test_is_read_at_the_bound_the_log_sets() {
    for seed in PRECHARGE_ABOVE_THE_TEST_SEEDS {
        let t = outline(seed);
        assert!(
            t.effects.len() == 1 && t.effects[0].name == "accumulator_precharge",
            "seed {seed} hides {:?}",
            t.effects.iter().map(|e| e.name).collect::<Vec<_>>()
        );
    }
    all_right(&PRECHARGE_ABOVE_THE_TEST_SEEDS);
}

/// The suite's seeds cover, without simulating them: every effect on every test where it
/// can act at all (the cylinder's friction on strokes only, the absorber's precharge on
/// pressure tests only) unless the coverage table records it as never showing there;
/// pairs of both kinds (hydraulic with motor-side, two hydraulic ones); every test; every
/// ordinary log rate and a fast one; and the false-alarm set every test.
#[test]
fn the_suite_covers_effects_tests_pairs_and_rates() {
    let outlines: Vec<Truth> = identification_seeds().map(outline).collect();
    let mut singles: BTreeMap<&str, BTreeSet<&str>> = BTreeMap::new();
    let (mut mixed, mut hydraulic) = (0, 0);
    for t in &outlines {
        match t.effects.as_slice() {
            [one] => {
                singles.entry(one.name).or_default().insert(t.test);
            }
            [a, b] if HYDRAULIC.contains(&a.name) && HYDRAULIC.contains(&b.name) => hydraulic += 1,
            [_, _] => mixed += 1,
            _ => {}
        }
    }
    let mut missing = Vec::new();
    for e in HYDRAULIC.iter().chain(&MOTOR) {
        for test in TESTS {
            let covered = singles.get(e).is_some_and(|s| s.contains(test.name()));
            let excused = tests::blind::NEVER_SHOWS.contains(&(*e, test));
            if tests::blind::possible_in(e, test) && !covered && !excused {
                missing.push(format!("{e} in {}", test.name()));
            }
        }
    }
    assert!(missing.is_empty(), "not covered: {}", missing.join(", "));
    // No row claims what its test cannot show, and a hydraulic pair acts differently.
    for (test, effects) in COVERAGE {
        for e in effects {
            let shows = tests::blind::possible_in(e, test)
                && !tests::blind::NEVER_SHOWS.contains(&(*e, test));
            assert!(shows, "{e} cannot show in {}", test.name());
        }
        if let [a, b] = effects {
            if HYDRAULIC.contains(a) && HYDRAULIC.contains(b) {
                assert!(tests::blind::acts_differently(a, b), "{a} + {b}");
            }
        }
    }
    assert!(
        mixed >= 6 && hydraulic >= 2,
        "{mixed} mixed pairs, {hydraulic} hydraulic"
    );
    let rates: BTreeSet<u64> = outlines.iter().map(|t| t.log_rate_hz as u64).collect();
    for r in RATES_HZ {
        assert!(rates.contains(&(r as u64)), "no log at {r} Hz");
    }
    assert!(
        FAST_RATES_HZ.iter().any(|r| rates.contains(&(*r as u64))),
        "no fast log"
    );
    assert!(COVERAGE.len() >= 40);
}

/// The generator's rule measures the effect, not the closed loop: a leak of 1e-20
/// (m³/s)/Pa (a ten-millionth of the rig's) is taken to show in no test. Where the closed
/// loop's own divergence (a limit cycle's phase) makes even such a leak stand several
/// times above the noise, its signature does not halve with it, and the rule refuses it.
#[test]
fn a_negligible_effect_is_taken_to_show_nowhere() {
    let rows: Vec<(&str, tests::blind::Shown)> = NOTHING_HIDDEN_SEEDS
        .take(TESTS.len())
        .collect::<Vec<_>>()
        .into_par_iter()
        .map(|seed| {
            let (mut d, _) = draw(seed).unwrap_or_else(|e| panic!("{e}"));
            d.structure.dropped.clear();
            let clean = d.log(&d.tolerance_rig, None).expect("run");
            let noisy = d.log(&d.tolerance_rig, Some(d.noise_seed)).expect("run");
            d.effects = vec![plant_model::Effect::ExtraLeakage {
                coefficient_m3_s_pa: 1e-20,
            }];
            let with = d.log(&d.truth_rig(), None).expect("run");
            let noise = noise_by_signal(&noisy);
            let mut half_rig = d.tolerance_rig.clone();
            halfway(&d.effects[0], &d.tolerance_rig).apply(&mut half_rig);
            let half = d.log(&half_rig, None).expect("run");
            let best = shown(&with, &clean, Some(&half), &noise).expect("a signal with noise");
            (d.truth.test, best)
        })
        .collect();
    for (test, s) in &rows {
        println!(
            "floor: {test}: {:.2}× the noise on {}, half over full {:.2}",
            s.ratio,
            s.signal.name(),
            s.half_over_full
        );
        assert!(!s.accepted(), "{test}: a negligible leak is taken to show");
    }
}

#[test]
fn the_log_tells_nothing_but_its_source() {
    let seeds = [NOTHING_HIDDEN_SEEDS.start, NOTHING_HIDDEN_SEEDS.start + 3];
    for seed in seeds {
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
        // The drawn rate for the drawn length.
        let rows = (truth.duration_s * truth.log_rate_hz).ceil() as usize;
        assert!(
            log.len().abs_diff(rows) <= 1,
            "{} rows, {rows} expected",
            log.len()
        );
        // The optional columns the draw dropped are absent, the others present.
        for (name, present) in [
            ("ud_v", log.ud_v.is_some()),
            ("uq_v", log.uq_v.is_some()),
            ("x_m", log.x_m.is_some()),
            ("p_low_pa", log.p_low_pa.is_some()),
        ] {
            assert_eq!(
                present,
                !truth.dropped.contains(&name),
                "seed {seed}: {name}"
            );
        }
        assert!(log.theta_m_rad.is_some());
    }
}
