//! The feed-forward by the method asked ([`Method`]): the model's table, from the
//! channels of the rig with the effects the diagnosis found switched on ([`fitted_plant`],
//! [`super::model`]), with the speed modulation against the pump's flow ripple
//! ([`crate::feedforward::flow`]); or the histogram's, the q current binned by angle
//! ([`super::histogram`]). Either is refused when the drive would refuse it.

use super::learn::Found;
use super::{histogram, model, table};
use crate::bench_log::BenchLog;
use crate::feedforward::flow::{self, FlowParams};
use crate::feedforward::Feedforward;
use crate::output::CliError;
use clap::ValueEnum;
use firmware::compensation::{Compensation, Table, BINS, CHANNELS};
use plant_model::Rig;

/// How the table is learned.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Method {
    /// From the diagnosis's fitted effects, each in the channel of its scaling law.
    Model,
    /// The q current binned by shaft angle at constant speed (moteus, ODrive).
    Histogram,
}

impl Method {
    pub(super) fn name(self) -> &'static str {
        match self {
            Method::Model => "model",
            Method::Histogram => "histogram",
        }
    }
}

/// The feed-forward learned from `found` (model) or `logs` (histogram) on `rig`: the table
/// of [`table_of`] and, for the model, the speed modulation against the pump's flow ripple
/// when `piston_ripple` was found and neither it nor [`flow::EXCLUDE_NAME`] is in
/// `exclude`; refused when the drive would refuse it.
pub fn feedforward_of(
    found: &Found,
    logs: &[BenchLog],
    rig: &Rig,
    method: Method,
    exclude: &[String],
) -> Result<Feedforward, CliError> {
    let table = table_of(found, logs, rig, method, exclude)?;
    let left_out = |n: &str| exclude.iter().any(|x| x == n);
    let flow = match method {
        Method::Model if !left_out("piston_ripple") && !left_out(flow::EXCLUDE_NAME) => found
            .effects
            .iter()
            .find_map(|l| FlowParams::of_effect(&l.effect, rig)),
        _ => None,
    };
    let ff = Feedforward { table, flow };
    ff.check(rig)
        .map_err(|e| CliError::BadInput(format!("the learned feed-forward is refused: {e}")))?;
    Ok(ff)
}

/// The histogram's table from `logs`: their constant channels averaged.
fn histogram_table(logs: &[BenchLog]) -> Result<Table, CliError> {
    let maps: Vec<Vec<f64>> = logs
        .iter()
        .filter_map(histogram::constant_channel)
        .collect();
    if maps.is_empty() {
        return Err(CliError::BadInput(
            "no stretch of steady rotation in the logs: the histogram needs the shaft turning \
             at constant speed (the bench sweep, or a hold that turns)"
                .into(),
        ));
    }
    let n = maps.len() as f64;
    let constant: Vec<f64> = (0..BINS)
        .map(|b| maps.iter().map(|m| m[b]).sum::<f64>() / n)
        .collect();
    let columns: [Vec<f64>; CHANNELS] = [constant, vec![0.0; BINS], vec![0.0; BINS]];
    table::quantise(&columns)
        .ok_or_else(|| CliError::Failed("the histogram does not fit the table's range".into()))
}

/// The table learned from `found` (model) or `logs` (histogram) on `rig`, leaving out the
/// effects named in `exclude`; refused when its amplitude exceeds the drive's limit.
pub fn table_of(
    found: &Found,
    logs: &[BenchLog],
    rig: &Rig,
    method: Method,
    exclude: &[String],
) -> Result<Table, CliError> {
    let table = match method {
        Method::Model => {
            let ch = model::channels_from_rig(&fitted_plant(found, rig)?, found.p_low_pa, exclude);
            table::build(&ch).ok_or_else(|| {
                CliError::Failed("the fitted effects do not fit the table's range".into())
            })?
        }
        Method::Histogram => histogram_table(logs)?,
    };
    let mut cfg = closed_loop::controller_config(rig);
    cfg.compensation.enabled = true;
    Compensation::check_amplitude(&table, &cfg)
        .map_err(|e| CliError::BadInput(format!("the learned table is refused: {e}")))?;
    Ok(table)
}

/// The rig with the effects `found` switched on: the model fitted to the logs.
pub fn fitted_plant(found: &Found, rig: &Rig) -> Result<Rig, CliError> {
    let mut plant = rig.clone();
    for l in &found.effects {
        l.effect.apply(&mut plant);
    }
    plant
        .validate()
        .map_err(|e| CliError::Failed(format!("the fitted plant is not a rig: {e}")))?;
    Ok(plant)
}
