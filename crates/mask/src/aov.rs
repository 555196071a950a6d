//! cos θ and plane ids on glass pixels from a render's other AOVs: an |N·I| AOV, or the Normal
//! and Position passes with the camera position; a plane-index AOV, or planes from the
//! geometry.

use crate::MaskError;
use crate::channels::PixelError;

/// The glass pixels of a frame as its AOVs are read: their ids, how an AOV's value is divided
/// by the glass coverage (when the AOV is written by glass only), and how an error names a
/// pixel.
pub(crate) struct GlassAovs<'a, D> {
    pub(crate) id: &'a [u16],
    pub(crate) divide: D,
    pub(crate) pixel: &'a PixelError<'a>,
}

impl<D: Fn(f32, usize) -> f32> GlassAovs<'_, D> {
    /// cos θ on glass pixels from an |N·I| AOV.
    pub(crate) fn cos(&self, aov: &[f32], channel: &str) -> Result<Vec<f32>, MaskError> {
        self.on_glass(aov, |v| {
            if !(v.is_finite() && (-1e-3..=1.0 + 1e-2).contains(&v)) {
                return Err(format!(
                    "cos θ {v} from AOV {channel:?} is not in [0, 1] (is the AOV |N·I|, and written by the materials the options say: the glass only, or every material?)"
                ));
            }
            Ok(v.clamp(0.0, 1.0))
        })
    }

    /// Plane indices on glass pixels from a plane AOV, rounded.
    pub(crate) fn planes(&self, aov: &[f32], name: &str) -> Result<Vec<u16>, MaskError> {
        self.on_glass(aov, |v| {
            let r = v.round();
            if !(0.0..=65535.0).contains(&r) {
                return Err(format!(
                    "plane {v} from AOV {name:?} is not an index in 0–65535"
                ));
            }
            Ok(r as u16)
        })
    }

    /// `convert` of each glass pixel's divided AOV value, zero elsewhere; the first value it
    /// refuses is an error naming the pixel.
    fn on_glass<T: Copy + Default>(
        &self,
        aov: &[f32],
        convert: impl Fn(f32) -> Result<T, String>,
    ) -> Result<Vec<T>, MaskError> {
        on_glass(self.id, |i| {
            convert((self.divide)(aov[i], i)).map_err(|message| self.pixel.at(i, message))
        })
    }
}

/// cos θ on glass pixels from world-space Normal (planes 0–2) and Position (planes 3–5) passes
/// and the camera position: |N·(P − C)| / (|N| |P − C|).
pub(crate) fn cos_from_geometry(
    passes: &[Vec<f32>],
    id: &[u16],
    camera_origin: [f64; 3],
    pixel: &PixelError<'_>,
) -> Result<Vec<f32>, MaskError> {
    on_glass(id, |i| {
        let nrm: [f64; 3] = std::array::from_fn(|k| f64::from(passes[k][i]));
        let v: [f64; 3] = std::array::from_fn(|k| f64::from(passes[3 + k][i]) - camera_origin[k]);
        let (ln, lv) = (norm(nrm), norm(v));
        if !(ln > 0.0 && lv > 0.0) {
            return Err(pixel.at(
                i,
                "the Normal or Position pass is zero on a glass pixel".into(),
            ));
        }
        let dot = nrm[0] * v[0] + nrm[1] * v[1] + nrm[2] * v[2];
        Ok((dot.abs() / (ln * lv)).clamp(0.0, 1.0) as f32)
    })
}

/// Plane indices on glass pixels from world-space Normal (planes 0–2) and Position (3–5)
/// passes: among the planes whose normal lies within `max_angle_deg` of the pixel's normal
/// (either orientation), the one nearest the pixel's position. At a pane's edge both passes
/// average over what the pixel sees, so where no plane is that close in angle the best
/// aligned one is taken.
pub(crate) fn planes_from_geometry(
    passes: &[Vec<f32>],
    id: &[u16],
    equations: &[[f64; 4]],
    max_angle_deg: f64,
    pixel: &PixelError<'_>,
) -> Result<Vec<u16>, MaskError> {
    let min_cos = max_angle_deg.to_radians().cos();
    on_glass(id, |i| {
        let nrm: [f64; 3] = std::array::from_fn(|k| f64::from(passes[k][i]));
        let pos: [f64; 3] = std::array::from_fn(|k| f64::from(passes[3 + k][i]));
        let ln = norm(nrm);
        if ln.is_nan() || ln <= 0.0 {
            return Err(pixel.at(i, "the Normal pass is zero on a glass pixel".into()));
        }
        let scored: Vec<(usize, f64, f64)> = equations
            .iter()
            .enumerate()
            .map(|(k, e)| {
                let alignment = (e[0] * nrm[0] + e[1] * nrm[1] + e[2] * nrm[2]).abs() / ln;
                let distance = (e[0] * pos[0] + e[1] * pos[1] + e[2] * pos[2] + e[3]).abs();
                (k, alignment, distance)
            })
            .collect();
        let nearest_aligned = scored
            .iter()
            .filter(|s| s.1 >= min_cos)
            .min_by(|a, b| a.2.total_cmp(&b.2));
        let best_aligned = scored.iter().max_by(|a, b| a.1.total_cmp(&b.1));
        Ok(nearest_aligned
            .or(best_aligned)
            .map_or(0, |&(k, _, _)| k as u16))
    })
}

/// `value` of each glass pixel (id ≠ 0), zero elsewhere; the first error stops.
fn on_glass<T: Copy + Default>(
    id: &[u16],
    mut value: impl FnMut(usize) -> Result<T, MaskError>,
) -> Result<Vec<T>, MaskError> {
    let mut out = vec![T::default(); id.len()];
    for (i, o) in out.iter_mut().enumerate() {
        if id[i] != 0 {
            *o = value(i)?;
        }
    }
    Ok(out)
}

fn norm(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}
