//! The generator of the blind identification suite: from a seed the diagnosis never
//! sees, it draws the bench test the log records ([`test_plan`]: a pressure step, a
//! staircase, a sine or a stroke, its length and its log rate), a rig whose parameters
//! deviate by their tolerances from the nominal one and whose open parts and controller
//! vary ([`structure`]), and what the log hides: nothing, one catalogue effect, or two at
//! once ([`catalogue`]); then it runs the firmware's controller (configured from the
//! NOMINAL rig, as on a bench where the engineer's rig file is nominal) against that plant
//! and writes the bench log the diagnosis gets — and nothing else.
//!
//! A pair is mostly one hydraulic effect with one on the motor side, sometimes two
//! hydraulic ones that act differently. Every hidden effect's magnitude comes from a
//! realistic range and is kept only where its signature (effect on minus off, same rig
//! and test, the other effect of a pair present in both) is at least five times the
//! sensor noise on some logged signal ([`observability`]); otherwise the magnitudes, and
//! then the effects, are drawn again. This is the rule of the independent simulator's
//! `shared/data/foreign-logs-2/`, drawn here from this project's own plant.
//!
//! It shares no code with the diagnosis (`host_sim::diagnose`): it only uses the plant model,
//! the closed loop (`host_sim::run`, which is simulation) and the bench-log writer. The log
//! carries the single metadata line `# source: blind-suite` and a file name drawn from the
//! generator's stream, so neither the effects, their parameters, the seed nor the test's
//! name can leak through it (the test's commands are of course in `p_ref_pa` and
//! `speed_ref_rad_s`, as on a bench).
//!
//! Seeds: the suite's coverage seeds ([`COVERAGE`]) take their test and effects from a
//! table and draw the rest; the false-alarm seeds ([`NOTHING_HIDDEN_SEEDS`]) hide nothing
//! in each test in turn; every other seed draws everything, and [`HELD_OUT_SEEDS`] are
//! never run by the suite nor looked at while the suite or the diagnosis is changed.

mod bench_sensors;
mod catalogue;
pub mod cut;
pub mod judge;
mod observability;
mod structure;
pub mod table;
mod test_plan;

pub use bench_sensors::{read_through, LowSideTransducer, POSITION_RESOLUTION_M};
pub use catalogue::{acts_differently, halfway, possible_in, HYDRAULIC, MOTOR};
pub use observability::{
    check, noise_by_signal, noise_rms, shown, Checked, Shown, HALF_SCALING, MEASURED, SHOWN_RATIO,
};
pub use structure::{ControllerVariant, Structure};
pub use test_plan::{TestKind, FAST_RATES_HZ, LENGTH_S, RATES_HZ, TESTS};

use host_sim::bench_log;
use plant_model::Rig;
use std::ops::Range;
use std::path::{Path, PathBuf};

mod coverage;
mod drawn;
mod stream;
pub use coverage::{COVERAGE, NEVER_SHOWS};
pub use drawn::{Draw, Hidden, Truth};
use stream::Stream;
pub use stream::TOLERANCE;

/// Seeds of the false-alarm set: every one hides nothing, in the test `seed mod 4` of
/// [`TESTS`], on a rig drawn like the others (tolerances, structure, controller, columns,
/// rate, length). Disjoint from the coverage seeds.
pub const NOTHING_HIDDEN_SEEDS: Range<u64> = 1000..1012;

/// Seeds the suite never runs and nobody tunes on: the held-out part of the generator.
/// Each draws its test, rate, length, structure and hidden effects from its own stream
/// (`cargo run --release -p tests --example blind_table -- DIR FROM N`).
pub const HELD_OUT_SEEDS: Range<u64> = 1_000_000..2_000_000;

/// Every seed the identification suite runs: the coverage seeds `0..COVERAGE.len()`.
pub fn identification_seeds() -> Range<u64> {
    0..COVERAGE.len() as u64
}

/// Share of freely drawn logs hiding nothing, and hiding one effect (the rest hide a pair). [1]
const FREE_SHARES: (f64, f64) = (0.15, 0.5);

/// Share of freely drawn pairs made of two hydraulic effects (the rest: one hydraulic, one
/// motor-side). [1]
const HYDRAULIC_PAIR_SHARE: f64 = 0.25;

/// Magnitude draws tried in one frame (rig, test, rate, columns) before the frame is drawn
/// again.
const MAGNITUDE_TRIES: usize = 3;

/// Frames drawn for one seed before the generator gives up.
const FRAME_TRIES: usize = 4;

/// The nominal rig with every parameter that is a manufacturing or operating tolerance
/// (not a fault) scaled by an independent factor uniform in 1 ± 3 %: motor R_s, L_d, L_q,
/// ψ_f, the shaft's inertias and viscous friction, pump displacement and leakages, cylinder
/// leakage, oil bulk modulus, chamber volumes, absorber gas volume and precharge, payload
/// mass. The sensors' noise is drawn too: a bench's transducers are noisier or quieter than
/// the data sheet (0.7–1.5 × the nominal rms); the ADC quantisation is the converter's and
/// stays.
fn tolerance_rig(s: &mut Stream) -> Rig {
    let mut r = Rig::nominal();
    let (m, sh, p, c, a) = (
        &mut r.motor,
        &mut r.shaft,
        &mut r.pump,
        &mut r.cylinder,
        &mut r.absorber,
    );
    for x in [
        &mut m.r_s_ohm,
        &mut m.l_d_h,
        &mut m.l_q_h,
        &mut m.psi_f_wb,
        &mut sh.motor_inertia_kg_m2,
        &mut sh.pump_inertia_kg_m2,
        &mut sh.viscous_nm_s,
        &mut p.displacement_m3_per_rev,
        &mut p.internal_leakage_m3_s_pa,
        &mut p.external_leakage_m3_s_pa,
        &mut c.internal_leakage_m3_s_pa,
        &mut c.chamber_a_volume_m3,
        &mut c.chamber_b_volume_m3,
        &mut c.mass_kg,
        &mut r.oil.bulk_modulus_pa,
        &mut a.shell_volume_m3,
        &mut a.precharge_pa,
    ] {
        *x = s.tolerance(*x);
    }
    let sn = &mut r.sensors;
    sn.current.noise_a_rms *= s.uniform(0.7, 1.5);
    sn.pressure.noise_pa_rms *= s.uniform(0.7, 1.5);
    r
}

/// A bench of the nominal design built within its tolerances ([`tolerance_rig`]), drawn
/// from a stream of its own seeded with `seed`: the fleet generator's drives.
pub fn seeded_tolerance_rig(seed: u64) -> Rig {
    tolerance_rig(&mut Stream::seeded(seed))
}

/// The optional columns without which the hidden `effects` cannot be seen in `test`: on a
/// moving piston, its position for every effect of the pressure's volume balance and of
/// the piston's force balance (without it the pump's largest flow is unknown), and the low
/// side's pressure for the piston's friction (along a one-way stroke the Coulomb force and
/// an unknown fill pressure are the same constant pressure step). The generator never drops
/// them for such a draw; the false-alarm set drops them freely.
fn needed_columns(effects: &[&str], test: TestKind) -> Vec<&'static str> {
    let mut needed = Vec::new();
    if test != TestKind::Stroke {
        return needed;
    }
    for e in effects {
        if HYDRAULIC.contains(e) && *e != "piston_ripple" {
            needed.push("x_m");
        }
        if *e == "cylinder_friction" {
            needed.push("p_low_pa");
        }
    }
    needed
}

/// What a seed hides before its magnitudes are drawn.
enum Plan {
    /// A coverage seed: this test and these effects.
    Fixed(TestKind, &'static [&'static str]),
    /// A false-alarm seed: nothing, in this test.
    Nothing(TestKind),
    /// Everything from the stream.
    Free,
}

fn plan(seed: u64) -> Plan {
    if let Some((test, effects)) = COVERAGE.get(seed as usize) {
        Plan::Fixed(*test, effects)
    } else if NOTHING_HIDDEN_SEEDS.contains(&seed) {
        Plan::Nothing(TESTS[(seed % TESTS.len() as u64) as usize])
    } else {
        Plan::Free
    }
}

/// A free draw's effects in `test`: none, one of any family, or a pair, among the effects
/// that can show there (not in [`NEVER_SHOWS`]).
fn draw_effect_names(s: &mut Stream, test: TestKind) -> Vec<&'static str> {
    let possible = |family: &[&'static str]| -> Vec<&'static str> {
        family
            .iter()
            .copied()
            .filter(|e| possible_in(e, test) && !NEVER_SHOWS.contains(&(*e, test)))
            .collect()
    };
    let (hydraulic, motor) = (possible(&HYDRAULIC), possible(&MOTOR));
    let u = s.unit();
    if u < FREE_SHARES.0 {
        return Vec::new();
    }
    if u < FREE_SHARES.0 + FREE_SHARES.1 {
        let all: Vec<&str> = hydraulic.iter().chain(&motor).copied().collect();
        return vec![s.pick(&all)];
    }
    let first = s.pick(&hydraulic);
    if s.unit() < HYDRAULIC_PAIR_SHARE {
        let partners: Vec<&str> = hydraulic
            .iter()
            .copied()
            .filter(|h| acts_differently(first, h))
            .collect();
        if !partners.is_empty() {
            return vec![first, s.pick(&partners)];
        }
    }
    vec![first, s.pick(&motor)]
}

/// Draws everything of `seed` but the magnitudes from `s`: test, rig, structure, rate,
/// noise and, for a free seed, the effects (drawn after the rest).
fn frame(seed: u64, s: &mut Stream) -> Draw {
    let (test, fixed): (TestKind, Option<&[&str]>) = match plan(seed) {
        Plan::Fixed(t, e) => (t, Some(e)),
        Plan::Nothing(t) => (t, Some(&[])),
        Plan::Free => (s.pick(&TESTS), None),
    };
    let mut tolerance_rig = tolerance_rig(s);
    let scenario = test_plan::draw_test(s, test);
    let log_rate_hz = test_plan::draw_log_rate(s);
    let noise_seed = s.next_u64();
    let token = s.next_u64();
    let names: Vec<&'static str> = match fixed {
        Some(e) => e.to_vec(),
        None => draw_effect_names(s, test),
    };
    let structure = structure::draw_structure(s, &needed_columns(&names, test));
    structure.apply(&mut tolerance_rig);
    let low_side = LowSideTransducer::like_the_drives(&tolerance_rig, s.uniform(-20e3, 20e3));
    let draw = Draw {
        truth: Truth {
            effects: names
                .iter()
                .map(|n| Hidden {
                    name: n,
                    parameters: Vec::new(),
                    signal: "",
                    ratio: 0.0,
                })
                .collect(),
            test: test.name(),
            log_rate_hz,
            duration_s: scenario.duration_s,
            dropped: structure.dropped.clone(),
        },
        effects: Vec::new(),
        tolerance_rig,
        structure,
        low_side,
        scenario,
        log_rate_hz,
        noise_seed,
        token,
    };
    draw
}

/// `d` hiding `names` at magnitudes drawn from `s`.
fn with_magnitudes(d: &Draw, names: &[&'static str], s: &mut Stream) -> Draw {
    let mut d = d.clone();
    d.effects = names.iter().map(|n| catalogue::draw_effect(n, s)).collect();
    d.truth.effects = d
        .effects
        .iter()
        .map(|e| Hidden {
            name: e.name(),
            parameters: e.parameters().into_iter().flatten().collect(),
            signal: "",
            ratio: 0.0,
        })
        .collect();
    d
}

/// The accepted draw of `seed` and its check (with the log it produced): magnitudes drawn
/// until every hidden effect shows ([`SHOWN_RATIO`]), [`MAGNITUDE_TRIES`] at a time; then
/// the whole frame is drawn again from the seed's stream (for a coverage or false-alarm
/// seed its test and effects stay, its rig, test parameters, rate and columns change; a
/// free seed draws everything again), up to [`FRAME_TRIES`] frames. A coverage seed whose
/// effects never show is an error: its row claims what the test cannot show.
pub fn draw(seed: u64) -> Result<(Draw, Checked), String> {
    let mut s = Stream::seeded(seed);
    let mut tried = Vec::new();
    let mut test = "";
    for _ in 0..FRAME_TRIES {
        let base = frame(seed, &mut s);
        test = base.truth.test;
        let names: Vec<&'static str> = base.truth.effects.iter().map(|h| h.name).collect();
        for _ in 0..MAGNITUDE_TRIES {
            let d = with_magnitudes(&base, &names, &mut s);
            let checked = check(&d)?;
            if checked.every_effect_shows() {
                let mut d = d;
                for (h, m) in d.truth.effects.iter_mut().zip(&checked.shown) {
                    h.signal = m.signal.name();
                    h.ratio = m.ratio;
                }
                return Ok((d, checked));
            }
            tried.push(format!(
                "{}: {:?}: {:?}",
                d.truth.test, d.effects, checked.shown
            ));
        }
    }
    Err(format!(
        "seed {seed}: no draw shows {SHOWN_RATIO}× the noise (scaling with the effect) in the \
         {test} test; tried:\n{}",
        tried.join("\n")
    ))
}

/// What `seed` hides and how it is logged, without simulating anything: the test, rate,
/// length, dropped columns and effect names of its first frame (which [`draw`] replaces
/// when no magnitude shows in it); no parameters or signals yet.
pub fn outline(seed: u64) -> Truth {
    let mut s = Stream::seeded(seed);
    frame(seed, &mut s).truth
}

/// Generates the log of `seed` into `dir`: returns its path and the truth.
pub fn generate(seed: u64, dir: &Path) -> Result<(PathBuf, Truth), String> {
    let (d, checked) = draw(seed)?;
    let mut log = checked.log;
    d.structure.drop_columns(&mut log);
    let path = dir.join(format!("blind-{:016x}.csv", d.token));
    bench_log::write(&path, &log).map_err(|e| e.to_string())?;
    Ok((path, d.truth))
}
