//! What `eha tune` reports: the `--json` document (`contracts/eha-cli.md`) and the text on
//! standard output, both with the CAN commands that apply the proposal.

use super::can;
use super::step::{StepMetrics, Target};
use super::tuning::{Identified, LoopKind, Tuning};
use serde_json::{json, Value};
use std::fmt::Write as _;

fn metrics_json(m: &StepMetrics, target: &Target) -> Value {
    json!({
        "overshoot_percent": m.overshoot_percent,
        "settling_s": m.settling_s,
        "meets_target": m.meets(target),
    })
}

impl Tuning {
    /// The `--json` document (`contracts/eha-cli.md`; `settling_s` is null for a response
    /// that has not settled by the end of its window).
    pub fn to_json(&self, commands: &[String]) -> Value {
        let identified = match &self.identified {
            Identified::Speed {
                shaft,
                assumed_inertia_kg_m2,
                assumed_viscous_nm_s,
            } => json!({
                "inertia_kg_m2": shaft.inertia_kg_m2,
                "viscous_nm_s": shaft.viscous_nm_s,
                "load_nm": shaft.load_nm,
                "fit_percent": shaft.fit_percent,
                "assumed_inertia_kg_m2": assumed_inertia_kg_m2,
                "assumed_viscous_nm_s": assumed_viscous_nm_s,
            }),
            Identified::Pressure {
                high,
                assumed_precharge_pa,
                assumed_oil_capacitance_m3_per_pa,
                capacitance_m3_per_pa,
                assumed_capacitance_m3_per_pa,
            } => json!({
                "capacitance_m3_per_pa": capacitance_m3_per_pa,
                "assumed_capacitance_m3_per_pa": assumed_capacitance_m3_per_pa,
                "at_pressure_pa": self.step.to,
                "oil_capacitance_m3_per_pa": high.oil_capacitance_m3_per_pa,
                "assumed_oil_capacitance_m3_per_pa": assumed_oil_capacitance_m3_per_pa,
                "precharge_pa": high.precharge_pa,
                "precharge_is_lower_bound": high.precharge_is_lower_bound,
                "assumed_precharge_pa": assumed_precharge_pa,
                "leakage_m3_per_s_pa": high.leakage_m3_per_s_pa,
                "max_pressure_pa": high.max_pressure_pa,
                "fit_percent": high.fit_percent,
            }),
        };
        let parameters: serde_json::Map<String, Value> = self
            .settings
            .iter()
            .map(|s| (s.id.name().to_string(), json!(s.value)))
            .collect();
        json!({
            "loop": loop_name(self.loop_kind),
            "step": {"from": self.step.from, "to": self.step.to, "t_s": self.step_time_s},
            "target": {
                "overshoot_percent": self.target.overshoot_percent,
                "settling_s": self.target.settling_s,
            },
            "identified": identified,
            "current_gains": {"kp": self.current_gains.kp, "ki": self.current_gains.ki},
            "proposed_gains": {"kp": self.proposed_gains.kp, "ki": self.proposed_gains.ki},
            "proposed_parameters": parameters,
            "measured": metrics_json(&self.measured, &self.target),
            "predicted": metrics_json(&self.predicted, &self.target),
            "current_replayed": metrics_json(&self.replayed_current, &self.target),
            "can_commands": commands,
            "notes": self.notes,
        })
    }

    /// The report printed on standard output.
    pub fn to_text(&self, commands: &[String]) -> String {
        let mut s = String::new();
        let (unit, scale) = match self.loop_kind {
            LoopKind::Speed => ("rad/s", 1.0),
            LoopKind::Pressure => ("MPa", 1e-6),
        };
        let _ = writeln!(
            s,
            "{} loop: step {:.2} → {:.2} {unit} at {:.3} s",
            loop_name(self.loop_kind),
            self.step.from * scale,
            self.step.to * scale,
            self.step_time_s
        );
        s.push_str(&self.identified_text());
        let settle = |m: &StepMetrics| {
            m.settling_s
                .map_or("not settled".to_string(), |v| format!("{v:.3} s"))
        };
        let _ = writeln!(
            s,
            "{:<44} {:>11} {:>11} {:>10} {:>12}",
            "", "kp", "ki", "overshoot", "settling"
        );
        let rows = [
            (
                "current gains, measured in the log",
                self.current_gains,
                &self.measured,
            ),
            (
                "current gains, replayed on identified plant",
                self.current_gains,
                &self.replayed_current,
            ),
            (
                "proposed gains, predicted",
                self.proposed_gains,
                &self.predicted,
            ),
        ];
        for (name, g, m) in rows {
            let _ = writeln!(
                s,
                "{name:<44} {:>11.4e} {:>11.4e} {:>8.1} % {:>12}",
                g.kp,
                g.ki,
                m.overshoot_percent,
                settle(m)
            );
        }
        let _ = writeln!(
            s,
            "{:<44} {:>11} {:>11} {:>8.1} % {:>10.3} s",
            "target (at most)", "", "", self.target.overshoot_percent, self.target.settling_s
        );
        for n in &self.notes {
            let _ = writeln!(s, "note: {n}");
        }
        let _ = writeln!(s, "CAN commands (cansend, node {}):", can::NODE);
        for c in commands {
            let _ = writeln!(s, "  {c}");
        }
        s
    }

    /// The identified plant's line of the report.
    fn identified_text(&self) -> String {
        let mut s = String::new();
        match &self.identified {
            Identified::Speed {
                shaft,
                assumed_inertia_kg_m2,
                ..
            } => {
                let _ = writeln!(
                    s,
                    "identified: inertia {:.3e} kg·m² ({:.2}× the rig's {:.3e}), viscous {:.2e} \
                     N·m·s, load {:.3} N·m; fit {:.1} %",
                    shaft.inertia_kg_m2,
                    shaft.inertia_kg_m2 / assumed_inertia_kg_m2,
                    assumed_inertia_kg_m2,
                    shaft.viscous_nm_s,
                    shaft.load_nm,
                    shaft.fit_percent
                );
            }
            Identified::Pressure {
                high,
                assumed_precharge_pa,
                capacitance_m3_per_pa,
                assumed_capacitance_m3_per_pa,
                ..
            } => {
                let _ = writeln!(
                    s,
                    "identified: capacitance at {:.2} MPa {:.3e} m³/Pa (the schedule assumes \
                     {:.3e}, {:.1}×); oil {:.3e} m³/Pa, leakage {:.2e} (m³/s)/Pa, absorber \
                     precharge {}{:.2} MPa (assumed {:.2} MPa); fit {:.1} %",
                    self.step.to * 1e-6,
                    capacitance_m3_per_pa,
                    assumed_capacitance_m3_per_pa,
                    assumed_capacitance_m3_per_pa / capacitance_m3_per_pa,
                    high.oil_capacitance_m3_per_pa,
                    high.leakage_m3_per_s_pa,
                    if high.precharge_is_lower_bound {
                        "> "
                    } else {
                        ""
                    },
                    high.precharge_pa * 1e-6,
                    assumed_precharge_pa * 1e-6,
                    high.fit_percent
                );
            }
        }
        s
    }
}

/// The loop's name in the JSON and the text.
pub fn loop_name(kind: LoopKind) -> &'static str {
    match kind {
        LoopKind::Speed => "speed",
        LoopKind::Pressure => "pressure",
    }
}
