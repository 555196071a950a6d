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
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// Corners in the plane z = 0.
    fn flat(xy: &[[f64; 2]]) -> Vec<Vec3> {
        xy.iter().map(|p| [p[0], p[1], 0.0]).collect()
    }

    fn area2(p: &[Vec3], [a, b, c]: [usize; 3]) -> Vec3 {
        cross(sub(p[b], p[a]), sub(p[c], p[a]))
    }

    /// Newell normal of the whole polygon (twice its vector area).
    fn newell(p: &[Vec3]) -> Vec3 {
        let n = p.len();
        (0..n).fold([0.0; 3], |acc, i| add(acc, cross(p[i], p[(i + 1) % n])))
    }

    /// Whether 2-D point `x` is inside (or on) triangle t of the flat polygon `p`.
    fn in_triangle(p: &[Vec3], [a, b, c]: [usize; 3], x: [f64; 2]) -> bool {
        let q = |i: usize| [p[i][0], p[i][1]];
        let (o1, o2, o3) = (
            orient(q(a), q(b), x),
            orient(q(b), q(c), x),
            orient(q(c), q(a), x),
        );
        (o1 >= 0.0 && o2 >= 0.0 && o3 >= 0.0) || (o1 <= 0.0 && o2 <= 0.0 && o3 <= 0.0)
    }

    /// Checks a successful triangulation: n − 2 triangles (or fewer, for flat corners), each
    /// with the polygon's winding, areas adding up to the polygon's.
    fn check_tiles(p: &[Vec3], t: &Triangulation) {
        assert_eq!(t.fallback, None, "{p:?}");
        assert!(t.triangles.len() <= p.len() - 2);
        let whole = newell(p);
        let mut sum = [0.0; 3];
        for &tri in &t.triangles {
            let a = area2(p, tri);
            assert!(dot(a, whole) > 0.0, "triangle {tri:?} is flipped");
            sum = add(sum, a);
        }
        assert!(
            norm(sub(sum, whole)) <= 1e-9 * norm(whole),
            "{sum:?} vs {whole:?}"
        );
    }

    /// A U-shaped pane 3 wide and 2 high with a 1 × 1 notch from the top middle.
    const U: [[f64; 2]; 8] = [
        [0.0, 0.0],
        [3.0, 0.0],
        [3.0, 2.0],
        [2.0, 2.0],
        [2.0, 1.0],
        [1.0, 1.0],
        [1.0, 2.0],
        [0.0, 2.0],
    ];

    #[test]
    fn a_u_shaped_pane_is_tiled_without_covering_its_notch() {
        for reversed in [false, true] {
            let mut xy = U.to_vec();
            if reversed {
                xy.reverse();
            }
            let p = flat(&xy);
            let t = triangulate_polygon(&p);
            check_tiles(&p, &t);
            assert_eq!(t.triangles.len(), 6);
            // Area 3·2 − 1 = 5 (newell is twice the area).
            assert!((norm(newell(&p)) / 2.0 - 5.0).abs() < 1e-12);
            let covered = |x: [f64; 2]| t.triangles.iter().any(|&tri| in_triangle(&p, tri, x));
            for x in [[1.5, 1.5], [1.1, 1.9], [1.9, 1.05], [1.5, 1.999]] {
                assert!(!covered(x), "notch point {x:?} covered ({reversed})");
            }
            for x in [[0.5, 1.5], [2.5, 1.9], [1.5, 0.5], [1.5, 0.99]] {
                assert!(covered(x), "pane point {x:?} not covered ({reversed})");
            }
            // The fan from corner 0 would have covered the notch.
            assert!(fan(8).iter().any(|&tri| in_triangle(&p, tri, [1.5, 1.5])));
        }
    }

    #[test]
    fn l_and_star_shapes_in_both_windings_and_any_plane() {
        let l = [
            [0.0, 0.0],
            [2.0, 0.0],
            [2.0, 1.0],
            [1.0, 1.0],
            [1.0, 2.0],
            [0.0, 2.0],
        ];
        let star: Vec<[f64; 2]> = (0..10)
            .map(|k| {
                let r = if k % 2 == 0 { 2.0 } else { 0.7 };
                let a = k as f64 * std::f64::consts::PI / 5.0;
                [r * a.cos(), r * a.sin()]
            })
            .collect();
        // A tilted plane: the polygon's own plane, not a coordinate plane.
        let tilt = |p: [f64; 2]| [p[0] + 3.0, 0.6 * p[1] - 1.0, 0.8 * p[1] + 0.25 * p[0]];
        for shape in [l.to_vec(), star] {
            for reversed in [false, true] {
                let mut xy = shape.clone();
                if reversed {
                    xy.reverse();
                }
                for rotate in 0..xy.len() {
                    let mut r = xy.clone();
                    r.rotate_left(rotate);
                    let p: Vec<Vec3> = r.iter().map(|&q| tilt(q)).collect();
                    let t = triangulate_polygon(&p);
                    check_tiles(&p, &t);
                    assert_eq!(t.triangles.len(), p.len() - 2);
                }
            }
        }
    }

    #[test]
    fn convex_polygons_give_exactly_the_fan() {
        let square = flat(&[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]);
        assert_eq!(
            triangulate_polygon(&square).triangles,
            vec![[0, 1, 2], [0, 2, 3]]
        );
        let mut cw = square.clone();
        cw.reverse();
        assert_eq!(
            triangulate_polygon(&cw).triangles,
            vec![[0, 1, 2], [0, 2, 3]]
        );
        let circle: Vec<Vec3> = (0..2000)
            .map(|k| {
                let a = k as f64 * std::f64::consts::TAU / 2000.0;
                [a.cos(), 0.5, a.sin()]
            })
            .collect();
        let t = triangulate_polygon(&circle);
        assert_eq!((t.triangles, t.fallback), (fan(2000), None));
        let tri = flat(&[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]);
        assert_eq!(triangulate_polygon(&tri).triangles, vec![[0, 1, 2]]);
    }

    #[test]
    fn duplicate_and_collinear_corners_are_skipped() {
        // The U with corner 0 repeated at the end, a doubled corner and a corner in the middle
        // of the bottom edge.
        let mut xy = vec![[0.0, 0.0], [1.5, 0.0]];
        xy.extend_from_slice(&U[1..]);
        xy.insert(5, xy[4]);
        xy.push([0.0, 0.0]);
        let p = flat(&xy);
        let t = triangulate_polygon(&p);
        check_tiles(&p, &t);
        for tri in &t.triangles {
            assert!(norm(area2(&p, *tri)) > 0.0, "degenerate triangle {tri:?}");
        }
        assert!(
            !t.triangles
                .iter()
                .any(|&tri| in_triangle(&p, tri, [1.5, 1.5]))
        );
        // A rectangle with a collinear corner: no zero-area triangle.
        let p = flat(&[[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [2.0, 1.0], [0.0, 1.0]]);
        let t = triangulate_polygon(&p);
        check_tiles(&p, &t);
        assert_eq!(t.triangles, vec![[0, 2, 3], [0, 3, 4]]);
        // All corners on one line: the (zero-area) fan, without a warning.
        let p = flat(&[[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [3.0, 0.0]]);
        assert_eq!(triangulate_polygon(&p).fallback, None);
    }

    #[test]
    fn a_polygon_with_a_hole_through_a_bridge_is_tiled() {
        // Outer square 4 × 4, square hole 2 × 2 reached by a doubled bridge edge.
        let p = flat(&[
            [0.0, 0.0],
            [4.0, 0.0],
            [4.0, 4.0],
            [0.0, 4.0],
            [0.0, 0.0],
            [1.0, 1.0],
            [1.0, 3.0],
            [3.0, 3.0],
            [3.0, 1.0],
            [1.0, 1.0],
        ]);
        let t = triangulate_polygon(&p);
        check_tiles(&p, &t);
        assert!(
            !t.triangles
                .iter()
                .any(|&tri| in_triangle(&p, tri, [2.0, 2.0]))
        );
    }

    #[test]
    fn non_planar_self_intersecting_and_huge_polygons_fall_back_to_the_fan() {
        let bent = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.3],
            [0.0, 1.0, 0.0],
        ];
        let t = triangulate_polygon(&bent);
        assert_eq!(t.triangles, fan(4));
        assert!(
            matches!(t.fallback, Some(FanReason::NonPlanar { deviation, size })
            if deviation > 0.05 && size > 1.0)
        );
        // Slightly bent (below the tolerance): triangulated as planar.
        let mut slight = bent.clone();
        slight[2][2] = 1e-5;
        assert_eq!(triangulate_polygon(&slight).fallback, None);

        // A pentagram {5/2}: every corner turns left but its edges cross.
        let star: Vec<Vec3> = (0..5)
            .map(|k| {
                let a = (2 * k) as f64 * std::f64::consts::TAU / 5.0;
                [a.cos(), a.sin(), 0.0]
            })
            .collect();
        let t = triangulate_polygon(&star);
        assert_eq!(t.triangles, fan(5));
        assert!(
            matches!(t.fallback, Some(FanReason::SelfIntersecting { .. })),
            "{t:?}"
        );

        // A crossed U: the notch's corners swapped.
        let mut crossed = U;
        crossed.swap(4, 5);
        let t = triangulate_polygon(&flat(&crossed));
        assert_eq!(
            t.fallback,
            Some(FanReason::SelfIntersecting { edges: [4, 6] }),
            "{t:?}"
        );

        // A bow tie encloses no net area.
        let bow = flat(&[[0.0, 0.0], [1.0, 1.0], [1.0, 0.0], [0.0, 1.0]]);
        assert_eq!(
            triangulate_polygon(&bow).fallback,
            Some(FanReason::ZeroArea)
        );

        // A comb with more corners than the clipper takes.
        let teeth = MAX_EAR_CLIP_VERTICES / 2 + 1;
        let mut comb: Vec<[f64; 2]> = Vec::new();
        for k in 0..teeth {
            comb.push([k as f64, if k % 2 == 0 { 1.0 } else { 2.0 }]);
        }
        comb.push([teeth as f64, 0.0]);
        for k in (0..teeth).rev() {
            comb.push([k as f64, -0.5 - (k % 3) as f64 * 0.1]);
        }
        let t = triangulate_polygon(&flat(&comb));
        assert_eq!(t.triangles, fan(comb.len()));
        assert_eq!(
            t.fallback,
            Some(FanReason::TooManyVertices {
                max: MAX_EAR_CLIP_VERTICES
            })
        );
    }

    /// Whether the interiors of two 2-D triangles overlap (separating-axis test with a small
    /// tolerance, so that triangles sharing an edge or a corner do not count).
    fn overlap(t1: [P2; 3], t2: [P2; 3]) -> bool {
        for (a, b) in [(t1, t2), (t2, t1)] {
            for k in 0..3 {
                let (p, q) = (a[k], a[(k + 1) % 3]);
                let axis = [q[1] - p[1], p[0] - q[0]];
                let proj = |t: [P2; 3]| {
                    let d: Vec<f64> = t.iter().map(|x| x[0] * axis[0] + x[1] * axis[1]).collect();
                    (
                        d.iter().copied().fold(f64::INFINITY, f64::min),
                        d.iter().copied().fold(f64::NEG_INFINITY, f64::max),
                    )
                };
                let ((lo1, hi1), (lo2, hi2)) = (proj(a), proj(b));
                let tol = 1e-9 * (axis[0].abs() + axis[1].abs()).max(1e-300);
                if hi1 <= lo2 + tol || hi2 <= lo1 + tol {
                    return false;
                }
            }
        }
        true
    }

    /// Even-odd point-in-polygon test.
    fn inside_polygon(xy: &[P2], x: P2) -> bool {
        let n = xy.len();
        let mut inside = false;
        for i in 0..n {
            let (a, b) = (xy[i], xy[(i + 1) % n]);
            if (a[1] > x[1]) != (b[1] > x[1]) {
                let t = (x[1] - a[1]) / (b[1] - a[1]);
                if x[0] < a[0] + t * (b[0] - a[0]) {
                    inside = !inside;
                }
            }
        }
        inside
    }

    /// The triangles tile the simple polygon `xy` exactly: areas add up, each lies inside
    /// (its centroid does), no two overlap.
    fn assert_exact_tiling(xy: &[P2], tris: &[[usize; 3]]) {
        let corners = |[a, b, c]: [usize; 3]| [xy[a], xy[b], xy[c]];
        for (i, &t) in tris.iter().enumerate() {
            let [a, b, c] = corners(t);
            let g = [(a[0] + b[0] + c[0]) / 3.0, (a[1] + b[1] + c[1]) / 3.0];
            assert!(inside_polygon(xy, g), "triangle {t:?} lies outside {xy:?}");
            for &u in &tris[i + 1..] {
                assert!(
                    !overlap(corners(t), corners(u)),
                    "{t:?} and {u:?} overlap in {xy:?}"
                );
            }
        }
    }

    /// Strictly simple: no two edges meet except neighbours at their shared corner.
    fn strictly_simple(xy: &[P2]) -> bool {
        let n = xy.len();
        let seg = |k: usize| (xy[k], xy[(k + 1) % n]);
        let on = |a: P2, b: P2, p: P2| {
            orient(a, b, p) == 0.0
                && p[0] >= a[0].min(b[0])
                && p[0] <= a[0].max(b[0])
                && p[1] >= a[1].min(b[1])
                && p[1] <= a[1].max(b[1])
        };
        for i in 0..n {
            if xy[i] == xy[(i + 1) % n] {
                return false;
            }
            for j in i + 1..n {
                let ((a, b), (c, d)) = (seg(i), seg(j));
                let neighbours = j == i + 1 || (i == 0 && j == n - 1);
                if neighbours {
                    // Only the shared corner: the other ends must not lie on the other edge.
                    let (far1, far2) = if j == i + 1 { (a, d) } else { (b, c) };
                    if on(c, d, far1) || on(a, b, far2) {
                        return false;
                    }
                    continue;
                }
                let (o1, o2, o3, o4) = (
                    orient(a, b, c),
                    orient(a, b, d),
                    orient(c, d, a),
                    orient(c, d, b),
                );
                if (o1 * o2 < 0.0 && o3 * o4 < 0.0)
                    || on(a, b, c)
                    || on(a, b, d)
                    || on(c, d, a)
                    || on(c, d, b)
                {
                    return false;
                }
            }
        }
        true
    }

    #[test]
    fn the_shapes_are_tiled_exactly() {
        let t = triangulate_polygon(&flat(&U));
        assert_exact_tiling(&U, &t.triangles);
        let mut rev = U;
        rev.reverse();
        assert_exact_tiling(&rev, &triangulate_polygon(&flat(&rev)).triangles);
    }

    proptest! {
        /// Star-shaped polygons (random radii around a centre) are simple: they are always
        /// tiled, with the polygon's winding, in any plane.
        #[test]
        fn random_star_shaped_polygons_are_tiled(
            radii in prop::collection::vec(0.05f64..2.0, 4..40),
            normal in prop::array::uniform3(-1.0f64..1.0),
            reversed in any::<bool>(),
        ) {
            let Some(nz) = normalize(normal) else { return Ok(()) };
            let helper = if nz[0].abs() < 0.9 { [1.0, 0.0, 0.0] } else { [0.0, 1.0, 0.0] };
            let u = normalize(cross(nz, helper)).unwrap();
            let v = cross(nz, u);
            let n = radii.len();
            let mut xy: Vec<P2> = radii
                .iter()
                .enumerate()
                .map(|(k, r)| {
                    let a = k as f64 * std::f64::consts::TAU / n as f64;
                    [r * a.cos(), r * a.sin()]
                })
                .collect();
            if reversed {
                xy.reverse();
            }
            let p: Vec<Vec3> = xy.iter().map(|q| add(scale(u, q[0]), scale(v, q[1]))).collect();
            let t = triangulate_polygon(&p);
            check_tiles(&p, &t);
            prop_assert_eq!(t.triangles.len(), n - 2);
            assert_exact_tiling(&xy, &t.triangles);
        }

        /// Skylines (a base and columns of random heights): orthogonal, like façades, with
        /// reflex corners exactly on the lines of others, collinear corners where neighbours
        /// are as high; always tiled exactly, from any start corner, in either winding.
        #[test]
        fn random_skylines_are_tiled_exactly(
            heights in prop::collection::vec(1i32..5, 1..12),
            start in 0usize..64,
            reversed in any::<bool>(),
        ) {
            let w = heights.len();
            let mut xy: Vec<P2> = vec![[0.0, 0.0], [w as f64, 0.0]];
            for (i, &h) in heights.iter().enumerate().rev() {
                xy.push([(i + 1) as f64, h as f64]);
                xy.push([i as f64, h as f64]);
            }
            xy.dedup(); // equal neighbours: one corner, collinear with its neighbours
            if reversed {
                xy.reverse();
            }
            let k = start % xy.len();
            xy.rotate_left(k);
            prop_assert!(strictly_simple(&xy), "{:?}", xy);
            let t = triangulate_polygon(&flat(&xy));
            check_tiles(&flat(&xy), &t);
            assert_exact_tiling(&xy, &t.triangles);
        }

        /// Polygons on a coarse grid (collinear corners, repeated corners, touching and
        /// crossing edges): never a panic; a strictly simple one is always tiled exactly, and
        /// any tiling that is returned is exact.
        #[test]
        fn random_grid_polygons_are_tiled_or_reported(
            cells in prop::collection::vec((0i32..6, 0i32..6), 4..14),
            by_angle in any::<bool>(),
        ) {
            let mut xy: Vec<P2> = cells.iter().map(|&(x, y)| [x as f64, y as f64]).collect();
            if by_angle {
                // Around a point off the grid: mostly simple, with many collinear corners.
                xy.sort_by(|a, b| {
                    let ang = |p: &P2| (p[1] - 2.55).atan2(p[0] - 2.45);
                    ang(a).total_cmp(&ang(b))
                });
            }
            let t = triangulate_polygon(&flat(&xy));
            if strictly_simple(&xy) {
                prop_assert_eq!(t.fallback, None, "{:?}", xy);
            }
            if t.fallback.is_none() && norm(newell(&flat(&xy))) > 0.0 {
                check_tiles(&flat(&xy), &t);
                if strictly_simple(&xy) {
                    assert_exact_tiling(&xy, &t.triangles);
                }
            } else {
                prop_assert_eq!(t.triangles, fan(xy.len()));
            }
        }
    }
}
