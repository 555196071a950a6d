//! End-to-end tests of the spectral commands.
