//! Prints where each effect shows in each of the four tests, the table the suite's coverage
//! rows and `NEVER_SHOWS` were chosen from (`tests::blind::COVERAGE`): for each effect
//! specification given on the command line (`name:param=value,…`, default: every effect at
//! the weak and the strong end of the generator's range) and each test, the signature
//! (noise-free log with the effect minus without) over the noise, RMS over the whole log,
//! per measured signal, every optional column logged, against the sensor noise estimated
//! from the effect-free log, and in brackets the signature at half the effect over the full
//! one (0.5 for an effect whose signature scales with it); then whether it shows by the
//! generator's rule and where. The rigs and tests are those of the false-alarm seeds, one
//! per test, or of `--seeds`. The specification `floor` perturbs the plant by a negligible
//! 1e-20 (m³/s)/Pa of leakage: what remains is the closed loop's own divergence under
//! quantisation.
//!
//! `cargo run --release -p tests --example blind_probe [--seeds A..B] [SPEC …]`

use plant_model::Effect;
use tests::blind::{draw, halfway, noise_by_signal, shown, MEASURED, NOTHING_HIDDEN_SEEDS, TESTS};

/// Every effect at the weak and at the strong end of the generator's ranges.
const ENDS: [&str; 23] = [
    "floor",
    "piston_ripple:pistons=9,amplitude_ratio=0.0153",
    "piston_ripple:pistons=7,amplitude_ratio=0.0760",
    "cogging_torque:amplitude_nm=0.03,order=72,phase_rad=1",
    "cogging_torque:amplitude_nm=0.15,order=72,phase_rad=1",
    "flux_harmonics:t6_ratio=0.02,phase_rad=1",
    "flux_harmonics:t6_ratio=0.08,phase_rad=1",
    "dead_time:dead_time_s=0.5e-6",
    "dead_time:dead_time_s=3e-6",
    "shaft_friction:coulomb_nm=0.05,static_nm=0.06",
    "shaft_friction:coulomb_nm=0.3,static_nm=0.48",
    "cylinder_friction:coulomb_n=200,static_n=240",
    "cylinder_friction:coulomb_n=2000,static_n=3200",
    "extra_leakage:coefficient_m3_s_pa=3e-13",
    "extra_leakage:coefficient_m3_s_pa=12e-13",
    "entrained_air:effective_bulk_modulus_pa=3.9e8",
    "entrained_air:effective_bulk_modulus_pa=1.6e8",
    "accumulator_precharge:precharge_pa=2.25e6",
    "accumulator_precharge:precharge_pa=3.9e6",
    "pressure_sensor_lag:time_constant_s=2e-3",
    "pressure_sensor_lag:time_constant_s=20e-3",
    "current_sensor_offset:offset_a=0.2",
    "current_sensor_offset:offset_a=1.0",
];

fn main() -> Result<(), String> {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    // `--seeds A..B`: the rigs and tests of these seeds instead (their own draws, any
    // effect they hide switched off).
    let seeds: Vec<u64> = match args.iter().position(|a| a == "--seeds") {
        Some(i) if i + 1 < args.len() => {
            let range = args.remove(i + 1);
            args.remove(i);
            let (a, b) = range.split_once("..").ok_or("--seeds A..B")?;
            let parse = |x: &str| {
                x.parse::<u64>()
                    .map_err(|e| format!("--seeds {range}: {e}"))
            };
            (parse(a)?..parse(b)?).collect()
        }
        Some(_) => return Err("--seeds needs A..B".into()),
        None => NOTHING_HIDDEN_SEEDS.take(TESTS.len()).collect(),
    };
    let specs: Vec<String> = if args.is_empty() {
        ENDS.iter().map(|s| s.to_string()).collect()
    } else {
        args
    };
    // One false-alarm seed per test (its rig, structure, rate and length), every column
    // kept; its effect-free log, noise-free and noisy.
    let mut bases = Vec::new();
    for seed in seeds {
        let (mut d, _) = draw(seed)?;
        d.structure.dropped.clear();
        d.effects.clear();
        let clean = d.log(&d.tolerance_rig, None)?;
        let noise = noise_by_signal(&d.log(&d.tolerance_rig, Some(d.noise_seed))?);
        bases.push((d, clean, noise));
    }
    let names: Vec<&str> = MEASURED.iter().map(|s| s.name()).collect();
    println!("signature RMS / noise RMS over the whole log");
    println!(
        "| effect | test | rate [Hz] | length [s] | {} | best |",
        names.join(" | ")
    );
    for spec in &specs {
        let effect = if spec == "floor" {
            Effect::ExtraLeakage {
                coefficient_m3_s_pa: 1e-20,
            }
        } else {
            Effect::parse(spec).map_err(|e| format!("{spec}: {e}"))?
        };
        for (base, without, noise) in &bases {
            let mut d = base.clone();
            d.effects = vec![effect];
            let with = d.log(&d.truth_rig(), None)?;
            let mut half_rig = d.tolerance_rig.clone();
            halfway(&effect, &d.tolerance_rig).apply(&mut half_rig);
            let half = d.log(&half_rig, None)?;
            let cells: Vec<String> = MEASURED
                .iter()
                .map(|&s| {
                    noise
                        .iter()
                        .find(|(n, _)| *n == s)
                        .and_then(|&one| shown(&with, without, Some(&half), &[one]))
                        .map(|r| format!("{:.1} ({:.2})", r.ratio, r.half_over_full))
                        .unwrap_or_else(|| "—".into())
                })
                .collect();
            let best = shown(&with, without, Some(&half), noise).map_or("—".into(), |b| {
                let verdict = if b.accepted() { "shows" } else { "no" };
                format!("{verdict}: {} {:.1}", b.signal.name(), b.ratio)
            });
            println!(
                "| {spec} | {} | {} | {:.1} | {} | {best} |",
                d.truth.test,
                d.log_rate_hz,
                d.scenario.duration_s,
                cells.join(" | ")
            );
        }
    }
    Ok(())
}
