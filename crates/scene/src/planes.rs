//! Glass planes: the plane equation `n·X + d = 0` (method.md, eqs. 4–7), its reflection, and
//! the grouping of coplanar glass faces into distinct planes (each needs its own reflection
//! pass, section 3).

use crate::error::SceneError;
use crate::math::{self, Vec3};
use crate::obj::Scene;

/// A plane `n·X + d = 0` with unit normal `n`; its front is the side `n` points to.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plane {
    /// Unit normal, pointing to the front.
    pub normal: Vec3,
    /// Offset: n·X + d = 0 on the plane.
    pub d: f64,
}

impl Plane {
    /// The plane `a·x + b·y + c·z + d = 0`, scaled so that (a, b, c) is a unit vector.
    pub fn from_equation(eq: [f64; 4]) -> Result<Plane, SceneError> {
        if !eq.iter().all(|x| x.is_finite()) {
            return Err(SceneError::DegeneratePlane {
                message: format!("plane {eq:?} has a non-finite coefficient"),
            });
        }
        // An equation and any multiple of it are the same plane: scaled by its largest
        // coefficient first, a normal of 1e308 (whose length overflows) and one of 1e-320 (a
        // subnormal, whose length underflows) are judged alike, by their direction.
        // (Coefficients whose squares neither overflow nor underflow are taken as they are.)
        let largest = eq.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let scale = if (1e-150..=1e150).contains(&largest) {
            1.0
        } else {
            largest
        };
        let [a, b, c, d] = eq.map(|x| if scale > 0.0 { x / scale } else { x });
        let len = math::norm([a, b, c]);
        if len < 1e-12 * (1.0 + d.abs()) || len == 0.0 {
            return Err(SceneError::DegeneratePlane {
                message: format!(
                    "plane {eq:?} has a zero normal (a, b, c), or one negligible beside d; it \
                     has no orientation"
                ),
            });
        }
        // `+ 0.0` turns −0 into +0, so equations print and serialise without "-0.0".
        Ok(Plane {
            normal: [a / len + 0.0, b / len + 0.0, c / len + 0.0],
            d: d / len + 0.0,
        })
    }

    /// `[a, b, c, d]` with (a, b, c) the unit normal.
    pub fn equation(&self) -> [f64; 4] {
        [
            self.normal[0] + 0.0,
            self.normal[1] + 0.0,
            self.normal[2] + 0.0,
            self.d + 0.0,
        ]
    }

    /// Signed distance `n·X + d` (positive on the front side), the `dist` of eqs. 4–7.
    #[inline]
    pub fn signed_distance(&self, x: Vec3) -> f64 {
        math::dot(self.normal, x) + self.d
    }

    /// Mirror image of a point: `X' = X − 2·n·(n·X + d)` (eqs. 4–7).
    #[inline]
    pub fn reflect_point(&self, x: Vec3) -> Vec3 {
        math::sub(x, math::scale(self.normal, 2.0 * self.signed_distance(x)))
    }

    /// Mirror image of a direction (normals, light directions): `v' = v − 2·n·(n·v)`.
    #[inline]
    pub fn reflect_direction(&self, v: Vec3) -> Vec3 {
        math::sub(v, math::scale(self.normal, 2.0 * math::dot(self.normal, v)))
    }

    /// The 4×4 homogeneous reflection matrix (row-major, acting on column vectors
    /// `[x, y, z, 1]`): `[[I − 2nnᵀ, −2dn], [0, 1]]`. For lights, sun and environment.
    pub fn reflection_matrix(&self) -> [[f64; 4]; 4] {
        let n = self.normal;
        let mut m = [[0.0; 4]; 4];
        for r in 0..3 {
            for c in 0..3 {
                m[r][c] = if r == c { 1.0 } else { 0.0 } - 2.0 * n[r] * n[c];
            }
            m[r][3] = -2.0 * self.d * n[r];
        }
        m[3][3] = 1.0;
        for v in m.iter_mut().flatten() {
            *v += 0.0; // no "-0.0" in planes.json
        }
        m
    }

    /// Same plane, opposite orientation.
    pub fn flipped(&self) -> Plane {
        Plane {
            normal: math::scale(self.normal, -1.0),
            d: -self.d,
        }
    }
}

/// How close glass faces must be to count as one plane.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlaneTolerance {
    /// Largest angle between face normals, degrees.
    pub angle_deg: f64,
    /// Largest distance of a face's vertices from the plane, scene units.
    pub distance: f64,
}

impl PlaneTolerance {
    /// Defaults: 0.1° and 1e-4 of the scene's bounding-box diagonal.
    pub fn default_for(scene: &Scene) -> PlaneTolerance {
        PlaneTolerance {
            angle_deg: 0.1,
            distance: 1e-4 * scene.diagonal().max(1e-300),
        }
    }

    /// Refuses a tolerance that is negative, not finite, or an angle of 90° or more.
    pub fn validate(&self) -> Result<(), SceneError> {
        if !(self.angle_deg.is_finite() && self.angle_deg >= 0.0 && self.angle_deg < 90.0) {
            return Err(SceneError::BadOption {
                message: format!(
                    "angle tolerance {} must be in [0, 90) degrees",
                    self.angle_deg
                ),
            });
        }
        if !(self.distance.is_finite() && self.distance >= 0.0) {
            return Err(SceneError::BadOption {
                message: format!(
                    "distance tolerance {} must be a finite number >= 0",
                    self.distance
                ),
            });
        }
        Ok(())
    }
}

/// A distinct plane found among the glass faces.
#[derive(Debug, Clone, PartialEq)]
pub struct GlassPlane {
    /// 0-based index (order of first appearance in the file); the mask's plane index.
    pub index: usize,
    /// Oriented like the (area-weighted) majority of its faces' normals: front = that side.
    pub plane: Plane,
    /// Total area of its glass faces, scene units².
    pub area: f64,
    /// Names of the glass materials with faces on it.
    pub materials: Vec<String>,
    /// Number of glass triangles on it.
    pub triangles: usize,
}

/// Where every glass triangle went: `assignment[mesh][triangle]` is `Some(plane index)` for
/// glass triangles with area, `None` for non-glass and degenerate glass triangles.
pub type PlaneAssignment = Vec<Vec<Option<usize>>>;

/// Glob patterns over material names (`Glass*`, `Clear?`), as given on the command line.
#[derive(Debug, Clone)]
pub struct MaterialMatcher {
    patterns: Vec<(String, glob::Pattern)>,
}

impl MaterialMatcher {
    /// A matcher of `patterns` (glob syntax); a malformed pattern is an error naming it.
    pub fn new<S: AsRef<str>>(patterns: &[S]) -> Result<MaterialMatcher, SceneError> {
        let patterns = patterns
            .iter()
            .map(|p| {
                let p = p.as_ref();
                glob::Pattern::new(p)
                    .map(|g| (p.to_string(), g))
                    .map_err(|e| SceneError::BadPattern {
                        pattern: p.to_string(),
                        message: e.to_string(),
                    })
            })
            .collect::<Result<_, _>>()?;
        Ok(MaterialMatcher { patterns })
    }

    /// Index of the first pattern matching `name`.
    pub fn first_match(&self, name: &str) -> Option<usize> {
        self.patterns.iter().position(|(_, g)| g.matches(name))
    }

    /// The patterns joined for messages.
    pub fn describe(&self) -> String {
        self.patterns
            .iter()
            .map(|(p, _)| format!("{p:?}"))
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// Per material of `scene`, the index of the first matching pattern.
    pub fn material_table(&self, scene: &Scene) -> Vec<Option<usize>> {
        scene
            .materials
            .iter()
            .map(|m| self.first_match(m))
            .collect()
    }

    /// Errors with the list of the scene's materials when no face uses a matched material.
    pub fn require_faces(&self, scene: &Scene) -> Result<Vec<Option<usize>>, SceneError> {
        let table = self.material_table(scene);
        let any = scene
            .meshes
            .iter()
            .any(|m| !m.triangles.is_empty() && m.material.and_then(|i| table[i]).is_some());
        if any {
            Ok(table)
        } else {
            Err(no_glass(scene, self.describe()))
        }
    }
}

pub(crate) fn no_glass(scene: &Scene, patterns: String) -> SceneError {
    let available = if scene.materials.is_empty() {
        "none (the OBJ has no usemtl statements)".to_string()
    } else {
        scene
            .materials
            .iter()
            .map(|m| format!("{m:?}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    SceneError::NoGlassFaces {
        path: scene.source.clone(),
        patterns,
        available,
    }
}

/// Accumulates an area-weighted plane fit.
#[derive(Debug, Clone)]
struct Cluster {
    normal_sum: Vec3,
    centroid_sum: Vec3,
    area: f64,
    plane: Plane,
    materials: Vec<usize>,
    triangles: usize,
}

impl Cluster {
    fn add(&mut self, unit_n: Vec3, area: f64, centroid: Vec3, material: Option<usize>) {
        self.normal_sum = math::add(self.normal_sum, math::scale(unit_n, area));
        self.centroid_sum = math::add(self.centroid_sum, math::scale(centroid, area));
        self.area += area;
        self.triangles += 1;
        if let Some(m) = material.filter(|m| !self.materials.contains(m)) {
            self.materials.push(m);
        }
        if let Some(n) = math::normalize(self.normal_sum) {
            let c = math::scale(self.centroid_sum, 1.0 / self.area);
            self.plane = Plane {
                normal: n,
                d: -math::dot(n, c),
            };
        }
    }
}

/// Relative area below which a triangle counts as degenerate (no normal).
const DEGENERATE_AREA: f64 = 1e-14;

/// The unit normal and the area of triangle `abc`, or `None` when it is degenerate: twice its
/// area at most [`DEGENERATE_AREA`] times `scale2` (the squared scene diagonal), or not finite.
fn unit_normal_and_area(a: Vec3, b: Vec3, c: Vec3, scale2: f64) -> Option<(Vec3, f64)> {
    let area2 = math::triangle_normal_area2(a, b, c);
    let len = math::norm(area2);
    if len <= DEGENERATE_AREA * scale2 || !len.is_finite() {
        return None;
    }
    Some((math::scale(area2, 1.0 / len), 0.5 * len))
}

/// Groups the triangles with `is_glass(material)` into distinct planes within `tol`.
/// Faces with opposite windings on the same plane join the same plane. Errors when no
/// glass triangle exists, or all glass triangles are degenerate.
pub fn detect_planes(
    scene: &Scene,
    is_glass: impl Fn(Option<usize>) -> bool,
    tol: PlaneTolerance,
    patterns: &str,
) -> Result<(Vec<GlassPlane>, PlaneAssignment), SceneError> {
    tol.validate()?;
    let cos_tol = tol.angle_deg.to_radians().cos();
    let scale2 = scene.diagonal().powi(2);
    let mut clusters: Vec<Cluster> = Vec::new();
    let mut assignment: PlaneAssignment = Vec::with_capacity(scene.meshes.len());
    let mut glass_seen = 0usize;
    for mesh in &scene.meshes {
        let glass = is_glass(mesh.material);
        let mut row = vec![None; mesh.triangles.len()];
        if glass {
            for (t, slot) in row.iter_mut().enumerate() {
                glass_seen += 1;
                let [a, b, c] = mesh.corners(t);
                let Some((n, area)) = unit_normal_and_area(a, b, c, scale2) else {
                    continue;
                };
                let centroid = math::scale(math::add(math::add(a, b), c), 1.0 / 3.0);
                let found = clusters.iter().position(|cl| {
                    math::dot(cl.plane.normal, n).abs() >= cos_tol
                        && [a, b, c]
                            .iter()
                            .all(|&p| cl.plane.signed_distance(p).abs() <= tol.distance)
                });
                let k = match found {
                    Some(k) => k,
                    None => {
                        clusters.push(Cluster {
                            normal_sum: [0.0; 3],
                            centroid_sum: [0.0; 3],
                            area: 0.0,
                            plane: Plane {
                                normal: n,
                                d: -math::dot(n, centroid),
                            },
                            materials: Vec::new(),
                            triangles: 0,
                        });
                        clusters.len() - 1
                    }
                };
                let sign = if math::dot(clusters[k].plane.normal, n) >= 0.0 {
                    1.0
                } else {
                    -1.0
                };
                clusters[k].add(math::scale(n, sign), area, centroid, mesh.material);
                *slot = Some(k);
            }
        }
        assignment.push(row);
    }
    if glass_seen == 0 {
        return Err(no_glass(scene, patterns.to_string()));
    }
    if clusters.is_empty() {
        return Err(SceneError::DegeneratePlane {
            message: format!(
                "all {glass_seen} glass triangles of {} have zero area",
                scene.source.display()
            ),
        });
    }
    let planes = clusters
        .into_iter()
        .enumerate()
        .map(|(index, cl)| GlassPlane {
            index,
            plane: cl.plane,
            area: cl.area,
            materials: cl
                .materials
                .iter()
                .filter_map(|&m| scene.materials.get(m).cloned())
                .collect(),
            triangles: cl.triangles,
        })
        .collect();
    Ok((planes, assignment))
}

/// Assigns every glass triangle to the closest of the given planes (for a mask that must use
/// the plane indices of an earlier `glassdb mirror`). Errors naming the first face that lies
/// on none of them within `tol`.
pub fn assign_to_planes(
    scene: &Scene,
    is_glass: impl Fn(Option<usize>) -> bool,
    planes: &[Plane],
    tol: PlaneTolerance,
) -> Result<PlaneAssignment, SceneError> {
    tol.validate()?;
    let cos_tol = tol.angle_deg.to_radians().cos();
    let scale2 = scene.diagonal().powi(2);
    let mut assignment = Vec::with_capacity(scene.meshes.len());
    for mesh in &scene.meshes {
        let mut row = vec![None; mesh.triangles.len()];
        if is_glass(mesh.material) {
            for (t, slot) in row.iter_mut().enumerate() {
                let [a, b, c] = mesh.corners(t);
                let Some((n, _)) = unit_normal_and_area(a, b, c, scale2) else {
                    continue;
                };
                let best = planes
                    .iter()
                    .enumerate()
                    .filter(|(_, p)| math::dot(p.normal, n).abs() >= cos_tol)
                    .map(|(k, p)| {
                        (
                            k,
                            [a, b, c]
                                .iter()
                                .map(|&x| p.signed_distance(x).abs())
                                .fold(0.0, f64::max),
                        )
                    })
                    .filter(|&(_, dist)| dist <= tol.distance)
                    .min_by(|x, y| x.1.total_cmp(&y.1));
                match best {
                    Some((k, _)) => *slot = Some(k),
                    None => {
                        return Err(SceneError::BadPlanes {
                            path: scene.source.clone(),
                            message: format!(
                                "glass triangle {t} of group {:?} (corners {a:?}, {b:?}, {c:?}) lies on none of the given planes",
                                mesh.group
                            ),
                        });
                    }
                }
            }
        }
        assignment.push(row);
    }
    Ok(assignment)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn huge_and_subnormal_equations_are_judged_by_their_direction() {
        for k in [1e308, -1e308, 1e-320, -1e-318, 1.0] {
            let p = Plane::from_equation([k, 0.0, 0.0, -0.5 * k]).unwrap();
            assert_eq!(p.normal, [k.signum(), 0.0, 0.0], "{k:e}");
            assert_eq!(p.d, -0.5 * k.signum(), "{k:e}");
        }
        let tiny = Plane::from_equation([0.0, 5e-324, 0.0, 0.0]).unwrap();
        assert_eq!(tiny.normal, [0.0, 1.0, 0.0]);
        let tilted = Plane::from_equation([1e308, 1e308, 0.0, 0.0]).unwrap();
        assert!((tilted.normal[0] - std::f64::consts::FRAC_1_SQRT_2).abs() < 1e-15);
        // A normal negligible beside d, at any scale, is still refused.
        for k in [1.0, 1e300, 1e-300] {
            assert!(
                Plane::from_equation([1e-14 * k, 0.0, 0.0, k]).is_err(),
                "{k:e}"
            );
        }
        for bad in [
            [0.0; 4],
            [f64::INFINITY, 0.0, 0.0, 1.0],
            [0.0, 0.0, 0.0, 1e-320],
        ] {
            assert!(Plane::from_equation(bad).is_err(), "{bad:?}");
        }
    }

    #[test]
    fn reflection_of_known_points() {
        // The plane x = 2 (normal +x): (5, 1, -3) is 3 in front, its image 3 behind.
        let p = Plane::from_equation([2.0, 0.0, 0.0, -4.0]).unwrap();
        assert_eq!(p.equation(), [1.0, 0.0, 0.0, -2.0]);
        assert_eq!(p.reflect_point([5.0, 1.0, -3.0]), [-1.0, 1.0, -3.0]);
        // The plane x + y = 0: (1, 0, 0) ↦ (0, −1, 0).
        let q = Plane::from_equation([1.0, 1.0, 0.0, 0.0]).unwrap();
        let r = q.reflect_point([1.0, 0.0, 0.0]);
        assert!(
            (r[0]).abs() < 1e-15 && (r[1] + 1.0).abs() < 1e-15 && r[2] == 0.0,
            "{r:?}"
        );
        // The matrix does the same as the point map.
        let m = q.reflection_matrix();
        let x = [0.3, -2.0, 7.0];
        let mx: Vec<f64> = (0..3)
            .map(|i| m[i][0] * x[0] + m[i][1] * x[1] + m[i][2] * x[2] + m[i][3])
            .collect();
        let px = q.reflect_point(x);
        for i in 0..3 {
            assert!((mx[i] - px[i]).abs() < 1e-14);
        }
    }

    #[test]
    fn degenerate_plane_is_an_error() {
        assert!(matches!(
            Plane::from_equation([0.0, 0.0, 0.0, 1.0]),
            Err(SceneError::DegeneratePlane { .. })
        ));
        assert!(matches!(
            Plane::from_equation([f64::NAN, 0.0, 1.0, 1.0]),
            Err(SceneError::DegeneratePlane { .. })
        ));
    }
}
