//! End-to-end tests of `glassdb plot` and `glassdb report`.
