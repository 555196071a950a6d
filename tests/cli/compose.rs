//! End-to-end tests of the compose commands.
