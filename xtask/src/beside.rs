//! Processes `cargo xtask test` runs beside its steps (the setup beside the linted build,
//! the Cortex-M4F images beside the host tests): started at once, their output written to
//! a file under the target directory so it does not mix with the step's, and shown when
//! they are joined.

use crate::workspace::target_dir;
use anyhow::{Context, Result};
use std::path::PathBuf;
use std::process::{Child, Command, Stdio};

/// What becomes of the processes when they are dropped unjoined (a step before failed).
#[derive(Clone, Copy, Debug)]
pub enum Unjoined {
    /// Stopped: builds, whose work the checks would do again anyway.
    Kill,
    /// Waited for: installs, which must not be cut off halfway (apt-get, dpkg).
    Wait,
}

/// Processes running beside the steps, their shared output file and what they are.
pub struct Beside {
    children: Vec<Child>,
    log: PathBuf,
    what: &'static str,
    unjoined: Unjoined,
}

/// Starts `commands` (`what` they are, for the output's heading), their output written to
/// `target/LOG_NAME`.
pub fn start(
    what: &'static str,
    log_name: &str,
    commands: impl IntoIterator<Item = Command>,
    unjoined: Unjoined,
) -> Result<Beside> {
    std::fs::create_dir_all(target_dir())?;
    let log = target_dir().join(log_name);
    let file =
        std::fs::File::create(&log).with_context(|| format!("creating {}", log.display()))?;
    let mut beside = Beside {
        children: Vec::new(),
        log,
        what,
        unjoined,
    };
    for mut cmd in commands {
        cmd.stdin(Stdio::null())
            .stdout(file.try_clone()?)
            .stderr(file.try_clone()?);
        let child = cmd
            .spawn()
            .with_context(|| format!("could not start {cmd:?}"))?;
        beside.children.push(child);
    }
    Ok(beside)
}

impl Beside {
    /// Waits for every process, shows their output and returns how each that failed
    /// ended (empty when all succeeded).
    pub fn join(mut self) -> Vec<String> {
        let mut failed = Vec::new();
        for mut child in std::mem::take(&mut self.children) {
            match child.wait() {
                Ok(status) if status.success() => {}
                Ok(status) => failed.push(status.to_string()),
                Err(e) => failed.push(e.to_string()),
            }
        }
        eprintln!("\n=== {}:", self.what);
        match std::fs::read_to_string(&self.log) {
            Ok(text) => eprint!("{text}"),
            Err(e) => eprintln!("({}: {e})", self.log.display()),
        }
        failed
    }
}

impl Drop for Beside {
    fn drop(&mut self) {
        for child in &mut self.children {
            if let Unjoined::Kill = self.unjoined {
                let _ = child.kill();
            }
            let _ = child.wait();
        }
    }
}
