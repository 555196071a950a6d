//! Property tests (fixed seeds, few cases) of the mirror: for random planes and triangles,
//! mirroring twice is the identity, the two half-spaces partition the area, and everything
//! written lies on the mirrored side.

use glassdb_scene::{Mesh, Plane, Scene, mirror_scene};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};

fn area(meshes: &[Mesh]) -> f64 {
    meshes
        .iter()
        .flat_map(|m| (0..m.triangles.len()).map(move |t| m.corners(t)))
        .map(|[a, b, c]| {
            let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
            let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
            let n = [
                u[1] * v[2] - u[2] * v[1],
                u[2] * v[0] - u[0] * v[2],
                u[0] * v[1] - u[1] * v[0],
            ];
            0.5 * (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt()
        })
        .sum()
}

fn soup(points: &[[f64; 3]]) -> Scene {
    let n = points.len() / 3 * 3;
    let mesh = Mesh {
        group: "soup".into(),
        material: Some(0),
        positions: points[..n].to_vec(),
        triangles: (0..n as u32 / 3)
            .map(|k| [3 * k, 3 * k + 1, 3 * k + 2])
            .collect(),
        ..Default::default()
    };
    Scene {
        meshes: vec![mesh],
        materials: vec!["M".into()],
        ..Default::default()
    }
}

fn runner() -> TestRunner {
    TestRunner::new_with_rng(
        Config {
            cases: 48,
            failure_persistence: None,
            ..Config::default()
        },
        TestRng::from_seed(RngAlgorithm::ChaCha, &[7; 32]),
    )
}

fn coord() -> impl Strategy<Value = f64> {
    -5.0..5.0f64
}

#[test]
fn mirror_partitions_the_area_and_twice_is_identity() {
    let strategy = (
        prop::array::uniform3(-1.0..1.0f64),
        -2.0..2.0f64,
        prop::collection::vec(prop::array::uniform3(coord()), 3..30),
    );
    runner()
        .run(&strategy, |(n, d, points)| {
            prop_assume!(n.iter().map(|x| x * x).sum::<f64>() > 0.01);
            let plane = Plane::from_equation([n[0], n[1], n[2], d]).unwrap();
            let scene = soup(&points);
            let total = area(&scene.meshes);
            let (front, _) = mirror_scene(&scene, &plane, 0.0, |_, _| false);
            let (back, _) = mirror_scene(&scene, &plane.flipped(), 0.0, |_, _| false);
            // Mirroring preserves areas, so the two images' areas add up to the scene's.
            let sum = area(&front) + area(&back);
            prop_assert!(
                (sum - total).abs() <= 1e-9 * total.max(1.0),
                "{sum} vs {total}"
            );
            // The front half-space is mirrored behind the plane.
            for m in &front {
                for p in &m.positions {
                    prop_assert!(plane.signed_distance(*p) <= 1e-9, "{p:?}");
                }
            }
            // Mirroring the image back (keeping its side) gives the front part again.
            let (again, _) = mirror_scene(
                &Scene {
                    meshes: front.clone(),
                    ..soup(&[])
                },
                &plane.flipped(),
                1e-12,
                |_, _| false,
            );
            prop_assert!((area(&again) - area(&front)).abs() <= 1e-9 * total.max(1.0));
            for (m, m2) in front.iter().zip(&again) {
                for (t, tri) in m.triangles.iter().enumerate() {
                    let back_tri = m2.corners(t);
                    for k in 0..3 {
                        let p = plane.reflect_point(m.positions[tri[k] as usize]);
                        let q = back_tri[[0, 2, 1][k]]; // the winding was reversed once more
                        prop_assert!((0..3).all(|i| (p[i] - q[i]).abs() < 1e-9), "{p:?} vs {q:?}");
                    }
                }
            }
            Ok(())
        })
        .unwrap();
}
