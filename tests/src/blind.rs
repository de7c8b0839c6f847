//! The generator of the blind identification suite: from a seed the diagnosis never
//! sees, it draws one effect of the catalogue (`shared/contracts/effects.md`) or none, its
//! parameters from realistic ranges, a rig whose other parameters deviate by their
//! tolerances from the nominal one, the sensor noise, and a scenario that excites the
//! effect; then it runs the firmware's controller (configured from the NOMINAL rig, as on a
//! bench where the engineer's rig file is nominal) against that plant and writes the bench
//! log the diagnosis gets — and nothing else.
//!
//! It shares no code with the diagnosis (`host_sim::diagnose`): it only uses the plant model,
//! the closed loop (`host_sim::run`, which is simulation) and the bench-log writer. The log
//! carries the single metadata line `# source: blind-suite` and a file name drawn from the
//! generator's stream, so neither the effect, its parameters, the seed nor the scenario's
//! name can leak through it (the scenario's commands are of course in `p_ref_pa` and
//! `speed_ref_rad_s`, as on a bench; every effect can be drawn with at least two scenarios
//! and every scenario hosts several effects, so the commands do not give the effect away).
//!
//! Beyond the tolerances each draw varies structure ([`structure`]): the parts the rig
//! contract leaves open, the controller's tuning, and the optional columns the bench logged
//! (never one without which the hidden effect cannot be seen, [`needed_columns`]). The seeds
//! of [`NOTHING_HIDDEN_SEEDS`] hide nothing: the false-alarm set.
//!
//! The ranges are physical, each justified where it is drawn ([`draw_effect`]); the
//! signal of each (effect, scenario) pair is where its closed-loop signature stands
//! furthest above the sensor noise ([`signal_for`]), measured with [`signature`].

mod observability;
mod structure;

pub use observability::{
    angle_locked_fit_bound, line_below_noise, line_fit_bound, ripple_orders, signature, Signature,
    LOGGED, RIPPLE_HARMONICS,
};
pub use structure::{ControllerVariant, Structure};

use closed_loop::{by_name, controller_config, Scenario};
use host_sim::bench_log::{self, BenchLog, Signal};
use host_sim::run::{run_with_config, RunOptions};
use plant_model::effects::EFFECT_NAMES;
use plant_model::pump::kinematic_ripple_ratio;
use plant_model::{Effect, Rig};
use rand_core::{RngCore, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use std::f64::consts::TAU;
use std::path::{Path, PathBuf};

/// Seeds of the suite: 0..36. The first 24 take effect `seed mod 12` (each of the 11
/// effects and `none` twice), the rest draw the effect from the seed's stream.
pub const SUITE_SEEDS: u64 = 36;

/// Draws from beyond `0..SUITE_SEEDS` the diagnosis once got wrong, run with the suite
/// once mended so that they stay right: 96, the flux harmonics at light load with the
/// voltages logged (named `none` while only their torque line was read).
pub const REGRESSION_SEEDS: [u64; 1] = [96];

/// Every seed the identification suite runs: `0..SUITE_SEEDS`, then [`REGRESSION_SEEDS`].
pub fn identification_seeds() -> Vec<u64> {
    (0..SUITE_SEEDS).chain(REGRESSION_SEEDS).collect()
}

/// Seeds of the false-alarm set: every one hides nothing, on a rig drawn like the others
/// (tolerances, structure, controller, columns). Disjoint from `0..SUITE_SEEDS`.
pub const NOTHING_HIDDEN_SEEDS: std::ops::Range<u64> = 1000..1020;

/// Seeds below this take their effect from `seed mod 12` (full coverage, twice).
const COVERED_SEEDS: u64 = 2 * EFFECT_NAMES.len() as u64;

/// Log rate of every generated log (the firmware's 1 kHz telemetry). [Hz]
pub const LOG_RATE_HZ: f64 = 1e3;

/// Relative tolerance of every perturbed rig parameter: uniform in ±this. [1]
pub const TOLERANCE: f64 = 0.03;

/// What the generator hid in one log: the answer the suite checks the diagnosis against.
#[derive(Clone, Debug, PartialEq)]
pub struct Truth {
    /// Effect name from the catalogue (`none` included).
    pub effect_name: &'static str,
    /// The effect's parameters by their contract names (SI), as applied to the plant.
    pub parameters: Vec<(&'static str, f64)>,
    /// Scenario the log was run with.
    pub scenario: &'static str,
    /// Length of the log. [s]
    pub duration_s: f64,
    /// Logged column where the effect shows most (contract column name).
    pub signal: &'static str,
}

/// Everything drawn for one seed: the truth plus how to simulate it. Kept inside the
/// generator and the suite's own checks; the diagnosis gets only the written log.
#[derive(Clone, Debug)]
pub struct Draw {
    /// The answer.
    pub truth: Truth,
    /// The hidden effect (with its parameters).
    pub effect: Effect,
    /// The plant's rig: nominal ± tolerances with the drawn structure, WITHOUT the effect.
    pub tolerance_rig: Rig,
    /// What was drawn beyond the tolerances: open parts of the rig, the controller's
    /// tuning, the columns not logged (already in `tolerance_rig` where it is the rig's).
    pub structure: Structure,
    /// The scenario, with its drawn length.
    pub scenario: Scenario,
    /// Sensor-noise seed of the plant.
    pub noise_seed: u64,
    /// File-name token (drawn, so the name carries nothing about the seed).
    token: u64,
}

impl Draw {
    /// The plant's true rig: the tolerance rig with the effect switched on.
    pub fn truth_rig(&self) -> Rig {
        let mut rig = self.tolerance_rig.clone();
        self.effect.apply(&mut rig);
        rig
    }

    /// The draw's scenario run on the plant `rig` under the draw's controller, with sensor
    /// noise `noise_seed` ([`simulate`]).
    pub fn run(&self, rig: &Rig, noise_seed: u64) -> Result<BenchLog, String> {
        simulate(rig, &self.structure.controller, &self.scenario, noise_seed)
    }
}

/// Uniform deviates from the generator's own xoshiro stream.
struct Stream(Xoshiro256PlusPlus);

impl Stream {
    /// Uniform in [0, 1) from the top 53 bits.
    fn unit(&mut self) -> f64 {
        (self.0.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in [lo, hi).
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }

    /// `x` scaled by a factor uniform in 1 ± [`TOLERANCE`].
    fn tolerance(&mut self, x: f64) -> f64 {
        x * self.uniform(1.0 - TOLERANCE, 1.0 + TOLERANCE)
    }

    /// One of `items`, uniformly.
    fn pick<T: Copy>(&mut self, items: &[T]) -> T {
        let k = (self.unit() * items.len() as f64) as usize;
        items[k.min(items.len() - 1)]
    }

    /// +1 or −1 with equal probability.
    fn sign(&mut self) -> f64 {
        if self.unit() < 0.5 {
            -1.0
        } else {
            1.0
        }
    }
}

/// The nominal rig with every parameter that is a manufacturing or operating tolerance
/// (not a fault) scaled by an independent factor uniform in 1 ± 3 %: motor R_s, L_d, L_q,
/// ψ_f, the shaft's inertias and viscous friction, pump displacement and leakages, cylinder
/// leakage, oil bulk modulus, chamber volumes, absorber gas volume and precharge, payload
/// mass. The sensors' noise is drawn too: a bench's transducers are noisier or quieter than
/// the data sheet (0.7–1.5 × the nominal rms); the ADC quantisation is the converter's and
/// stays.
fn tolerance_rig(s: &mut Stream) -> Rig {
    let mut r = Rig::nominal();
    let (m, sh, p, c, a) = (
        &mut r.motor,
        &mut r.shaft,
        &mut r.pump,
        &mut r.cylinder,
        &mut r.absorber,
    );
    for x in [
        &mut m.r_s_ohm,
        &mut m.l_d_h,
        &mut m.l_q_h,
        &mut m.psi_f_wb,
        &mut sh.motor_inertia_kg_m2,
        &mut sh.pump_inertia_kg_m2,
        &mut sh.viscous_nm_s,
        &mut p.displacement_m3_per_rev,
        &mut p.internal_leakage_m3_s_pa,
        &mut p.external_leakage_m3_s_pa,
        &mut c.internal_leakage_m3_s_pa,
        &mut c.chamber_a_volume_m3,
        &mut c.chamber_b_volume_m3,
        &mut c.mass_kg,
        &mut r.oil.bulk_modulus_pa,
        &mut a.shell_volume_m3,
        &mut a.precharge_pa,
    ] {
        *x = s.tolerance(*x);
    }
    let sn = &mut r.sensors;
    sn.current.noise_a_rms *= s.uniform(0.7, 1.5);
    sn.pressure.noise_pa_rms *= s.uniform(0.7, 1.5);
    r
}

/// A bench of the nominal design built within its tolerances ([`tolerance_rig`]), drawn
/// from a stream of its own seeded with `seed`: the fleet generator's drives.
pub fn seeded_tolerance_rig(seed: u64) -> Rig {
    tolerance_rig(&mut Stream(Xoshiro256PlusPlus::seed_from_u64(seed)))
}

/// Total leakage conductance out of the high-pressure port of the nominal rig: pump
/// internal and external, cylinder cross-piston. [(m³/s)/Pa]
fn nominal_total_leakage() -> f64 {
    let r = Rig::nominal();
    r.pump.internal_leakage_m3_s_pa
        + r.pump.external_leakage_m3_s_pa
        + r.cylinder.internal_leakage_m3_s_pa
}

/// The effect `name` with parameters drawn from realistic ranges: each clearly beyond the
/// ±3 % tolerances of [`tolerance_rig`] and, in the scenarios [`scenarios_for`] offers,
/// above the sensor noise (measured by `signature` and the suite's generator test).
/// `round` is the coverage round of a covered seed (0 or 1), `None` for a freely drawn one:
/// it makes the two covered absorber seeds one gas loss and one overcharge.
fn draw_effect(name: &str, s: &mut Stream, round: Option<u64>) -> Effect {
    let nominal = Rig::nominal();
    match name {
        // Port-plate timing and oil compression in the bores make a real pump's ripple
        // larger than the kinematic one; between 1× and 3× kinematic is the measured spread
        // of axial piston pumps. 7 or 9 pistons are the usual odd counts.
        "piston_ripple" => {
            let z = s.pick(&[7u32, 9]);
            let k = kinematic_ripple_ratio(z);
            Effect::PistonRipple {
                pistons: z,
                amplitude_ratio: s.uniform(k, 3.0 * k),
            }
        }
        // Slotting torque of a small servo motor: 0.03–0.15 N·m is 1–5 % of its rated
        // torque (≈ 3 N·m), the range of motors without skew; order LCM(9, 8) = 72 for the
        // rig's 9-slot/8-pole motor, with any phase against the encoder's zero.
        "cogging_torque" => Effect::CoggingTorque {
            amplitude_nm: s.uniform(0.03, 0.15),
            order: nominal.motor.cogging_fundamental_order(),
            phase_rad: s.uniform(0.0, TAU),
        },
        // Non-sinusoidal back-EMF of surface magnets: 2–8 % 6th-harmonic torque ripple.
        "flux_harmonics" => Effect::FluxHarmonics {
            t6_ratio: s.uniform(0.02, 0.08),
            phase_rad: s.uniform(0.0, TAU),
        },
        // IGBT/MOSFET bridges of this size need 0.5–3 µs of dead time.
        "dead_time" => Effect::DeadTime {
            dead_time_s: s.uniform(0.5e-6, 3e-6),
        },
        // Seal and bearing drag of motor and pump: 0.05–0.3 N·m is 2–10 % of the 5 MPa
        // holding torque D_p/(2π)·p ≈ 1.2 N·m; breakaway 1.2–1.6× Coulomb (Stribeck).
        "shaft_friction" => {
            let coulomb = s.uniform(0.05, 0.3);
            Effect::ShaftFriction {
                coulomb_nm: coulomb,
                static_nm: coulomb * s.uniform(1.2, 1.6),
            }
        }
        // Worn or over-tightened rod seals: 200–2000 N on top of Table 2's 15 N, i.e.
        // 28–280 kPa of port pressure over the 71 cm² piston; breakaway 1.2–1.6× Coulomb.
        "cylinder_friction" => {
            let coulomb = s.uniform(200.0, 2000.0);
            Effect::CylinderFriction {
                coulomb_n: coulomb,
                static_n: coulomb * s.uniform(1.2, 1.6),
            }
        }
        // A worn pump (scored port plate, slipper wear) leaks 1–4× the rig's whole
        // leakage again; ±3 % tolerance on the nominal leakages is 30× smaller.
        "extra_leakage" => Effect::ExtraLeakage {
            coefficient_m3_s_pa: nominal_total_leakage() * s.uniform(1.0, 4.0),
        },
        // Undissolved air of 0.1–1 % by volume takes the effective bulk modulus of oil down
        // to 25–60 % of the rig file's value at these pressures.
        "entrained_air" => Effect::EntrainedAir {
            effective_bulk_modulus_pa: nominal.oil.bulk_modulus_pa * s.uniform(0.25, 0.6),
        },
        // Gas loss through the bladder (the common fault): 40–75 % of the nominal
        // precharge; or, one time in three, a bladder charged too high: 130–160 %.
        "accumulator_precharge" => {
            let gas_loss = match round {
                Some(r) => r % 2 == 0,
                None => s.unit() < 2.0 / 3.0,
            };
            let f = if gas_loss {
                s.uniform(0.4, 0.75)
            } else {
                s.uniform(1.3, 1.6)
            };
            Effect::AccumulatorPrecharge {
                precharge_pa: nominal.absorber.precharge_pa * f,
            }
        }
        // A transducer with a damping orifice or a long, compliant sensing line: 2–20 ms.
        "pressure_sensor_lag" => Effect::PressureSensorLag {
            time_constant_s: s.uniform(2e-3, 20e-3),
        },
        // Shunt-amplifier offset drift: 0.2–1 A, either sign (0.2–1 % of the 100 A range).
        "current_sensor_offset" => Effect::CurrentSensorOffset {
            offset_a: s.sign() * s.uniform(0.2, 1.0),
        },
        _ => Effect::None,
    }
}

/// Scenarios that excite `effect` (names of `closed_loop::SCENARIOS`), chosen from the
/// signature table (effect at the weak end of its range, RMS over the second half of the
/// log against the sensor noise; see the crate's `blind_probe` example):
/// - motor-side torque effects need torque variation the speed loop cannot hide: cogging in
///   the paper's low-speed holding (q-current ratio 1.1 at 0.03 N·m, the holding loop's own
///   quantisation limit cycle is 0.55), flux harmonics while the shaft turns under load
///   (speed step, slow stroke: 1.4–1.7);
/// - dead time distorts the commanded voltage most at low current and speed (holding:
///   u_q ratio 18 at 0.5 µs; speed step 1.9);
/// - shaft friction, a torque offset, needs the shaft to start and run (speed step, slow
///   stroke: i_q ratio 2.5);
/// - cylinder friction and entrained air need a moving payload (speed step, slow stroke:
///   pressure ratio 19–23 and 4–18);
/// - extra leakage shows in the pump speed that replaces it at pressure (holding ratio 21,
///   step 140);
/// - the absorber's precharge only matters where the pressure crosses it (pressure step:
///   ratio 170–380; below precharge, in the free-payload scenarios, it is exactly 0);
/// - the transducer lag needs fast pressure changes (the payload's hydraulic resonance
///   after a speed step: ratio 6.2 at 2 ms);
/// - a current offset gives a first-electrical-harmonic torque whenever current flows;
/// - piston ripple's torque, D/2π·(s(θ) − 1)·Δp, needs pressure: in the holding it is a
///   line at order 2z in the q current, 0.2–0.5× the current's noise per sample at 1–3×
///   kinematic (see [`BELOW_NOISE`]). Elsewhere the payload is free and Δp a few kPa; the
///   flow ripple against the chambers' oil is a few hundred pascals. Measured with
///   [`angle_locked_fit_bound`] (the blind suite's
///   `piston_ripple_shows_most_where_the_generator_puts_it`): the holding's q current is
///   the only place where a model of it can gain anything.
pub fn scenarios_for(effect: &str) -> &'static [&'static str] {
    match effect {
        "piston_ripple" => &["pressure-hold"],
        "cogging_torque" => &["pressure-hold"],
        "flux_harmonics" => &["speed-step", "slow-stroke"],
        "dead_time" => &["pressure-hold", "speed-step"],
        "shaft_friction" => &["speed-step", "slow-stroke"],
        "cylinder_friction" => &["speed-step", "slow-stroke"],
        "extra_leakage" => &["pressure-hold", "pressure-step"],
        "entrained_air" => &["speed-step", "slow-stroke"],
        "accumulator_precharge" => &["pressure-step"],
        "pressure_sensor_lag" => &["speed-step"],
        "current_sensor_offset" => &["pressure-hold", "speed-step", "slow-stroke"],
        _ => &[
            "pressure-hold",
            "pressure-step",
            "speed-step",
            "slow-stroke",
        ],
    }
}

/// Effects whose signature at realistic values is not above the sensor noise in any
/// scenario (measured; see [`scenarios_for`]): kept in the suite, since the catalogue has
/// them, but the generator's own range check cannot hold for them. Piston ripple of 1–3×
/// kinematic in the holding is a coherent line in the q current at 0.2–0.5× its noise
/// per sample (a 0.01–0.03 N·m torque at 5 MPa): a model that has it exactly can gain
/// 10 points of fit on some logs and not on others ([`ripple_fit_bound`]).
pub const BELOW_NOISE: [&str; 1] = ["piston_ripple"];

/// Parameters no drawn scenario makes observable, as (effect, parameter): the shaft's
/// breakaway torque. The shaft only sticks before the first command, and the speed loop's
/// current step passes any breakaway level within one current-loop period: the noise-free
/// logs of Coulomb 0.15 N·m with breakaway 0.24 N·m and with breakaway 0.15 N·m differ by
/// 0.65× (speed step) and 1.01× (slow stroke) the noise on the speed, the same as the
/// quantisation floor a 0.3 mN·m torque change leaves (0.88–1.11× and 1.16–1.20×), and
/// not at all in the holding (the shaft never stops). The suite reports them but does not
/// hold the diagnosis to them.
pub const UNOBSERVABLE_PARAMETERS: [(&str, &str); 1] = [("shaft_friction", "static_nm")];

/// The logged column where `effect` shows most (from the same table): the q voltage for
/// dead time when the voltages are logged, else the q current it disturbs.
pub fn signal_for(effect: &str, voltages: bool) -> Signal {
    match effect {
        "piston_ripple" | "cogging_torque" | "flux_harmonics" | "shaft_friction" => Signal::Iq,
        "current_sensor_offset" => Signal::Iq,
        "dead_time" if voltages => Signal::Uq,
        "dead_time" => Signal::Iq,
        "extra_leakage" => Signal::Speed,
        _ => Signal::Pressure,
    }
}

/// The optional columns without which `effect` cannot be seen in `scenario`: a moving
/// piston's position for every effect of the pressure's volume balance and of the piston's
/// force balance (without it the pump's largest flow is unknown), and the low side's
/// pressure for the piston's friction. The generator never drops
/// them for such a draw; the false-alarm set drops them freely.
fn needed_columns(effect: &str, scenario: &Scenario) -> &'static [&'static str] {
    let hydraulic = matches!(
        effect,
        "extra_leakage"
            | "entrained_air"
            | "accumulator_precharge"
            | "pressure_sensor_lag"
            | "cylinder_friction"
    );
    match (effect, scenario.blocked) {
        // Along a one-way stroke the Coulomb force and an unknown fill pressure are the same
        // constant pressure step: the low side must be logged to tell them apart.
        ("cylinder_friction", false) => &["x_m", "p_low_pa"],
        (_, false) if hydraulic => &["x_m"],
        _ => &[],
    }
}

/// Draws everything for `seed`.
pub fn draw(seed: u64) -> Draw {
    let mut s = Stream(Xoshiro256PlusPlus::seed_from_u64(seed));
    let n = EFFECT_NAMES.len() as u64;
    let (effect_name, round) = if NOTHING_HIDDEN_SEEDS.contains(&seed) {
        ("none", None)
    } else if seed < COVERED_SEEDS {
        (EFFECT_NAMES[(seed % n) as usize], Some(seed / n))
    } else {
        (s.pick(&EFFECT_NAMES), None)
    };
    let mut tolerance_rig = tolerance_rig(&mut s);
    let effect = draw_effect(effect_name, &mut s, round);
    let scenario_name = s.pick(scenarios_for(effect_name));
    let mut scenario = *by_name(scenario_name).unwrap_or(&closed_loop::SCENARIOS[0]);
    // Vary the length: the diagnosis must not rely on one log length; each scenario runs
    // a few times its demonstration length, as a bench recording does (seconds of steady
    // holding or running, not one second).
    scenario.duration_s *= match scenario.name {
        "speed-step" => s.uniform(3.0, 5.0),
        "pressure-hold" => s.uniform(2.0, 3.5),
        // Its 4 s barely cover the fill of an absorber that lost its gas, and the
        // validation half must still see the fill's end.
        "pressure-step" => s.uniform(1.0, 1.25),
        _ => s.uniform(1.5, 2.0),
    };
    let noise_seed = s.0.next_u64();
    let token = s.0.next_u64();
    let structure = structure::draw_structure(&mut s, needed_columns(effect_name, &scenario));
    structure.apply(&mut tolerance_rig);
    let voltages = !structure.dropped.contains(&"uq_v");
    let parameters = effect.parameters().into_iter().flatten().collect();
    Draw {
        truth: Truth {
            effect_name,
            parameters,
            scenario: scenario.name,
            duration_s: scenario.duration_s,
            signal: signal_for(effect_name, voltages).name(),
        },
        effect,
        tolerance_rig,
        structure,
        scenario,
        noise_seed,
        token,
    }
}

/// Runs `plant_rig` through `scenario` under the controller of the nominal rig tuned by
/// `controller`, with sensor noise `noise_seed`, logged at [`LOG_RATE_HZ`]; the log's only
/// metadata is its source.
pub fn simulate(
    plant_rig: &Rig,
    controller: &ControllerVariant,
    scenario: &Scenario,
    noise_seed: u64,
) -> Result<BenchLog, String> {
    let opt = RunOptions {
        duration_s: scenario.duration_s,
        log_rate_hz: LOG_RATE_HZ,
        seed: noise_seed,
        progress: false,
        metadata: vec![("source".into(), "blind-suite".into())],
        compensation: None,
    };
    let config = controller.apply(&controller_config(&Rig::nominal()));
    Ok(run_with_config(plant_rig, &config, scenario, &opt)?.log)
}

/// Generates the log of `seed` into `dir`: returns its path and the truth.
pub fn generate(seed: u64, dir: &Path) -> Result<(PathBuf, Truth), String> {
    let d = draw(seed);
    let mut log = d.run(&d.truth_rig(), d.noise_seed)?;
    d.structure.drop_columns(&mut log);
    let path = dir.join(format!("blind-{:016x}.csv", d.token));
    bench_log::write(&path, &log).map_err(|e| e.to_string())?;
    Ok((path, d.truth))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The ranges of the brief, as (parameter, low, high) in SI; the nominal rig's
    /// total leakage is 3e-13 (m³/s)/Pa, its bulk modulus 6.5e8 Pa, its precharge 3 MPa.
    fn in_range(name: &str, v: f64) -> bool {
        let (lo, hi) = match name {
            "amplitude_nm" => (0.03, 0.15),
            "order" => (72.0, 72.0),
            "phase_rad" => (0.0, TAU),
            "t6_ratio" => (0.02, 0.08),
            "dead_time_s" => (0.5e-6, 3e-6),
            "coulomb_nm" => (0.05, 0.3),
            "static_nm" => (0.06, 0.48),
            "coulomb_n" => (200.0, 2000.0),
            "static_n" => (240.0, 3200.0),
            "coefficient_m3_s_pa" => (3e-13, 12e-13),
            "effective_bulk_modulus_pa" => (0.25 * 6.5e8, 0.6 * 6.5e8),
            "time_constant_s" => (2e-3, 20e-3),
            _ => return false,
        };
        (lo * (1.0 - 1e-12)..=hi * (1.0 + 1e-12)).contains(&v)
    }

    #[test]
    fn draws_stay_in_their_ranges_and_tolerances() {
        let nominal = Rig::nominal();
        for seed in 0..SUITE_SEEDS {
            let d = draw(seed);
            let r = &d.tolerance_rig;
            for (v, n) in [
                (r.motor.r_s_ohm, nominal.motor.r_s_ohm),
                (r.motor.psi_f_wb, nominal.motor.psi_f_wb),
                (
                    r.pump.displacement_m3_per_rev,
                    nominal.pump.displacement_m3_per_rev,
                ),
                (r.oil.bulk_modulus_pa, nominal.oil.bulk_modulus_pa),
                (r.absorber.precharge_pa, nominal.absorber.precharge_pa),
                (r.cylinder.mass_kg, nominal.cylinder.mass_kg),
            ] {
                assert!((v / n - 1.0).abs() <= 0.03, "seed {seed}: {v} vs {n}");
                assert_ne!(v, n, "seed {seed}: a tolerance left at its nominal value");
            }
            let t = &d.truth;
            for (name, v) in &t.parameters {
                let ok = match (t.effect_name, *name) {
                    ("piston_ripple", "pistons") => *v == 7.0 || *v == 9.0,
                    // Kinematic (π/2z)·tan(π/4z): 1.527 % for 9 pistons, 2.53 % for 7.
                    ("piston_ripple", "amplitude_ratio") => (0.0152..=0.0760).contains(v),
                    ("accumulator_precharge", "precharge_pa") => {
                        (1.2e6..=2.25e6).contains(v) || (3.9e6..=4.8e6).contains(v)
                    }
                    ("current_sensor_offset", "offset_a") => (0.2..=1.0).contains(&v.abs()),
                    _ => in_range(name, *v),
                };
                assert!(ok, "seed {seed}: {} {name} = {v}", t.effect_name);
            }
            assert!(scenarios_for(t.effect_name).contains(&t.scenario));
        }
    }
}
