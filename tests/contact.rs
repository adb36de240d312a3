//! Tests of `contact`: plane-of-action limit, common-normal residual against an independent
//! root search, continuity of the overlap in ζ and φp, mesh periodicity, fast walk against the
//! exhaustive search.

mod common;

use std::f64::consts::PI;

use helical_gear_mesh::PairGeometry;
use helical_gear_mesh::contact::{ContactPoint, ContactSolver};
use helical_gear_mesh::geometry::{Flank, SegmentKind};

use common::{SplitMix64 as Rng, table1_geometry as table1};

#[test]
fn involute_contacts_lie_in_the_plane_of_action_with_base_radius_arms() {
    let g = table1();
    let s = ContactSolver::new(&g);
    let zetas = s.slice_zetas(40);
    let mut cs = Vec::new();
    let (sa, ca) = g.alpha_wt.sin_cos();
    let mut n_inv = 0;
    for i in 0..50 {
        let phi_p = -0.2 + 0.4 * i as f64 / 50.0;
        for te in [-30e-6, 0.0, 17e-6, 60e-6] {
            let phi_g = g.phi_g_for_te(phi_p, te);
            s.contacts(phi_p, phi_g, &zetas, &mut cs);
            for c in cs
                .iter()
                .filter(|c| c.kind_p == SegmentKind::Involute && c.kind_g == SegmentKind::Involute)
            {
                n_inv += 1;
                assert!((c.arm_p_m - g.pinion.rb).abs() < 1e-9 * g.pinion.rb);
                assert!((c.arm_g_m - g.gear.rb).abs() < 1e-9 * g.gear.rb);
                // P1 on the line of action through T_p = rb·(cos α, −sin α), direction
                // (sin α, cos α): its distance from that line is zero.
                let d = c.point_p[0] * ca - c.point_p[1] * sa - g.pinion.rb;
                assert!(d.abs() < 1e-12, "off the plane of action by {d}");
                // No profile deviation on the involutes: overlap = TE.
                assert!((c.overlap_m - te).abs() < 1e-12, "{} vs {te}", c.overlap_m);
            }
        }
    }
    assert!(n_inv > 1000);
}

/// Independent common-normal search: bisection on ν of (P2(ν+π) − P1(ν))·m(ν) using only the
/// flanks' point-for-normal maps, over the normal range both flanks cover. Returns the overlap.
fn root_search_overlap(g: &PairGeometry, c: &ContactPoint, tp: f64, tg: f64) -> f64 {
    let gc = [g.center_distance, 0.0];
    let pt = |flank: &Flank, theta: f64, center: [f64; 2], nu_fixed: f64| {
        let local = nu_fixed - theta;
        let local = local - 2.0 * PI * ((local - flank.nu_tip()) / (2.0 * PI)).floor();
        flank.point_at_normal(local).map(|p| {
            let (s, co) = theta.sin_cos();
            let [x, y] = p.position;
            [center[0] + co * x - s * y, center[1] + s * x + co * y]
        })
    };
    let f = |nu: f64| -> Option<(f64, f64)> {
        let p1 = pt(&g.pinion.flank, tp, [0.0, 0.0], nu)?;
        let p2 = pt(&g.gear.flank, tg, gc, nu + PI)?;
        let (s, co) = nu.sin_cos();
        let d = [p2[0] - p1[0], p2[1] - p1[1]];
        Some((d[0] * s - d[1] * co, -(d[0] * co + d[1] * s)))
    };
    // Bracket around the solver's normal angle.
    let (mut lo, mut hi) = (c.normal_angle - 1e-3, c.normal_angle + 1e-3);
    let (flo, _) = f(lo).expect("bracket inside both flanks");
    let (fhi, _) = f(hi).expect("bracket inside both flanks");
    assert!(flo * fhi <= 0.0, "no sign change around the solution");
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        let (fm, _) = f(mid).unwrap();
        if (fm <= 0.0) == (flo <= 0.0) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    f(0.5 * (lo + hi)).unwrap().1
}

#[test]
fn common_normal_residual_and_independent_root_search() {
    let g = table1();
    let s = ContactSolver::new(&g);
    let zetas = s.slice_zetas(25);
    let mut cs = Vec::new();
    let mut rng = Rng(7);
    let mut checked = 0;
    let mut kinds = std::collections::BTreeSet::new();
    for _ in 0..200 {
        let phi_p = (rng.unit() - 0.5) * 0.5;
        let te = (rng.unit() - 0.3) * 100e-6;
        let phi_g = g.phi_g_for_te(phi_p, te);
        let red = s.contacts(phi_p, phi_g, &zetas, &mut cs);
        for c in &cs {
            assert!(c.normal_residual() < 1e-10, "residual {}", c.normal_residual());
            kinds.insert(c.kind_name());
            // Rotation angles of this tooth pair for the root search.
            let k = (c.pair + red.pitches) as f64;
            let zm = c.zeta * g.params.normal_module_m;
            let inv_w = helical_gear_mesh::geometry::inv(g.alpha_wt);
            let tp = red.phi_p + inv_w - g.pinion.lambda0
                + g.pinion.angular_pitch() * k
                + g.pinion.twist_rate * zm;
            let tg = red.phi_g + PI + inv_w - g.gear.lambda0 - g.gear.angular_pitch() * k
                + g.gear.twist_rate * zm;
            // Skip corner contacts (their normal is not a function of the point) and points
            // within the bracket of a flank end.
            if c.kind_p == SegmentKind::ReliefCorner || c.kind_g == SegmentKind::ReliefCorner {
                continue;
            }
            let inside = |flank: &Flank, nu: f64| {
                let l = nu - 2.0 * PI * ((nu - flank.nu_tip()) / (2.0 * PI)).floor();
                l > flank.nu_tip() + 2e-3 && l < flank.nu_root() - 2e-3
            };
            if !inside(&g.pinion.flank, c.normal_angle - tp)
                || !inside(&g.gear.flank, c.normal_angle + PI - tg)
            {
                continue;
            }
            let o = root_search_overlap(&g, c, tp, tg);
            assert!((o - c.overlap_m).abs() < 1e-10, "{} vs {o} ({})", c.overlap_m, c.kind_name());
            checked += 1;
        }
    }
    assert!(checked > 1000, "checked {checked}");
    for k in ["involute/involute", "involute/relief", "relief/involute", "involute/rounding"] {
        assert!(kinds.contains(k), "kind {k} never seen: {kinds:?}");
    }
}

#[test]
fn fast_walk_equals_exhaustive_search() {
    let g = table1();
    let s = ContactSolver::new(&g);
    let mut rng = Rng(11);
    for _ in 0..30000 {
        let phi_p = (rng.unit() - 0.5) * 0.3;
        let te = (rng.unit() - 0.5) * 400e-6;
        let phi_g = g.phi_g_for_te(phi_p, te);
        let zeta = rng.unit() * g.b0();
        let k = (rng.unit() * 5.0) as i64 - 2;
        let a = s.contact_fast(phi_p, phi_g, k, zeta);
        let b = s.contact_exhaustive(phi_p, phi_g, k, zeta);
        match (a, b) {
            (None, None) => {}
            (Some(a), Some(b)) => {
                assert!((a.overlap_m - b.overlap_m).abs() < 1e-13);
                assert_eq!(a.kind_name(), b.kind_name());
            }
            (a, b) => panic!("fast {a:?} vs exhaustive {b:?}"),
        }
    }
}

/// Overlap of every (pair, slice) over a sweep of φp at fixed TE, by pair and slice index.
fn sweep(
    g: &PairGeometry,
    zetas: &[f64],
    te: f64,
    phi0: f64,
    phi1: f64,
    n: usize,
) -> Vec<Vec<Option<(f64, String)>>> {
    let s = ContactSolver::new(g);
    let mut cs = Vec::new();
    // Track pair 0 (absolute numbering) through the sweep.
    let mut rows = Vec::with_capacity(n + 1);
    for i in 0..=n {
        let phi_p = phi0 + (phi1 - phi0) * i as f64 / n as f64;
        s.contacts(phi_p, g.phi_g_for_te(phi_p, te), zetas, &mut cs);
        let row = zetas
            .iter()
            .map(|&z| {
                cs.iter().find(|c| c.pair == 0 && c.zeta == z).map(|c| (c.overlap_m, c.kind_name()))
            })
            .collect();
        rows.push(row);
    }
    rows
}

#[test]
fn overlap_is_continuous_in_phi_across_kind_changes() {
    let g = table1();
    let zetas = [0.3, 2.1, 4.7];
    let te = 30e-6;
    let pitch = g.pinion.angular_pitch();
    // Pair 0 enters and leaves the mesh within ±1.2 pitches.
    let (phi0, phi1) = (-1.2 * pitch, 1.2 * pitch);
    let max_jump = |n: usize| {
        let rows = sweep(&g, &zetas, te, phi0, phi1, n);
        let mut worst: f64 = 0.0;
        let mut kind_changes = 0;
        for j in 0..zetas.len() {
            for w in rows.windows(2) {
                if let (Some(a), Some(b)) = (&w[0][j], &w[1][j]) {
                    // Only where the teeth are close (what the load solver uses).
                    if a.0 > -50e-6 || b.0 > -50e-6 {
                        worst = worst.max((a.0 - b.0).abs());
                        if a.1 != b.1 {
                            kind_changes += 1;
                        }
                    }
                }
            }
        }
        (worst, kind_changes)
    };
    let (j1, k1) = max_jump(4000);
    let (j4, _) = max_jump(16000);
    assert!(k1 >= 6, "too few kind changes seen: {k1}");
    // A continuous overlap with bounded slope: 4× finer steps give ~4× smaller steps in Δ.
    assert!(j4 < 0.35 * j1, "max step {j1} at n=4000 vs {j4} at n=16000: a jump");
    // Bounded slope: |∂Δ/∂φp| at fixed TE below 0.2·r_bp (measured: about 0.06·r_bp, at the
    // rounding contacts).
    let step = (phi1 - phi0) / 4000.0;
    assert!(j1 < 0.2 * g.pinion.rb * step, "max step {j1}");
}

#[test]
fn overlap_is_continuous_in_zeta() {
    let g = table1();
    let s = ContactSolver::new(&g);
    let te = 25e-6;
    let mut cs = Vec::new();
    for i in 0..40 {
        let phi_p = -0.1 + 0.2 * i as f64 / 40.0;
        let phi_g = g.phi_g_for_te(phi_p, te);
        let jump = |n: usize, cs: &mut Vec<ContactPoint>| {
            let zetas: Vec<f64> = (0..=n).map(|k| g.b0() * k as f64 / n as f64).collect();
            s.contacts(phi_p, phi_g, &zetas, cs);
            let mut worst: f64 = 0.0;
            for w in cs.windows(2) {
                if w[0].pair == w[1].pair && (w[0].overlap_m > -50e-6 || w[1].overlap_m > -50e-6) {
                    worst = worst.max((w[0].overlap_m - w[1].overlap_m).abs());
                }
            }
            worst
        };
        let j1 = jump(500, &mut cs);
        let j4 = jump(2000, &mut cs);
        assert!(j4 <= 0.35 * j1 + 1e-12, "φp = {phi_p}: {j1} vs {j4}");
    }
}

#[test]
fn shifting_by_one_pitch_reproduces_the_contact_set() {
    let g = table1();
    let s = ContactSolver::new(&g);
    let zetas = s.slice_zetas(30);
    let (mut a, mut b) = (Vec::new(), Vec::new());
    let mut rng = Rng(3);
    for _ in 0..50 {
        let phi_p = (rng.unit() - 0.5) * 0.3;
        let phi_g = g.phi_g_for_te(phi_p, (rng.unit() - 0.2) * 80e-6);
        for shift in [1.0, -3.0, 17.0] {
            s.contacts(phi_p, phi_g, &zetas, &mut a);
            s.contacts(
                phi_p + shift * g.pinion.angular_pitch(),
                phi_g - shift * g.gear.angular_pitch(),
                &zetas,
                &mut b,
            );
            assert_eq!(a.len(), b.len());
            for (x, y) in a.iter().zip(&b) {
                assert_eq!(x.pair - shift as i64, y.pair);
                assert_eq!(x.kind_name(), y.kind_name());
                assert!((x.overlap_m - y.overlap_m).abs() < 1e-11);
                assert!((x.arm_p_m - y.arm_p_m).abs() < 1e-11);
            }
        }
    }
}

#[test]
fn tip_rounding_and_relief_contacts_have_true_arms_and_radii() {
    let g = table1();
    let s = ContactSolver::new(&g);
    let zetas = s.slice_zetas(50);
    let mut cs = Vec::new();
    let mut seen_rounding = false;
    for i in 0..200 {
        let phi_p = -0.2 + 0.4 * i as f64 / 200.0;
        s.contacts(phi_p, g.phi_g_for_te(phi_p, 40e-6), &zetas, &mut cs);
        for c in &cs {
            match c.kind_g {
                SegmentKind::Rounding => {
                    seen_rounding = true;
                    assert!((c.rho_g_m - g.gear.rounding_radius).abs() < 1e-15);
                    // Outside the plane of action: the gear arm is shorter than its base radius.
                    assert!(c.arm_g_m < g.gear.rb);
                    assert!(c.tau_g >= 0.0);
                }
                SegmentKind::Relief => {
                    assert!((c.arm_g_m - g.gear.rb_relief).abs() < 1e-12);
                    assert!(c.rho_g_m > 0.0);
                }
                _ => {}
            }
            if c.kind_p == SegmentKind::Involute {
                assert!((c.tau_p).abs() == 0.0 && c.eta_star_p > 0.0);
            }
        }
    }
    assert!(seen_rounding);
}

#[test]
fn back_flanks_touch_through_the_backlash() {
    use helical_gear_mesh::contact::FlankSide;
    let g = table1();
    let s = ContactSolver::new(&g);
    let zetas = s.slice_zetas(30);
    let mut cs = Vec::new();
    let mut n_inv = 0;
    let mut kinds = std::collections::BTreeSet::new();
    for i in 0..60 {
        let phi_p = -0.2 + 0.4 * i as f64 / 60.0;
        for te in [-g.backlash_te - 30e-6, -g.backlash_te, -g.backlash_te + 20e-6, 0.0] {
            s.contacts_on(FlankSide::Back, phi_p, g.phi_g_for_te(phi_p, te), &zetas, &mut cs);
            for c in &cs {
                assert_eq!(c.side, FlankSide::Back);
                assert!(c.normal_residual() < 1e-10);
                kinds.insert(c.kind_name());
                if c.kind_p == SegmentKind::Involute && c.kind_g == SegmentKind::Involute {
                    n_inv += 1;
                    // Overlap of the back flanks: −(TE + backlash along the base tangent).
                    assert!((c.overlap_m + te + g.backlash_te).abs() < 1e-12, "{}", c.overlap_m);
                    // The torques reverse: the arms are minus the base radii.
                    assert!((c.arm_p_m + g.pinion.rb).abs() < 1e-9 * g.pinion.rb);
                    assert!((c.arm_g_m + g.gear.rb).abs() < 1e-9 * g.gear.rb);
                }
            }
        }
    }
    assert!(n_inv > 500, "{n_inv}");
    assert!(kinds.contains("relief/involute") && kinds.contains("involute/rounding"), "{kinds:?}");
    // Fast walk against exhaustive search on the back flanks.
    let mut rng = Rng(5);
    for _ in 0..20000 {
        let phi_p = (rng.unit() - 0.5) * 0.3;
        let te = -g.backlash_te + (rng.unit() - 0.5) * 400e-6;
        let phi_g = g.phi_g_for_te(phi_p, te);
        let zeta = rng.unit() * g.b0();
        let k = (rng.unit() * 7.0) as i64 - 3;
        let a = s.contact_fast_on(FlankSide::Back, phi_p, phi_g, k, zeta);
        let b = s.contact_exhaustive_on(FlankSide::Back, phi_p, phi_g, k, zeta);
        match (a, b) {
            (None, None) => {}
            (Some(a), Some(b)) => assert!((a.overlap_m - b.overlap_m).abs() < 1e-13),
            (a, b) => panic!("fast {a:?} vs exhaustive {b:?}"),
        }
    }
}
