//! The command-line front end of glassdb: argument parsing and output formatting only.
//! Every computation lives in the library crates under `crates/`; each subcommand is a module
//! of [`cmd`] with a clap `Args` struct and a `run` function returning the process exit code.

pub mod cmd;
