//! End-to-end tests: one binary that drives the built `glassdb` and `compose` executables.
//! One module per area; shared helpers in `util`.


mod fit;
mod spectral;
mod registry;
mod compose;
mod scene;
mod plot;
mod util;
