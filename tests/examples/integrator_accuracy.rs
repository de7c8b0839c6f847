//! The plant's integrators against RK4 at a quarter of the PWM period on the closed loop's
//! own duties (see `tests::integrator_accuracy`): the table of `docs/plant-model.md`.
//!
//! ```text
//! cargo run --release -p tests --example integrator_accuracy
//! ```

use plant_model::Integrator;
use tests::integrator_accuracy::{compare, standard_cases};

fn main() {
    let schemes = [Integrator::Exponential, Integrator::Rk4 { substeps: 1 }];
    println!(
        "| case | integrator | p_A [Pa] | ω [rad/s] | θ [rad] | i_abc [A] | p_A/σ | ω/σ | θ/σ | i/σ |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    let mut noise_line = String::new();
    for case in standard_cases() {
        let (devs, noise) = match compare(&case, &schemes) {
            Ok(r) => r,
            Err(e) => {
                eprintln!("integrator_accuracy: {}: {e}", case.label);
                std::process::exit(1);
            }
        };
        for (scheme, d) in schemes.iter().zip(&devs) {
            let r = d.over(&noise);
            println!(
                "| {} | {} | {:.2e} | {:.2e} | {:.2e} | {:.2e} | {:.1e} | {:.1e} | {:.1e} | {:.1e} |",
                case.label,
                scheme.name(),
                d.pressure_pa,
                d.speed_rad_s,
                d.angle_rad,
                d.current_a,
                r[0],
                r[1],
                r[2],
                r[3]
            );
        }
        noise_line = format!(
            "σ (sensor noise rms per PWM sample): p_A {:.0} Pa, ω {:.2} rad/s, θ {:.2e} rad, i {:.4} A",
            noise.pressure_pa, noise.speed_rad_s, noise.angle_rad, noise.current_a
        );
    }
    println!("\n{noise_line}");
}
