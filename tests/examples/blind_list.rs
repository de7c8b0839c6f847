//! Lists what the blind generator draws for a range of seeds, without simulating them: the
//! test, log rate, length, dropped columns and hidden effects (for a freely drawn seed the
//! first choice, which the generator's observability check may replace). A tool to pick
//! draws of one kind: `cargo run --release -p tests --example blind_list -- FROM TO`, then
//! `blind_log` to write the chosen ones.

use tests::blind::outline;

fn main() {
    let usage = "usage: blind_list FROM TO (seeds FROM..TO)";
    let mut args = std::env::args().skip(1);
    let mut seed = || -> u64 {
        args.next().and_then(|a| a.parse().ok()).unwrap_or_else(|| {
            eprintln!("{usage}");
            std::process::exit(2)
        })
    };
    let (from, to) = (seed(), seed());
    for seed in from..to {
        let t = outline(seed);
        println!(
            "{seed} {} {} Hz {:.1} s dropped={:?} hides {}",
            t.test,
            t.log_rate_hz,
            t.duration_s,
            t.dropped,
            t.label()
        );
    }
}
