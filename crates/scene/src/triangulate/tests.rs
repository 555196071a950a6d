//! Ear clipping against hand-made polygons, and its invariants on random ones.

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
