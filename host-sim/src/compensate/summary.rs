//! What `eha compensate` reports of a run: the printed summary — the effects learned, the
//! table written, the speed modulation, the pulsation predicted on the paper's holding
//! without and with the feed-forward, the CAN frames that load it — and the JSON of the
//! `eha` CLI contract.

use super::args::CompensateArgs;
use super::can;
use super::learn::Learned;
use super::outcome::Outcome;
use super::predict::reduction_percent;
use firmware::can_protocol::{Frame, NodeId};
use firmware::compensation::record;
use firmware::compensation::{Channel, BINS};
use serde_json::{json, Value};
use std::fmt::Write as _;

/// What the table file and the CAN frames came to, for the summary.
pub(super) struct Written<'a> {
    /// Length of the table file written to `--out`. [bytes]
    pub file_len: usize,
    /// The node the frames address.
    pub node: NodeId,
    /// The frames loading, enabling and saving the feed-forward.
    pub frames: &'a [Frame],
}

/// The learned effects that went into the table: those `exclude` does not name.
pub(super) fn in_table(outcome: &Outcome, exclude: &[String]) -> Vec<Learned> {
    outcome
        .found
        .effects
        .iter()
        .filter(|l| !exclude.iter().any(|x| x == l.effect.name()))
        .cloned()
        .collect()
}

/// One line per learned effect: name, Λ, logs, fitted parameters.
fn effect_lines(effects: &[Learned]) -> String {
    let mut s = String::from("effect                      Λ  fits  parameters\n");
    for l in effects {
        let params: Vec<String> = l
            .effect
            .parameters()
            .iter()
            .flatten()
            .map(|(k, v)| format!("{k}={v:.4e}"))
            .collect();
        let _ = writeln!(
            s,
            "{:<22} {:>7.0} {:>5}  {}",
            l.effect.name(),
            l.score,
            l.diagnoses,
            params.join(" ")
        );
    }
    if effects.is_empty() {
        s.push_str("(none significant: the table is empty)\n");
    }
    s
}

/// The printed summary of a run on `logs` log(s): effects, table, modulation, predicted
/// pulsation and the CAN frames in `cansend` notation.
pub(super) fn text(
    args: &CompensateArgs,
    logs: usize,
    outcome: &Outcome,
    in_table: &[Learned],
    written: &Written<'_>,
) -> String {
    let mut text = String::new();
    let _ = writeln!(
        text,
        "{} method from {logs} log(s); effects learned:",
        args.method.name()
    );
    text.push_str(&effect_lines(in_table));
    if in_table.len() < outcome.found.effects.len() {
        let _ = writeln!(text, "(left out of the table: {})", args.exclude.join(", "));
    }
    push_table_and_flow(&mut text, args, outcome, written.file_len);
    push_prediction(&mut text, outcome);
    let _ = writeln!(
        text,
        "CAN frames loading, enabling and saving it on node {} ({} frames):",
        written.node.get(),
        written.frames.len()
    );
    text.push_str(&can::cansend_lines(written.frames));
    text
}

/// The table's line (peaks, file, length, CRC) and the speed modulation's.
fn push_table_and_flow(text: &mut String, args: &CompensateArgs, outcome: &Outcome, len: usize) {
    let table = &outcome.ff.table;
    let peak = table.peak();
    let _ = writeln!(
        text,
        "table: {BINS} bins; peaks {:.4} A, {:.3e} A/Pa, {:.4} A/A; written to {} ({} bytes, record CRC {:#010x})",
        peak[Channel::Constant as usize],
        peak[Channel::PerPressure as usize],
        peak[Channel::PerCurrent as usize],
        args.out.display(),
        len,
        record::crc_of(table)
    );
    match &outcome.ff.flow {
        Some(f) => {
            let _ = writeln!(
                text,
                "speed modulation against the pump's flow ripple: {} pistons, {:.3} % peak-to-peak, phase {:.3} rad, J = {:.3e} kg·m²",
                f.pistons,
                100.0 * f.ratio,
                f.phase_rad,
                f.inertia_kg_m2
            );
        }
        None => {
            let _ = writeln!(text, "speed modulation against the pump's flow ripple: off");
        }
    }
}

/// The predicted pulsation on the holding, without and with the feed-forward, and the
/// reduction of each figure.
fn push_prediction(text: &mut String, outcome: &Outcome) {
    let (without, with) = (&outcome.without, &outcome.with);
    let _ = writeln!(
        text,
        "predicted, holding at 5 MPa on the rig with the learned effects (true signals, steady part):"
    );
    let _ = writeln!(
        text,
        "                          without       with  reduction"
    );
    for (name, w, t, unit) in [
        (
            "pressure pp",
            without.pressure_pp_pa,
            with.pressure_pp_pa,
            "Pa",
        ),
        (
            "pressure locked pp",
            without.pressure_locked_pp_pa,
            with.pressure_locked_pp_pa,
            "Pa",
        ),
        (
            "speed pp",
            without.speed_pp_rad_s,
            with.speed_pp_rad_s,
            "rad/s",
        ),
        (
            "speed locked pp",
            without.speed_locked_pp_rad_s,
            with.speed_locked_pp_rad_s,
            "rad/s",
        ),
    ] {
        let _ = writeln!(
            text,
            "  {name:<20} {w:>10.3} {t:>10.3} {:>8.0} %  [{unit}]",
            reduction_percent(w, t)
        );
    }
}

/// The results as the JSON of the `eha` CLI contract.
pub(super) fn json(args: &CompensateArgs, outcome: &Outcome, in_table: &[Learned]) -> Value {
    let (without, with) = (&outcome.without, &outcome.with);
    let table = &outcome.ff.table;
    let peak = table.peak();
    json!({
        "method": args.method.name(),
        "effects": in_table.iter().map(|e| e.effect.name()).collect::<Vec<_>>(),
        "table_bins": BINS,
        "predicted": {
            "pressure_pp_pa": {"without": without.pressure_pp_pa, "with": with.pressure_pp_pa},
            "speed_pp_rad_s": {"without": without.speed_pp_rad_s, "with": with.speed_pp_rad_s},
            "pressure_angle_locked_pp_pa": {"without": without.pressure_locked_pp_pa, "with": with.pressure_locked_pp_pa},
            "speed_angle_locked_pp_rad_s": {"without": without.speed_locked_pp_rad_s, "with": with.speed_locked_pp_rad_s},
        },
        "table_crc": record::crc_of(table),
        "flow_ripple": outcome.ff.flow.map(|f| json!({
            "pistons": f.pistons,
            "ratio": f.ratio,
            "phase_rad": f.phase_rad,
            "inertia_kg_m2": f.inertia_kg_m2,
        })),
        "table_peaks": {"constant_a": peak[0], "per_pressure_a_per_pa": peak[1], "per_current": peak[2]},
        "logs": args.logs.iter().map(|p| p.display().to_string()).collect::<Vec<_>>(),
    })
}
