//! Placeholder replaced below once the engine builds.
fn main() {}
