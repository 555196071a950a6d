//! The exact angle dependences the report measures against ("exact physics"): the uncoated
//! slab and the WINDOW-4 coated-glass curves of `glassdb_registry::physics`, and the fits
//! made from their samples.

use glassdb_fit::{AngleSamples, Basis, CurveFit, FitOptions, Quantity, cos_deg, fit_curve};
use glassdb_registry::physics::{CoatedCurve, UncoatedSlab};

/// An exact angle dependence used as reference: (r, t) at cos θ.
#[derive(Clone)]
pub(crate) struct Reference {
    pub(crate) name: &'static str,
    pub(crate) description: String,
    kind: RefKind,
}

#[derive(Clone, Copy)]
enum RefKind {
    Slab(UncoatedSlab),
    Coated {
        curve: CoatedCurve,
        t0: f64,
        r0: f64,
    },
}

impl Reference {
    /// (r, t) at cos θ.
    pub(crate) fn eval(&self, cos: f64) -> (f64, f64) {
        match self.kind {
            RefKind::Slab(s) => s.at(cos),
            RefKind::Coated { curve, t0, r0 } => curve.at(t0, r0, cos),
        }
    }

    /// r (`Quantity::Reflectance`) or t at cos θ.
    pub(crate) fn eval_quantity(&self, quantity: Quantity, cos: f64) -> f64 {
        let (rv, tv) = self.eval(cos);
        if quantity == Quantity::Reflectance {
            rv
        } else {
            tv
        }
    }
}

/// The four references of every table, the first (the lossless slab) also of the figures.
pub(crate) fn references() -> Vec<Reference> {
    let n: f64 = 1.52;
    let rho0 = ((n - 1.0) / (n + 1.0)).powi(2);
    let clear6 = UncoatedSlab::from_normal(0.88, 0.08);
    vec![
        Reference {
            name: "slab n=1.52",
            description: "uncoated slab, n = 1.52, no absorption (s/p Fresnel, incoherent multiple reflections)".into(),
            kind: RefKind::Slab(UncoatedSlab { rho0, n, internal_transmittance: 1.0 }),
        },
        Reference {
            name: "clear 6 mm",
            description: format!(
                "uncoated absorbing slab solved from T0 = 0.88, R0 = 0.08 (n = {:.4}, internal transmittance {:.4})",
                clear6.n, clear6.internal_transmittance
            ),
            kind: RefKind::Slab(clear6),
        },
        Reference {
            name: "coated bronze",
            description: "coated glass T0 = 0.30, R0 = 0.20 with the WINDOW-4 bronze curve (as glassdb-registry applies it)".into(),
            kind: RefKind::Coated { curve: CoatedCurve::Bronze, t0: 0.30, r0: 0.20 },
        },
        Reference {
            name: "coated clear",
            description: "coated glass T0 = 0.80, R0 = 0.10 with the WINDOW-4 clear curve".into(),
            kind: RefKind::Coated { curve: CoatedCurve::Clear, t0: 0.80, r0: 0.10 },
        },
    ]
}

/// The fit samples: 0–90° in 1° steps from the reference.
pub(crate) fn samples(r: &Reference, quantity: Quantity) -> AngleSamples {
    let angle_deg: Vec<f64> = (0..=90).map(f64::from).collect();
    let value = angle_deg
        .iter()
        .map(|&a| r.eval_quantity(quantity, cos_deg(a)))
        .collect();
    AngleSamples { angle_deg, value }
}

/// A fit at a fixed degree and basis (`None` when the fit fails).
pub(crate) fn fit_fixed(
    s: &AngleSamples,
    q: Quantity,
    degree: u32,
    basis: Basis,
) -> Option<CurveFit> {
    let mut o = FitOptions::new(q);
    o.degree = Some(degree);
    o.basis = Some(basis);
    fit_curve(s, &o).ok()
}
