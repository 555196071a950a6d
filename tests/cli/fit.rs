//! End-to-end tests of the fit commands.
