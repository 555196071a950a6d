//! End-to-end tests: one binary that drives the built `glassdb` and `compose` executables.
//! One module per area; shared helpers in `util`.

mod architecture;
mod blender;
mod blender_ghosts;
mod cameras;
mod colour;
mod compose;
mod dusk;
mod farm;
mod first_contact;
mod fit;
mod fixtures;
mod ghosts;
mod lights;
mod limits;
mod masks;
mod passes;
mod plot;
mod registry;
mod reliability;
mod relight;
mod scene;
mod spectral;
mod spectral_formats;
mod stack;
mod util;
mod validation;
mod values;
mod view;
mod viewer;
