//! Prints the signature table the blind suite's scenarios and signals were chosen from
//! (`tests::blind::scenarios_for`): for each effect specification given on the command line
//! (`name:param=value,…`, default: every effect at the weak end of its drawn range) and each
//! scenario, the noise-free RMS of (with effect − without) over the second half of the log
//! against the sensor noise's RMS, and the fit gain that would attain, per logged signal.
//! The specification `floor` instead perturbs the plant by a negligible 1e-20 (m³/s)/Pa of
//! leakage: what remains is the closed loop's own divergence under quantisation. `A|B`
//! compares effect A against effect B instead of against none (e.g. two breakaway levels
//! of one friction, to see whether the breakaway is observable at all).
//!
//! `cargo run --release -p tests --example blind_probe [SPEC …]`

use closed_loop::{by_name, SCENARIOS};
use plant_model::Effect;
use tests::blind::{draw, signature, LOGGED};

/// Every effect at the weak end of the generator's range (both piston counts and both
/// directions of a wrong precharge).
const WEAK: [&str; 13] = [
    "piston_ripple:pistons=9,amplitude_ratio=0.0153",
    "piston_ripple:pistons=7,amplitude_ratio=0.0253",
    "cogging_torque:amplitude_nm=0.03,order=72,phase_rad=1",
    "flux_harmonics:t6_ratio=0.02,phase_rad=1",
    "dead_time:dead_time_s=0.5e-6",
    "shaft_friction:coulomb_nm=0.05,static_nm=0.06",
    "cylinder_friction:coulomb_n=200,static_n=240",
    "extra_leakage:coefficient_m3_s_pa=3e-13",
    "entrained_air:effective_bulk_modulus_pa=3.9e8",
    "accumulator_precharge:precharge_pa=2.25e6",
    "accumulator_precharge:precharge_pa=3.9e6",
    "pressure_sensor_lag:time_constant_s=2e-3",
    "current_sensor_offset:offset_a=0.2",
];

fn main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let specs: Vec<String> = if args.is_empty() {
        WEAK.iter().map(|s| s.to_string()).collect()
    } else {
        args
    };
    let header: Vec<&str> = LOGGED.iter().map(|s| s.name()).collect();
    println!(
        "effect RMS / noise RMS ; attainable fit gain [points]\n| effect | scenario | {} |",
        header.join(" | ")
    );
    for spec in &specs {
        let (with, base) = spec.split_once('|').unwrap_or((spec, "none"));
        let effect = if with == "floor" {
            Effect::ExtraLeakage {
                coefficient_m3_s_pa: 1e-20,
            }
        } else {
            Effect::parse(with).map_err(|e| format!("{with}: {e}"))?
        };
        let base = Effect::parse(base).map_err(|e| format!("{base}: {e}"))?;
        for sc in SCENARIOS {
            let mut d = draw(1000);
            d.effect = effect;
            base.apply(&mut d.tolerance_rig);
            d.scenario = *by_name(sc.name).ok_or("scenario")?;
            let t_from = d.scenario.duration_s / 2.0;
            let mut row = format!("| {spec} | {} |", sc.name);
            for s in LOGGED {
                let g = signature(&d, s, t_from)?;
                row += &format!(" {:.2} ; {:.1} |", g.ratio(), g.attainable_fit_gain());
            }
            println!("{row}");
        }
    }
    Ok(())
}
