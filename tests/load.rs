//! Tests of the load distribution solver (Eq. 12) and its outputs (Eqs. 13–15).

mod common;

use std::time::Instant;

use faer::Mat;
use faer::linalg::solvers::Solve;
use helical_gear_mesh::Material;
use helical_gear_mesh::compliance::hertz::LocalContact;
use helical_gear_mesh::load::{
    HertzLocal, LoadError, LoadProblem, LoadSettings, LoadSolver, LocalTerm, Start,
    damping_torques, hertz_pressures, mesh_torque, total_force,
};

use common::XorShift64Star as Rng;

/// g = C·(w∘q) + u(q) − d computed independently of the solver.
fn gaps(c: &Mat<f64>, w: &[f64], d: &[f64], q: &[f64], local: Option<&dyn LocalTerm>) -> Vec<f64> {
    let n = d.len();
    (0..n)
        .map(|i| {
            let lin: f64 = (0..n).map(|j| c[(i, j)] * w[j] * q[j]).sum();
            let u = match local {
                Some(l) if q[i] > 0.0 => l.eval(i, q[i]).0,
                _ => 0.0,
            };
            lin + u - d[i]
        })
        .collect()
}

/// Checks q ≥ 0 and complementarity with the solver's tolerance.
fn assert_complementary(q: &[f64], g: &[f64], tol: f64) {
    for (i, (&q, &g)) in q.iter().zip(g).enumerate() {
        assert!(q >= 0.0, "q[{i}] = {q}");
        if q > 0.0 {
            assert!(g.abs() <= tol, "loaded slice {i}: g = {g:e} > tol {tol:e}");
        } else {
            assert!(g >= -tol, "unloaded slice {i}: g = {g:e} < -tol {tol:e}");
        }
    }
}

#[test]
fn uniform_compliance_oracle() {
    // Diagonal C = c/w_i: each slice alone, q_i = d_i/c on d_i > 0, 0 elsewhere.
    let n = 9;
    let c = 1.3e-11; // m per N/m
    let w: Vec<f64> = (0..n).map(|i| 1e-3 * (1.0 + 0.1 * i as f64)).collect();
    let d: Vec<f64> = (0..n).map(|i| 1e-5 * ((i as f64) - 3.5) / 4.0).collect();
    let cm = Mat::from_fn(n, n, |i, j| if i == j { c / w[i] } else { 0.0 });
    let p = LoadProblem { approach: &d, line_length: &w, compliance: cm.as_ref(), local: None };
    let mut s = LoadSolver::with_capacity(n);
    let r = s.solve(&p, Start::Cold).expect("solves");
    for (i, (&q, &di)) in s.load().iter().zip(&d).enumerate() {
        let expect = if di > 0.0 { di / c } else { 0.0 };
        assert!((q - expect).abs() <= 1e-14 * expect.abs(), "slice {i}: {q} vs {expect}");
        if di <= 0.0 {
            assert_eq!(q, 0.0);
        }
    }
    assert_eq!(r.active, 5);
    let f: f64 = (0..n).filter(|&i| d[i] > 0.0).map(|i| d[i] / c * w[i]).sum();
    assert!((r.total_force - f).abs() <= 1e-13 * f);
}

#[test]
fn full_coupling_uniform_approach() {
    // C = a·11ᵀ + b·I, w uniform, d uniform: by symmetry q uniform with
    // d = (n·a + b)·w·q  ⇒  q = d/((n·a + b)·w).
    let n = 20;
    let (a, b, w0, d0) = (2e-10, 5e-9, 2e-3, 1.5e-5);
    let w = vec![w0; n];
    let d = vec![d0; n];
    let cm = Mat::from_fn(n, n, |i, j| a + if i == j { b } else { 0.0 });
    let p = LoadProblem { approach: &d, line_length: &w, compliance: cm.as_ref(), local: None };
    let mut s = LoadSolver::with_capacity(n);
    let r = s.solve(&p, Start::Cold).expect("solves");
    let expect = d0 / ((n as f64 * a + b) * w0);
    for &q in s.load() {
        assert!((q - expect).abs() <= 1e-12 * expect, "{q} vs {expect}");
    }
    assert!((r.total_force - expect * w0 * n as f64).abs() <= 1e-12 * r.total_force);
}

/// The unique LCP solution by enumeration of all active sets (linear problem).
fn brute_force(c: &Mat<f64>, w: &[f64], d: &[f64]) -> Vec<f64> {
    let n = d.len();
    let mut best: Option<(f64, Vec<f64>)> = None;
    for mask in 0u32..(1 << n) {
        let set: Vec<usize> = (0..n).filter(|&i| mask & (1 << i) != 0).collect();
        let m = set.len();
        let mut q = vec![0.0; n];
        if m > 0 {
            let a = Mat::from_fn(m, m, |r, k| c[(set[r], set[k])] * w[set[k]]);
            let rhs = Mat::from_fn(m, 1, |r, _| d[set[r]]);
            let x = a.partial_piv_lu().solve(&rhs);
            for (r, &i) in set.iter().enumerate() {
                q[i] = x[(r, 0)];
            }
        }
        let g = gaps(c, w, d, &q, None);
        let qmax = q.iter().fold(0.0_f64, |m, &x| m.max(x.abs())).max(1.0);
        let dmax = d.iter().fold(0.0_f64, |m, &x| m.max(x.abs()));
        // Violation of q_S ≥ 0 and g_N ≥ 0 in relative terms.
        let mut viol = 0.0_f64;
        for i in 0..n {
            if mask & (1 << i) != 0 {
                viol = viol.max(-q[i] / qmax);
            } else {
                viol = viol.max(-g[i] / dmax);
            }
        }
        if best.as_ref().is_none_or(|(v, _)| viol < *v) {
            best = Some((viol, q));
        }
    }
    let (viol, q) = best.expect("at least the empty set");
    assert!(viol <= 1e-12, "no feasible active set found: {viol}");
    q.into_iter().map(|x| x.max(0.0)).collect()
}

#[test]
fn random_spd_against_enumeration() {
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    let mut s = LoadSolver::with_capacity(12);
    let mut max_iter = 0;
    for case in 0..400 {
        let n = 2 + case % 11;
        let b = Mat::from_fn(n, n, |_, _| rng.range(-1.0, 1.0));
        // Odd cases: a skew-symmetric part makes C non-symmetric (LU path); C·diag(w) stays a
        // P-matrix since xᵀ·C·x > 0 for x ≠ 0.
        let skew = if case % 2 == 1 { 0.3 } else { 0.0 };
        let s_mat = Mat::from_fn(n, n, |_, _| rng.range(-1.0, 1.0));
        let c = Mat::from_fn(n, n, |i, j| {
            let bbt: f64 = (0..n).map(|k| b[(i, k)] * b[(j, k)]).sum();
            let sk = skew * (s_mat[(i, j)] - s_mat[(j, i)]);
            1e-10 * (bbt / n as f64 + sk + if i == j { 0.05 } else { 0.0 })
        });
        let w: Vec<f64> = (0..n).map(|_| rng.range(0.5e-3, 1.5e-3)).collect();
        let d: Vec<f64> = (0..n).map(|_| rng.range(-1e-5, 1e-5)).collect();
        let p = LoadProblem { approach: &d, line_length: &w, compliance: c.as_ref(), local: None };
        let r = s.solve(&p, Start::Cold).unwrap_or_else(|e| panic!("case {case}: {e}"));
        max_iter = max_iter.max(r.iterations);
        let oracle = brute_force(&c, &w, &d);
        let qmax = oracle.iter().fold(0.0_f64, |m, &x| m.max(x));
        for (i, (&q, &o)) in s.load().iter().zip(&oracle).enumerate() {
            assert!((q - o).abs() <= 1e-10 * qmax, "case {case} slice {i}: {q} vs {o}");
        }
        let g = gaps(&c, &w, &d, s.load(), None);
        assert_complementary(s.load(), &g, r.tolerance * 1.01);
    }
    eprintln!("random SPD n<=12: max iterations {max_iter}");
}

/// A realistic non-linear problem: two contact lines of n/2 slices each, compliance
/// c0·exp(−|z_i − z_j|/ℓ) within a line plus a weak coupling c1 of all slices, steel
/// Weber–Banaschek local term with ρ ≈ 10 mm, h = 0.6 mm.
struct Nonlinear {
    c: Mat<f64>,
    w: Vec<f64>,
    d: Vec<f64>,
    rho: Vec<f64>,
    contact: LocalContact,
}

fn nonlinear(n: usize, shift: f64) -> Nonlinear {
    let half = n / 2;
    let line = 0.045; // m of contact line per pair
    let (c0, c1, ell) = (2e-9, 2e-11, 4e-3);
    let z: Vec<f64> = (0..n).map(|i| ((i % half) as f64 + 0.5) * line / half as f64).collect();
    let pair: Vec<usize> = (0..n).map(|i| i / half).collect();
    let w = vec![line / half as f64; n];
    let c = Mat::from_fn(n, n, |i, j| {
        c1 + if pair[i] == pair[j] { c0 * (-(z[i] - z[j]).abs() / ell).exp() } else { 0.0 }
    });
    // Crowned approach: line 0 loaded over most of its length, line 1 only partly.
    let d: Vec<f64> = (0..n)
        .map(|i| {
            let x = (z[i] - 0.5 * line - shift) / (0.5 * line);
            if pair[i] == 0 { 25e-6 - 20e-6 * x * x } else { 14e-6 - 20e-6 * x * x }
        })
        .collect();
    let rho: Vec<f64> = (0..n).map(|i| 8e-3 + 4e-3 * z[i] / line).collect();
    let steel = Material::steel();
    let contact = LocalContact::new(&steel, &steel, 0.6e-3, 0.6e-3).expect("valid");
    Nonlinear { c, w, d, rho, contact }
}

impl Nonlinear {
    fn solve(&self, s: &mut LoadSolver, start: Start<'_>) -> Result<(f64, usize, f64), LoadError> {
        let local = HertzLocal::new(&self.contact, &self.rho)?;
        let p = LoadProblem {
            approach: &self.d,
            line_length: &self.w,
            compliance: self.c.as_ref(),
            local: Some(&local),
        };
        let r = s.solve(&p, start)?;
        let g = gaps(&self.c, &self.w, &self.d, s.load(), Some(&local));
        assert_complementary(s.load(), &g, r.tolerance * 1.01);
        Ok((r.total_force, r.iterations, r.residual))
    }
}

#[test]
fn nonlinear_weber_banaschek() {
    let n = 200;
    let prob = nonlinear(n, 0.0);
    let mut s = LoadSolver::with_capacity(n);
    let (f, iters, res) = prob.solve(&mut s, Start::Cold).expect("solves");
    let active = s.load().iter().filter(|&&q| q > 0.0).count();
    let qmax = s.load().iter().fold(0.0_f64, |m, &x| m.max(x));
    eprintln!(
        "n = 200 cold: {iters} iterations, residual {res:e} m, F = {f:.1} N, {active} loaded, \
         q_max = {qmax:.4e} N/m"
    );
    assert!(active > 20 && active < n, "mixed active set expected, got {active}");
    assert!(f > 0.0);

    // Monotone in a uniform increase of the approach.
    let mut last = f;
    for k in 1..=20 {
        let mut p2 = nonlinear(n, 0.0);
        for d in &mut p2.d {
            *d += 0.5e-6 * k as f64;
        }
        let (f2, _, _) = p2.solve(&mut s, Start::Warm).expect("solves");
        assert!(f2 > last, "F not increasing: {f2} after {last}");
        last = f2;
    }
}

#[test]
fn smooth_onset_of_one_slice() {
    // Slice k (an end of the second line) is swept from a gap to a deep overlap: its load starts
    // from 0 and the total force is continuous.
    let n = 200;
    let mut prob = nonlinear(n, 0.0);
    let k = n - 1;
    let mut s = LoadSolver::with_capacity(n);
    let steps = 600;
    let (t0, t1) = (-5e-6, 25e-6);
    let mut forces = Vec::with_capacity(steps + 1);
    let mut qk = Vec::with_capacity(steps + 1);
    for m in 0..=steps {
        prob.d[k] = t0 + (t1 - t0) * m as f64 / steps as f64;
        let (f, _, _) = prob.solve(&mut s, Start::Warm).expect("solves");
        forces.push(f);
        qk.push(s.load()[k]);
    }
    assert_eq!(qk[0], 0.0);
    let first = qk.iter().position(|&q| q > 0.0).expect("slice gets loaded");
    let q_end = qk[steps];
    assert!(q_end > 0.0);
    assert!(qk[first] < 0.05 * q_end, "onset jump: {} vs {}", qk[first], q_end);
    let jumps: Vec<f64> = forces.windows(2).map(|p| (p[1] - p[0]).abs()).collect();
    let mean = (forces[steps] - forces[0]).abs() / steps as f64;
    let max = jumps.iter().fold(0.0_f64, |m, &x| m.max(x));
    assert!(max <= 4.0 * mean, "F jumps by {max} N (mean step {mean} N)");
    for p in forces.windows(2) {
        assert!(p[1] >= p[0] - 1e-9 * p[0], "F decreased");
    }
}

#[test]
fn warm_start_saves_iterations_and_timing() {
    for n in [50, 200, 400] {
        let mut s = LoadSolver::with_capacity(n);
        let prob = nonlinear(n, 0.0);
        let t = Instant::now();
        let (_, cold_iters, cold_res) = prob.solve(&mut s, Start::Cold).expect("solves");
        let cold_time = t.elapsed();
        // A sequence of nearby problems (the crowning moves along the line as in a time step).
        let mut warm_iters = 0;
        let mut warm_res: f64 = 0.0;
        let mut warm_time = std::time::Duration::ZERO;
        let mut cold_seq_iters = 0;
        let steps = 20;
        for k in 1..=steps {
            let p = nonlinear(n, 1e-5 * k as f64 / steps as f64);
            let local = HertzLocal::new(&p.contact, &p.rho).expect("valid");
            let lp = LoadProblem {
                approach: &p.d,
                line_length: &p.w,
                compliance: p.c.as_ref(),
                local: Some(&local),
            };
            let mut cold = LoadSolver::with_capacity(n);
            cold_seq_iters += cold.solve(&lp, Start::Cold).expect("solves").iterations;
            let t = Instant::now();
            let r = s.solve(&lp, Start::Warm).expect("solves");
            warm_time += t.elapsed();
            warm_iters += r.iterations;

            warm_res = warm_res.max(r.residual);
            // Both meet the gap tolerance (~1e-12 m); loads agree to the matching precision.
            let qmax = cold.load().iter().fold(0.0_f64, |m, &x| m.max(x));
            for (a, b) in s.load().iter().zip(cold.load()) {
                assert!((a - b).abs() <= 1e-6 * qmax, "warm {a} vs cold {b}");
            }
        }
        eprintln!(
            "n = {n}: cold {cold_iters} it, residual {cold_res:.2e} m, {:.3} ms; \
             warm mean {:.2} it (cold {:.2} it), max residual {warm_res:.2e} m, mean {:.3} ms",
            cold_time.as_secs_f64() * 1e3,
            warm_iters as f64 / steps as f64,
            cold_seq_iters as f64 / steps as f64,
            warm_time.as_secs_f64() * 1e3 / steps as f64
        );
        assert!(warm_iters < cold_seq_iters, "warm {warm_iters} vs cold {cold_seq_iters}");
    }
}

#[test]
fn no_overlap_gives_exactly_zero() {
    let n = 30;
    let prob = nonlinear(n, 0.0);
    let d: Vec<f64> = (0..n).map(|i| -1e-6 * (i % 4) as f64).collect();
    let local = HertzLocal::new(&prob.contact, &prob.rho).expect("valid");
    let p = LoadProblem {
        approach: &d,
        line_length: &prob.w,
        compliance: prob.c.as_ref(),
        local: Some(&local),
    };
    let mut s = LoadSolver::with_capacity(n);
    // Start from a loaded guess: the answer is still exactly zero.
    let guess = vec![1e5; n];
    for start in [Start::Cold, Start::From(&guess), Start::Warm] {
        let r = s.solve(&p, start).expect("solves");
        assert!(s.load().iter().all(|&q| q == 0.0));
        assert_eq!(r.total_force, 0.0);
        assert_eq!(r.iterations, 0);
        assert_eq!(total_force(s.load(), &prob.w), 0.0);
    }
}

#[test]
fn non_finite_inputs_are_named_errors() {
    let n = 6;
    let prob = nonlinear(n, 0.0);
    let mut s = LoadSolver::with_capacity(n);
    let mut d = prob.d.clone();
    d[3] = f64::NAN;
    let p = LoadProblem {
        approach: &d,
        line_length: &prob.w,
        compliance: prob.c.as_ref(),
        local: None,
    };
    match s.solve(&p, Start::Cold) {
        Err(LoadError::NonFinite { name: "approach", index: 3, .. }) => {}
        other => panic!("unexpected {other:?}"),
    }
    let mut c = prob.c.clone();
    c[(2, 4)] = f64::NAN;
    let p = LoadProblem {
        approach: &prob.d,
        line_length: &prob.w,
        compliance: c.as_ref(),
        local: None,
    };
    match s.solve(&p, Start::Cold) {
        Err(e @ LoadError::NonFiniteCompliance { row: 2, col: 4, .. }) => {
            assert!(e.to_string().contains("compliance"));
        }
        other => panic!("unexpected {other:?}"),
    }
    let mut c = prob.c.clone();
    c[(1, 1)] = f64::INFINITY;
    let p = LoadProblem {
        approach: &prob.d,
        line_length: &prob.w,
        compliance: c.as_ref(),
        local: None,
    };
    assert!(matches!(s.solve(&p, Start::Cold), Err(LoadError::NonFiniteCompliance { .. })));
    assert!(s.load().is_empty());
    // A local term returning NaN.
    let bad = |_: usize, _: f64| (f64::NAN, 1.0);
    let p = LoadProblem {
        approach: &prob.d,
        line_length: &prob.w,
        compliance: prob.c.as_ref(),
        local: Some(&bad),
    };
    assert!(matches!(s.solve(&p, Start::Cold), Err(LoadError::LocalTerm { .. })));
    // Wrong sizes.
    let p = LoadProblem {
        approach: &prob.d[..5],
        line_length: &prob.w,
        compliance: prob.c.as_ref(),
        local: None,
    };
    assert!(matches!(
        s.solve(&p, Start::Cold),
        Err(LoadError::DimensionMismatch { name: "line_length", expected: 5, found: 6 })
    ));
}

#[test]
fn ill_posed_problems_are_typed_errors() {
    let w = [1e-3, 1e-3];
    let d = [1e-5, 1e-5];
    // Indefinite: eigenvalues 3 and −1 (×1e-10).
    let c = Mat::from_fn(2, 2, |i, j| if i == j { 1e-10 } else { 2e-10 });
    let p = LoadProblem { approach: &d, line_length: &w, compliance: c.as_ref(), local: None };
    let mut s = LoadSolver::with_capacity(2);
    match s.solve(&p, Start::Cold) {
        Err(e @ LoadError::Indefinite { .. }) => eprintln!("{e}"),
        other => panic!("unexpected {other:?}"),
    }
    // Singular: rank one.
    let c = Mat::from_fn(2, 2, |_, _| 1e-10);
    let p = LoadProblem { approach: &d, line_length: &w, compliance: c.as_ref(), local: None };
    match s.solve(&p, Start::Cold) {
        Err(e @ LoadError::Singular { .. }) => eprintln!("{e}"),
        other => panic!("unexpected {other:?}"),
    }
    // Non-positive diagonal.
    let c = Mat::from_fn(2, 2, |i, j| if i == j { -1e-10 } else { 0.0 });
    let p = LoadProblem { approach: &d, line_length: &w, compliance: c.as_ref(), local: None };
    assert!(matches!(
        s.solve(&p, Start::Cold),
        Err(LoadError::NonPositive { name: "compliance diagonal", index: 0, .. })
    ));
    // Iteration cap: a non-linear problem cannot converge in one iteration.
    let prob = nonlinear(40, 0.0);
    let mut s =
        LoadSolver::with_settings(40, LoadSettings { max_iterations: 1, ..Default::default() });
    match prob.solve(&mut s, Start::Cold) {
        Err(LoadError::NoConvergence { iterations: 1, residual, tolerance }) => {
            assert!(residual.is_finite() && residual > tolerance);
        }
        other => panic!("unexpected {other:?}"),
    }
}

#[test]
fn torques_and_pressures() {
    // Eq. 13: uniform q on a line in the plane of action gives M = g·q·Σ m_n·Δζ.
    let q = [1e5, 2e5, 0.0];
    let arm = [0.05, 0.05, 0.05];
    let dz = [1e-3, 2e-3, 3e-3];
    let m = mesh_torque(&q, &arm, &dz).expect("valid");
    assert!((m - 0.05 * (1e5 * 1e-3 + 2e5 * 2e-3)).abs() < 1e-9);
    assert!(matches!(mesh_torque(&q, &arm[..2], &dz), Err(LoadError::DimensionMismatch { .. })));
    // Eq. 14 by hand.
    let [mp, mg] = damping_torques(100.0, 10.0, -5.0, 0.04, 0.07, 12.0);
    let rate = 10.0 * 0.04 - 5.0 * 0.07;
    assert!((mp - 100.0 * rate * 0.04 * 12.0).abs() < 1e-12);
    assert!((mg - 100.0 * rate * 0.07 * 12.0).abs() < 1e-12);
    // Eq. 15 against the hertz module; zero load, zero pressure.
    let steel = Material::steel();
    let contact = LocalContact::new(&steel, &steel, 0.6e-3, 0.6e-3).expect("valid");
    let mut p = [0.0; 3];
    hertz_pressures(&contact, &q, &[0.02, 0.02, 0.02], &[0.02, f64::INFINITY, 0.01], &mut p)
        .expect("valid");
    let expect = contact.max_pressure(1e5, 0.01).expect("valid");
    assert!((p[0] - expect).abs() <= 1e-12 * expect);
    assert_eq!(p[2], 0.0);
    assert!(matches!(
        hertz_pressures(&contact, &q, &[0.02, -1.0, 0.02], &[0.02; 3], &mut p),
        Err(LoadError::Hertz { slice: 1, .. })
    ));
}

#[test]
fn random_problems_converge_with_complementarity() {
    // Random positive definite C (symmetric, or with a skew part: still a P-matrix), random
    // line lengths, mixed-sign approach, with and without the Weber–Banaschek term.
    let steel = Material::steel();
    let contact = LocalContact::new(&steel, &steel, 0.6e-3, 0.6e-3).expect("valid");
    let mut rng = Rng(987_654_321);
    let mut s = LoadSolver::with_capacity(40);
    let mut max_iter = [0usize; 2];
    for case in 0..1500 {
        let n = 2 + case % 39;
        let b = Mat::from_fn(n, n, |_, _| rng.range(-1.0, 1.0));
        let sk = Mat::from_fn(n, n, |_, _| rng.range(-1.0, 1.0));
        let skew = if case % 3 == 0 { rng.range(0.0, 1.0) } else { 0.0 };
        let diag = rng.range(0.01, 0.5);
        let c = Mat::from_fn(n, n, |i, j| {
            let bbt: f64 = (0..n).map(|k| b[(i, k)] * b[(j, k)]).sum();
            let extra = skew * (sk[(i, j)] - sk[(j, i)]) + if i == j { diag } else { 0.0 };
            1e-9 * (bbt / n as f64 + extra)
        });
        let w: Vec<f64> = (0..n).map(|_| rng.range(0.1e-3, 1.5e-3)).collect();
        let d: Vec<f64> = (0..n).map(|_| rng.range(-3e-5, 3e-5)).collect();
        let rho: Vec<f64> = (0..n).map(|_| rng.range(2e-3, 3e-2)).collect();
        let hl = HertzLocal::new(&contact, &rho).expect("valid");
        let nonlinear = case % 2 == 1;
        let local: Option<&dyn LocalTerm> = if nonlinear { Some(&hl) } else { None };
        let p = LoadProblem { approach: &d, line_length: &w, compliance: c.as_ref(), local };
        let r = s.solve(&p, Start::Cold).unwrap_or_else(|e| panic!("case {case}: {e}"));
        max_iter[usize::from(nonlinear)] = max_iter[usize::from(nonlinear)].max(r.iterations);
        let g = gaps(&c, &w, &d, s.load(), local);
        // The independent re-evaluation differs from the solver's by round-off only.
        assert_complementary(s.load(), &g, r.tolerance * 1.01 + 1e-18);
    }
    eprintln!("random problems: max iterations linear {}, non-linear {}", max_iter[0], max_iter[1]);
}
