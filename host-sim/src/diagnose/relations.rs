//! The log's windows and the parity relations it supports, and each relation's baseline:
//! what the diagnosis's stages share. Identification and validation windows of each
//! relation's length, thinned to [`MAX_FIT_S`] of the log; the hydraulic (eq. 6–11),
//! mechanical (eq. 3–5), electrical (eq. 1–2, when the voltages are logged) and cylinder
//! (eq. 12, when the piston moves) relations; and the orders the angle-locked lines are
//! read at.

use super::calibration::{thinned, Calibration, Patient, MAX_FIT_S};
use super::cylinder::CylinderRelation;
use super::effort::Effort;
use super::electrical::ElectricalRelation;
use super::facts::{rows_spanning, LogFacts};
use super::hydraulic_relation::{HydraulicRelation, HYDRAULIC_WINDOW_S};
use super::mechanical::ShaftMotion;
use super::mechanical_relation::MechanicalRelation;
use crate::bench_log::BenchLog;
use plant_model::pump::ripple_order;
use plant_model::Rig;
use std::ops::Range;

/// Length of the mechanical relation's calibration windows (thinned on long logs). [s]
const MECHANICAL_WINDOW_S: f64 = 1.0;

/// The orders the lines are read at: a current offset's p_n, flux harmonics' and dead
/// time's 6·p_n, the pumps' 2z and the rig's slot order.
pub(super) fn line_orders(rig: &Rig) -> Vec<u32> {
    let pp = rig.motor.pole_pairs;
    let mut v = vec![pp, 6 * pp, rig.motor.cogging_fundamental_order()];
    v.extend(
        super::candidates::RIPPLE_PISTONS
            .iter()
            .map(|z| ripple_order(*z)),
    );
    v.sort_unstable();
    v.dedup();
    v
}

/// How far the fits are driven.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Precision {
    /// Until the decision is settled: `eha diagnose`.
    Diagnosis,
    /// Until the fitted parameters stop moving: a feed-forward learned from them.
    Learning,
}

/// The log's windows and the parity relations it supports.
pub(super) struct Relations<'a> {
    pub(super) h_id: Vec<Range<usize>>,
    pub(super) h_val: Vec<Range<usize>>,
    pub(super) m_id: Vec<Range<usize>>,
    pub(super) m_val: Vec<Range<usize>>,
    pub(super) hydraulic: HydraulicRelation<'a>,
    pub(super) mechanical: MechanicalRelation<'a>,
    pub(super) electrical: Option<ElectricalRelation<'a>>,
    pub(super) cylinder: Option<CylinderRelation<'a>>,
    pub(super) orders: Vec<u32>,
    /// How far the fits whose values are used are driven: every relation's but the
    /// hydraulic one's screening.
    pub(super) effort: Effort,
    /// How far the hydraulic relation's calibrations and tests are driven.
    pub(super) screening: Effort,
}

impl<'a> Relations<'a> {
    pub(super) fn of(
        log: &'a BenchLog,
        facts: &'a LogFacts,
        motion: &'a ShaftMotion,
        rig: &'a Rig,
        precision: Precision,
    ) -> Relations<'a> {
        let budget = rows_spanning(MAX_FIT_S, facts.period_s, 1);
        let windows =
            |rows, length, signal: &[f64]| thinned(facts.windows(rows, length), signal, budget);
        let orders = line_orders(rig);
        Relations {
            h_id: windows(facts.identification(), HYDRAULIC_WINDOW_S, &log.p_pa),
            h_val: windows(facts.validation(), HYDRAULIC_WINDOW_S, &log.p_pa),
            m_id: windows(
                facts.identification(),
                MECHANICAL_WINDOW_S,
                &log.speed_rad_s,
            ),
            m_val: windows(facts.validation(), MECHANICAL_WINDOW_S, &log.speed_rad_s),
            hydraulic: HydraulicRelation { log, facts, rig },
            mechanical: MechanicalRelation::new(log, facts, motion, rig, &orders),
            electrical: ElectricalRelation::of(log, facts, rig),
            cylinder: CylinderRelation::of(log, facts, rig),
            orders,
            effort: match precision {
                Precision::Diagnosis => Effort::REPORTED,
                Precision::Learning => Effort::THOROUGH,
            },
            screening: match precision {
                // A moving piston's volume balance is read for the position, a sum of
                // rows without an integration to screen (`hydraulic::stroke`).
                _ if facts.piston_moves => Effort::THOROUGH,
                Precision::Diagnosis => Effort::SCREENING,
                Precision::Learning => Effort::THOROUGH,
            },
        }
    }

    /// How far the hydraulic fits the report predicts with are driven on from the
    /// screening's: `None` where the screening drives them that far already.
    pub(super) fn reported_effort(&self) -> Option<Effort> {
        self.screening.refined()
    }

    /// The hydraulic relation, whose flat valleys the screening does not follow to their
    /// end ([`super::effort`]), fitted with the precision's screening effort.
    pub(super) fn screened<'r, R>(&self, relation: &'r R) -> Patient<'r, R> {
        Patient {
            relation,
            effort: self.screening,
        }
    }

    /// `relation` fitted with the precision's effort.
    pub(super) fn patient<'r, R>(&self, relation: &'r R) -> Patient<'r, R> {
        Patient {
            relation,
            effort: self.effort,
        }
    }
}

/// Each relation's baseline, fitted within the tolerance bands.
pub(super) struct Calibrations {
    pub(super) hydraulic: Calibration,
    pub(super) mechanical: Calibration,
    pub(super) electrical: Option<Calibration>,
    pub(super) cylinder: Option<Calibration>,
}
