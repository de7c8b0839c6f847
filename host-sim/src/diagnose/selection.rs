//! Stage 5 of the diagnosis: the set of effects the log convicts, several at once.
//!
//! The parity relations are structured residuals (Gertler): the hydraulic relation reads
//! the pressure from the logged shaft angle and is blind to the motor; the mechanical one
//! reads the torque balance with the angle-locked lines projected out; each line lives at
//! its own order of the shaft angle; the cylinder's force balance and the stator voltages
//! are relations of their own. An effect acting on one of them leaves the others' tests
//! as they were, so each relation (each line) is judged on its own:
//!
//! - **One relation, several effects: forward selection.** On the hydraulic relation the
//!   qualifying release with the largest Λ ([`super::decision`]) joins the model; every
//!   other release is tested again against the model so extended (its parameter freed
//!   beside the named ones, [`Freed`]), the best qualifying one joins, until none does.
//!   With two or more named, each is judged once more against the model extended by all
//!   the others (a backward check): one that the others explain is dropped.
//! - **The other relations and the lines**: every effect that qualifies against the
//!   calibrated baseline, once per effect (the pump's ripple at its best piston count;
//!   the dead time and the flux harmonics, which share the lines at 6·p_n, through the
//!   veto of [`apply_vetoes`]).
//!
//! The named effects are ranked by Λ over its χ² threshold, the strongest first; what the
//! log cannot tell them from is marked beside them ([`super::ambiguity`]).

use super::ambiguity::mark;
use super::calibration::{
    calibrate, polished, test_release, Calibration, Freed, Relation, Release,
};
use super::candidates::{reread, short, Extension, Tested};
use super::decision::{apply_vetoes, threshold, why_not};
use super::displacement::{read_volumes_at, Displacement};
use super::hydraulic_relation::hyd;
use super::relations::Relations;
use super::release_verdict::from_release;
use super::unseen_precharge::least_unseen_precharge;
use plant_model::Rig;
use rayon::prelude::*;

/// Which residual an effect's test reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Family {
    Hydraulic,
    Other,
}

fn family(t: &Tested) -> Family {
    match t.extension {
        Extension::Hydraulic(_) => Family::Hydraulic,
        _ => Family::Other,
    }
}

/// The effects named, as indices into `tested` (whose hydraulic entries are replaced by
/// their tests against the model extended by the others, their volume balance's readings
/// taken at `displacement` when the shaft fixes it), the strongest first; and the
/// hydraulic relation's values with every named hydraulic effect released.
pub(super) fn select(
    rel: &Relations<'_>,
    tested: &mut [Tested],
    rig: &Rig,
    displacement: Option<Displacement>,
) -> (Vec<usize>, Option<Vec<f64>>) {
    apply_vetoes(tested);
    let first: Vec<f64> = tested.iter().map(|t| t.lambda).collect();
    let mut named: Vec<usize> = Vec::new();
    // Every relation but the hydraulic one, and every line: once per effect.
    for (i, t) in tested.iter().enumerate() {
        if family(t) != Family::Other || why_not(t).is_some() {
            continue;
        }
        match named.iter().position(|&j| tested[j].effect == t.effect) {
            Some(k) if tested[named[k]].lambda < t.lambda => named[k] = i,
            Some(_) => {}
            None => named.push(i),
        }
    }
    let (hydraulic, values) = forward_hydraulic(rel, tested, rig);
    // Before the ambiguities are marked: they are said in the readings' terms.
    if let Some(d) = displacement {
        read_volumes_at(tested, d, rig);
    }
    named.extend(hydraulic);
    named.sort_by(|a, b| strength(&tested[*b]).total_cmp(&strength(&tested[*a])));
    mark(
        tested,
        &named,
        &first,
        rel.hydraulic.facts(),
        rig.oil.bulk_modulus_pa,
    );
    (named, values)
}

/// Λ over its χ² threshold.
fn strength(t: &Tested) -> f64 {
    t.lambda / threshold(t.dof)
}

/// The hydraulic relation's forward selection and backward check; the named entries of
/// `tested` and the relation's values with all of them released.
fn forward_hydraulic(
    rel: &Relations<'_>,
    tested: &mut [Tested],
    rig: &Rig,
) -> (Vec<usize>, Option<Vec<f64>>) {
    let relation = rel.screened(&rel.hydraulic);
    let first_round: Vec<Tested> = tested.to_vec();
    // The model with the releases of `kept` freed, `but` one.
    let freed_by = |kept: &[usize], but: Option<usize>, tested: &[Tested]| Freed {
        relation: &relation,
        freed: kept
            .iter()
            .filter(|&&i| Some(i) != but)
            .map(|&i| tested[i].release)
            .collect(),
    };
    let mut pool: Vec<usize> = (0..tested.len())
        .filter(|&i| family(&tested[i]) == Family::Hydraulic)
        .collect();
    let mut named: Vec<usize> = Vec::new();
    let mut base: Option<Calibration> = None;
    loop {
        let best = pool
            .iter()
            .copied()
            .filter(|&i| why_not(&tested[i]).is_none())
            .max_by(|a, b| tested[*a].lambda.total_cmp(&tested[*b].lambda));
        let Some(b) = best else { break };
        named.push(b);
        base = tested[b].fit.clone();
        pool.retain(|&i| i != b);
        let Some(base) = &base else { break };
        if pool.is_empty() {
            break;
        }
        let freed = freed_by(&named, None, tested);
        let again: Vec<Tested> = pool
            .par_iter()
            .map(|&i| judged(&freed, base, tested[i].release, rel, rig))
            .collect();
        for (&i, t) in pool.iter().zip(again) {
            tested[i] = t;
        }
    }
    if named.len() < 2 {
        let values = base.map(|b| reported(rel, tested, &named, b, rig));
        return (named, values);
    }
    // Backward: each named effect against the model extended by all the others. The checks
    // and the extended model's calibration run side by side as though none were dropped; a
    // check after a drop is run again against the effects still kept.
    let check = |a: usize, kept: &[usize], tested: &[Tested]| -> Tested {
        let freed = freed_by(kept, Some(a), tested);
        let with_others = calibrate(&freed, &rel.h_id);
        judged(&freed, &with_others, tested[a].release, rel, rig)
    };
    let extended_by =
        |kept: &[usize], tested: &[Tested]| calibrate(&freed_by(kept, None, tested), &rel.h_id);
    let (guessed, all_kept) = rayon::join(
        || {
            named
                .par_iter()
                .map(|&a| check(a, &named, tested))
                .collect::<Vec<_>>()
        },
        || extended_by(&named, tested),
    );
    let mut kept = named.clone();
    for (&a, guess) in named.iter().zip(guessed) {
        let again = if kept == named {
            guess
        } else {
            check(a, &kept, tested)
        };
        if why_not(&again).is_none() {
            tested[a] = again;
        } else {
            kept.retain(|&i| i != a);
            // Its first-round entry says why it is not named on its own.
            tested[a] = first_round[a].clone();
            tested[a].veto = Some(format!(
                "the other named hydraulic effects explain it (against them: {})",
                why_not(&again).unwrap_or_default()
            ));
        }
    }
    let extended = match kept.as_slice() {
        [] => None,
        [one] => tested[*one].fit.clone(),
        _ if kept == named => Some(all_kept),
        _ => Some(extended_by(&kept, tested)),
    };
    let values = extended.map(|c| reported(rel, tested, &kept, c, rig));
    (kept, values)
}

/// The hydraulic relation's values with the `named` releases freed, from their fit `c`:
/// driven on to the report's effort, and each named entry of `tested` read again there; a
/// named precharge the log bounds from below only read at that bound
/// ([`least_unseen_precharge`]).
fn reported(
    rel: &Relations<'_>,
    tested: &mut [Tested],
    named: &[usize],
    c: Calibration,
    rig: &Rig,
) -> Vec<f64> {
    let mut c = match rel.reported_effort() {
        None => c,
        Some(effort) => {
            let freed = Freed {
                relation: &rel.hydraulic,
                freed: named.iter().map(|&i| tested[i].release).collect(),
            };
            let c = polished(&freed, &rel.h_id, &c, effort);
            for &i in named {
                reread(&mut tested[i], &c, rig);
            }
            c
        }
    };
    read_unseen_precharge(rel, tested, named, &mut c, rig);
    c.fitted.values
}

/// A named precharge that `c` fits above every pressure of the identification segment,
/// read at the least precharge the log cannot tell from the fit ([`least_unseen_precharge`])
/// in `c` and in its entry of `tested`, whose evidence says so.
fn read_unseen_precharge(
    rel: &Relations<'_>,
    tested: &mut [Tested],
    named: &[usize],
    c: &mut Calibration,
    rig: &Rig,
) {
    let Some(i) = named
        .iter()
        .copied()
        .find(|&i| tested[i].release == Release::Precharge)
    else {
        return;
    };
    let nominal = rel.hydraulic.specs(Release::Nothing)[hyd::PRECHARGE].nominal;
    let p_pa = &rel.hydraulic.log.p_pa;
    let v = &c.fitted.values;
    let Some(p) = least_unseen_precharge(&rel.hydraulic, &rel.h_id, v, c.scale, p_pa, nominal)
    else {
        return;
    };
    let fitted = v[hyd::PRECHARGE];
    c.fitted.values[hyd::PRECHARGE] = p;
    reread(&mut tested[i], c, rig);
    tested[i].evidence.push_str(&format!(
        "; the identification's pressure never reaches it, so the log bounds it from below \
         only: read at the least precharge that fits as well as the fit's {} Pa",
        short(fitted)
    ));
}

/// `release` tested on `relation` (the model extended by its freed effects) against
/// `base`, that model's calibration.
fn judged<R: Relation>(
    relation: &R,
    base: &Calibration,
    release: Release,
    rel: &Relations<'_>,
    rig: &Rig,
) -> Tested {
    let t = test_release(relation, &rel.h_id, release, base);
    let mut tested = from_release(relation, &t, &rel.h_id, &rel.h_val, rig);
    tested
        .evidence
        .push_str(" (against the model with the other named effects)");
    tested
}
