//! The compositor's own 8-bit lookup tables as `oiiotool --colormap` knots, so that
//! `scripts/bench_compose_vs_oiiotool.sh` can have oiiotool compute exactly the same composite.
//!
//! The mask's packed 8-bit pixel (G = id, B = cos θ code) becomes one coordinate
//! `u = (256·id + code) / (N − 1)` with `N = 256·(max_id + 1)` knots (oiiotool reads PNG samples
//! as `value / 255`, so `--chsum:weight=0,WG,WB` with `WG = 255·256/(N − 1)`,
//! `WB = 255/(N − 1)` computes it); knot `256·id + code` holds r (or t) of that id at that code,
//! and id 0 ("no glass") or an id the registry lacks holds r = 0, t = 1. Prints three shell assignments:
//! `CHSUM_WEIGHTS=0,WG,WB`, `R_KNOTS=…` and `T_KNOTS=…` (RGB triples, front side).
//!
//! `cargo run --release -p glassdb-compose --example oiiotool_colormaps -- MAX_ID`

use glassdb_compose::lut::GlassLut;
use glassdb_registry::{Side, default_registry};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let max_id: u16 = match args.as_slice() {
        [_, id] => id.parse()?,
        _ => return Err("usage: oiiotool_colormaps MAX_ID".into()),
    };
    let lut = GlassLut::from_table(default_registry()?.default_table());
    let knots = 256 * (usize::from(max_id) + 1);
    let mut r_knots = Vec::with_capacity(knots * 3);
    let mut t_knots = Vec::with_capacity(knots * 3);
    for id in 0..=max_id {
        for code in 0..=255u8 {
            let (r, t) = match lut.side(id, Side::Front) {
                Some(side) => {
                    let rt = side.at_code8(code);
                    (rt.r, rt.t)
                }
                // "No glass", and ids the registry lacks (compose --unknown passthrough).
                None => ([0.0; 3], [1.0; 3]),
            };
            r_knots.extend(r.iter().map(|v| format!("{v:.9}")));
            t_knots.extend(t.iter().map(|v| format!("{v:.9}")));
        }
    }
    let last = (knots - 1) as f64;
    println!(
        "CHSUM_WEIGHTS=0,{:.12},{:.12}",
        255.0 * 256.0 / last,
        255.0 / last
    );
    println!("R_KNOTS={}", r_knots.join(","));
    println!("T_KNOTS={}", t_knots.join(","));
    Ok(())
}
