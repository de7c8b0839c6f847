use closed_loop::*;
use plant_model::Rig;
fn main() {
    let name = std::env::args().nth(1).unwrap_or("pressure-hold".into());
    let sc = by_name(&name).unwrap();
    let rig = Rig::nominal();
    let cfg = controller_config(&rig);
    let mut cl = ClosedLoop::new(&rig, &cfg, sc, 1).unwrap();
    let t0 = std::time::Instant::now();
    cl.run(sc.duration_s, 1000, |s| {
        let t = &s.telemetry;
        println!("t {:.3} p_ref {:.3} p {:.4} truth {:.4} w {:.2} wref {:.2} iq {:.2} id {:.2} mode {:?} fault {:?} x {:.5}", t.t_s, t.p_ref_pa/1e6, t.p_pa/1e6, s.truth.p_a_pa/1e6, t.speed_rad_s, t.speed_ref_rad_s, t.iq_a, t.id_a, t.mode, t.fault, s.truth.x_m);
    });
    eprintln!("wall {:?} for {} s", t0.elapsed(), sc.duration_s);
}
