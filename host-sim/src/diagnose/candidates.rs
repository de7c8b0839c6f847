//! The catalogue's effects (`shared/contracts/effects.md`) as candidate explanations: which
//! subsystem replay each shows in, how its parameters are searched, and how large it must
//! be to count as a fault rather than the rig's ordinary tolerances.
//!
//! Each candidate maps a search vector `u` (unbounded, about unit scale) to the effect's
//! parameters, so one optimiser serves them all: positive quantities are searched in
//! logarithm (their plausible ranges span decades), signed ones linearly, phases as angles.
//!
//! The last coordinates are tolerances, not faults: the scales of the quantities that
//! couple the subsystem's input to its output (the pump's displacement and the absorber's
//! gas volume for the hydraulics, the magnet flux, i.e. the torque constant, for the
//! motor), within a few percent of the rig file ([`TOLERANCE_STEP`] per unit, clamped to ±[`TOLERANCE_LIMIT`] units). A real rig is
//! never exactly its rig file; without this coordinate a Coulomb friction would absorb a 3 %
//! torque-constant error and an air content a 3 % displacement error, and be named. The
//! `none` candidate fits only this coordinate: the nominal model within its tolerances.

use super::predict::Predictor;
use plant_model::pump::kinematic_ripple_ratio;
use plant_model::{Effect, Rig};
use std::f64::consts::PI;

/// Relative change of the tolerance scale per search unit. [1]
pub const TOLERANCE_STEP: f64 = 0.02;

/// Largest tolerance excursion, in search units (±5 %). [1]
pub const TOLERANCE_LIMIT: f64 = 2.5;

/// Tolerance coordinates of a predictor's candidates.
pub fn tolerance_dims(p: Predictor) -> usize {
    match p {
        Predictor::Hydraulics | Predictor::Cylinder => 2,
        Predictor::Motor | Predictor::InnerLoops | Predictor::PressureLoop => 1,
        Predictor::Electrical => 0,
    }
}

/// One candidate effect with its search space.
#[derive(Clone, Debug, PartialEq)]
pub struct Candidate {
    /// Effect name (the contract's).
    pub name: &'static str,
    /// The replay it shows in.
    pub predictor: Predictor,
    /// Fixed structure the search does not vary (pistons, cogging order).
    pub structure: Structure,
    /// Start of the search. [search units]
    pub start: Vec<f64>,
    /// A second start the grid is also tried from (the calibrated tolerances of the
    /// predictor's `none` fit); empty when there is none. [search units]
    pub alternative_start: Vec<f64>,
    /// Initial simplex step per search coordinate. [search units]
    pub step: Vec<f64>,
    /// Coarse grid over the first coordinate, tried before the simplex so it starts in the
    /// right basin (pressure and friction responses are far from linear). [search units]
    pub grid: Vec<f64>,
    /// Values of the first tolerance coordinate the grid is also tried at (a second grid
    /// axis, for an effect whose cost valley with that tolerance is too narrow for the
    /// simplex to follow from one of the starts); empty for most. [search units]
    pub tolerance_grid: Vec<f64>,
}

/// The part of a candidate that is chosen, not fitted.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Structure {
    /// Nothing.
    None,
    /// Pump pistons z.
    Pistons(u32),
    /// Cogging order per revolution.
    Order(u32),
}

/// Nominal leakage of the rig's high-pressure side, the scale of `extra_leakage`.
/// [(m³/s)/Pa]
fn nominal_leakage(rig: &Rig) -> f64 {
    rig.pump.internal_leakage_m3_s_pa + rig.pump.external_leakage_m3_s_pa
}

impl Candidate {
    /// The tolerance scales at `u`, last coordinates (1 where there is none). [1]
    pub fn tolerance_scales(&self, u: &[f64]) -> [f64; 2] {
        let dims = tolerance_dims(self.predictor);
        let mut k = [1.0; 2];
        for (j, t) in u[u.len().saturating_sub(dims)..].iter().enumerate() {
            k[j] = (TOLERANCE_STEP * t.clamp(-TOLERANCE_LIMIT, TOLERANCE_LIMIT)).exp();
        }
        k
    }

    /// The rig at search point `u`: `nominal` with the tolerance scales and the effect.
    pub fn rig_at(&self, u: &[f64], nominal: &Rig) -> Rig {
        let mut rig = nominal.clone();
        let [k0, k1] = self.tolerance_scales(u);
        match self.predictor {
            Predictor::Hydraulics | Predictor::Cylinder => {
                rig.pump.displacement_m3_per_rev *= k0;
                rig.absorber.shell_volume_m3 *= k1;
            }
            Predictor::Motor | Predictor::InnerLoops => rig.motor.psi_f_wb *= k0,
            // The pump speed that replaces a flow scales with 1/displacement.
            Predictor::PressureLoop => rig.pump.displacement_m3_per_rev *= k0,
            Predictor::Electrical => {}
        }
        self.effect(u, nominal).apply(&mut rig);
        rig
    }

    /// The effect at search point `u` on `rig`.
    pub fn effect(&self, u: &[f64], rig: &Rig) -> Effect {
        let g = |k: usize| u.get(k).copied().unwrap_or(0.0);
        match self.name {
            "piston_ripple" => {
                let z = match self.structure {
                    Structure::Pistons(z) => z,
                    _ => rig.pump.pistons,
                };
                Effect::PistonRipple {
                    pistons: z,
                    amplitude_ratio: (kinematic_ripple_ratio(z) * g(0).exp()).min(0.9),
                }
            }
            "cogging_torque" => Effect::CoggingTorque {
                amplitude_nm: 0.05 * g(0).exp(),
                order: match self.structure {
                    Structure::Order(k) => k,
                    _ => 0,
                },
                phase_rad: wrap_pi(g(1)),
            },
            "flux_harmonics" => Effect::FluxHarmonics {
                t6_ratio: 0.02 * g(0).exp(),
                phase_rad: wrap_pi(g(1)),
            },
            "dead_time" => Effect::DeadTime {
                dead_time_s: 1e-6 * g(0).exp(),
            },
            "shaft_friction" => {
                let c = 0.05 * g(0).exp();
                Effect::ShaftFriction {
                    coulomb_nm: c,
                    static_nm: c * (1.0 + g(1).exp()),
                }
            }
            "cylinder_friction" => {
                let c = 300.0 * g(0).exp();
                Effect::CylinderFriction {
                    coulomb_n: c,
                    static_n: c * (1.0 + g(1).exp()),
                }
            }
            "extra_leakage" => Effect::ExtraLeakage {
                coefficient_m3_s_pa: nominal_leakage(rig) * g(0).exp(),
            },
            "entrained_air" => Effect::EntrainedAir {
                effective_bulk_modulus_pa: rig.oil.bulk_modulus_pa / (1.0 + g(0).exp()),
            },
            "accumulator_precharge" => Effect::AccumulatorPrecharge {
                precharge_pa: rig.absorber.precharge_pa * g(0).exp(),
            },
            "pressure_sensor_lag" => Effect::PressureSensorLag {
                time_constant_s: 5e-3 * g(0).exp(),
            },
            "current_sensor_offset" => Effect::CurrentSensorOffset {
                offset_a: 0.5 * g(0),
            },
            _ => Effect::None,
        }
    }

    /// The current-sensor offset the motor replay must assume at `u`. [A]
    pub fn phase_a_offset_a(&self, u: &[f64]) -> f64 {
        if self.name == "current_sensor_offset" {
            0.5 * u.first().copied().unwrap_or(0.0)
        } else {
            0.0
        }
    }

    /// Whether the effect at `u` is beyond what the rig's ordinary tolerances (a few percent
    /// on every parameter) can produce, i.e. a fault worth naming, and physically plausible.
    /// The thresholds are detection limits: the largest value the diagnosis fits on logs of
    /// rigs with only tolerances (the blind suite's `none` seeds, ±3 % on every parameter)
    /// is below them — e.g. shaft Coulomb friction up to 0.073 N·m, absorbed from start-up
    /// transients of a speed step. A first-order lag beyond 50 ms is no transducer's: a fit
    /// that long is absorbing a slow model error.
    pub fn is_significant(&self, u: &[f64], rig: &Rig) -> bool {
        match self.effect(u, rig) {
            Effect::PistonRipple {
                amplitude_ratio, ..
            } => amplitude_ratio > 0.003,
            Effect::CoggingTorque { amplitude_nm, .. } => amplitude_nm > 0.01,
            Effect::FluxHarmonics { t6_ratio, .. } => t6_ratio > 0.008,
            Effect::DeadTime { dead_time_s } => dead_time_s > 0.2e-6,
            Effect::ShaftFriction { coulomb_nm, .. } => coulomb_nm > 0.08,
            Effect::CylinderFriction { coulomb_n, .. } => coulomb_n > 100.0,
            Effect::ExtraLeakage {
                coefficient_m3_s_pa,
            } => coefficient_m3_s_pa > 0.3 * nominal_leakage(rig),
            Effect::EntrainedAir {
                effective_bulk_modulus_pa,
            } => effective_bulk_modulus_pa < 0.85 * rig.oil.bulk_modulus_pa,
            Effect::AccumulatorPrecharge { precharge_pa } => {
                (precharge_pa / rig.absorber.precharge_pa).ln().abs() > 0.15
            }
            Effect::PressureSensorLag { time_constant_s } => {
                time_constant_s > 1e-3 && time_constant_s < 0.05
            }
            Effect::CurrentSensorOffset { offset_a } => offset_a.abs() > 0.08,
            Effect::None => false,
        }
    }

    /// Whether `u` lies in the physically plausible range of the effect (the fit's search
    /// space: outside it the cost is infinite, so an effect cannot stretch to an absurd
    /// value to absorb a model error of another kind). The ranges are generous: a worn pump
    /// leaks at most some twenty times its rig-file leakage, entrained air lowers the bulk
    /// modulus at most twentyfold, breakaway friction is at most three times Coulomb's, a
    /// transducer lags at most 0.1 s.
    pub fn is_plausible(&self, u: &[f64], rig: &Rig) -> bool {
        let breakaway_ok = |c: f64, s: f64| s <= 3.0 * c + 1e-12;
        match self.effect(u, rig) {
            Effect::PistonRipple {
                amplitude_ratio, ..
            } => amplitude_ratio <= 0.5,
            Effect::CoggingTorque { amplitude_nm, .. } => amplitude_nm <= 1.0,
            Effect::FluxHarmonics { t6_ratio, .. } => t6_ratio <= 0.3,
            Effect::DeadTime { dead_time_s } => dead_time_s <= 10e-6,
            Effect::ShaftFriction {
                coulomb_nm,
                static_nm,
            } => coulomb_nm <= 2.0 && breakaway_ok(coulomb_nm, static_nm),
            Effect::CylinderFriction {
                coulomb_n,
                static_n,
            } => coulomb_n <= 10e3 && breakaway_ok(coulomb_n, static_n),
            Effect::ExtraLeakage {
                coefficient_m3_s_pa,
            } => coefficient_m3_s_pa <= 20.0 * nominal_leakage(rig),
            Effect::EntrainedAir {
                effective_bulk_modulus_pa,
            } => effective_bulk_modulus_pa >= 0.05 * rig.oil.bulk_modulus_pa,
            Effect::AccumulatorPrecharge { precharge_pa } => {
                (precharge_pa / rig.absorber.precharge_pa).ln().abs() <= 2.3
            }
            Effect::PressureSensorLag { time_constant_s } => time_constant_s <= 0.1,
            Effect::CurrentSensorOffset { offset_a } => offset_a.abs() <= 3.0,
            Effect::None => true,
        }
    }

    /// The fitted parameters by the catalogue's names (SI).
    pub fn parameters(&self, u: &[f64], rig: &Rig) -> Vec<(&'static str, f64)> {
        let mut e = self.effect(u, rig);
        // The catalogue's cogging order 0 means "the rig's"; report the number.
        if let Effect::CoggingTorque { order, .. } = &mut e {
            if *order == 0 {
                *order = rig.motor.cogging_fundamental_order();
            }
        }
        e.parameters().into_iter().flatten().collect()
    }
}

/// Wraps an angle to (−π, π]. [rad]
pub fn wrap_pi(a: f64) -> f64 {
    let w = (a + PI).rem_euclid(2.0 * PI) - PI;
    if w <= -PI {
        w + 2.0 * PI
    } else {
        w
    }
}

fn log_grid(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|k| lo + (hi - lo) * k as f64 / (n - 1).max(1) as f64)
        .collect()
}

/// The usual odd piston counts of axial piston pumps, the ones the diagnosis tries.
pub const RIPPLE_PISTONS: [u32; 3] = [7, 9, 11];

/// Every candidate the log can show, given the predictors it supports (`predictors`),
/// whether it logs the shaft angle, the orders the residual spectrum points at
/// (`cogging_orders`; the rig's slot/pole order when empty) and the piston counts whose
/// ripple order it shows (`ripple_pistons`). Every predictor with tolerance
/// coordinates gets its `none`, the nominal model within those tolerances; the angle-locked
/// torque effects are fitted on the inner loops when they can be replayed, else on the
/// motor replay.
pub fn candidates(
    rig: &Rig,
    predictors: &[Predictor],
    has_angle: bool,
    cogging_orders: &[u32],
    ripple_pistons: &[u32],
) -> Vec<Candidate> {
    let supports = |p: Predictor| predictors.contains(&p);
    let ripple = if supports(Predictor::InnerLoops) {
        Predictor::InnerLoops
    } else {
        Predictor::Motor
    };
    let one = |name, predictor: Predictor, grid: Vec<f64>, dims: usize| {
        let tolerance = tolerance_dims(predictor);
        let mut step = vec![0.5; dims];
        step.extend(std::iter::repeat_n(1.0, tolerance));
        Candidate {
            name,
            predictor,
            structure: Structure::None,
            start: vec![0.0; dims + tolerance],
            alternative_start: Vec::new(),
            step,
            grid,
            tolerance_grid: Vec::new(),
        }
    };
    // The nominal model within its tolerances, per predictor (tolerance coordinates only;
    // its grid runs over the first).
    let mut out: Vec<Candidate> = predictors
        .iter()
        .filter(|p| tolerance_dims(**p) > 0)
        .map(|p| one("none", *p, log_grid(-2.0, 2.0, 5), 0))
        .collect();
    out.extend([
        // Search units: ln(coefficient / nominal leakage), from 1/20 to 20 times nominal.
        one(
            "extra_leakage",
            Predictor::Hydraulics,
            log_grid(-3.0, 3.0, 7),
            1,
        ),
        // ln(β_nom/β − 1): β from 95 % down to 5 % of nominal. Half-unit steps, and at
        // every whole unit of the displacement tolerance: the cost valley between the bulk
        // modulus and the displacement is narrow and curved (in a slow stroke 2 % of
        // displacement changes the squared error sixty-fold), and from a whole-unit grid at
        // the two starts the simplex stopped tens of percent off or not at all.
        Candidate {
            tolerance_grid: log_grid(-2.0, 2.0, 5),
            ..one(
                "entrained_air",
                Predictor::Hydraulics,
                log_grid(-3.0, 3.0, 13),
                1,
            )
        },
        // ln(p0/p0_nom): a fifth to five times nominal.
        one(
            "accumulator_precharge",
            Predictor::Hydraulics,
            log_grid(-1.6, 1.6, 9),
            1,
        ),
        // ln(τ/5 ms): 0.25 ms to 100 ms.
        one(
            "pressure_sensor_lag",
            Predictor::Hydraulics,
            log_grid(-3.0, 3.0, 7),
            1,
        ),
        // ln(T_c/0.05 N·m), ln(T_s/T_c − 1).
        one(
            "shaft_friction",
            Predictor::Motor,
            log_grid(-2.5, 2.5, 6),
            2,
        ),
    ]);
    if supports(Predictor::PressureLoop) {
        out.push(one(
            "extra_leakage",
            Predictor::PressureLoop,
            log_grid(-3.0, 3.0, 7),
            1,
        ));
    }
    if supports(Predictor::Cylinder) {
        // ln(F_c/300 N): 25 N to 5 kN.
        out.push(one(
            "cylinder_friction",
            Predictor::Cylinder,
            log_grid(-2.5, 2.8, 7),
            2,
        ));
    }
    if has_angle {
        out.push(one(
            "dead_time",
            Predictor::Electrical,
            log_grid(-3.0, 1.6, 7),
            1,
        ));
        // Offset / 0.5 A, both signs up to 2 A.
        out.push(one(
            "current_sensor_offset",
            ripple,
            vec![-4.0, -2.0, -1.0, -0.4, 0.4, 1.0, 2.0, 4.0],
            1,
        ));
        // ln(T6/0.02), phase: the grid is over the phase at a mid amplitude; the simplex
        // then moves both.
        let mut flux = one("flux_harmonics", ripple, Vec::new(), 2);
        flux.grid = log_grid(-PI, PI * 0.75, 8);
        out.push(flux);
        let orders: Vec<u32> = if cogging_orders.is_empty() {
            vec![rig.motor.cogging_fundamental_order()]
        } else {
            cogging_orders.to_vec()
        };
        for k in orders {
            let mut c = one("cogging_torque", ripple, Vec::new(), 2);
            c.structure = Structure::Order(k);
            c.grid = log_grid(-PI, PI * 0.75, 8);
            out.push(c);
        }
        // The flow ripple on the hydraulics whatever the spectrum; the torque ripple where
        // the spectrum shows its line, on the loops' answer to it.
        let ripple_at = |z: u32, predictor, grid| {
            let mut c = one("piston_ripple", predictor, grid, 1);
            c.structure = Structure::Pistons(z);
            c
        };
        out.extend(
            RIPPLE_PISTONS
                .iter()
                .map(|&z| ripple_at(z, Predictor::Hydraulics, log_grid(-1.0, 1.5, 6))),
        );
        if supports(Predictor::InnerLoops) {
            out.extend(
                ripple_pistons
                    .iter()
                    .map(|&z| ripple_at(z, Predictor::InnerLoops, log_grid(-1.0, 2.5, 8))),
            );
        }
    }
    out
}

/// Whether a candidate's grid runs over the phase (second coordinate) rather than the
/// magnitude.
pub fn grid_is_phase(c: &Candidate) -> bool {
    matches!(c.name, "cogging_torque" | "flux_harmonics")
}
