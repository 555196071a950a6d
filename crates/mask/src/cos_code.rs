//! The one cos θ codec of glassdb: integer codes of 8 or 16 bits for cos θ ∈ [0, 1], with
//! `cos θ = code / max` and `code = round(clamp(cos θ, 0, 1) · max)`. The mask reader and
//! writer, the scene rasteriser, the compositor's kernel and tables and the accuracy report
//! all go through it, so a stored code means the same cos θ everywhere (`docs/mask.md`).

/// How many bits a cos θ code has.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CosCode {
    /// The paper's packed mask: 256 codes, cos θ = code / 255.
    Bits8,
    /// 16-bit PNG masks: 65536 codes, cos θ = code / 65535.
    Bits16,
}

impl CosCode {
    /// The largest code, which stands for cos θ = 1 (normal incidence): 255 or 65535.
    #[inline]
    pub const fn max_code(self) -> u16 {
        match self {
            CosCode::Bits8 => 255,
            CosCode::Bits16 => 65535,
        }
    }

    /// The distance in cos θ between neighbouring codes (1/255 or 1/65535); rounding to the
    /// nearest code is off by at most half of it.
    #[inline]
    pub fn step(self) -> f64 {
        1.0 / f64::from(self.max_code())
    }

    /// The nearest code to `cos_theta`, clamped to [0, 1] first; NaN gives code 0.
    #[inline]
    pub fn encode(self, cos_theta: f64) -> u16 {
        (cos_theta.clamp(0.0, 1.0) * f64::from(self.max_code())).round() as u16
    }

    /// The cos θ a code stands for, `code / max`. Codes above the maximum (only possible for
    /// [`CosCode::Bits8`]) decode above 1; callers hold codes of the right width.
    #[inline]
    pub fn decode(self, code: u16) -> f64 {
        f64::from(code) / f64::from(self.max_code())
    }

    /// [`CosCode::decode`] in f32, for the compositor's per-pixel lookups. Equal to
    /// `decode(code) as f32` (an f32 division of these integers is correctly rounded).
    #[inline]
    pub fn decode_f32(self, code: u16) -> f32 {
        f32::from(code) / f32::from(self.max_code())
    }

    /// The cos θ that storing `cos_theta` as a code gives back: `decode(encode(cos_theta))`.
    #[inline]
    pub fn quantize(self, cos_theta: f64) -> f64 {
        self.decode(self.encode(cos_theta))
    }

    /// The 8-bit code of `cos_theta` (see [`CosCode::encode`]).
    #[inline]
    pub fn encode8(cos_theta: f64) -> u8 {
        CosCode::Bits8.encode(cos_theta) as u8
    }

    /// The cos θ of an 8-bit code, `code / 255`.
    #[inline]
    pub fn decode8(code: u8) -> f64 {
        CosCode::Bits8.decode(u16::from(code))
    }

    /// A code of this width widened to 16 bits without changing the cos θ it stands for
    /// (`code · 257` for 8-bit codes: 255 · 257 = 65535).
    #[inline]
    pub fn to_bits16(self, code: u16) -> u16 {
        match self {
            CosCode::Bits8 => code * 257,
            CosCode::Bits16 => code,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn codes_round_trip_and_rounding_is_to_nearest() {
        for width in [CosCode::Bits8, CosCode::Bits16] {
            let max = width.max_code();
            for code in (0..=max).step_by(if max == 255 { 1 } else { 97 }) {
                assert_eq!(width.encode(width.decode(code)), code, "{width:?} {code}");
                assert_eq!(width.decode_f32(code), width.decode(code) as f32);
            }
            assert_eq!(width.decode(max), 1.0);
            assert_eq!(width.decode(0), 0.0);
            // Half a step either side of a code still rounds to it.
            let c = width.decode(max / 3);
            let half = 0.499 * width.step();
            assert_eq!(width.encode(c + half), max / 3);
            assert_eq!(width.encode(c - half), max / 3);
            assert!((width.quantize(0.3) - 0.3).abs() <= 0.5 * width.step());
        }
    }

    #[test]
    fn out_of_range_is_clamped() {
        assert_eq!(CosCode::Bits8.encode(-0.2), 0);
        assert_eq!(CosCode::Bits8.encode(1.7), 255);
        assert_eq!(CosCode::Bits16.encode(2.0), 65535);
        assert_eq!(CosCode::Bits16.encode(f64::NAN), 0);
        assert_eq!(CosCode::encode8(0.2), 51);
        assert_eq!(CosCode::decode8(51), 0.2);
        assert_eq!(CosCode::Bits16.encode(0.2), 13107);
    }

    #[test]
    fn widening_keeps_the_value() {
        for code in 0..=255u16 {
            let wide = CosCode::Bits8.to_bits16(code);
            assert_eq!(CosCode::Bits16.decode(wide), CosCode::Bits8.decode(code));
        }
    }
}
