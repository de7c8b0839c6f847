//! The hydraulic side's parameters: the axial piston pump (eq. 9, 20–21), the cylinder with
//! its payload (eq. 10–12), the oil, the pulsation absorber (eq. 22–26) and the fill
//! accumulator with its check and relief valves.

use core::f64::consts::PI;

/// Fixed-displacement axial piston pump (eq. 9, 20–21).
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct PumpParams {
    /// Displacement D_p. [m³/rev]
    pub displacement_m3_per_rev: f64,
    /// Pistons z (odd or even). [1]
    pub pistons: u32,
    /// Kinematic flow ripple of eq. 20 on or off (off: ideal flow D_p·ω).
    pub piston_ripple: bool,
    /// Peak-to-peak flow ripple over mean flow when the ripple is on; 0 means the kinematic
    /// value of eq. 20 for `pistons` (the shape is always the kinematic one). [1]
    pub ripple_amplitude_ratio: f64,
    /// Internal (port-to-port) leakage C_ip. [(m³/s)/Pa]
    pub internal_leakage_m3_s_pa: f64,
    /// External (port-to-case) leakage C_ep. [(m³/s)/Pa]
    pub external_leakage_m3_s_pa: f64,
    /// Extra leakage from the high-pressure port A to the case beyond C_ep (effect
    /// `extra_leakage`); 0 is off. [(m³/s)/Pa]
    pub extra_leakage_m3_s_pa: f64,
}

impl PumpParams {
    /// Displacement per radian D_p/(2π). [m³/rad]
    pub fn displacement_m3_per_rad(&self) -> f64 {
        self.displacement_m3_per_rev / (2.0 * PI)
    }
}

/// Double-acting symmetric cylinder and its load (eq. 11–12).
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct CylinderParams {
    /// Effective piston area, each side, A_p. [m²]
    pub area_m2: f64,
    /// Chamber 1 (port A side) volume at mid-stroke, lines included, V_10. [m³]
    pub chamber_a_volume_m3: f64,
    /// Chamber 2 (port B side) volume at mid-stroke, lines included, V_20. [m³]
    pub chamber_b_volume_m3: f64,
    /// Cross-piston leakage C_ic. [(m³/s)/Pa]
    pub internal_leakage_m3_s_pa: f64,
    /// Viscous damping B_p. [N·s/m]
    pub viscous_n_s_per_m: f64,
    /// Static (breakaway) friction F_s. [N]
    pub static_friction_n: f64,
    /// Coulomb (sliding) friction F_c. [N]
    pub coulomb_friction_n: f64,
    /// Payload mass referred to the piston m_t. [kg]
    pub mass_kg: f64,
    /// Half stroke: hard end stops at ±this about mid-stroke (*assumed*). [m]
    pub half_stroke_m: f64,
    /// End-stop contact stiffness (*assumed*). [N/m]
    pub end_stop_stiffness_n_per_m: f64,
    /// End-stop contact damping (*assumed*). [N·s/m]
    pub end_stop_damping_n_s_per_m: f64,
    /// Load spring K of eq. 12; 0 is off. [N/m]
    pub spring_n_per_m: f64,
    /// Inclination of the stroke axis from horizontal; gravity pulls the load towards −x
    /// with m·g·sin(angle). 0 is off. [rad]
    pub gravity_angle_rad: f64,
    /// Pressure-holding configuration: the piston is held at mid-stroke.
    pub blocked: bool,
}

/// Hydraulic oil.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct OilParams {
    /// Effective bulk modulus β_e. [Pa]
    pub bulk_modulus_pa: f64,
    /// Density ρ (*assumed*). [kg/m³]
    pub density_kg_m3: f64,
}

/// Gas-loaded bladder pulsation absorber on port A (eq. 22–26).
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct AbsorberParams {
    /// Absorber fitted (false: the "without accumulator" reference run).
    pub enabled: bool,
    /// Shell volume = gas volume at precharge V_0. [m³]
    pub shell_volume_m3: f64,
    /// Gas precharge p_0 (gauge). [Pa]
    pub precharge_pa: f64,
    /// Polytropic exponent n. [1]
    pub polytropic_exponent: f64,
    /// Oil inertance of the inlet, ρ·l/A (*assumed*: 12 mm port, 50 mm long). [kg/m⁴]
    pub inlet_inertance_kg_m4: f64,
    /// Linearised inlet and bladder loss resistance (*assumed*: damping ratio ≈ 0.15 at the
    /// nominal precharge and 5 MPa). [Pa·s/m³]
    pub inlet_resistance_pa_s_m3: f64,
}

/// Low-side fill (boost) accumulator with its check valves, and the relief valves.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct FillParams {
    /// Fill pressure p_r at the start of a run (*assumed*). [Pa]
    pub pressure_pa: f64,
    /// Gas precharge of the fill accumulator (*assumed*). [Pa]
    pub precharge_pa: f64,
    /// Shell volume of the fill accumulator (*assumed*). [m³]
    pub shell_volume_m3: f64,
    /// Polytropic exponent of its gas. [1]
    pub polytropic_exponent: f64,
    /// Check-valve cracking pressure, fill to port (*assumed*). [Pa]
    pub check_cracking_pa: f64,
    /// Check-valve conductance above cracking (*assumed*). [(m³/s)/Pa]
    pub check_conductance_m3_s_pa: f64,
    /// Relief-valve cracking pressure, each port to the fill side (*assumed*). [Pa]
    pub relief_cracking_pa: f64,
    /// Relief-valve conductance above cracking (*assumed*). [(m³/s)/Pa]
    pub relief_conductance_m3_s_pa: f64,
}

/// Standard gravity. [m/s²]
pub const GRAVITY_M_S2: f64 = 9.80665;
