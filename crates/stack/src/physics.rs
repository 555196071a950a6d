//! Angle models that turn normal-incidence values (one wavelength, or one channel) into values at
//! any angle of incidence. Equations and sources in `docs/registry.md`:
//!
//! - [`UncoatedSlab`]: the model of LBNL WINDOW and EnergyPlus for uncoated (monolithic) glass
//!   (Finlayson et al. 1993, LBL-33943, "WINDOW 4.0: documentation of calculation procedures";
//!   EnergyPlus Engineering Reference, "Optical properties of glazing"; LBNL Windows-CalcEngine
//!   `CAngularPropertiesUncoated`): a plane slab with two equal interfaces and bulk absorption,
//!   the single-surface reflectance and internal transmittance solved from T0 and R0, then s/p
//!   Fresnel with incoherent multiple reflections at each angle.
//! - [`CoatedCurve`]: WINDOW-4's empirical "clear" and "bronze" angular polynomials for coated
//!   glass, `T = T0·τ(θ)`, `R = R0·(1 − ρ(θ)) + ρ(θ)`.
//! - [`fresnel_single_surface`]: unpolarised Fresnel reflectance of one interface from air into
//!   a medium of complex refractive index `n + i·k` (opaque specular surfaces: metal, stone,
//!   water seen from above, mirrors).

/// A plane-parallel uncoated slab described by the refractive index of its two (equal)
/// interfaces and its internal (bulk) transmittance at normal incidence.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UncoatedSlab {
    /// Single-surface reflectance at normal incidence (ρ0).
    pub rho0: f64,
    /// Real refractive index from ρ0: `n = (1 + √ρ0) / (1 − √ρ0)`.
    pub n: f64,
    /// Internal transmittance of the bulk at normal incidence (one pass), `τi = e^{−α·d}`.
    pub internal_transmittance: f64,
}

/// Largest single-surface reflectance accepted (keeps n finite for R0 → 1).
const RHO_MAX: f64 = 0.999_999;

impl UncoatedSlab {
    /// Solves the slab from normal-incidence `t0`, `r0` (fractions, `t0 + r0 ≤ 1`).
    ///
    /// With single-surface reflectance ρ and internal transmittance τi, incoherent multiple
    /// reflections give `T0 = (1−ρ)²·τi / (1 − ρ²·τi²)` and `R0 = ρ·(1 + T0·τi)`. Eliminating τi
    /// leaves `(2 − R0)·ρ² − β·ρ + R0 = 0`, `β = T0² − R0² + 2·R0 + 1`, whose smaller root is ρ0;
    /// then `τi = (R0 − ρ0) / (T0·ρ0)`.
    pub fn from_normal(t0: f64, r0: f64) -> UncoatedSlab {
        let t0 = t0.clamp(0.0, 1.0);
        let r0 = r0.clamp(0.0, 1.0);
        let beta = t0 * t0 - r0 * r0 + 2.0 * r0 + 1.0;
        let disc = (beta * beta - 4.0 * (2.0 - r0) * r0).max(0.0);
        let rho0 = ((beta - disc.sqrt()) / (2.0 * (2.0 - r0))).clamp(0.0, RHO_MAX);
        let sq = rho0.sqrt();
        let n = (1.0 + sq) / (1.0 - sq);
        let internal_transmittance = if t0 <= 0.0 {
            0.0
        } else if rho0 <= 1e-12 {
            t0 // no reflecting interface: all of the loss is absorption
        } else {
            ((r0 - rho0) / (t0 * rho0)).clamp(0.0, 1.0)
        };
        UncoatedSlab {
            rho0,
            n,
            internal_transmittance,
        }
    }

    /// `(R, T)` of the slab at incidence `cos θ` (unpolarised: mean of s and p).
    ///
    /// `cos θ' = √(1 − sin²θ/n²)`; `ρs = ((cos θ − n·cos θ')/(cos θ + n·cos θ'))²`,
    /// `ρp = ((n·cos θ − cos θ')/(n·cos θ + cos θ'))²`; path transmittance
    /// `a = τi^{1/cos θ'}`; per polarisation `T = a·(1−ρ)²/(1 − a²ρ²)`, `R = ρ·(1 + a·T)`.
    pub fn at(&self, cos_theta: f64) -> (f64, f64) {
        let c = cos_theta.clamp(0.0, 1.0);
        if c <= 1e-12 {
            return (1.0, 0.0); // grazing: every interface reflects everything
        }
        let n = self.n;
        let sin2 = 1.0 - c * c;
        let cp = (1.0 - sin2 / (n * n)).max(0.0).sqrt();
        let a = if self.internal_transmittance > 0.0 {
            self.internal_transmittance.powf(1.0 / cp)
        } else {
            0.0
        };
        let rs = ((c - n * cp) / (c + n * cp)).powi(2);
        let rp = ((n * c - cp) / (n * c + cp)).powi(2);
        let pol = |rho: f64| {
            let t = a * (1.0 - rho).powi(2) / (1.0 - a * a * rho * rho);
            let r = rho * (1.0 + a * t);
            (r, t)
        };
        let (r_s, t_s) = pol(rs);
        let (r_p, t_p) = pol(rp);
        (0.5 * (r_s + r_p), 0.5 * (t_s + t_p))
    }
}

/// WINDOW-4's angular polynomials for coated glass.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CoatedCurve {
    /// For clear coated glass (WINDOW picks it where T0 > 0.645).
    Clear,
    /// For tinted / reflective coated glass (T0 ≤ 0.645).
    Bronze,
}

/// Normal transmittance above which WINDOW picks the clear curve.
pub const CLEAR_THRESHOLD: f64 = 0.645;

impl CoatedCurve {
    /// The curve WINDOW-4 picks for a normal transmittance `t0` (clear where `t0 > 0.645`).
    pub fn for_t0(t0: f64) -> CoatedCurve {
        if t0 > CLEAR_THRESHOLD {
            CoatedCurve::Clear
        } else {
            CoatedCurve::Bronze
        }
    }

    /// Coefficients c0…c4 of `τ(cos θ)` and of `τ(cos θ) + ρ(cos θ)` (WINDOW 4.0, LBL-33943;
    /// the same numbers in EnergyPlus and Windows-CalcEngine `CCoatingCoefficients`).
    fn coefficients(self) -> ([f64; 5], [f64; 5]) {
        match self {
            CoatedCurve::Clear => (
                [-0.0015, 3.355, -3.84, 1.46, 0.0288],
                [0.999, -0.563, 2.043, -2.532, 1.054],
            ),
            CoatedCurve::Bronze => (
                [-0.002, 2.813, -2.341, -0.05725, 0.599],
                [0.997, -1.868, 6.513, -7.862, 3.225],
            ),
        }
    }

    /// The published `(τ(cos θ), ρ(cos θ))` with `ρ = P_R(cos θ) − τ(cos θ)`.
    pub fn raw(self, cos_theta: f64) -> (f64, f64) {
        let (ct, cr) = self.coefficients();
        let poly = |c: &[f64; 5]| c.iter().rev().fold(0.0, |acc, &k| acc * cos_theta + k);
        let tau = poly(&ct);
        (tau, poly(&cr) - tau)
    }

    /// `(τ̂, ρ̂)`: the published curves renormalised so that they pass exactly through the
    /// normal values (τ̂(0°) = 1, ρ̂(0°) = 0): the published polynomials give τ(0°) = 1.0023
    /// (clear) and 1.01175 (bronze). `τ̂ = τ/τ(0°)`, `ρ̂ = (ρ − ρ(0°)) / (1 − ρ(0°))`.
    pub fn normalised(self, cos_theta: f64) -> (f64, f64) {
        let (tau1, rho1) = self.raw(1.0);
        let (tau, rho) = self.raw(cos_theta);
        (tau / tau1, (rho - rho1) / (1.0 - rho1))
    }

    /// `(R, T)` at `cos θ` for normal values `r0`, `t0`, clamped to [0, 1] (as WINDOW does):
    /// `T = T0·τ̂`, `R = R0·(1 − ρ̂) + ρ̂`.
    pub fn at(self, t0: f64, r0: f64, cos_theta: f64) -> (f64, f64) {
        let c = cos_theta.clamp(0.0, 1.0);
        let (tau, rho) = self.normalised(c);
        let t = (t0 * tau).clamp(0.0, 1.0);
        let r = (r0 * (1.0 - rho) + rho).clamp(0.0, 1.0);
        (r, t)
    }
}

impl CoatedCurve {
    /// `(R, T)` at `cos θ` with the published polynomials as WINDOW applies them (LBNL
    /// Windows-CalcEngine `CAngularPropertiesCoated`): `T = T0·τ`, `R = R0·(1 − ρ) + ρ`, each
    /// clamped to [0, 1], without the renormalisation of [`CoatedCurve::at`] (so that T(0°) =
    /// 1.0023·T0 for the clear curve and 1.01175·T0 for the bronze one).
    pub fn at_published(self, t0: f64, r0: f64, cos_theta: f64) -> (f64, f64) {
        let (tau, rho) = self.raw(cos_theta.clamp(0.0, 1.0));
        let t = (t0 * tau).clamp(0.0, 1.0);
        let r = (r0 * (1.0 - rho) + rho).clamp(0.0, 1.0);
        (r, t)
    }
}

/// A complex number, just enough for Fresnel's equations.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Complex {
    re: f64,
    im: f64,
}

impl Complex {
    fn new(re: f64, im: f64) -> Complex {
        Complex { re, im }
    }
    fn add(self, o: Complex) -> Complex {
        Complex::new(self.re + o.re, self.im + o.im)
    }
    fn sub(self, o: Complex) -> Complex {
        Complex::new(self.re - o.re, self.im - o.im)
    }
    fn mul(self, o: Complex) -> Complex {
        Complex::new(
            self.re * o.re - self.im * o.im,
            self.re * o.im + self.im * o.re,
        )
    }
    fn scale(self, s: f64) -> Complex {
        Complex::new(self.re * s, self.im * s)
    }
    fn norm_sqr(self) -> f64 {
        self.re * self.re + self.im * self.im
    }
    /// Principal square root (non-negative real part).
    fn sqrt(self) -> Complex {
        let m = self.norm_sqr().sqrt();
        let re = ((m + self.re) * 0.5).max(0.0).sqrt();
        let im_mag = ((m - self.re) * 0.5).max(0.0).sqrt();
        Complex::new(re, if self.im < 0.0 { -im_mag } else { im_mag })
    }
    /// |a/b|² without forming the quotient.
    fn ratio_norm_sqr(a: Complex, b: Complex) -> f64 {
        let d = b.norm_sqr();
        if d == 0.0 { 1.0 } else { a.norm_sqr() / d }
    }
}

/// Unpolarised reflectance of a single interface from air into a medium of complex refractive
/// index `n + i·k` (k = 0 for dielectrics) at incidence `cos θ`:
/// with `u = √(N² − sin²θ)`, `r_s = (cos θ − u)/(cos θ + u)`, `r_p = (N²·cos θ − u)/(N²·cos θ + u)`,
/// `R = (|r_s|² + |r_p|²)/2` (Born & Wolf, *Principles of Optics*, §1.5 and §14.2).
pub fn fresnel_single_surface(n: f64, k: f64, cos_theta: f64) -> f64 {
    let c = cos_theta.clamp(0.0, 1.0);
    let big_n = Complex::new(n, k);
    let n2 = big_n.mul(big_n);
    let sin2 = 1.0 - c * c;
    let u = n2.sub(Complex::new(sin2, 0.0)).sqrt();
    let cc = Complex::new(c, 0.0);
    let rs = Complex::ratio_norm_sqr(cc.sub(u), cc.add(u));
    let n2c = n2.scale(c);
    let rp = Complex::ratio_norm_sqr(n2c.sub(u), n2c.add(u));
    (0.5 * (rs + rp)).clamp(0.0, 1.0)
}

/// Real refractive index of a dielectric whose single-surface normal reflectance is `r0`.
pub fn ior_from_reflectance(r0: f64) -> f64 {
    let sq = r0.clamp(0.0, RHO_MAX).sqrt();
    (1.0 + sq) / (1.0 - sq)
}

/// Single-surface reflectance of an opaque specular surface at `cos θ` with normal value `r0`,
/// shaped by the Fresnel curve of `ior` = (n, k): `R = r0 + (1 − r0)·(F(θ) − F(0))/(1 − F(0))`,
/// which is exactly `F(θ)` when `r0 = F(0)`, and 1 at grazing for any r0.
pub fn opaque_reflectance(r0: f64, ior: (f64, f64), cos_theta: f64) -> f64 {
    let f0 = fresnel_single_surface(ior.0, ior.1, 1.0);
    let f = fresnel_single_surface(ior.0, ior.1, cos_theta);
    if f0 >= 1.0 - 1e-12 {
        return r0.clamp(0.0, 1.0); // a perfect conductor: no angle dependence left to shape
    }
    (r0 + (1.0 - r0) * (f - f0) / (1.0 - f0)).clamp(0.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Fresnel slab with no absorption computed independently (textbook formulas).
    fn slab_reference(n: f64, theta_deg: f64) -> (f64, f64) {
        let th = theta_deg.to_radians();
        let tt = (th.sin() / n).asin();
        let rs = ((th - tt).sin() / (th + tt).sin()).powi(2);
        let rp = ((th - tt).tan() / (th + tt).tan()).powi(2);
        let slab = |r: f64| (2.0 * r / (1.0 + r), (1.0 - r) / (1.0 + r));
        let (r1, t1) = slab(rs);
        let (r2, t2) = slab(rp);
        ((r1 + r2) / 2.0, (t1 + t2) / 2.0)
    }

    #[test]
    fn lossless_slab_recovers_index_and_matches_textbook_fresnel() {
        let n = 1.52f64;
        let rho = ((n - 1.0) / (n + 1.0)).powi(2);
        let r0 = 2.0 * rho / (1.0 + rho);
        let t0 = (1.0 - rho) / (1.0 + rho);
        let slab = UncoatedSlab::from_normal(t0, r0);
        assert!((slab.n - n).abs() < 1e-9, "n = {}", slab.n);
        assert!((slab.internal_transmittance - 1.0).abs() < 1e-9);
        for deg in [5.0, 30.0, 45.0, 60.0, 75.0, 85.0, 89.0] {
            let (r, t) = slab.at(f64::to_radians(deg).cos());
            let (re, te) = slab_reference(n, deg);
            assert!(
                (r - re).abs() < 1e-12 && (t - te).abs() < 1e-12,
                "{deg}: {r} {t} vs {re} {te}"
            );
        }
    }

    #[test]
    fn absorbing_slab_reproduces_its_normal_values() {
        for (t0, r0) in [(0.899, 0.083), (0.5, 0.06), (0.05, 0.045), (0.3, 0.2)] {
            let slab = UncoatedSlab::from_normal(t0, r0);
            let (r, t) = slab.at(1.0);
            assert!(
                (r - r0).abs() < 1e-12 && (t - t0).abs() < 1e-12,
                "{t0} {r0}: {r} {t}"
            );
            let (rg, tg) = slab.at(0.0);
            assert_eq!((rg, tg), (1.0, 0.0));
        }
    }

    #[test]
    fn opaque_slab_is_one_surface() {
        let slab = UncoatedSlab::from_normal(0.0, 0.04);
        assert!((slab.rho0 - 0.04).abs() < 1e-12);
        let (r, t) = slab.at(0.5);
        assert_eq!(t, 0.0);
        assert!((r - fresnel_single_surface(slab.n, 0.0, 0.5)).abs() < 1e-12);
    }

    #[test]
    fn fresnel_matches_closed_forms() {
        // Normal incidence: |(N−1)/(N+1)|²; aluminium-like N = 1.2 + 7i → 0.9129...
        let r = fresnel_single_surface(1.2, 7.0, 1.0);
        let expect = ((1.2f64 - 1.0).powi(2) + 49.0) / ((1.2f64 + 1.0).powi(2) + 49.0);
        assert!((r - expect).abs() < 1e-14);
        // Brewster angle of n = 1.5: p reflectance vanishes, so R = R_s/2.
        let th = 1.5f64.atan();
        let tt = (th.sin() / 1.5).asin();
        let rs = ((th - tt).sin() / (th + tt).sin()).powi(2);
        assert!((fresnel_single_surface(1.5, 0.0, th.cos()) - rs / 2.0).abs() < 1e-14);
        assert!((fresnel_single_surface(1.5, 0.0, 0.0) - 1.0).abs() < 1e-14);
    }

    #[test]
    fn coated_curves_published_values() {
        // Published polynomials at normal incidence: sums of coefficients.
        let (tau, rho) = CoatedCurve::Clear.raw(1.0);
        assert!((tau - 1.0023).abs() < 1e-12 && (rho - (1.001 - 1.0023)).abs() < 1e-12);
        let (tau, _) = CoatedCurve::Bronze.raw(1.0);
        assert!((tau - 1.01175).abs() < 1e-12);
        for curve in [CoatedCurve::Clear, CoatedCurve::Bronze] {
            let (t, r) = curve.normalised(1.0);
            assert!((t - 1.0).abs() < 1e-15 && r.abs() < 1e-15);
            let (r90, t90) = curve.at(0.7, 0.1, 0.0);
            assert!(t90 <= 1e-12 && (r90 - 1.0).abs() < 2e-3, "{r90} {t90}");
        }
        assert_eq!(CoatedCurve::for_t0(0.646), CoatedCurve::Clear);
        assert_eq!(CoatedCurve::for_t0(0.645), CoatedCurve::Bronze);
    }

    #[test]
    fn opaque_reflectance_blend() {
        let f0 = fresnel_single_surface(1.33, 0.0, 1.0);
        for c in [1.0, 0.7, 0.3, 0.05] {
            let a = opaque_reflectance(f0, (1.33, 0.0), c);
            assert!((a - fresnel_single_surface(1.33, 0.0, c)).abs() < 1e-14);
        }
        assert!((opaque_reflectance(0.5, (1.5, 0.0), 1.0) - 0.5).abs() < 1e-15);
        assert!((opaque_reflectance(0.5, (1.5, 0.0), 0.0) - 1.0).abs() < 1e-15);
    }
}
