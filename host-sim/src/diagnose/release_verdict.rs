//! A released parameter's test in the catalogue's terms ([`from_release`]): whether its
//! estimate left the tolerance band, how far the validation segment could move a loss
//! there, the standard errors reported, and the vetoes that keep a convicting release from
//! being named (a lag within a bench's own, a lag run to its range's top, air read stiffer
//! than the oil). [`test_relation`] tests every release a relation offers.

use crate::diagnose::calibration::{
    test_release, weighed_sse, Calibration, Relation, Release, ReleaseTest,
};
use crate::diagnose::candidates::{parameters_at, released_effect, short, Tested};
use crate::diagnose::hydraulic_relation::LAG_BAND_S;
use crate::diagnose::least_squares::ParamSpec;
use crate::diagnose::validation_spread::{validation_spread, VALIDATION_TOLERANCE};
use plant_model::Rig;
use rayon::prelude::*;
use std::ops::Range;

/// Fraction of a released parameter's search range (in its search coordinate) from its
/// top within which its fit counts as run to the edge. [1]
pub const SEARCH_EDGE: f64 = 0.02;

/// Shortest transducer lag named: twice its tolerance band's top. Logs of an independent
/// bench with no lag hidden read lags past the band's top when it is released (their
/// transducer's and logger's own); one that short is the bench's, not a fault. [s]
pub const LAG_NAMED_FLOOR_S: f64 = 2.0 * LAG_BAND_S;

/// A released parameter's test in the catalogue's terms.
///
/// `identification` holds the rows the test was fitted on: a loss on the `validation` rows
/// is weighed against the spread the two fits' uncertainty there gives it
/// ([`validation_spread`]).
pub fn from_release<R: Relation>(
    relation: &R,
    test: &ReleaseTest,
    identification: &[Range<usize>],
    validation: &[Range<usize>],
    rig: &Rig,
) -> Tested {
    let v = &test.fitted.values;
    let specs = relation.specs(test.release);
    let base_specs = relation.specs(Release::Nothing);
    let (all, effect, extension) = released_effect(test.release, v);
    // The main parameter, and the others the relation released on this log (the
    // cylinder's breakaway only where the piston is seen resting).
    let indices: Vec<usize> = all
        .iter()
        .enumerate()
        .filter(|(n, i)| *n == 0 || specs[**i].band.is_none())
        .map(|(_, i)| *i)
        .collect();
    // Outside its band: the main parameter's released estimate lies beyond it (the others
    // released beside it are reported, not judged: the cylinder's breakaway rests on the
    // few reversals a log holds, where the stick's model is at its coarsest). That it lies
    // there significantly is the likelihood ratio itself: the baseline is the best fit with
    // the parameter held within the band (at its edge, when the data pull outwards), so Λ
    // is the profile likelihood ratio of the band's edge against the estimate — a test that
    // needs no covariance of the nuisance parameters, which flat bands leave singular along
    // the directions the log does not fix.
    let u = test.fitted.u[indices[0]];
    let band = base_specs[indices[0]].band;
    let outside_band = band.is_some_and(|(lo, hi)| u > hi || u < lo);
    let parameters = parameters_at(test.release, v, rig);
    let validation_gain = (!validation.is_empty()).then(|| {
        weighed_sse(relation, &test.baseline.values, validation, test.scale)
            - weighed_sse(relation, &test.fitted.values, validation, test.scale)
    });
    // Where the validation segment reads a loss beyond its tolerance: how far the two fits'
    // own uncertainty could move it.
    let validation_spread = match validation_gain {
        Some(g) if g < -VALIDATION_TOLERANCE => {
            let spread = |specs: &[ParamSpec], u: &[f64]| {
                validation_spread(relation, specs, u, identification, validation, test.scale)
            };
            Some(spread(&base_specs, &test.baseline.u).hypot(spread(&specs, &test.fitted.u)))
        }
        _ => None,
    };
    // Each reported parameter's spread at one standard error of the coordinate it was
    // searched in (the catalogue's value moves with the search value one to one but for an
    // additive nominal: the leakage's, the cylinder's friction levels).
    let standard_errors = parameters
        .iter()
        .zip(&indices)
        .map(|((name, reported), &i)| {
            let spread = released_spread(test, &specs, i);
            // The bulk modulus is reported at the rig file's volume: the same ratio.
            let scale = match test.release {
                Release::BulkModulus => reported / specs[i].value(test.fitted.u[i]),
                _ => 1.0,
            };
            (*name, spread * scale)
        })
        .collect();
    // A transducer lag that ran to the top of its plausible range (a fifth of a second,
    // ten times a snubbed transducer's) asks for more than a lag can be: the log's mismatch
    // is something else, which a low-pass bends towards. (Other releases may sit at their
    // range's edge legitimately: a cylinder's friction is bounded by the payload's force.)
    let main = &specs[indices[0]];
    let (lo, hi) = main.u_bounds;
    let at_top = hi > lo && hi - u <= SEARCH_EDGE * (hi - lo);
    // Entrained air only softens the oil (the catalogue's effect is a bulk modulus below the
    // rig file's): a reading above the band is a stiffness the log trades against the line
    // volume or another tolerance, not air.
    let above_band = band.is_some_and(|(_, top)| u > top);
    let veto = release_veto(test.release, main, u, above_band, at_top);
    let mut evidence = release_evidence(test, &indices, &specs, &base_specs);
    if let (Some(g), Some(s)) = (validation_gain, validation_spread) {
        evidence.push_str(&format!(
            "; the validation segment reads a loss of {:.1} with a spread of {:.1} from where \
             the two fits stopped along the directions the identification leaves flat",
            -g, s
        ));
    }
    Tested {
        effect,
        parameters,
        lambda: test.lambda,
        dof: indices.len(),
        outside_band,
        validation_gain,
        validation_spread,
        veto,
        evidence,
        extension,
        standard_errors,
        release: test.release,
        fit: Some(Calibration {
            fitted: test.fitted.clone(),
            scale: test.scale,
        }),
        ambiguous_with: Vec::new(),
    }
}

/// The spread of parameter `i`'s value at one standard error of its search coordinate
/// (infinite where the log does not bound it). [unit of the parameter]
fn released_spread(test: &ReleaseTest, specs: &[ParamSpec], i: usize) -> f64 {
    let u = test.fitted.u[i];
    let se = test.fitted.standard_error(i, 1.0);
    let spread = 0.5 * (specs[i].value(u + se) - specs[i].value(u - se)).abs();
    if spread.is_finite() {
        spread
    } else {
        f64::INFINITY
    }
}

/// Largest standard error shown, relative to the estimate: beyond it the linearised
/// error says only that the log does not bound the parameter by itself. [1]
const SPREAD_SHOWN: f64 = 100.0;

/// What a release measured, in words: each released parameter's estimate, its standard
/// error and band, and Λ.
fn release_evidence(
    test: &ReleaseTest,
    indices: &[usize],
    specs: &[ParamSpec],
    base_specs: &[ParamSpec],
) -> String {
    let released: Vec<String> = indices
        .iter()
        .map(|&i| {
            let value = specs[i].value(test.fitted.u[i]);
            let spread = released_spread(test, specs, i);
            // A direction the log leaves flat has no finite error: above the precharge
            // p₀ the gas's capacitance V₀·p₀^(1/n)/(n·p^(1+1/n)) sets p₀ against V₀.
            let error = if spread.is_finite() && spread <= SPREAD_SHOWN * value.abs() {
                format!("± {} at one standard error", short(spread))
            } else {
                "standard error unbounded: the log trades it against another parameter".to_string()
            };
            format!(
                "{} released from its tolerance band to {} ({error}, band {})",
                specs[i].name,
                short(value),
                band_text(&base_specs[i])
            )
        })
        .collect();
    format!(
        "{}: Λ = {:.1} on the identification segment",
        released.join(", "),
        test.lambda
    )
}

/// A parameter's tolerance band in words.
fn band_text(s: &ParamSpec) -> String {
    match s.band {
        Some((lo, hi)) => format!("{}–{}", short(s.value(lo)), short(s.value(hi))),
        None => "none".into(),
    }
}

/// Tests every release a relation offers.
pub fn test_relation<R: Relation>(
    relation: &R,
    calibration: &Calibration,
    identification: &[Range<usize>],
    validation: &[Range<usize>],
    releases: &[Release],
    rig: &Rig,
) -> Vec<Tested> {
    releases
        .par_iter()
        .map(|r| {
            let t = test_release(relation, identification, *r, calibration);
            from_release(relation, &t, identification, validation, rig)
        })
        .collect()
}

/// Why a release that convicts is still not named, if it is not: a lag within twice its
/// band's top (a bench's own), a lag run to the top of its range (`at_top`: a mismatch of
/// another kind), a bulk modulus above its band (`above_band`: a stiffness, not air).
/// `main` is the main parameter's spec and `u` its fitted search value.
fn release_veto(
    release: Release,
    main: &ParamSpec,
    u: f64,
    above_band: bool,
    at_top: bool,
) -> Option<String> {
    if release == Release::SensorLag && main.value(u) < LAG_NAMED_FLOOR_S {
        Some(format!(
            "its lag ({:.2} ms) is below {:.1} ms, twice its tolerance band's top: a bench's \
             transducer with its snubber, sensing line and the logger's filter reads that much \
             with no fault, so the lag is not told apart from the bench's own",
            1e3 * main.value(u),
            1e3 * LAG_NAMED_FLOOR_S
        ))
    } else if release == Release::SensorLag && at_top {
        Some(format!(
            "its fit ran to the edge of the plausible range ({} = {:.4e}): the log asks for \
             more than this effect can be, a mismatch of another kind",
            main.name,
            main.value(u)
        ))
    } else if release == Release::BulkModulus && above_band {
        Some(format!(
            "its bulk modulus reads above its band ({:.4e} Pa): air only softens the oil, so \
             a stiffer reading is a volume or a tolerance the log does not separate, not air",
            main.value(u)
        ))
    } else {
        None
    }
}
