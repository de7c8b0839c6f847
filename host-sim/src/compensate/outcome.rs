//! One run of `eha compensate` between reading the logs and writing: the feed-forward
//! learned from the logs, and its effect predicted on the paper's holding against the
//! plant fitted to them ([`super::predict`]).

use super::args::CompensateArgs;
use super::learn::{find, Found};
use super::method::{feedforward_of, fitted_plant};
use super::predict::{self, Pulsation};
use crate::bench_log::BenchLog;
use crate::feedforward::Feedforward;
use crate::output::CliError;
use plant_model::Rig;

/// What one run learned from the logs and predicted of it on the paper's holding.
pub(super) struct Outcome {
    /// What the diagnosis found in the logs.
    pub found: Found,
    /// The feed-forward learned.
    pub ff: Feedforward,
    /// The holding's pulsation on the fitted plant without the feed-forward.
    pub without: Pulsation,
    /// The same with it.
    pub with: Pulsation,
}

/// Learns the feed-forward from `logs` by `args.method` and predicts its effect on the
/// holding against the plant fitted to the logs, under a progress spinner.
pub(super) fn learn_and_predict(
    rig: &Rig,
    logs: &[BenchLog],
    args: &CompensateArgs,
) -> Result<Outcome, CliError> {
    let busy = crate::output::progress::spinner(format!(
        "learning the feed-forward from {} log(s)",
        logs.len()
    ));
    let learned = (|| {
        let found = find(logs, rig)?;
        let ff = feedforward_of(&found, logs, rig, args.method, &args.exclude)?;
        let plant = fitted_plant(&found, rig)?;
        let (without, with) = predict::without_and_with(&plant, rig, &[&ff])?;
        let with = with
            .into_iter()
            .next()
            .ok_or_else(|| CliError::Failed("no run with the table".into()))?;
        Ok::<_, CliError>(Outcome {
            found,
            ff,
            without,
            with,
        })
    })();
    busy.finish_and_clear();
    learned
}
