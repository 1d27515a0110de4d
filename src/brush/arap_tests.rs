//! Tests of the ARAP deformation against analytic references.

use super::*;
use std::f64::consts::FRAC_PI_2;

/// A straight exemplar: `n` ribs along +x, spacing `h`, half-width `w`.
fn straight(n: usize, h: f64, w: f64) -> (Vec<Point>, Vec<Point>, Vec<Point>) {
    let spine: Vec<Point> = (0..n).map(|i| Point::new(i as f64 * h, 0.0)).collect();
    let left = spine.iter().map(|p| *p + Vec2::new(0.0, -w)).collect();
    let right = spine.iter().map(|p| *p + Vec2::new(0.0, w)).collect();
    (spine, left, right)
}

fn rigid(angle: f64, t: Vec2) -> Affine {
    Affine::translate(t) * Affine::rotate(angle)
}

#[test]
fn rigid_motion_of_the_pins_is_reproduced_exactly() {
    // A curved exemplar, so the test does not rely on a straight spine.
    let spine: Vec<Point> = (0..25)
        .map(|i| Point::new(i as f64 * 2.0, 6.0 * (i as f64 * 0.2).sin()))
        .collect();
    let normal = |i: usize| {
        let a = spine[i.saturating_sub(1)];
        let b = spine[(i + 1).min(spine.len() - 1)];
        let d = (b - a).normalize();
        Vec2::new(-d.y, d.x)
    };
    let left: Vec<Point> = (0..25).map(|i| spine[i] + normal(i) * 3.0).collect();
    let right: Vec<Point> = (0..25).map(|i| spine[i] - normal(i) * 2.5).collect();
    for divisions in [1, 3] {
        let mesh = RibMesh::from_ribs(&spine, &left, &right, divisions).unwrap();
        let arap = Arap::new(&mesh, &mesh.spine).unwrap();
        let m = rigid(0.83, Vec2::new(-40.0, 17.5));
        let pins: Vec<Point> = mesh.spine.iter().map(|&v| m * mesh.rest[v]).collect();
        for out in [
            arap.solve_similarity(&pins).unwrap(),
            arap.solve(&pins).unwrap(),
        ] {
            for (v, p) in out.iter().enumerate() {
                let want = m * mesh.rest[v];
                assert!((*p - want).hypot() < 1e-9, "vertex {v}: {p:?} vs {want:?}");
            }
            assert!(mean_distortion(&mesh, &out) < 1e-9);
        }
    }
}

/// The quarter-circle bend of a straight 60-rib exemplar (spacing 1,
/// half-width 4): spine pins on an arc of the same length.
fn bend() -> (RibMesh, Vec<Point>, f64) {
    let (spine, left, right) = straight(60, 1.0, 4.0);
    let mesh = RibMesh::from_ribs(&spine, &left, &right, 2).unwrap();
    let radius = 59.0 / FRAC_PI_2;
    let pins: Vec<Point> = (0..60)
        .map(|i| {
            let a = i as f64 / radius;
            Point::new(radius * a.sin(), radius * (1.0 - a.cos()))
        })
        .collect();
    (mesh, pins, radius)
}

#[test]
fn bend_keeps_triangles_nearly_rigid() {
    let (mesh, pins, radius) = bend();
    let arap = Arap::new(&mesh, &mesh.spine).unwrap();
    let out = arap.solve(&pins).unwrap();
    let d_arap = mean_distortion(&mesh, &out);
    // Naive per-vertex projection: each rib point keeps its rest offset
    // from its spine sample (translation only).
    let mut naive = mesh.rest.clone();
    for (i, &sv) in mesh.spine.iter().enumerate() {
        for k in 0..mesh.per_rib {
            let v = i * mesh.per_rib + k;
            naive[v] = pins[i] + (mesh.rest[v] - mesh.rest[sv]);
        }
    }
    let d_naive = mean_distortion(&mesh, &naive);
    // Bound: with the spine pinned isometrically onto curvature 1/R, a
    // perpendicular rib of half-width w has its outline stretched or
    // compressed by w/R (the normal-offset map); the triangles span offsets
    // 0..w, so a map that keeps ribs perpendicular averages w/(2R) per
    // singular value. ARAP may trade that for some shear, so allow w/R.
    let bound = 4.0 / radius;
    eprintln!("bend: ARAP {d_arap:.4}, naive {d_naive:.4}, bound {bound:.4}");
    assert!(d_arap < bound, "ARAP distortion {d_arap} ≥ {bound}");
    assert!(d_arap * 5.0 < d_naive, "ARAP {d_arap} vs naive {d_naive}");
    // The outline stays at about the rest width from the spine.
    for (i, &sv) in mesh.spine.iter().enumerate() {
        let l = (out[sv - 2] - out[sv]).hypot();
        let r = (out[sv + 2] - out[sv]).hypot();
        assert!(
            (l - 4.0).abs() < 0.6 && (r - 4.0).abs() < 0.6,
            "rib {i}: {l} {r}"
        );
    }
}

#[test]
fn factorization_is_reused_across_pin_placements() {
    let (mesh, pins, _) = bend();
    let arap = Arap::new(&mesh, &mesh.spine).unwrap();
    let straight_pins: Vec<Point> = mesh.spine.iter().map(|&v| mesh.rest[v]).collect();
    let a = arap.solve(&pins).unwrap();
    let b = arap.solve(&straight_pins).unwrap();
    let c = arap.solve(&pins).unwrap();
    assert_eq!(a, c, "same pins, same answer");
    for (p, r) in b.iter().zip(&mesh.rest) {
        assert!((*p - *r).hypot() < 1e-9, "rest pins give the rest mesh");
    }
    let fresh = Arap::new(&mesh, &mesh.spine).unwrap().solve(&pins).unwrap();
    assert_eq!(a, fresh);
    assert!(arap.solve(&pins[1..]).is_err(), "pin count is checked");
}

#[test]
fn degenerate_meshes_are_errors() {
    let (spine, left, right) = straight(10, 1.0, 0.0);
    assert!(
        RibMesh::from_ribs(&spine, &left, &right, 1).is_err(),
        "zero width"
    );
    // Ribs lying along the spine.
    let along: Vec<Point> = spine.iter().map(|p| *p + Vec2::new(0.3, 0.0)).collect();
    let back: Vec<Point> = spine.iter().map(|p| *p - Vec2::new(0.3, 0.0)).collect();
    assert!(
        RibMesh::from_ribs(&spine, &along, &back, 1).is_err(),
        "collinear"
    );
    let (s1, l1, r1) = straight(1, 1.0, 2.0);
    assert!(RibMesh::from_ribs(&s1, &l1, &r1, 1).is_err(), "one rib");
    let (spine, mut left, right) = straight(5, 1.0, 2.0);
    assert!(
        RibMesh::from_ribs(&spine, &left, &right, 0).is_err(),
        "no divisions"
    );
    left[2].x = f64::NAN;
    assert!(RibMesh::from_ribs(&spine, &left, &right, 1).is_err(), "NaN");
    assert!(
        RibMesh::from_ribs(&spine, &right[..4], &right, 1).is_err(),
        "lengths"
    );
    // One pin, or a pin twice, cannot fix a similarity.
    let (spine, left, right) = straight(5, 1.0, 2.0);
    let mesh = RibMesh::from_ribs(&spine, &left, &right, 1).unwrap();
    assert!(Arap::new(&mesh, &mesh.spine[..1]).is_err());
    assert!(Arap::new(&mesh, &[mesh.spine[0], mesh.spine[0]]).is_err());
    assert!(Arap::new(&mesh, &[0, 999]).is_err());
}

#[test]
fn rasterized_coordinates_invert_the_deformation() {
    let (spine, left, right) = straight(12, 2.0, 3.0);
    let mesh = RibMesh::from_ribs(&spine, &left, &right, 1).unwrap();
    let m = rigid(0.4, Vec2::new(20.0, 10.0));
    let arap = Arap::new(&mesh, &mesh.spine).unwrap();
    let pins: Vec<Point> = mesh.spine.iter().map(|&v| m * mesh.rest[v]).collect();
    let out = arap.solve(&pins).unwrap();
    let to_pixel = Affine::scale(2.0);
    let grid = rasterize_coords(&mesh, &out, 80, 80, to_pixel).unwrap();
    let back = (to_pixel * m).inverse();
    let mut covered = 0;
    for y in 0..80 {
        for x in 0..80 {
            if let Some(c) = grid.get(x, y) {
                covered += 1;
                let want = back * Point::new(x as f64 + 0.5, y as f64 + 0.5);
                assert!((c - want).hypot() < 1e-6, "({x},{y}): {c:?} vs {want:?}");
            }
        }
    }
    // The rest mesh is 22 × 6 units, 4 pixels per unit².
    let area = 22.0 * 6.0 * 4.0;
    assert!(
        (covered as f64 - area).abs() < 0.1 * area,
        "{covered} vs {area}"
    );
    // A mesh far outside the canvas costs nothing and covers nothing.
    let far: Vec<Point> = out.iter().map(|p| *p + Vec2::new(1e12, 0.0)).collect();
    let g = rasterize_coords(&mesh, &far, 16, 16, Affine::IDENTITY).unwrap();
    assert!(g.data().iter().all(Option::is_none));
    assert!(rasterize_coords(&mesh, &out[1..], 16, 16, Affine::IDENTITY).is_err());
}
