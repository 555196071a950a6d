//! Glass masks: which pixels show glass, which glass (registration id), at what cos θ, on which
//! plane. Read by `glassdb registry build --mask` and by the compositor; written by
//! `glassdb mask`. The on-disk formats are documented in `docs/mask.md`.

/// A decoded mask, row-major, row 0 at the top. All per-pixel vectors have `width * height`
/// entries.
#[derive(Debug, Clone, PartialEq)]
pub struct MaskImage {
    pub width: u32,
    pub height: u32,
    /// Glass registration id per pixel; 0 means "no glass".
    pub id: Vec<u16>,
    /// cos θ per pixel (angle of incidence of the view ray on the glass), as stored.
    pub cos_theta: CosTheta,
    /// Glass plane index per pixel (selects the reflection pass); all 0 with one plane.
    pub plane: Vec<u16>,
    /// Fraction of the pixel covered by glass, when the mask carries it (antialiased edges).
    pub coverage: Option<Vec<f32>>,
}

/// cos θ as the mask stores it: quantised codes are kept as codes so that lookups into
/// 256-entry tables stay exact.
#[derive(Debug, Clone, PartialEq)]
pub enum CosTheta {
    /// 8-bit: cos θ = code / 255 (the paper's packed mask).
    Quantized8(Vec<u8>),
    /// 16-bit: cos θ = code / 65535.
    Quantized16(Vec<u16>),
    /// Float: cos θ as given (EXR masks).
    Float(Vec<f32>),
    /// A binary mask carries no angle: every glass pixel is seen at normal incidence.
    Normal,
}
