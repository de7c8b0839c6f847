//! The rig's tests: the nominal rig against the contract's numbers, and each invalid
//! parameter named.

use super::*;

#[test]
fn nominal_rig_is_valid_and_matches_the_contract() {
    let r = Rig::nominal();
    assert_eq!(r.validate(), Ok(()));
    // nominal-rig.md: K_t = 1.5·p_n·ψ_f = 1.0962 N·m/A; J = 8.0e-4 kg·m²; N_cog = 72.
    assert!((r.motor.torque_constant_nm_per_a() - 1.0962).abs() < 1e-4);
    assert!((r.shaft.inertia_kg_m2() - 8.0e-4).abs() < 1e-9);
    assert_eq!(r.motor.cogging_fundamental_order(), 72);
    // U_dc/√3 is Table 1's 161.6 V current-PI limit.
    assert!((r.inverter.u_dc_v / 3f64.sqrt() - 161.6).abs() < 0.1);
}

#[test]
fn invalid_parameters_are_named() {
    let mut r = Rig::nominal();
    r.cylinder.chamber_a_volume_m3 = -1e-4;
    assert_eq!(
        r.validate().unwrap_err().parameter,
        "cylinder.chamber_a_volume_m3"
    );
    let mut r = Rig::nominal();
    r.pump.pistons = 0;
    assert_eq!(r.validate().unwrap_err().parameter, "pump.pistons");
    let mut r = Rig::nominal();
    r.oil.bulk_modulus_pa = f64::NAN;
    let e = r.validate().unwrap_err();
    assert_eq!(e.parameter, "oil.bulk_modulus_pa");
    assert!(e.reason.contains("finite"));
    let mut r = Rig::nominal();
    r.motor.flux_harmonics[0].amplitude_wb = 0.01;
    r.motor.flux_harmonics[0].order = 3;
    assert_eq!(
        r.validate().unwrap_err().parameter,
        "motor.flux_harmonics.order"
    );
    let mut r = Rig::nominal();
    r.absorber.precharge_pa = f64::INFINITY;
    assert_eq!(r.validate().unwrap_err().parameter, "absorber.precharge_pa");
}

#[test]
fn values_beyond_any_actuator_are_named() {
    // A step far below a microsecond makes a simulated second cost millions of steps.
    for step in [1e-30, 1e-9] {
        let mut r = Rig::nominal();
        r.integration.max_step_s = step;
        let e = r.validate().unwrap_err();
        assert_eq!(e.parameter, "integration.max_step_s");
        assert!(e.reason.contains("1e-6"), "{}", e.reason);
    }
    let mut r = Rig::nominal();
    r.absorber.precharge_pa = 1e30;
    assert_eq!(r.validate().unwrap_err().parameter, "absorber.precharge_pa");
    let mut r = Rig::nominal();
    r.cylinder.mass_kg = 1e30;
    assert_eq!(r.validate().unwrap_err().parameter, "cylinder.mass_kg");
    let mut r = Rig::nominal();
    r.motor.cogging[0].phase_rad = -1e30;
    assert_eq!(
        r.validate().unwrap_err().parameter,
        "motor.cogging.phase_rad"
    );
}
