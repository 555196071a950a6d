//! Triangulating an OBJ polygon by ear clipping in its own plane.
//!
//! The polygon is projected onto the plane of its Newell normal, in a frame where it turns
//! counter-clockwise whatever its winding, so every triangle cut from it keeps its winding
//! (orientation) in 3-D. A strictly convex polygon gives exactly the fan (0,1,2), (0,2,3), …
//! that OBJ readers (and `tobj`) make, so convex faces triangulate as they always did. When
//! the polygon cannot be cut into triangles that lie inside it (it is not planar, crosses
//! itself, overlaps itself or has too many corners), the result is the fan together with the
//! reason, for a warning; a polygon whose corners all lie on one line gives its (zero-area) fan
//! silently.
//!
//! Crate choice: the maintained ports of mapbox's earcut (`earcut`, `earcutr`) were considered
//! and not used. They triangulate 2-D rings (the projection is ours to do anyway), they never
//! report failure (a self-intersecting ring is silently "cured", so there would be nothing to
//! warn about), their triangles for a convex quad are not the fan (every committed virtual
//! scene and mask would change), and their strength, holes, does not apply: an OBJ face has
//! none. OBJ polygons have a few to a few hundred corners, so a plain ear clipper with exact
//! failure reporting is short and sufficient.

use crate::math::{Vec3, add, cross, dot, norm, normalize, scale, sub};
use crate::warning::FanReason;

/// Most corners of a non-convex polygon that is ear-clipped (the clipper is quadratic or
/// worse in the corner count); larger ones are fanned with a warning. Convex polygons of any
/// size take the fan directly.
pub const MAX_EAR_CLIP_VERTICES: usize = 1024;

/// Largest distance of a corner from the polygon's plane, relative to the polygon's size
/// (bounding-box diagonal), for the polygon to count as planar.
pub const PLANARITY_TOLERANCE: f64 = 1e-3;

/// Twice a triangle's area below this times size² counts as zero (collinear corners).
const AREA_EPS: f64 = 1e-12;
/// Corners closer than this times the size coincide.
const LENGTH_EPS: f64 = 1e-12;
/// Corners within this times the size of one line make a degenerate polygon.
const COLLINEAR_EPS: f64 = 1e-9;

/// The triangles of one polygon, as corner positions `0..n` in the polygon's order.
#[derive(Debug, Clone, PartialEq)]
pub struct Triangulation {
    /// Corner triples, with the polygon's winding.
    pub triangles: Vec<[usize; 3]>,
    /// `Some` when ear clipping was not possible and `triangles` is the fan.
    pub fallback: Option<FanReason>,
}

/// The fan (0,1,2), (0,2,3), … of an `n`-gon.
pub fn fan(n: usize) -> Vec<[usize; 3]> {
    (1..n.saturating_sub(1)).map(|k| [0, k, k + 1]).collect()
}

/// Triangulates the polygon with corners `points` (in face order) by ear clipping in its
/// plane; see the module documentation. Never panics, whatever the input.
pub fn triangulate_polygon(points: &[Vec3]) -> Triangulation {
    match ear_clip(points) {
        Ok(triangles) => Triangulation {
            triangles,
            fallback: None,
        },
        Err(reason) => Triangulation {
            triangles: fan(points.len()),
            fallback: reason,
        },
    }
}

/// A 2-D point in the polygon's plane.
type P2 = [f64; 2];

/// Twice the signed area of (a, b, c): positive when they turn counter-clockwise.
#[inline]
fn orient(a: P2, b: P2, c: P2) -> f64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

#[inline]
fn dist2(a: P2, b: P2) -> f64 {
    (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)
}

/// Ear clipping, or `Err` with the reason to fan (`None`: fan silently, the polygon has no
/// area because its corners are collinear).
fn ear_clip(points: &[Vec3]) -> Result<Vec<[usize; 3]>, Option<FanReason>> {
    let n = points.len();
    if n <= 3 {
        return Ok(fan(n));
    }
    let centroid = scale(
        points.iter().fold([0.0; 3], |acc, p| add(acc, *p)),
        1.0 / n as f64,
    );
    let rel: Vec<Vec3> = points.iter().map(|p| sub(*p, centroid)).collect();
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in &rel {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let size = norm(sub(hi, lo));
    if !(size > 0.0 && size.is_finite()) {
        return Err(None); // all corners coincide (or are not finite: the reader refuses those)
    }

    // Newell's normal: twice the vector area, along the right-hand rule of the winding.
    let mut area_vec = [0.0; 3];
    for i in 0..n {
        area_vec = add(area_vec, cross(rel[i], rel[(i + 1) % n]));
    }
    let eps_area = AREA_EPS * size * size;
    let normal = match normalize(area_vec) {
        Some(u) if norm(area_vec) > eps_area => u,
        _ => {
            return Err(if collinear(&rel, size) {
                None
            } else {
                Some(FanReason::ZeroArea)
            });
        }
    };
    let deviation = rel
        .iter()
        .map(|p| dot(*p, normal).abs())
        .fold(0.0, f64::max);
    if deviation > PLANARITY_TOLERANCE * size {
        return Err(Some(FanReason::NonPlanar { deviation, size }));
    }

    // An orthonormal frame (u, v) of the plane with u × v = normal: the polygon turns
    // counter-clockwise in it, so counter-clockwise triangles keep the polygon's winding.
    let helper = {
        let a = normal.map(f64::abs);
        if a[0] <= a[1] && a[0] <= a[2] {
            [1.0, 0.0, 0.0]
        } else if a[1] <= a[2] {
            [0.0, 1.0, 0.0]
        } else {
            [0.0, 0.0, 1.0]
        }
    };
    let u = normalize(cross(normal, helper)).ok_or(Some(FanReason::NoEar))?;
    let v = cross(normal, u);
    let q: Vec<P2> = rel.iter().map(|p| [dot(*p, u), dot(*p, v)]).collect();

    if strictly_convex(&q, eps_area) {
        return Ok(fan(n));
    }
    if n > MAX_EAR_CLIP_VERTICES {
        return Err(Some(FanReason::TooManyVertices {
            max: MAX_EAR_CLIP_VERTICES,
        }));
    }

    // The ring of corners without consecutive duplicates (corner 0 always kept).
    let eps_len2 = (LENGTH_EPS * size).powi(2);
    let mut ring: Vec<usize> = Vec::with_capacity(n);
    for (i, &p) in q.iter().enumerate() {
        if ring
            .last()
            .is_some_and(|&last| dist2(q[last], p) <= eps_len2)
        {
            continue;
        }
        ring.push(i);
    }
    while ring.len() > 1
        && ring
            .last()
            .is_some_and(|&l| dist2(q[l], q[ring[0]]) <= eps_len2)
    {
        ring.pop();
    }
    if ring.len() < 3 {
        return Err(Some(FanReason::NoEar));
    }
    if let Some([i, j]) = first_crossing(&q, &ring, eps_area) {
        return Err(Some(FanReason::SelfIntersecting {
            edges: [ring[i] + 1, ring[j] + 1],
        }));
    }
    let triangles = clip(&q, &ring, eps_area, eps_len2).ok_or(Some(FanReason::NoEar))?;

    // The triangles must tile the polygon: their areas (all positive) add up to its area.
    let polygon: f64 = (0..ring.len())
        .map(|k| {
            let (a, b) = (q[ring[k]], q[ring[(k + 1) % ring.len()]]);
            a[0] * b[1] - a[1] * b[0]
        })
        .sum();
    let tiles: f64 = triangles
        .iter()
        .map(|&[a, b, c]| orient(q[a], q[b], q[c]))
        .sum();
    if (tiles - polygon).abs() > 1e-9 * (tiles.abs() + polygon.abs()) + n as f64 * eps_area {
        return Err(Some(FanReason::NoEar));
    }
    Ok(triangles)
}

/// Whether every corner lies within `COLLINEAR_EPS · size` of one line.
fn collinear(rel: &[Vec3], size: f64) -> bool {
    let p0 = rel[0];
    let far = rel
        .iter()
        .copied()
        .max_by(|a, b| norm(sub(*a, p0)).total_cmp(&norm(sub(*b, p0))))
        .unwrap_or(p0);
    let Some(dir) = normalize(sub(far, p0)) else {
        return true;
    };
    rel.iter()
        .all(|p| norm(cross(sub(*p, p0), dir)) <= COLLINEAR_EPS * size)
}

/// Every corner turns left (beyond the tolerance) and the outline turns once in all: a simple
/// convex polygon, whose fan lies inside it.
fn strictly_convex(q: &[P2], eps_area: f64) -> bool {
    let n = q.len();
    let mut turning = 0.0;
    for i in 0..n {
        let (a, b, c) = (q[(i + n - 1) % n], q[i], q[(i + 1) % n]);
        let o = orient(a, b, c);
        if o <= eps_area {
            return false;
        }
        let (e1, e2) = ([b[0] - a[0], b[1] - a[1]], [c[0] - b[0], c[1] - b[1]]);
        turning += o.atan2(e1[0] * e2[0] + e1[1] * e2[1]);
    }
    turning < 3.0 * std::f64::consts::PI
}

/// Whether segments (a, b) and (c, d) cross at a point inside both (touching and collinear
/// overlap do not count).
fn properly_cross(a: P2, b: P2, c: P2, d: P2, eps_area: f64) -> bool {
    let opposite =
        |x: f64, y: f64| (x > eps_area && y < -eps_area) || (x < -eps_area && y > eps_area);
    opposite(orient(a, b, c), orient(a, b, d)) && opposite(orient(c, d, a), orient(c, d, b))
}

/// The first pair of ring edges (by ring position of their first corners) that cross.
fn first_crossing(q: &[P2], ring: &[usize], eps_area: f64) -> Option<[usize; 2]> {
    let m = ring.len();
    let edge = |k: usize| (q[ring[k]], q[ring[(k + 1) % m]]);
    let bbox = |(a, b): (P2, P2)| {
        (
            [a[0].min(b[0]), a[1].min(b[1])],
            [a[0].max(b[0]), a[1].max(b[1])],
        )
    };
    let boxes: Vec<(P2, P2)> = (0..m).map(|k| bbox(edge(k))).collect();
    for i in 0..m {
        for j in i + 2..m {
            if i == 0 && j == m - 1 {
                continue; // adjacent through the closing edge
            }
            let ((lo1, hi1), (lo2, hi2)) = (boxes[i], boxes[j]);
            if lo1[0] > hi2[0] || lo2[0] > hi1[0] || lo1[1] > hi2[1] || lo2[1] > hi1[1] {
                continue;
            }
            let ((a, b), (c, d)) = (edge(i), edge(j));
            if properly_cross(a, b, c, d, eps_area) {
                return Some([i, j]);
            }
        }
    }
    None
}

/// Cuts ears from the counter-clockwise `ring` (positions into `q`); `None` when a full turn
/// finds no ear. Returns corner triples (indices into `q`).
///
/// It starts at the corner after corner 0 and, after each cut, tries the corner after the
/// one cut first, so a convex ring gives the fan from corner 0. Flat corners (collinear with
/// their neighbours, or a zero-width spike) are dropped without a triangle.
fn clip(q: &[P2], ring: &[usize], eps_area: f64, eps_len2: f64) -> Option<Vec<[usize; 3]>> {
    let m0 = ring.len();
    let mut prev: Vec<usize> = (0..m0).map(|k| (k + m0 - 1) % m0).collect();
    let mut next: Vec<usize> = (0..m0).map(|k| (k + 1) % m0).collect();
    let p = |k: usize| q[ring[k]];
    let mut out = Vec::with_capacity(m0 - 2);
    let mut m = m0;
    let mut cur = 1;
    let mut idle = 0;
    while m > 3 {
        let (a, b, c) = (prev[cur], cur, next[cur]);
        let o = orient(p(a), p(b), p(c));
        let flat = o.abs() <= eps_area;
        if flat || (o > 0.0 && is_ear(&p, &next, [a, b, c], eps_area, eps_len2)) {
            if !flat {
                out.push([ring[a], ring[b], ring[c]]);
            }
            next[a] = c;
            prev[c] = a;
            m -= 1;
            cur = c;
            idle = 0;
            continue;
        }
        cur = c;
        idle += 1;
        if idle > m {
            return None;
        }
    }
    let (a, b, c) = (prev[cur], cur, next[cur]);
    let o = orient(p(a), p(b), p(c));
    if o > eps_area {
        out.push([ring[a], ring[b], ring[c]]);
    } else if o < -eps_area {
        return None;
    }
    Some(out)
}

/// Whether (a, b, c), convex at b, is an ear: no other remaining corner in the closed triangle
/// (corners at the same place as a, b or c excepted: a polygon may touch itself there) and no
/// remaining edge crossing the new diagonal c–a.
fn is_ear(
    p: &impl Fn(usize) -> P2,
    next: &[usize],
    [a, b, c]: [usize; 3],
    eps_area: f64,
    eps_len2: f64,
) -> bool {
    let (pa, pb, pc) = (p(a), p(b), p(c));
    let mut k = next[c];
    while k != a {
        let pk = p(k);
        let inside = orient(pa, pb, pk) >= -eps_area
            && orient(pb, pc, pk) >= -eps_area
            && orient(pc, pa, pk) >= -eps_area;
        if inside && ![pa, pb, pc].iter().any(|&x| dist2(x, pk) <= eps_len2) {
            return false;
        }
        let k2 = next[k];
        if k2 != a && properly_cross(pc, pa, pk, p(k2), eps_area) {
            return false;
        }
        k = k2;
    }
    true
}

#[cfg(test)]
mod tests;
