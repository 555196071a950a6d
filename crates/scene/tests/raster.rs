//! The mask rasteriser against an independent ray caster: for every pixel the ray through its
//! centre is intersected analytically with the scene's quads and boxes here, and the nearest
//! hit decides the expected id, plane and cos θ = |n · d̂|.

use std::path::Path;

use glassdb_scene::{
    Camera, CameraSpec, CosMode, GlassMapping, PlaneSource, PlaneTolerance, RasterOptions,
    RasterOutput, build_mask_scene, load_obj, rasterize,
};

type V = [f64; 3];

fn sub(a: V, b: V) -> V {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn dot(a: V, b: V) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn cross(a: V, b: V) -> V {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn unit(a: V) -> V {
    let n = dot(a, a).sqrt();
    [a[0] / n, a[1] / n, a[2] / n]
}

/// A planar parallelogram `corner + s·e1 + t·e2`, s, t ∈ [0, 1]; `id` 0 = opaque.
#[derive(Clone, Copy)]
struct Quad {
    corner: V,
    e1: V,
    e2: V,
    id: u16,
    plane: u16,
}

impl Quad {
    fn normal(&self) -> V {
        unit(cross(self.e1, self.e2))
    }
    /// Ray parameter of the hit and the distance of the hit from the quad's border in (s, t).
    fn hit(&self, o: V, d: V) -> Option<(f64, f64)> {
        let n = cross(self.e1, self.e2);
        let den = dot(n, d);
        if den.abs() < 1e-14 {
            return None;
        }
        let t = dot(n, sub(self.corner, o)) / den;
        if t <= 0.0 {
            return None;
        }
        let p = [o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]];
        let r = sub(p, self.corner);
        // Solve r = s e1 + u e2 in the plane.
        let (a, b, c) = (
            dot(self.e1, self.e1),
            dot(self.e1, self.e2),
            dot(self.e2, self.e2),
        );
        let (r1, r2) = (dot(r, self.e1), dot(r, self.e2));
        let det = a * c - b * b;
        let s = (r1 * c - r2 * b) / det;
        let u = (r2 * a - r1 * b) / det;
        let margin = s.min(1.0 - s).min(u).min(1.0 - u);
        (margin >= 0.0).then_some((t, margin))
    }
}

/// Writes quads as an OBJ (two triangles each, or `split`×`split` cells of 2 triangles) with
/// materials `Glass<id>` for glass and `Wall` for opaque quads.
fn write_scene(dir: &Path, quads: &[Quad], split: usize) -> std::path::PathBuf {
    let mut s = String::new();
    let mut nv = 0;
    for (k, q) in quads.iter().enumerate() {
        s.push_str(&format!(
            "g quad{k}\nusemtl {}\n",
            if q.id == 0 {
                "Wall".to_string()
            } else {
                format!("Glass{}", q.id)
            }
        ));
        let c = q.corner;
        for b in 0..=split {
            for a in 0..=split {
                let (sa, tb) = (a as f64 / split as f64, b as f64 / split as f64);
                let p = [
                    c[0] + sa * q.e1[0] + tb * q.e2[0],
                    c[1] + sa * q.e1[1] + tb * q.e2[1],
                    c[2] + sa * q.e1[2] + tb * q.e2[2],
                ];
                s.push_str(&format!("v {:?} {:?} {:?}\n", p[0], p[1], p[2]));
            }
        }
        let idx = |a: usize, b: usize| nv + b * (split + 1) + a + 1;
        for b in 0..split {
            for a in 0..split {
                s.push_str(&format!(
                    "f {} {} {} {}\n",
                    idx(a, b),
                    idx(a + 1, b),
                    idx(a + 1, b + 1),
                    idx(a, b + 1)
                ));
            }
        }
        nv += (split + 1) * (split + 1);
    }
    let p = dir.join("scene.obj");
    std::fs::write(&p, s).unwrap();
    p
}

fn spec(width: u32, height: u32, fov: f64) -> CameraSpec {
    camera([0.2, 0.1, 4.0], [0.0, 0.0, 0.0], fov, (width, height))
}

/// A camera at `origin` looking at `target`, +y up, `fov_x_deg` wide, `size` (width, height)
/// pixels.
fn camera(origin: V, target: V, fov_x_deg: f64, size: (u32, u32)) -> CameraSpec {
    CameraSpec::look_at(origin, target, [0.0, 1.0, 0.0], fov_x_deg, size.0, size.1)
}

/// The ray through image point (x, y), from the camera spec alone (docs/scene.md conventions).
fn ray(s: &CameraSpec, x: f64, y: f64) -> V {
    let f = unit(sub(s.target.unwrap(), s.origin.unwrap()));
    let r = unit(cross(f, s.up.unwrap()));
    let u = cross(r, f);
    let tx = (s.fov_x_deg.unwrap().to_radians() / 2.0).tan();
    let ty = tx * s.height as f64 / s.width as f64;
    let sx = (2.0 * x / s.width as f64 - 1.0) * tx;
    let sy = (1.0 - 2.0 * y / s.height as f64) * ty;
    unit([
        f[0] + sx * r[0] + sy * u[0],
        f[1] + sx * r[1] + sy * u[1],
        f[2] + sx * r[2] + sy * u[2],
    ])
}

/// Nearest quad hit along a ray: (quad index, border margin).
fn cast(quads: &[Quad], o: V, d: V) -> Option<(usize, f64)> {
    quads
        .iter()
        .enumerate()
        .filter_map(|(k, q)| q.hit(o, d).map(|(t, m)| (k, t, m)))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(k, _, m)| (k, m))
}

fn render(quads: &[Quad], split: usize, s: &CameraSpec, opts: RasterOptions) -> RasterOutput {
    let dir = tempfile::tempdir().unwrap();
    let path = write_scene(dir.path(), quads, split);
    let scene = load_obj(&path).unwrap();
    let mut ids: Vec<u16> = quads.iter().map(|q| q.id).filter(|&i| i != 0).collect();
    ids.sort();
    ids.dedup();
    let mappings: Vec<GlassMapping> = ids
        .iter()
        .map(|i| GlassMapping {
            pattern: format!("Glass{i}"),
            id: *i,
        })
        .collect();
    let tol = PlaneTolerance {
        angle_deg: 0.1,
        distance: 1e-6,
    };
    let ms = build_mask_scene(
        &scene,
        &mappings,
        &PlaneSource::Detect(tol),
        matches!(opts.cos, CosMode::Gouraud { .. }),
    )
    .unwrap();
    let cam = Camera::new(s, Path::new("camera.json")).unwrap();
    rasterize(&ms.raster, &cam, &opts).unwrap()
}

/// Compares every pixel whose centre ray is not within `margin` of a quad border.
fn check_against_ray_caster(quads: &[Quad], out: &RasterOutput, s: &CameraSpec) -> usize {
    let mut checked_glass = 0;
    for j in 0..s.height {
        for i in 0..s.width {
            let d = ray(s, i as f64 + 0.5, j as f64 + 0.5);
            let p = (j * s.width + i) as usize;
            let hit = cast(quads, s.origin.unwrap(), d);
            if hit.is_some_and(|(_, m)| m < 1e-6) {
                continue; // the ray grazes a border: either answer is right
            }
            match hit {
                Some((k, _)) if quads[k].id != 0 => {
                    let q = quads[k];
                    assert_eq!(out.id[p], q.id, "pixel ({i}, {j})");
                    assert_eq!(out.plane[p], q.plane, "pixel ({i}, {j})");
                    let expect = dot(q.normal(), d).abs();
                    assert!(
                        (out.cos_theta[p] as f64 - expect).abs() < 1e-6,
                        "pixel ({i}, {j}): {} vs {expect}",
                        out.cos_theta[p]
                    );
                    checked_glass += 1;
                }
                _ => {
                    assert_eq!(out.id[p], 0, "pixel ({i}, {j}) should show no glass");
                    assert_eq!(out.cos_theta[p], 0.0);
                }
            }
        }
    }
    checked_glass
}

const EXACT: RasterOptions = RasterOptions {
    cos: CosMode::Exact,
    samples: 1,
};

fn tilted_pane() -> Quad {
    // A pane rotated 35° about y and 10° about x, off-centre.
    let (a, b) = (35f64.to_radians(), 10f64.to_radians());
    let e1 = [2.3 * a.cos(), 0.0, -2.3 * a.sin()];
    let e2 = [
        0.0 * b.cos() + 1.7 * (a.sin() * b.sin()),
        1.7 * b.cos(),
        1.7 * a.cos() * b.sin(),
    ];
    Quad {
        corner: [-1.37, -0.83, -0.41],
        e1,
        e2,
        id: 3,
        plane: 0,
    }
}

#[test]
fn one_quad_matches_the_analytic_projection_and_cos() {
    let s = spec(96, 72, 60.0);
    let quads = [tilted_pane()];
    let out = render(&quads, 1, &s, EXACT);
    let n = check_against_ray_caster(&quads, &out, &s);
    assert!(n > 500, "only {n} glass pixels checked");
}

#[test]
fn a_pane_of_many_triangles_has_no_cracks() {
    let s = spec(80, 60, 60.0);
    let quads = [tilted_pane()];
    let out = render(&quads, 7, &s, EXACT);
    check_against_ray_caster(&quads, &out, &s);
}

#[test]
fn a_box_in_front_of_the_glass_hides_it() {
    let s = spec(96, 72, 60.0);
    let pane = Quad {
        corner: [-1.5, -1.0, -1.0],
        e1: [3.0, 0.0, 0.0],
        e2: [0.0, 2.1, 0.0],
        id: 1,
        plane: 0,
    };
    // A box (x, y ∈ [−0.41, 0.37], z ∈ [0.3, 0.9]) between the camera and the pane.
    let (x0, x1, y0, y1, z0, z1) = (-0.41, 0.37, -0.33, 0.29, 0.3, 0.9);
    let wall = |corner: V, e1: V, e2: V| Quad {
        corner,
        e1,
        e2,
        id: 0,
        plane: 0,
    };
    let (dx, dy, dz) = (x1 - x0, y1 - y0, z1 - z0);
    let quads = [
        pane,
        wall([x0, y0, z1], [dx, 0.0, 0.0], [0.0, dy, 0.0]),
        wall([x0, y0, z0], [0.0, dy, 0.0], [dx, 0.0, 0.0]),
        wall([x0, y0, z0], [0.0, 0.0, dz], [0.0, dy, 0.0]),
        wall([x1, y0, z0], [0.0, dy, 0.0], [0.0, 0.0, dz]),
        wall([x0, y1, z0], [0.0, 0.0, dz], [dx, 0.0, 0.0]),
        wall([x0, y0, z0], [dx, 0.0, 0.0], [0.0, 0.0, dz]),
    ];
    let out = render(&quads, 1, &s, EXACT);
    check_against_ray_caster(&quads, &out, &s);
    // The box really hides part of the pane: the image centre shows the box, not glass.
    let d = ray(&s, 48.5, 36.5);
    assert_eq!(
        cast(&quads, s.origin.unwrap(), d).map(|h| quads[h.0].id),
        Some(0)
    );
    assert_eq!(out.id[36 * 96 + 48], 0);
}

#[test]
fn several_planes_get_their_own_index() {
    let s = spec(96, 72, 70.0);
    let quads = [
        Quad {
            corner: [-2.0, -1.0, -1.0],
            e1: [1.6, 0.0, 0.0],
            e2: [0.0, 2.0, 0.0],
            id: 1,
            plane: 0,
        },
        // A second pane on a plane at 30° with another id.
        Quad {
            corner: [0.1, -1.0, -1.0],
            e1: [
                1.5 * 30f64.to_radians().cos(),
                0.0,
                1.5 * 30f64.to_radians().sin(),
            ],
            e2: [0.0, 2.0, 0.0],
            id: 2,
            plane: 1,
        },
        // A third pane, same id as the first, parallel but 0.5 further: a third plane.
        Quad {
            corner: [-1.0, 1.1, -1.5],
            e1: [2.0, 0.0, 0.0],
            e2: [0.0, 0.6, 0.0],
            id: 1,
            plane: 2,
        },
    ];
    let out = render(&quads, 1, &s, EXACT);
    check_against_ray_caster(&quads, &out, &s);
    for plane in 0..3 {
        assert!(
            out.plane
                .iter()
                .zip(&out.id)
                .any(|(&p, &i)| p == plane && i != 0),
            "plane {plane} is not visible"
        );
    }
}

#[test]
fn glass_reaching_behind_the_camera_is_clipped_not_lost() {
    // A floor of glass under the camera, from behind it to far in front.
    let s = spec(64, 48, 90.0);
    let quads = [Quad {
        corner: [-20.0, -1.0, 30.0],
        e1: [40.0, 0.0, 0.0],
        e2: [0.0, 0.0, -80.0],
        id: 5,
        plane: 0,
    }];
    let out = render(&quads, 1, &s, EXACT);
    let n = check_against_ray_caster(&quads, &out, &s);
    assert!(n > 64 * 20, "{n}");
}

#[test]
fn coverage_counts_the_sub_pixel_rays() {
    let s = spec(40, 30, 60.0);
    let quads = [tilted_pane()];
    let k = 4u32;
    let out = render(
        &quads,
        1,
        &s,
        RasterOptions {
            cos: CosMode::Exact,
            samples: k,
        },
    );
    let cov = out.coverage.as_ref().unwrap();
    let mut partial = 0;
    for j in 0..s.height {
        for i in 0..s.width {
            let mut hits = 0;
            let mut grazing = false;
            for b in 0..k {
                for a in 0..k {
                    let d = ray(
                        &s,
                        i as f64 + (a as f64 + 0.5) / k as f64,
                        j as f64 + (b as f64 + 0.5) / k as f64,
                    );
                    match cast(&quads, s.origin.unwrap(), d) {
                        Some((_, m)) if m < 1e-6 => grazing = true,
                        Some(_) => hits += 1,
                        None => {}
                    }
                }
            }
            if grazing {
                continue;
            }
            let p = (j * s.width + i) as usize;
            let expect = hits as f32 / (k * k) as f32;
            assert_eq!(cov[p], expect, "pixel ({i}, {j})");
            if hits > 0 {
                assert_eq!(out.id[p], 3, "pixel ({i}, {j}) has glass samples");
            }
            if hits > 0 && hits < k * k {
                partial += 1;
            }
        }
    }
    assert!(partial > 20, "{partial}");
}

/// Largest |Gouraud − exact| over the glass pixels.
fn gouraud_error(mesh: u32) -> f64 {
    let s = camera([0.0, 0.0, 1.5], [0.8, 0.0, 0.0], 100.0, (160, 120));
    // A wide pane seen obliquely: cos θ varies strongly and non-linearly across it.
    let quads = [Quad {
        corner: [-3.0, -1.5, -0.5],
        e1: [6.0, 0.0, 0.0],
        e2: [0.0, 3.0, 0.0],
        id: 1,
        plane: 0,
    }];
    let exact = render(&quads, 1, &s, EXACT);
    let g = render(
        &quads,
        1,
        &s,
        RasterOptions {
            cos: CosMode::Gouraud { mesh },
            samples: 1,
        },
    );
    assert_eq!(exact.id, g.id);
    exact
        .cos_theta
        .iter()
        .zip(&g.cos_theta)
        .zip(&exact.id)
        .filter(|(_, id)| **id != 0)
        .map(|((a, b), _)| (*a as f64 - *b as f64).abs())
        .fold(0.0, f64::max)
}

#[test]
fn gouraud_converges_to_the_exact_cos() {
    let (e1, e8, e16, e32) = (
        gouraud_error(1),
        gouraud_error(8),
        gouraud_error(16),
        gouraud_error(32),
    );
    // cos θ = |n·d̂| is not linear on the screen, so one cell is visibly wrong...
    assert!(e1 > 0.1, "{e1}");
    // ...and linear interpolation is second order: halving the cells quarters the error.
    assert!(e8 < e1 && e16 < e8 && e32 < e16, "{e1} {e8} {e16} {e32}");
    for (coarse, fine) in [(e8, e16), (e16, e32)] {
        let ratio = coarse / fine;
        assert!(
            (3.0..5.0).contains(&ratio),
            "error ratio {ratio} ({e8} {e16} {e32})"
        );
    }
    assert!(e32 < 2e-3, "{e32}");
}
