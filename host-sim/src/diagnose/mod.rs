//! `eha diagnose`: what the model gets wrong on a measured log, why, the extended model,
//! and the gain on data the fit never saw. A pipeline that reads top to bottom
//! ([`analysis`] lists the stages):
//!
//! - [`facts`]: facts about the log, computed once (sampling, angle, noise, segments,
//!   steady windows).
//! - The parity relations, each predicting one logged signal from the others over short
//!   windows re-started from the measurement, so nothing drifts: [`hydraulic`] (pressure
//!   from the shaft angle), [`mechanical`] (q current and speed from the torque balance),
//!   [`electrical`] (voltages, when logged), [`cylinder`] (pressure from the piston's
//!   force balance, when it moves).
//! - [`least_squares`] and [`calibration`]: the nominal model fitted to the log within the
//!   rig's tolerance bands, and with one effect's parameter released.
//! - [`relations`]: the log's windows, the relations it supports and their baselines,
//!   shared by the stages.
//! - [`lines`], [`angle_locked`], [`dead_time`]: the angle-locked lines of the steady
//!   windows and the effects that make them; [`loop_response`]: the Table 1 loops'
//!   responses the line readings use; [`emf_law`]: the 6·p_n voltage lines read as a
//!   back-EMF and as a dead time's voltage.
//! - [`candidates`], [`decision`]: every effect tested, and the one the log convicts;
//!   `release_verdict`: a released parameter's test read in the catalogue's terms (its
//!   band, the validation's spread, the vetoes).
//! - [`displacement`]: the pump's displacement fixed by the torque balance and the stator
//!   voltages, at which a blocked cylinder's leakage and bulk modulus are read.
//! - [`predictions`]: the contract's per-signal predictions and scores ([`fit_score`]).
//! - [`signatures`], [`spectrum`]: the baseline residuals' time-domain signatures and
//!   order spectra, for the report.
//! - [`findings`]: everything one run computed; [`diagnosis`]: the contract's JSON;
//!   [`report`]: the markdown report; [`command`]: the CLI.

pub mod active_set;
pub mod ambiguity;
pub mod analysis;
pub mod angle_locked;
pub mod back_emf;
pub mod calibration;
pub mod candidates;
pub mod command;
pub mod contributions;
pub mod count_lines;
pub mod cylinder;
pub mod dead_time;
pub mod decision;
pub mod diagnosis;
pub mod displacement;
pub mod effort;
pub mod electrical;
pub mod emf_law;
mod error;
pub mod facts;
pub mod findings;
pub mod fit_score;
pub mod hydraulic;
pub mod hydraulic_relation;
pub mod intervals;
pub mod least_squares;
pub mod line_split;
pub mod lines;
pub mod lock_in;
pub mod loop_response;
pub mod low_side;
pub mod mechanical;
pub mod mechanical_relation;
pub mod param_spec;
pub mod predictions;
pub mod relations;
#[cfg(test)]
mod release_tests;
mod release_verdict;
pub mod report;
pub mod result;
pub mod retime;
pub mod secant;
pub mod selection;
pub mod signatures;
pub mod spectrum;
pub mod speed_angle;
pub mod steady;
pub mod stick;
#[cfg(test)]
mod test_noise;
pub mod uneven_derivative;
pub mod unseen_motion;
pub mod unseen_precharge;
pub mod validation_spread;

pub use diagnosis::{Cause, Diagnosis, Extended, Fit, Gain};

pub use error::DiagnoseError;
pub use fit_score::{fit_percent, residual};

pub use analysis::{analyse, diagnose};
pub use findings::Analysis;
