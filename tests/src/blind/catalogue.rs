//! The effects the blind generator hides, and in which combinations: each catalogue effect
//! (`shared/contracts/effects.md`) with its parameters drawn from a realistic range
//! ([`draw_effect`]), the hydraulic and motor-side families a pair is drawn from, and the
//! physics that rules a combination out before any simulation does ([`possible_in`],
//! [`acts_differently`]). Whether a drawn magnitude shows in the log is measured afterwards
//! ([`super::observability::check`]).

use super::stream::Stream;
use super::test_plan::TestKind;
use plant_model::pump::kinematic_ripple_ratio;
use plant_model::{Effect, Rig};
use std::f64::consts::TAU;

/// The hydraulic side: what acts on the oil, the piston or the pressure's measurement.
pub const HYDRAULIC: [&str; 6] = [
    "extra_leakage",
    "entrained_air",
    "accumulator_precharge",
    "pressure_sensor_lag",
    "piston_ripple",
    "cylinder_friction",
];

/// The motor side: what acts on the shaft's torque or the drive's currents and voltages.
pub const MOTOR: [&str; 5] = [
    "cogging_torque",
    "flux_harmonics",
    "dead_time",
    "current_sensor_offset",
    "shaft_friction",
];

/// Whether `effect` can change anything at all in `test`, from physics alone:
/// - the cylinder's friction acts only on a moving piston: strokes only (the pressure
///   tests block the cylinder);
/// - the absorber's precharge only matters where the pressure crosses it: the free
///   payload of a stroke stays at the boost pressure, below every drawn precharge.
///
/// Everything else acts in every test; how much is measured per draw.
pub fn possible_in(effect: &str, test: TestKind) -> bool {
    match effect {
        "cylinder_friction" => test == TestKind::Stroke,
        "accumulator_precharge" => test != TestKind::Stroke,
        _ => true,
    }
}

/// Whether two hydraulic effects act differently enough to be a pair the generator hides:
/// a line in the pump's flow (piston ripple) against anything; a leak (a flow lost in
/// proportion to the pressure) against a compliance or a lag; the piston's friction (a
/// force on the moving payload) against a leak or a compliance. Two compliances (air,
/// the absorber's gas) or a compliance and the transducer's lag shape the same pressure
/// transients and are left out.
pub fn acts_differently(a: &str, b: &str) -> bool {
    let one_way = |x: &str, y: &str| match x {
        "piston_ripple" => y != "piston_ripple",
        "extra_leakage" => matches!(
            y,
            "entrained_air" | "accumulator_precharge" | "pressure_sensor_lag"
        ),
        "cylinder_friction" => matches!(y, "extra_leakage" | "entrained_air"),
        _ => false,
    };
    one_way(a, b) || one_way(b, a)
}

/// Total leakage conductance out of the high-pressure port of the nominal rig: pump
/// internal and external, cylinder cross-piston. [(m³/s)/Pa]
fn nominal_total_leakage() -> f64 {
    let r = Rig::nominal();
    r.pump.internal_leakage_m3_s_pa
        + r.pump.external_leakage_m3_s_pa
        + r.cylinder.internal_leakage_m3_s_pa
}

/// The effect `name` with parameters drawn from realistic ranges, each clearly beyond the
/// ±3 % tolerances of the rig. Whether the drawn value shows in the log is checked apart.
pub(super) fn draw_effect(name: &str, s: &mut Stream) -> Effect {
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
            let f = if s.unit() < 2.0 / 3.0 {
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

/// `e` at half its departure from `rig` (the rig without it): amplitudes, offsets,
/// frictions, leaks and lags halved; the oil's compliance (1/bulk modulus) and the
/// precharge halfway between `rig`'s and the drawn value. An effect's own signature scales with it; a
/// difference that does not is the closed loop taking another path.
pub fn halfway(e: &Effect, rig: &Rig) -> Effect {
    let mid = |own: f64, drawn: f64| 0.5 * (own + drawn);
    match *e {
        Effect::PistonRipple {
            pistons,
            amplitude_ratio,
        } => Effect::PistonRipple {
            pistons,
            amplitude_ratio: 0.5 * amplitude_ratio,
        },
        Effect::CoggingTorque {
            amplitude_nm,
            order,
            phase_rad,
        } => Effect::CoggingTorque {
            amplitude_nm: 0.5 * amplitude_nm,
            order,
            phase_rad,
        },
        Effect::FluxHarmonics {
            t6_ratio,
            phase_rad,
        } => Effect::FluxHarmonics {
            t6_ratio: 0.5 * t6_ratio,
            phase_rad,
        },
        Effect::DeadTime { dead_time_s } => Effect::DeadTime {
            dead_time_s: 0.5 * dead_time_s,
        },
        Effect::ShaftFriction {
            coulomb_nm,
            static_nm,
        } => Effect::ShaftFriction {
            coulomb_nm: 0.5 * coulomb_nm,
            static_nm: 0.5 * static_nm,
        },
        Effect::CylinderFriction {
            coulomb_n,
            static_n,
        } => Effect::CylinderFriction {
            coulomb_n: 0.5 * coulomb_n,
            static_n: 0.5 * static_n,
        },
        Effect::ExtraLeakage {
            coefficient_m3_s_pa,
        } => Effect::ExtraLeakage {
            coefficient_m3_s_pa: 0.5 * coefficient_m3_s_pa,
        },
        // The air adds compliance 1/K: half of it is the harmonic mean of the moduli.
        Effect::EntrainedAir {
            effective_bulk_modulus_pa,
        } => Effect::EntrainedAir {
            effective_bulk_modulus_pa: 1.0
                / mid(
                    1.0 / rig.oil.bulk_modulus_pa,
                    1.0 / effective_bulk_modulus_pa,
                ),
        },
        Effect::AccumulatorPrecharge { precharge_pa } => Effect::AccumulatorPrecharge {
            precharge_pa: mid(rig.absorber.precharge_pa, precharge_pa),
        },
        Effect::PressureSensorLag { time_constant_s } => Effect::PressureSensorLag {
            time_constant_s: 0.5 * time_constant_s,
        },
        Effect::CurrentSensorOffset { offset_a } => Effect::CurrentSensorOffset {
            offset_a: 0.5 * offset_a,
        },
        Effect::None => Effect::None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_families_split_the_catalogue() {
        let mut all: Vec<&str> = HYDRAULIC.iter().chain(&MOTOR).copied().collect();
        all.sort_unstable();
        let mut names: Vec<&str> = plant_model::effects::EFFECT_NAMES
            .iter()
            .copied()
            .filter(|n| *n != "none")
            .collect();
        names.sort_unstable();
        assert_eq!(all, names);
    }

    #[test]
    fn distinct_pairs_are_symmetric_and_never_a_self_pair() {
        for a in HYDRAULIC {
            assert!(!acts_differently(a, a), "{a}");
            for b in HYDRAULIC {
                assert_eq!(acts_differently(a, b), acts_differently(b, a), "{a} {b}");
            }
        }
    }
}
