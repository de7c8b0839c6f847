//! `eha commission`: the firmware's commissioning sequence
//! ([`firmware::commissioning`]) in closed loop on the rig's simulated motor, with the
//! sensors' noise and quantisation on, from a drive configured with the nameplate only
//! ([`closed_loop::commissioning::nameplate_config`]). Prints identified vs true values,
//! the derived current- and speed-loop gains and their margins on the rig
//! ([`margins`]); `--json` writes the contract's object (`shared/contracts/eha-cli.md`).

pub mod margins;

use crate::output::paths::Declared;
use crate::output::{is_stdout, CliError, Outputs};
use crate::values::{positive_f64, show};
use clap::Args;
use closed_loop::commissioning::{commission, nameplate_config};
use firmware::commissioning::CommissioningResult;
use margins::{current_loop, margins, speed_loop, Margins, SpeedPlant};
use plant_model::Rig;
use serde_json::json;
use std::f64::consts::TAU;
use std::fmt::Write as _;
use std::path::PathBuf;

/// `eha commission`.
#[derive(Debug, Args)]
pub struct CommissionArgs {
    /// Current-loop bandwidth to design for. [rad/s]
    #[arg(long, value_name = "RAD_S", default_value = "1100", value_parser = positive_f64, allow_negative_numbers = true)]
    pub bandwidth: f64,
    /// Write the results as JSON (`-`: standard output).
    #[arg(long, value_name = "PATH")]
    pub json: Option<PathBuf>,
}

impl CommissionArgs {
    /// The files it writes.
    pub fn paths(&self) -> Declared<'_> {
        Declared::default().file("--json", self.json.as_ref())
    }
}

/// Seed of the sensor noise (a fixed seed: the same rig gives the same report).
pub const SEED: u64 = 1;

/// The motor quantities commissioning identifies, in the JSON's names and units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Motor {
    /// R_s. [Ω]
    pub r_s: f64,
    /// L_d. [H]
    pub l_d: f64,
    /// L_q. [H]
    pub l_q: f64,
    /// ψ_f. [Wb]
    pub psi_f: f64,
    /// Encoder offset in [0, 2π). [rad]
    pub encoder_offset_rad: f64,
    /// Shaft inertia J. [kg·m²]
    pub j: f64,
}

impl Motor {
    /// The rig's true values.
    pub fn of_rig(rig: &Rig) -> Motor {
        Motor {
            r_s: rig.motor.r_s_ohm,
            l_d: rig.motor.l_d_h,
            l_q: rig.motor.l_q_h,
            psi_f: rig.motor.psi_f_wb,
            encoder_offset_rad: rig.sensors.encoder.offset_rad.rem_euclid(TAU),
            j: rig.shaft.inertia_kg_m2(),
        }
    }

    /// What commissioning identified.
    pub fn of_result(r: &CommissioningResult) -> Motor {
        Motor {
            r_s: r.stator_resistance_ohm as f64,
            l_d: r.d_inductance_h as f64,
            l_q: r.q_inductance_h as f64,
            psi_f: r.flux_linkage_wb as f64,
            encoder_offset_rad: r.encoder_offset_rad as f64,
            j: r.inertia_kg_m2 as f64,
        }
    }

    fn to_json(self) -> serde_json::Value {
        json!({
            "R_s": self.r_s,
            "L_d": self.l_d,
            "L_q": self.l_q,
            "psi_f": self.psi_f,
            "encoder_offset_rad": self.encoder_offset_rad,
            "J": self.j,
        })
    }
}

/// Offset error `identified − truth` wrapped into (−180°, 180°]. [° electrical]
pub fn offset_error_deg(identified: f64, truth: f64) -> f64 {
    let d = identified - truth;
    (d - TAU * (d / TAU).round()).to_degrees()
}

/// Everything `eha commission` reports.
#[derive(Clone, Debug)]
pub struct Report {
    /// Identified values.
    pub identified: Motor,
    /// The rig's values.
    pub truth: Motor,
    /// The firmware's result (gains included).
    pub result: CommissioningResult,
    /// Current-loop margins on the rig's d and q axes.
    pub current_margins: [Margins; 2],
    /// Speed-loop margins on the rig's shaft.
    pub speed_margins: Margins,
    /// Simulated duration of the sequence, current offsets included. [s]
    pub duration_s: f64,
}

impl Report {
    /// The report of a completed sequence on `rig` (PWM period `t_pwm` [s], speed-loop
    /// period `t_speed` [s]).
    pub fn new(
        rig: &Rig,
        result: CommissioningResult,
        duration_s: f64,
        t_pwm: f64,
        t_speed: f64,
    ) -> Report {
        let g = result.current_gains;
        let m = &rig.motor;
        let d = margins(current_loop(
            m.l_d_h,
            m.r_s_ohm,
            g.kp_d as f64,
            g.ki as f64,
            t_pwm,
        ));
        let q = margins(current_loop(
            m.l_q_h,
            m.r_s_ohm,
            g.kp_q as f64,
            g.ki as f64,
            t_pwm,
        ));
        let sg = result.speed_gains;
        let plant = SpeedPlant {
            j: rig.shaft.inertia_kg_m2(),
            b: rig.shaft.viscous_nm_s,
            k_t: rig.motor.torque_constant_nm_per_a(),
            omega_c: g.bandwidth_rad_s as f64,
            t_s: t_speed,
        };
        Report {
            identified: Motor::of_result(&result),
            truth: Motor::of_rig(rig),
            result,
            current_margins: [d, q],
            speed_margins: margins(speed_loop(
                plant,
                sg.kp as f64,
                sg.ki as f64,
                sg.active_damping as f64,
            )),
            duration_s,
        }
    }

    /// The contract's JSON object with the extras.
    pub fn to_json(&self) -> serde_json::Value {
        let (i, t) = (self.identified, self.truth);
        let pct = |a: f64, b: f64| 100.0 * (a - b) / b;
        let g = self.result.current_gains;
        let s = self.result.speed_gains;
        json!({
            "identified": i.to_json(),
            "true": t.to_json(),
            "current_gains": {"kp_d": g.kp_d, "kp_q": g.kp_q, "ki": g.ki},
            "duration_s": self.duration_s,
            "bandwidth_rad_s": g.bandwidth_rad_s,
            "error_percent": {
                "R_s": pct(i.r_s, t.r_s),
                "L_d": pct(i.l_d, t.l_d),
                "L_q": pct(i.l_q, t.l_q),
                "psi_f": pct(i.psi_f, t.psi_f),
                "J": pct(i.j, t.j),
            },
            "encoder_offset_error_deg": offset_error_deg(i.encoder_offset_rad, t.encoder_offset_rad),
            "speed_gains": {"kp": s.kp, "ki": s.ki, "active_damping": s.active_damping},
            "margins": {
                "current_d": self.current_margins[0],
                "current_q": self.current_margins[1],
                "speed": self.speed_margins,
            },
            "seed": SEED,
        })
    }

    /// The table printed on standard output.
    pub fn to_table(&self) -> String {
        let (i, t) = (self.identified, self.truth);
        let mut out = String::from("commissioning on the simulated motor (noise on)\n");
        out.push_str("quantity              true          identified    error\n");
        for (name, unit, scale, a, b) in [
            ("R_s", "Ω", 1.0, i.r_s, t.r_s),
            ("L_d", "mH", 1e3, i.l_d, t.l_d),
            ("L_q", "mH", 1e3, i.l_q, t.l_q),
            ("psi_f", "Wb", 1.0, i.psi_f, t.psi_f),
            ("J", "g·m²", 1e3, i.j, t.j),
        ] {
            let _ = writeln!(
                out,
                "{:<22}{:<14.5}{:<14.5}{:+.2} %",
                format!("{name} [{unit}]"),
                b * scale,
                a * scale,
                100.0 * (a - b) / b
            );
        }
        let _ = writeln!(
            out,
            "{:<22}{:<14.5}{:<14.5}{:+.3}° el",
            "encoder offset [rad]",
            t.encoder_offset_rad,
            i.encoder_offset_rad,
            offset_error_deg(i.encoder_offset_rad, t.encoder_offset_rad)
        );
        let g = self.result.current_gains;
        let s = self.result.speed_gains;
        let [d, q] = self.current_margins;
        let sm = self.speed_margins;
        let _ = writeln!(
            out,
            "current gains at {} rad/s: kp_d {:.4} V/A, kp_q {:.4} V/A, ki {:.2} V/(A·s)",
            g.bandwidth_rad_s, g.kp_d, g.kp_q, g.ki
        );
        for (name, m) in [("current d", d), ("current q", q), ("speed", sm)] {
            let _ = writeln!(
                out,
                "  {name} loop on the rig: crossover {:.1} rad/s, phase margin {:.1}°, gain margin {:.1} dB",
                m.crossover_rad_s, m.phase_margin_deg, m.gain_margin_db
            );
        }
        let _ = writeln!(
            out,
            "speed gains: kp {:.4} A/(rad/s), ki {:.3} A/rad, active damping {} A/(rad/s)",
            s.kp, s.ki, s.active_damping
        );
        let _ = writeln!(
            out,
            "sequence duration: {:.3} s (simulated)",
            self.duration_s
        );
        out
    }
}

/// `eha commission`.
pub fn run_commission(rig: &Rig, args: &CommissionArgs) -> Result<(), CliError> {
    let mut config = nameplate_config(rig);
    // The firmware's bounds on the bandwidth, said in the user's terms before its own
    // validation (which names configuration fields).
    let pwm_hz = config.rates.pwm_hz as f64;
    let most = 0.1 * TAU * pwm_hz;
    let speed_wn = config.commissioning.speed_natural_frequency_rad_s as f64;
    let least = 4.0 * speed_wn;
    if !(least..=most).contains(&args.bandwidth) {
        return Err(CliError::BadInput(format!(
            "--bandwidth {} rad/s: the current loop's bandwidth must lie between {least:.0} \
             rad/s (4× the speed loop's {speed_wn:.1} rad/s natural frequency) and {most:.0} rad/s \
             (a tenth of the {pwm_hz} Hz PWM frequency)",
            show(args.bandwidth)
        )));
    }
    config.commissioning.current_bandwidth_rad_s = args.bandwidth as f32;
    config
        .validate()
        .map_err(|e| CliError::BadInput(format!("--bandwidth {}: {e}", show(args.bandwidth))))?;
    let outcome = commission(rig, &config, SEED).map_err(|e| CliError::BadInput(e.to_string()))?;
    let result = match (outcome.result, outcome.fault) {
        (Some(r), None) => r,
        (_, Some(f)) => {
            return Err(CliError::Failed(format!(
                "commissioning stopped after {:.3} s with {f}",
                outcome.duration_s
            )))
        }
        (None, None) => {
            return Err(CliError::Failed(format!(
                "commissioning did not finish within {} s",
                closed_loop::commissioning::LONGEST_S
            )))
        }
    };
    let report = Report::new(
        rig,
        result,
        outcome.duration_s,
        1.0 / config.rates.pwm_hz as f64,
        1.0 / config.rates.speed_loop_hz as f64,
    );
    let mut out = Outputs::new();
    if let Some(path) = &args.json {
        out.json("--json", path, &report.to_json())?;
    }
    if !args.json.as_deref().is_some_and(is_stdout) {
        out.print(&report.to_table());
    }
    out.commit()
}
