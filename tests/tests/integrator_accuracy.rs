//! The exponential integrator stays within a tenth of every compared signal's sensor noise
//! of the reference (RK4 at a quarter of the PWM period) on the closed loop's pressure step,
//! a hold with every effect of the catalogue and a slow stroke, each at full length.

use plant_model::Integrator;
use tests::integrator_accuracy::{compare, standard_cases};

#[test]
fn exponential_integrator_within_a_tenth_of_sensor_noise_of_reference() {
    for case in standard_cases() {
        let (devs, noise) = compare(&case, &[Integrator::Exponential]).unwrap();
        let r = devs[0].over(&noise);
        eprintln!("{}: deviation over noise (p, ω, θ, i) {r:?}", case.label);
        for (name, v) in ["p_A", "ω", "θ", "i_abc"].iter().zip(r) {
            assert!(
                v < 0.1,
                "{}: {name} deviates {v:.2e} of its sensor noise",
                case.label
            );
        }
    }
}
