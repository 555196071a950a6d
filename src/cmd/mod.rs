//! One module per subcommand. Each exposes clap `Args` and `run(args) -> anyhow::Result<ExitCode>`.
//! Command output goes through `outln!` / `out!` ([`out`]: a closed pipe ends the process
//! quietly instead of panicking).

/// `println!` for command output, through [`out::write`].
macro_rules! outln {
    () => {
        $crate::cmd::out::write(format_args!("\n"))
    };
    ($($arg:tt)*) => {
        $crate::cmd::out::write(format_args!("{}\n", format_args!($($arg)*)))
    };
}

/// `print!` for command output, through [`out::write`].
macro_rules! out {
    ($($arg:tt)*) => {
        $crate::cmd::out::write(format_args!($($arg)*))
    };
}

pub mod blender;
pub mod compose;
pub mod fit;
pub mod hints;
pub mod inputs;
pub mod out;
pub mod plot;
pub mod progress;
pub mod registry;
pub mod relight;
pub mod report;
pub mod scene;
pub mod spectral;
pub mod stack;
pub mod table;
pub mod view;

use std::process::ExitCode;

/// Exit code for a run that failed on its input or output (clap uses 2 for usage errors).
pub const EXIT_FAILURE: u8 = 1;

/// Exit code for a run that failed inside glassdb (an error of kind internal: a caught panic),
/// `EX_SOFTWARE` of sysexits.h: the input is not to blame, and a retry will not help.
pub const EXIT_INTERNAL: u8 = 70;

/// What every binary does first (docs/reliability.md): protect each file it reads from its
/// outputs, and on SIGINT, SIGTERM or SIGHUP remove the unfinished outputs' temporary files
/// and exit with 128 + the signal's number (130, 143, 129).
pub fn init_process() {
    glassdb_io::protect_inputs();
    install_signal_cleanup();
}

/// The signals this process was started with set to be ignored (`nohup` ignores SIGHUP, a
/// shell's background job SIGINT), as the `SigIgn` mask of `/proc/self/status` (bit N − 1 for
/// signal N; 0 where it cannot be read): such a signal keeps being ignored rather than handled.
#[cfg(unix)]
fn ignored_at_start() -> u64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|status| {
            status
                .lines()
                .find_map(|l| l.strip_prefix("SigIgn:"))
                .and_then(|mask| u64::from_str_radix(mask.trim(), 16).ok())
        })
        .unwrap_or(0)
}

#[cfg(unix)]
fn install_signal_cleanup() {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
    let warn = |e: std::io::Error| {
        eprintln!(
            "warning: cannot handle SIGINT and SIGTERM ({e}): a stopped run may leave {}* files",
            glassdb_io::TEMP_PREFIX
        );
    };
    let ignored = ignored_at_start();
    let handled: Vec<i32> = [SIGINT, SIGTERM, SIGHUP]
        .into_iter()
        .filter(|&s| !((1..=64).contains(&s) && ignored & (1 << (s - 1)) != 0))
        .collect();
    let mut signals = match signal_hook::iterator::Signals::new(handled) {
        Ok(s) => s,
        Err(e) => return warn(e),
    };
    let spawned = std::thread::Builder::new()
        .name("signals".into())
        .spawn(move || {
            if let Some(signal) = signals.forever().next() {
                let name = stop_signal_name(128 + signal);
                eprintln!("stopped by {name}: unfinished outputs removed");
                glassdb_io::exit_removing_temporaries(128 + signal);
            }
        });
    if let Err(e) = spawned {
        warn(e);
    }
}

#[cfg(not(unix))]
fn install_signal_cleanup() {}

/// The name of the signal a stop by which exits with `code` (128 + its number).
pub fn stop_signal_name(code: i32) -> &'static str {
    match code - 128 {
        1 => "SIGHUP",
        2 => "SIGINT",
        15 => "SIGTERM",
        _ => "a signal",
    }
}

/// Turns a subcommand's result into the process exit code, printing the whole error chain and
/// the hints that say which flag or command fixes it. The code follows the error's kind:
/// [`EXIT_INTERNAL`] for glassdb's own failure, [`EXIT_FAILURE`] for everything a user can act
/// on (the input, an option, a limit, the files).
pub fn finish(result: anyhow::Result<ExitCode>) -> ExitCode {
    match result {
        Ok(code) => code,
        Err(err) => {
            eprintln!("error: {err:#}");
            for hint in hints::hints(&err) {
                eprintln!("hint: {hint}");
            }
            match hints::kind(&err) {
                Some(glassdb_io::ErrorKind::Internal) => {
                    eprintln!(
                        "hint: this is a bug of glassdb's, not a problem of the input: please \
                         report it with the command and its files"
                    );
                    ExitCode::from(EXIT_INTERNAL)
                }
                _ => ExitCode::from(EXIT_FAILURE),
            }
        }
    }
}

/// The exit of a command over frames: success, or the failed frames listed and exit code 1.
pub(crate) fn frames_exit(failed: &[u32], total: usize) -> ExitCode {
    if failed.is_empty() {
        return ExitCode::SUCCESS;
    }
    let list: Vec<String> = failed.iter().map(u32::to_string).collect();
    eprintln!(
        "error: {} of {total} frame(s) failed: {}",
        failed.len(),
        list.join(", ")
    );
    ExitCode::from(EXIT_FAILURE)
}
