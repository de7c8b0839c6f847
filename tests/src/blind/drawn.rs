//! What one seed draws: the answer the suite checks the diagnosis against ([`Truth`], each
//! hidden effect a [`Hidden`]) and how to simulate it ([`Draw`]: the tolerance rig, the drawn
//! structure, the bench's low-side transducer, the test and the log rate), with the run that
//! turns a draw into the bench log the diagnosis gets.

use super::bench_sensors::{read_through, LowSideTransducer};
use super::structure::Structure;
use closed_loop::{controller_config, Scenario};
use host_sim::bench_log::BenchLog;
use host_sim::run::{run_with_config, RunOptions};
use plant_model::{Effect, Rig};

/// One hidden effect: the answer for it.
#[derive(Clone, Debug, PartialEq)]
pub struct Hidden {
    /// Effect name from the catalogue.
    pub name: &'static str,
    /// Its parameters by their contract names (SI), as applied to the plant.
    pub parameters: Vec<(&'static str, f64)>,
    /// The logged signal where its signature stands highest over the noise.
    pub signal: &'static str,
    /// That signature over the noise. [1]
    pub ratio: f64,
}

/// What the generator hid in one log: the answer the suite checks the diagnosis against.
#[derive(Clone, Debug, PartialEq)]
pub struct Truth {
    /// The hidden effects (empty: nothing hidden), in the order they were drawn.
    pub effects: Vec<Hidden>,
    /// The test the log records (a name of [`TESTS`]).
    pub test: &'static str,
    /// Log rate. [Hz]
    pub log_rate_hz: f64,
    /// Length of the log. [s]
    pub duration_s: f64,
    /// The contract's optional columns the log does not hold.
    pub dropped: Vec<&'static str>,
}

impl Truth {
    /// `none`, the effect's name, or the two names in alphabetical order joined by `+` (the
    /// label of `truth.json`).
    pub fn label(&self) -> String {
        let mut names: Vec<&str> = self.effects.iter().map(|h| h.name).collect();
        names.sort_unstable();
        if names.is_empty() {
            "none".into()
        } else {
            names.join("+")
        }
    }
}

/// Everything drawn for one seed: the truth plus how to simulate it. Kept inside the
/// generator and the suite's own checks; the diagnosis gets only the written log.
#[derive(Clone, Debug)]
pub struct Draw {
    /// The answer.
    pub truth: Truth,
    /// The hidden effects (with their parameters).
    pub effects: Vec<Effect>,
    /// The plant's rig: nominal ± tolerances with the drawn structure, WITHOUT the effects.
    pub tolerance_rig: Rig,
    /// What was drawn beyond the tolerances: open parts of the rig, the controller's
    /// tuning, the columns not logged (already in `tolerance_rig` where it is the rig's).
    pub structure: Structure,
    /// The bench's low-side pressure transducer.
    pub low_side: LowSideTransducer,
    /// The test, with its drawn setpoints and length.
    pub scenario: Scenario,
    /// Log rate. [Hz]
    pub log_rate_hz: f64,
    /// Sensor-noise seed of the plant and the bench's extra sensors.
    pub noise_seed: u64,
    /// File-name token (drawn, so the name carries nothing about the seed).
    pub(super) token: u64,
}

/// `rig` with the white noise of every sensor off (quantisation stays).
fn noise_free(rig: &Rig) -> Rig {
    let mut r = rig.clone();
    r.sensors.current.noise_a_rms = 0.0;
    r.sensors.pressure.noise_pa_rms = 0.0;
    r.sensors.dc_link.noise_v_rms = 0.0;
    r
}

impl Draw {
    /// The plant's true rig: the tolerance rig with every hidden effect switched on.
    pub fn truth_rig(&self) -> Rig {
        let mut rig = self.tolerance_rig.clone();
        for e in &self.effects {
            e.apply(&mut rig);
        }
        rig
    }

    /// The true rig without the `k`-th hidden effect (the others on).
    pub fn rig_without(&self, k: usize) -> Rig {
        let mut rig = self.tolerance_rig.clone();
        for (i, e) in self.effects.iter().enumerate() {
            if i != k {
                e.apply(&mut rig);
            }
        }
        rig
    }

    /// The draw's test run on the plant `rig` under the draw's controller (the nominal
    /// rig's, tuned by the drawn variant), logged at the draw's rate with every column,
    /// the bench's extra sensors read through; with every sensor's noise seeded by `noise`
    /// (the truth's is [`Draw::noise_seed`]), or with their quantisation only when `None`.
    pub fn log(&self, rig: &Rig, noise: Option<u64>) -> Result<BenchLog, String> {
        let plant = if noise.is_some() {
            rig.clone()
        } else {
            noise_free(rig)
        };
        let opt = RunOptions {
            duration_s: self.scenario.duration_s,
            log_rate_hz: self.log_rate_hz,
            seed: noise.unwrap_or(self.noise_seed),
            progress: false,
            metadata: vec![("source".into(), "blind-suite".into())],
            compensation: None,
            integrator: Default::default(),
        };
        let config = self
            .structure
            .controller
            .apply(&controller_config(&Rig::nominal()));
        let mut log = run_with_config(&plant, &config, &self.scenario, &opt)?.log;
        let extra = noise.map(|n| n ^ 0x5851_f42d_4c95_7f2d);
        read_through(&mut log, &self.low_side, extra);
        Ok(log)
    }
}
