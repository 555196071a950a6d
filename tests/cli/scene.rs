//! End-to-end tests of the scene commands.
