//! The drive's speed modulation against the pump's kinematic flow ripple
//! ([`firmware::compensation::flow`]) as `eha compensate` learns it and the table file
//! carries it: the piston count and peak-to-peak ratio of the diagnosis's `piston_ripple`
//! effect, the shape's phase against the encoder's angle, and the shaft inertia of the
//! rig file for the acceleration current. They are live parameters of the drive (ids
//! 64–67), loaded with `SetParameter` frames and kept by `SaveParameters`.
//!
//! The catalogue's `piston_ripple` is referenced to the logged shaft angle with the pump's
//! piston 0 at its zero (the plant's convention) and carries no phase: the phase written
//! is 0. A rig whose pump sits otherwise against the encoder's index needs
//! `compensation.flow_phase_rad` set by hand.
//!
//! # Table file trailer (little endian)
//!
//! A table file is the drive's table record ([`firmware::compensation::record`]),
//! optionally followed by the live parameters that go with it:
//!
//! | offset | size | content                                            |
//! |--------|------|----------------------------------------------------|
//! | 0      | 4    | magic `0x5043_4845` (bytes `E H C P`)              |
//! | 4      | 2    | format version ([`TRAILER_VERSION`])               |
//! | 6      | 2    | number N of parameters                              |
//! | 8      | 8·N  | per parameter: wire id (u32), value (f32)           |
//! | 8+8N   | 4    | CRC-32 (ISO-HDLC) of bytes 0‥8+8N                  |
//!
//! The id field is read whole: the drive's wire ids fit in its low byte, and an id beyond
//! them (320 is not 64) is an unknown parameter, named as written. Only the modulation's
//! parameters ([`FLOW_IDS`]) may appear, each once, each within its bounds. A file without a trailer is a table alone (the modulation off), as before.

use firmware::compensation::record::CRC;
use firmware::parameters::ParamId;
use firmware::Config;
use plant_model::pump::kinematic_ripple_ratio;
use plant_model::{Effect, Rig};

/// Trailer magic (`E H C P` in memory order).
pub const TRAILER_MAGIC: u32 = 0x5043_4845;
/// Trailer format version.
pub const TRAILER_VERSION: u16 = 1;

/// The parameters a table file may set, in the order written.
pub const FLOW_IDS: [ParamId; 4] = [
    ParamId::CompensationFlowPistons,
    ParamId::CompensationFlowRatio,
    ParamId::CompensationFlowPhase,
    ParamId::CompensationInertia,
];

/// Name under which `--exclude` leaves the speed modulation out.
pub const EXCLUDE_NAME: &str = "flow_ripple";

/// The modulation's parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlowParams {
    /// Pistons z. [1]
    pub pistons: u32,
    /// Peak-to-peak flow ripple over mean flow. [1]
    pub ratio: f64,
    /// Phase of the shape against the encoder's angle, in [0, 2π). [rad]
    pub phase_rad: f64,
    /// Shaft inertia (motor and pump). [kg·m²]
    pub inertia_kg_m2: f64,
}

impl FlowParams {
    /// From a `piston_ripple` effect (its ratio 0 meaning the kinematic one, as in the
    /// plant) on a shaft of `rig`'s inertia; `None` for any other effect.
    pub fn of_effect(effect: &Effect, rig: &Rig) -> Option<FlowParams> {
        let Effect::PistonRipple {
            pistons,
            amplitude_ratio,
        } = *effect
        else {
            return None;
        };
        Some(FlowParams {
            pistons,
            ratio: if amplitude_ratio > 0.0 {
                amplitude_ratio
            } else {
                kinematic_ripple_ratio(pistons)
            },
            phase_rad: 0.0,
            inertia_kg_m2: rig.shaft.inertia_kg_m2(),
        })
    }

    /// The plant's own pump ripple (the ideal), if it has one.
    pub fn of_rig(rig: &Rig) -> Option<FlowParams> {
        if !rig.pump.piston_ripple {
            return None;
        }
        FlowParams::of_effect(
            &Effect::PistonRipple {
                pistons: rig.pump.pistons,
                amplitude_ratio: rig.pump.ripple_amplitude_ratio,
            },
            rig,
        )
    }

    /// The live parameters, in [`FLOW_IDS`] order.
    pub fn parameters(&self) -> [(ParamId, f32); 4] {
        [
            (FLOW_IDS[0], self.pistons as f32),
            (FLOW_IDS[1], self.ratio as f32),
            (FLOW_IDS[2], self.phase_rad as f32),
            (FLOW_IDS[3], self.inertia_kg_m2 as f32),
        ]
    }

    /// Writes them into `cfg` as the drive takes them (bounds, cross-checks and the
    /// modulation depth's bound); the refusal names the parameter and its bound.
    pub fn apply(&self, cfg: &mut Config) -> Result<(), String> {
        for (id, v) in self.parameters() {
            let c = &cfg.compensation;
            let depth = c.scale * v;
            if id == ParamId::CompensationFlowRatio && depth > c.max_flow_ratio {
                return Err(format!(
                    "{id}: modulation depth {depth} (scale {} × ratio {v}) exceeds \
                     compensation.max_flow_ratio = {}",
                    c.scale, c.max_flow_ratio
                ));
            }
            id.set(cfg, v).map_err(|e| e.to_string())?;
        }
        Ok(())
    }

    /// The trailer's bytes.
    pub fn trailer(&self) -> Vec<u8> {
        let p = self.parameters();
        let mut b = Vec::with_capacity(12 + 8 * p.len());
        b.extend_from_slice(&TRAILER_MAGIC.to_le_bytes());
        b.extend_from_slice(&TRAILER_VERSION.to_le_bytes());
        b.extend_from_slice(&(p.len() as u16).to_le_bytes());
        for (id, v) in p {
            b.extend_from_slice(&u32::from(id.code()).to_le_bytes());
            b.extend_from_slice(&v.to_le_bytes());
        }
        let crc = CRC.checksum(&b);
        b.extend_from_slice(&crc.to_le_bytes());
        b
    }

    /// Decodes a trailer (every field checked; the error says what is wrong).
    pub fn from_trailer(b: &[u8]) -> Result<FlowParams, String> {
        let u16_at = |at: usize| u16::from_le_bytes([b[at], b[at + 1]]);
        let u32_at = |at: usize| u32::from_le_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]]);
        if b.len() < 12 {
            return Err(format!(
                "parameter trailer of {} bytes is too short",
                b.len()
            ));
        }
        if u32_at(0) != TRAILER_MAGIC {
            return Err("bytes after the table record are not a parameter trailer".into());
        }
        if u16_at(4) != TRAILER_VERSION {
            return Err(format!(
                "parameter trailer version {} (this eha reads {TRAILER_VERSION})",
                u16_at(4)
            ));
        }
        let n = usize::from(u16_at(6));
        if b.len() != 12 + 8 * n {
            return Err(format!(
                "parameter trailer of {} bytes for {n} parameters (expected {})",
                b.len(),
                12 + 8 * n
            ));
        }
        if CRC.checksum(&b[..8 + 8 * n]) != u32_at(8 + 8 * n) {
            return Err("parameter trailer CRC mismatch".into());
        }
        let mut values: [Option<f32>; 4] = [None; 4];
        for k in 0..n {
            let at = 8 + 8 * k;
            let code = u32_at(at);
            let id = u8::try_from(code)
                .ok()
                .and_then(ParamId::from_code)
                .ok_or_else(|| format!("parameter trailer: unknown parameter id {code}"))?;
            let slot = FLOW_IDS
                .iter()
                .position(|f| *f == id)
                .ok_or_else(|| format!("parameter trailer: {id} is not the table's to set"))?;
            if values[slot].is_some() {
                return Err(format!("parameter trailer: {id} twice"));
            }
            let v = f32::from_bits(u32_at(at + 4));
            id.check(v).map_err(|e| format!("parameter trailer: {e}"))?;
            values[slot] = Some(v);
        }
        let [Some(z), Some(r), Some(ph), Some(j)] = values else {
            return Err(format!(
                "parameter trailer: needs each of {}",
                FLOW_IDS.map(|f| f.name()).join(", ")
            ));
        };
        Ok(FlowParams {
            pistons: z as u32,
            ratio: r as f64,
            phase_rad: ph as f64,
            inertia_kg_m2: j as f64,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn nominal() -> FlowParams {
        FlowParams {
            pistons: 9,
            ratio: 0.0152,
            phase_rad: 0.1,
            inertia_kg_m2: 8e-4,
        }
    }

    #[test]
    fn a_trailer_round_trips_and_is_laid_out_as_documented() {
        let t = nominal().trailer();
        assert_eq!(t.len(), 12 + 8 * 4);
        assert_eq!(&t[..4], b"EHCP");
        assert_eq!(t[8], 64);
        assert_eq!(f32::from_le_bytes(t[12..16].try_into().unwrap()), 9.0);
        let back = FlowParams::from_trailer(&t).unwrap();
        assert_eq!(back.pistons, 9);
        assert!((back.ratio - 0.0152).abs() < 1e-9);
    }

    #[test]
    fn a_bad_trailer_says_what_is_wrong() {
        let t = nominal().trailer();
        let mut crc = t.clone();
        crc[13] ^= 1;
        assert!(FlowParams::from_trailer(&crc).unwrap_err().contains("CRC"));
        assert!(FlowParams::from_trailer(&t[..20])
            .unwrap_err()
            .contains("bytes"));
        let mut gains = FlowParams::from_trailer(&t).unwrap().trailer();
        gains[8] = ParamId::SpeedKp.code();
        let n = gains.len();
        let crc = CRC.checksum(&gains[..n - 4]);
        gains[n - 4..].copy_from_slice(&crc.to_le_bytes());
        assert!(FlowParams::from_trailer(&gains)
            .unwrap_err()
            .contains("not the table's"));
    }

    #[test]
    fn a_depth_over_the_bound_is_refused_naming_it() {
        let mut cfg = Config::nominal();
        let deep = FlowParams {
            ratio: 0.2,
            ..nominal()
        };
        let e = deep.apply(&mut cfg).unwrap_err();
        assert!(e.contains("compensation.max_flow_ratio = 0.1"), "{e}");
        nominal().apply(&mut cfg).unwrap();
        assert_eq!(cfg.compensation.flow_pistons, 9);
    }
}
