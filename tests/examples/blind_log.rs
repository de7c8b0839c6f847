//! Writes the blind suite's log of each seed given on the command line into a directory and
//! prints what was hidden, with each effect's parameters and the signal where it stands
//! highest over the noise: a tool to inspect one seed with `eha diagnose`
//! (`cargo run --release -p tests --example blind_log -- DIR SEED…`).

use std::path::PathBuf;
use std::process::ExitCode;
use tests::blind::generate;

fn main() -> ExitCode {
    let mut args = std::env::args().skip(1);
    let Some(dir) = args.next().map(PathBuf::from) else {
        eprintln!("usage: blind_log DIR SEED…");
        return ExitCode::from(2);
    };
    if let Err(e) = std::fs::create_dir_all(&dir) {
        eprintln!("blind_log: {}: {e}", dir.display());
        return ExitCode::from(2);
    }
    for arg in args {
        let Ok(seed) = arg.parse::<u64>() else {
            eprintln!("blind_log: `{arg}`: a seed is an unsigned integer");
            return ExitCode::from(2);
        };
        let written = generate(seed, &dir).and_then(|(path, truth)| {
            let target = dir.join(format!("seed-{seed}.csv"));
            std::fs::rename(&path, &target).map_err(|e| format!("{}: {e}", target.display()))?;
            Ok((target, truth))
        });
        match written {
            Ok((target, t)) => {
                let hidden: Vec<String> = t
                    .effects
                    .iter()
                    .map(|h| {
                        format!(
                            "{} {:?} ({:.1}× noise on {})",
                            h.name, h.parameters, h.ratio, h.signal
                        )
                    })
                    .collect();
                println!(
                    "{seed}: {} {} Hz {:.1} s dropped={:?} hides {} → {}",
                    t.test,
                    t.log_rate_hz,
                    t.duration_s,
                    t.dropped,
                    if hidden.is_empty() {
                        "none".into()
                    } else {
                        hidden.join(" + ")
                    },
                    target.display()
                );
            }
            Err(e) => {
                eprintln!("blind_log: seed {seed}: {e}");
                return ExitCode::FAILURE;
            }
        }
    }
    ExitCode::SUCCESS
}
