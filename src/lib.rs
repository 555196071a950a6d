//! The command-line front end of glassdb: argument parsing and output formatting only.
//! Every computation lives in the library crates under `crates/`; each subcommand is a module
//! of [`cmd`] with a clap `Args` struct and a `run` function returning the process exit code.
//! Standard output is written through `cmd::out` only (a closed pipe is a quiet exit), which
//! the `clippy::print_stdout` lint enforces.

#![warn(clippy::print_stdout)]

pub mod cmd;
