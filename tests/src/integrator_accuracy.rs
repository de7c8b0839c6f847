//! The plant's integrators against the accuracy reference, on the closed loop's own duties.
//!
//! The reference is classical RK4 at a quarter of the PWM period
//! ([`Integrator::Rk4`] with 4 substeps), run inside the closed loop (controller, sensors,
//! scenario). Each scheme under test runs as a shadow plant: a copy of the reference plant,
//! fed every period the duties and bridge enable the controller gave the reference, and put
//! back onto the reference's state every [`RESYNC_S`] so that what is compared is the
//! integration error over that window, not the loop's sensitivity to it (the controller of a
//! shadowed run would act on different ADC counts and the two runs would part by the noise,
//! not by the integrator).
//!
//! The deviations are the largest over the run of |shadow − reference| for port A's pressure,
//! the shaft's speed and angle and the phase currents, each divided by the noise the drive's
//! own sensor puts on that signal ([`SensorNoise`]): an integration error well under it is
//! one no measurement of the rig could see.

use closed_loop::{controller_config, ClosedLoop, Scenario};
use plant_model::{Effect, Inputs, Integrator, Observables, Plant, Rig};

/// How often the shadows are put back onto the reference's state. [s]
pub const RESYNC_S: f64 = 0.25;

/// The rms noise each compared signal's sensor puts on it at a rig, one sample at the PWM
/// rate: white noise and quantisation q/√12 added in power; the speed's from the encoder's
/// count over one PWM period (two independent quantisation errors: q/√6 over the period).
#[derive(Clone, Copy, Debug)]
pub struct SensorNoise {
    /// Port A's pressure transducer. [Pa]
    pub pressure_pa: f64,
    /// The shaft's speed from the encoder's counts. [rad/s]
    pub speed_rad_s: f64,
    /// The shaft's angle from the encoder. [rad]
    pub angle_rad: f64,
    /// A phase current's shunt channel. [A]
    pub current_a: f64,
}

impl SensorNoise {
    /// The noise of `rig`'s sensors, with the PWM period `period_s`. [s]
    pub fn of(rig: &Rig, period_s: f64) -> SensorNoise {
        let s = &rig.sensors;
        let quantised = |white: f64, lsb: f64| (white * white + lsb * lsb / 12.0).sqrt();
        let count = 2.0 * core::f64::consts::PI / f64::from(s.encoder.counts_per_rev);
        SensorNoise {
            pressure_pa: quantised(s.pressure.noise_pa_rms, s.pressure.pa_per_lsb),
            speed_rad_s: count / 6f64.sqrt() / period_s,
            angle_rad: count / 12f64.sqrt(),
            current_a: quantised(s.current.noise_a_rms, s.current.a_per_lsb),
        }
    }
}

/// The largest deviations of one scheme from the reference over a run, in the signals' units.
#[derive(Clone, Copy, Debug, Default)]
pub struct Deviation {
    /// Port A's pressure. [Pa]
    pub pressure_pa: f64,
    /// The shaft's speed. [rad/s]
    pub speed_rad_s: f64,
    /// The shaft's angle. [rad]
    pub angle_rad: f64,
    /// The largest phase current's. [A]
    pub current_a: f64,
}

impl Deviation {
    /// Each deviation over its sensor's noise: pressure, speed, angle, current. [1]
    pub fn over(&self, noise: &SensorNoise) -> [f64; 4] {
        [
            self.pressure_pa / noise.pressure_pa,
            self.speed_rad_s / noise.speed_rad_s,
            self.angle_rad / noise.angle_rad,
            self.current_a / noise.current_a,
        ]
    }

    fn widen(&mut self, a: &Observables, b: &Observables) {
        let current = (0..3)
            .map(|k| (a.i_abc_a[k] - b.i_abc_a[k]).abs())
            .fold(0.0, f64::max);
        self.pressure_pa = self.pressure_pa.max((a.p_a_pa - b.p_a_pa).abs());
        self.speed_rad_s = self
            .speed_rad_s
            .max((a.omega_m_rad_s - b.omega_m_rad_s).abs());
        self.angle_rad = self.angle_rad.max((a.theta_m_rad - b.theta_m_rad).abs());
        self.current_a = self.current_a.max(current);
    }
}

/// One case of the check: a scenario on the nominal rig with effects, for a duration.
#[derive(Clone, Debug)]
pub struct Case {
    /// What the table calls it.
    pub label: &'static str,
    /// The closed loop's scenario.
    pub scenario: &'static Scenario,
    /// The plant's effects (contract names with parameters).
    pub effects: Vec<&'static str>,
    /// How long it runs. [s]
    pub duration_s: f64,
}

/// The cases of `docs/plant-model.md`'s table, each at its scenario's full length: the
/// pressure step, the hold with every effect of the catalogue on, and the slow stroke with
/// the paper's low-speed effects and both frictions.
pub fn standard_cases() -> Vec<Case> {
    let by = |n| closed_loop::by_name(n).expect("a scenario of the catalogue");
    let every: Vec<&'static str> = plant_model::effects::EFFECT_NAMES
        .iter()
        .copied()
        .filter(|n| *n != "none")
        .collect();
    vec![
        Case {
            label: "pressure step 3 → 5 MPa",
            scenario: by("pressure-step"),
            effects: vec![],
            duration_s: by("pressure-step").duration_s,
        },
        Case {
            label: "5 MPa hold, every effect",
            scenario: by("pressure-hold"),
            effects: every,
            duration_s: by("pressure-hold").duration_s,
        },
        Case {
            label: "slow stroke, low-speed effects and friction",
            scenario: by("slow-stroke"),
            effects: vec![
                "cogging_torque",
                "flux_harmonics",
                "piston_ripple",
                "shaft_friction",
                "cylinder_friction",
            ],
            duration_s: by("slow-stroke").duration_s,
        },
    ]
}

/// The largest deviation of each of `schemes` from the reference on `case`, with the noise
/// of the rig's sensors.
pub fn compare(
    case: &Case,
    schemes: &[Integrator],
) -> Result<(Vec<Deviation>, SensorNoise), String> {
    let mut rig = Rig::nominal();
    for e in &case.effects {
        Effect::parse(e)
            .map_err(|err| format!("effect `{e}`: {err}"))?
            .apply(&mut rig);
    }
    let config = controller_config(&Rig::nominal());
    let mut reference =
        ClosedLoop::new(&rig, &config, case.scenario, 1).map_err(|e| e.to_string())?;
    reference
        .plant_mut()
        .set_integrator(Integrator::Rk4 { substeps: 4 });
    let period = reference.period_s();
    let noise = SensorNoise::of(&rig, period);
    let mut shadows: Vec<(Integrator, Plant, Deviation)> = schemes
        .iter()
        .map(|s| (*s, reference.plant().clone(), Deviation::default()))
        .collect();
    let periods = (case.duration_s / period).round() as u64;
    let resync = ((RESYNC_S / period).round() as u64).max(1);
    for k in 0..periods {
        if k % resync == 0 {
            for (scheme, plant, _) in &mut shadows {
                *plant = reference.plant().clone();
                plant.set_integrator(*scheme);
            }
        }
        let sample = reference.step();
        let d = sample.outputs.duties;
        let inputs = Inputs::duties(
            [f64::from(d[0]), f64::from(d[1]), f64::from(d[2])],
            sample.outputs.pwm_enabled,
        );
        for (_, plant, dev) in &mut shadows {
            dev.widen(&plant.observe(), &sample.truth);
            plant.advance(period, &inputs);
        }
    }
    Ok((shadows.into_iter().map(|(_, _, d)| d).collect(), noise))
}
