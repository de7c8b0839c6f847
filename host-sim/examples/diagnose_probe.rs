//! Prints the closed-loop replay of a bench log beside the log, every 100th row: a tool to
//! inspect what the diagnosis compares (`cargo run --release -p host-sim --example
//! diagnose_probe -- LOG.csv`).

use host_sim::diagnose::closed_replay::replay_closed_loop;
use plant_model::Rig;
use std::path::PathBuf;

fn main() {
    let path = PathBuf::from(
        std::env::args()
            .nth(1)
            .expect("usage: diagnose_probe LOG.csv"),
    );
    let log = host_sim::bench_log::read(&path).expect("a valid bench log");
    let rig = Rig::nominal();
    let cl = replay_closed_loop(&log, &rig).expect("a log with setpoints");
    println!("t_s  p_log p_cl  w_log w_cl  iq_log iq_cl");
    for k in (0..log.len()).step_by(100) {
        println!(
            "{:.3} {:.0} {:.0}  {:.3} {:.3}  {:.3} {:.3}",
            log.t_s[k],
            log.p_pa[k],
            cl.p_pa[k],
            log.speed_rad_s[k],
            cl.speed_rad_s[k],
            log.iq_a[k],
            cl.iq_a[k]
        );
    }
}
