//! Section "cos θ storage": the error of storing cos θ in each way a mask can, measured through
//! the codec the masks use ([`glassdb_mask::CosCode`]) and the float types of EXR masks.

use std::fmt::Write as _;

use glassdb_fit::cos_deg;
use glassdb_mask::CosCode;

use crate::measure::{dense_angles, max_abs_diff};
use crate::reference::Reference;
use crate::text::fmt_err;

/// How a mask stores cos θ.
#[derive(Clone, Copy)]
pub(crate) enum CosStorage {
    /// An integer code (8- or 16-bit PNG masks).
    Code(CosCode),
    /// Half float (EXR).
    Half,
    /// 32-bit float (EXR).
    Float32,
}

impl CosStorage {
    /// Every storage, in the order of the table's rows.
    pub(crate) const ALL: [CosStorage; 4] = [
        CosStorage::Code(CosCode::Bits8),
        CosStorage::Code(CosCode::Bits16),
        CosStorage::Half,
        CosStorage::Float32,
    ];

    pub(crate) fn name(self) -> &'static str {
        match self {
            CosStorage::Code(CosCode::Bits8) => "8-bit (paper's mask, code/255)",
            CosStorage::Code(CosCode::Bits16) => "16-bit PNG (code/65535)",
            CosStorage::Half => "half float (EXR)",
            CosStorage::Float32 => "float (EXR)",
        }
    }

    /// The cos θ a mask gives back after storing `c`.
    pub(crate) fn store(self, c: f64) -> f64 {
        match self {
            CosStorage::Code(code) => code.quantize(c),
            CosStorage::Half => half::f16::from_f64(c).to_f64(),
            CosStorage::Float32 => c as f32 as f64,
        }
    }
}

/// Writes the section: per storage, the largest r error of every reference, the t error of the
/// first, and the largest angle error.
pub(crate) fn section_quantisation(md: &mut String, refs: &[Reference]) {
    let _ = writeln!(md, "## cos θ storage: 8 bits vs 16 bits vs float\n");
    let _ = writeln!(
        md,
        "Error from storing cos θ alone (the exact physics evaluated at the stored cos θ against the \
         true one), max over θ = 0–89° on a 0.001° grid, with the angle where it occurs. Near grazing \
         incidence cos θ changes little per degree, so one 8-bit step (1/255) spans several degrees \
         (last column: largest angle error the storage causes, max |θ(stored) − θ|).\n"
    );
    let grid = dense_angles(89.0, 0.001);
    let mut header = String::from("| storage |");
    let mut rule = String::from("|---|");
    for r in refs {
        let _ = write!(header, " max \\|Δr\\| {} |", r.name);
        rule.push_str("---|");
    }
    header.push_str(" max \\|Δt\\| slab n=1.52 | max \\|Δθ\\| |");
    rule.push_str("---|---|");
    let _ = writeln!(md, "{header}\n{rule}");
    for st in CosStorage::ALL {
        md.push_str(&storage_row(st, refs, &grid));
    }
    let _ = writeln!(md);
}

/// One row of the storage table.
fn storage_row(st: CosStorage, refs: &[Reference], grid: &[f64]) -> String {
    let mut row = format!("| {} |", st.name());
    for r in refs {
        let e = max_abs_diff(
            grid,
            |a| r.eval(st.store(cos_deg(a))).0,
            |a| r.eval(cos_deg(a)).0,
        );
        let _ = write!(row, " {} |", fmt_err(e));
    }
    let et = max_abs_diff(
        grid,
        |a| refs[0].eval(st.store(cos_deg(a))).1,
        |a| refs[0].eval(cos_deg(a)).1,
    );
    let dtheta = max_abs_diff(
        grid,
        |a| st.store(cos_deg(a)).clamp(0.0, 1.0).acos().to_degrees(),
        |a| a,
    );
    let _ = writeln!(
        row,
        " {} | {:.3}° ({:.1}°) |",
        fmt_err(et),
        dtheta.0,
        dtheta.1
    );
    row
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use glassdb_mask::{
        CosTheta, MaskFormat, MaskImage, MaskReadOptions, read_mask_bytes, write_mask_bytes,
    };

    use super::*;

    #[test]
    fn stored_cos_is_what_a_written_png_mask_reads_back() {
        // The table measures the masks' own round trip: float cos θ → PNG mask → cos θ.
        let cos: Vec<f32> = (0..=1000).map(|k| k as f32 / 1000.0).collect();
        let n = cos.len();
        let mask = MaskImage {
            width: n as u32,
            height: 1,
            id: vec![1; n],
            cos_theta: CosTheta::Float(cos.clone()),
            plane: vec![0; n],
            coverage: None,
        };
        let path = Path::new("round_trip.png");
        for (format, code) in [
            (MaskFormat::Png8, CosCode::Bits8),
            (MaskFormat::Png16, CosCode::Bits16),
        ] {
            let bytes = write_mask_bytes(path, &mask, format).unwrap();
            let back = read_mask_bytes(&bytes, path, &MaskReadOptions::default()).unwrap();
            for (i, &c) in cos.iter().enumerate() {
                assert_eq!(
                    back.cos_theta_at(i),
                    CosStorage::Code(code).store(f64::from(c)),
                    "{code:?} at cos θ {c}"
                );
            }
        }
    }
}
