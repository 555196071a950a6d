//! Standard output of every command. Rust starts programs with SIGPIPE ignored, so a write to
//! a closed pipe (`glassdb registry show … | head -1`) fails with `BrokenPipe`, on which
//! `println!` panics. Commands print through `outln!` and `out!` (defined in `cmd`) instead,
//! which call [`write()`] (the crate's `clippy::print_stdout` lint keeps `println!` out). When the
//! reader has gone, the process exits at once, quietly, with status 0, as ripgrep and other
//! Rust tools do: what it printed was read as far as the reader wanted, and every file a
//! command writes is complete before the command prints about it. Any other write error (a
//! full disk behind a redirection) is reported and exits with status 1. SIGPIPE's disposition
//! is left as it is (restoring the default would need `unsafe`, which the workspace forbids).

use std::io::Write as _;

/// Writes formatted text to standard output (see the module documentation for a closed pipe).
pub fn write(args: std::fmt::Arguments<'_>) {
    let mut stdout = std::io::stdout().lock();
    if let Err(e) = stdout.write_fmt(args) {
        failed(&e);
    }
}

/// Ends the process after a failed write to standard output.
fn failed(e: &std::io::Error) -> ! {
    if e.kind() == std::io::ErrorKind::BrokenPipe {
        std::process::exit(0);
    }
    eprintln!("error: cannot write to standard output: {e}");
    std::process::exit(i32::from(super::EXIT_FAILURE));
}
