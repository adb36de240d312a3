//! Tests of the Levenberg–Marquardt solver, the fitted influence function (Eqs. 5–9) and the
//! direct interpolation of influence grids, on synthetic grids with known answers.
//!
//! The synthetic grids mimic the FE data of the paper's gear (Table 1: b₀ = 5, η* from −0.1 to
//! 2.2, τ > 0 on the top rows): 14 profile rows × 9 ζ columns, teeth −1, 0, 1, α* of order
//! 1e-11…1e-10 m/N, neighbour blocks about 20 % of the loaded tooth's.

mod common;

use helical_gear_mesh::compliance::data::ComplianceData;
use helical_gear_mesh::compliance::fitted::{FitError, FittedInfluence, InfluenceParameters};
use helical_gear_mesh::compliance::interpolated::{InterpolatedInfluence, SliceInfluence};
use helical_gear_mesh::compliance::lm::{
    Jacobian, LmError, LmOptions, levenberg_marquardt, levenberg_marquardt_fd,
};
use helical_gear_mesh::compliance::{Compliance, FlankCoord, InfluenceGrid};
use helical_gear_mesh::geometry::Member;
use std::time::Instant;

use common::Lcg;

const B0: f64 = 5.0;
/// Reference compliance of the synthetic gear, m/N.
const ALPHA_REF: f64 = 4e-11;

// ---------------------------------------------------------------------------------------------
// Levenberg–Marquardt
// ---------------------------------------------------------------------------------------------

fn rosenbrock(x: &[f64], r: &mut [f64]) {
    r[0] = 10.0 * (x[1] - x[0] * x[0]);
    r[1] = 1.0 - x[0];
}

#[test]
fn lm_rosenbrock_analytic_and_forward_difference() {
    let opts = LmOptions::default();
    let jac = |x: &[f64], j: &mut [f64]| {
        j.copy_from_slice(&[-20.0 * x[0], 10.0, -1.0, 0.0]);
    };
    let s = levenberg_marquardt(&[-1.2, 1.0], 2, rosenbrock, Jacobian::Analytic(jac), &opts)
        .expect("analytic LM converges");
    eprintln!("Rosenbrock (analytic): {:?} {:?}", s.x, s.stats);
    assert!((s.x[0] - 1.0).abs() < 1e-8 && (s.x[1] - 1.0).abs() < 1e-8);
    assert!(s.stats.cost < 1e-20);
    let s = levenberg_marquardt_fd(&[-1.2, 1.0], 2, rosenbrock, &opts).expect("FD LM converges");
    eprintln!("Rosenbrock (forward differences): {:?} {:?}", s.x, s.stats);
    assert!((s.x[0] - 1.0).abs() < 1e-6 && (s.x[1] - 1.0).abs() < 1e-6);
}

#[test]
fn lm_exponential_fit_recovers_parameters() {
    let truth = [2.5, -1.3, 0.4];
    let t: Vec<f64> = (0..40).map(|k| 0.1 * k as f64).collect();
    let y: Vec<f64> = t.iter().map(|&t| truth[0] * (truth[1] * t).exp() + truth[2]).collect();
    let res = |x: &[f64], r: &mut [f64]| {
        for k in 0..t.len() {
            r[k] = x[0] * (x[1] * t[k]).exp() + x[2] - y[k];
        }
    };
    let jac = |x: &[f64], j: &mut [f64]| {
        for k in 0..t.len() {
            let e = (x[1] * t[k]).exp();
            j[3 * k] = e;
            j[3 * k + 1] = x[0] * t[k] * e;
            j[3 * k + 2] = 1.0;
        }
    };
    let opts = LmOptions::default();
    let s = levenberg_marquardt(&[1.0, -0.5, 0.0], t.len(), res, Jacobian::Analytic(jac), &opts)
        .expect("converges");
    eprintln!("exponential fit (analytic): {:?} {:?}", s.x, s.stats);
    for (got, want) in s.x.iter().zip(truth) {
        assert!((got - want).abs() < 1e-8, "{:?}", s.x);
    }
    let s = levenberg_marquardt_fd(&[1.0, -0.5, 0.0], t.len(), res, &opts).expect("converges");
    eprintln!("exponential fit (forward differences): {:?} {:?}", s.x, s.stats);
    for (got, want) in s.x.iter().zip(truth) {
        assert!((got - want).abs() < 1e-6, "{:?}", s.x);
    }
}

#[test]
fn lm_errors_are_typed_and_finite() {
    let opts = LmOptions::default();
    let bad = levenberg_marquardt_fd(&[f64::NAN, 1.0], 2, rosenbrock, &opts);
    assert!(matches!(bad, Err(LmError::InvalidInput(_))));
    let empty = levenberg_marquardt_fd(&[], 2, rosenbrock, &opts);
    assert!(matches!(empty, Err(LmError::InvalidInput(_))));
    let nan_start =
        levenberg_marquardt_fd(&[1.0], 1, |_: &[f64], r: &mut [f64]| r[0] = f64::NAN, &opts);
    assert!(matches!(nan_start, Err(LmError::NonFiniteStart)));
    let short = LmOptions { max_iterations: 2, ..opts };
    match levenberg_marquardt_fd(&[-1.2, 1.0], 2, rosenbrock, &short) {
        Err(LmError::MaxIterations { best, stats }) => {
            assert!(best.iter().all(|v| v.is_finite()));
            assert!(stats.cost <= stats.initial_cost && stats.cost.is_finite());
        }
        other => panic!("expected MaxIterations, got {other:?}"),
    }
    // Residuals that become non-finite away from the start: steps are rejected, never NaN.
    let wall = |x: &[f64], r: &mut [f64]| {
        r[0] = if x[0] > 1.5 { f64::NAN } else { x[0] - 2.0 };
    };
    match levenberg_marquardt_fd(&[0.0], 1, wall, &opts) {
        Ok(s) => assert!(s.x[0].is_finite() && s.x[0] <= 1.5),
        Err(LmError::Stalled { best, .. }) | Err(LmError::MaxIterations { best, .. }) => {
            assert!(best[0].is_finite() && best[0] <= 1.5)
        }
        Err(e) => panic!("unexpected {e}"),
    }
}

// ---------------------------------------------------------------------------------------------
// Synthetic grids
// ---------------------------------------------------------------------------------------------

/// A known, realistic parameter set of Eqs. 6–8 (scaled form).
fn true_parameters() -> InfluenceParameters {
    InfluenceParameters {
        a: [0.3, 1.2, -0.8, 0.3, 0.2, -0.5, -1.5, 0.2, 0.25, 0.2, -0.5, -1.5, 0.2],
        b: [0.5, 0.1, 0.1],
        c: [0.8, 0.1, -0.02, 0.1, 0.01, 0.0, 0.0, 0.1, 1.6],
    }
}

/// Rows (profile, η*, τ): three rows on the tip rounding (τ = 0.3, 0.2, 0.1 rad, rounding from
/// η*_q = 0 with radius 0.3 m_n), then 11 involute rows η* = 0…2.2; columns ζ = 0…b₀.
fn axes(rows_involute: usize, cols: usize) -> (Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>) {
    let (mut profile, mut eta, mut tau) = (vec![], vec![], vec![]);
    for t in [0.3, 0.2, 0.1] {
        let p = -t * 0.3;
        profile.push(p);
        eta.push(p);
        tau.push(t);
    }
    for k in 0..rows_involute {
        let e = 2.2 * k as f64 / (rows_involute - 1) as f64;
        profile.push(e);
        eta.push(e);
        tau.push(0.0);
    }
    let zeta = (0..cols).map(|k| B0 * k as f64 / (cols - 1) as f64).collect();
    (profile, eta, tau, zeta)
}

/// A grid with α*(obs, load) = `f(obs, load, tooth)` on the given axes.
fn grid_from(
    (profile, eta, tau, zeta): (Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>),
    teeth: &[i32],
    f: impl Fn(FlankCoord, FlankCoord, i32) -> f64,
) -> InfluenceGrid {
    let mut g = InfluenceGrid {
        profile,
        eta_star: eta,
        tau,
        zeta,
        teeth: teeth.to_vec(),
        alpha: vec![],
        depth_h: 1.5e-3,
        eta_star_rounding_start: 0.0,
        rounding_radius_mn: 0.3,
    };
    let n = g.points();
    for &t in teeth {
        let mut block = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                block[i * n + j] = f(g.coord(i), g.coord(j), t);
            }
        }
        g.alpha.push(block);
    }
    g
}

/// Neighbour-tooth coupling (about 10–25 % of the loaded tooth), m/N.
fn neighbour(o: FlankCoord, l: FlankCoord, t: i32) -> f64 {
    let amp = |c: FlankCoord| 0.4 + 1.1 * (-0.9 * c.eta_star).exp();
    let s = o.zeta - l.zeta - 0.8 * t as f64;
    ALPHA_REF * 0.2 * (amp(o) * amp(l)).sqrt() * (-0.15 * s * s).exp()
}

/// The Eq. 5–8 family with the true parameters, plus neighbours.
fn family_grid() -> InfluenceGrid {
    let p = true_parameters();
    grid_from(axes(11, 9), &[-1, 0, 1], |o, l, t| {
        if t == 0 { ALPHA_REF * p.alpha(o, l, B0) } else { neighbour(o, l, t) }
    })
}

/// A smooth influence function outside the Eq. 5–8 family: two Gaussians in ζ − ζ_F with a
/// profile- and edge-dependent amplitude (symmetric in obs ↔ load).
fn other_alpha(o: FlankCoord, l: FlankCoord) -> f64 {
    let g = |c: FlankCoord| {
        0.4 + 1.1 * (-0.9 * c.eta_star).exp()
            + 0.4 * c.tau
            + 0.3 * (-2.0 * c.zeta).exp()
            + 0.3 * (-2.0 * (B0 - c.zeta)).exp()
    };
    let d = o.zeta - l.zeta;
    let width = 0.8 + 0.15 * (o.eta_star + l.eta_star);
    let shape =
        0.7 * (-d * d / (2.0 * width * width)).exp() + 0.3 * (-d * d / (2.0 * 2.0 * 2.0)).exp();
    ALPHA_REF * (g(o) * g(l)).sqrt() * shape
}

fn other_grid() -> InfluenceGrid {
    grid_from(
        axes(11, 9),
        &[-1, 0, 1],
        |o, l, t| {
            if t == 0 { other_alpha(o, l) } else { neighbour(o, l, t) }
        },
    )
}

// ---------------------------------------------------------------------------------------------
// Fitted influence (Eqs. 5–9)
// ---------------------------------------------------------------------------------------------

#[test]
fn fit_recovers_exact_family_data() {
    let grid = family_grid();
    let t = Instant::now();
    let (fit, report) = FittedInfluence::fit(&grid, B0).expect("fit succeeds");
    eprintln!("exact data: {report:?} in {:.2?}", t.elapsed());
    eprintln!("fitted constants: {:?}", fit.params);
    assert!(report.sigma_e_rel < 1e-3, "σ(e_rel) = {}", report.sigma_e_rel);
    assert_eq!(report.fitted_values, grid.points() * grid.points());
    // Off-node check against the true function (scaled by the diagonal at the load point).
    let p = true_parameters();
    let mut rng = Lcg(7);
    let mut worst: f64 = 0.0;
    for _ in 0..500 {
        let c = |r: &mut Lcg| FlankCoord {
            eta_star: 2.2 * r.uniform(),
            tau: 0.0,
            zeta: B0 * r.uniform(),
        };
        let (o, l) = (c(&mut rng), c(&mut rng));
        let truth = ALPHA_REF * p.alpha(o, l, B0);
        let e = (fit.alpha(o, l, 0) - truth) / (ALPHA_REF * p.alpha(l, l, B0));
        worst = worst.max(e.abs());
    }
    eprintln!("exact data: max off-node |e_rel| vs the true function = {worst:.3e}");
    assert!(worst < 1e-2);
    // Evaluation cost of the formula (same 200 × 200 pattern as the interpolation test).
    let pts: Vec<FlankCoord> = (0..200)
        .map(|k| {
            let s = k as f64 / 199.0;
            FlankCoord { eta_star: 0.1 + 1.8 * s, tau: 0.0, zeta: 5.0 * s }
        })
        .collect();
    let t = Instant::now();
    let mut sum = 0.0;
    for &o in &pts {
        for &l in &pts {
            sum += fit.alpha(o, l, 0);
        }
    }
    let el = t.elapsed();
    assert!(sum.is_finite() && sum > 0.0);
    eprintln!(
        "fitted formula: 200×200 matrix in {el:.2?} ({:.0} ns/evaluation)",
        el.as_nanos() as f64 / 40_000.0
    );
}

#[test]
fn fit_with_two_percent_noise() {
    let clean = family_grid();
    let mut noisy = clean.clone();
    let mut rng = Lcg(42);
    let noise = 0.02;
    for block in &mut noisy.alpha {
        for v in block.iter_mut() {
            *v *= 1.0 + noise * rng.normal();
        }
    }
    let (fit, report) = FittedInfluence::fit(&noisy, B0).expect("fit succeeds");
    eprintln!("2 % noise: {report:?}");
    assert!(report.sigma_e_rel <= 0.03, "σ(e_rel) = {}", report.sigma_e_rel);
    assert!(report.sigma_e_rel >= 0.25 * noise, "σ(e_rel) = {}", report.sigma_e_rel);
    // The fit averages the noise: its error against the clean data is below the noise level.
    let n = clean.points();
    let mut s2 = 0.0;
    for i in 0..n {
        for j in 0..n {
            let e = (fit.alpha(clean.coord(i), clean.coord(j), 0) - clean.value(1, i, j))
                / clean.value(1, j, j);
            s2 += e * e;
        }
    }
    let rms = (s2 / (n * n) as f64).sqrt();
    eprintln!("2 % noise: rms e_rel against the clean data = {rms:.3e}");
    assert!(rms < 0.5 * noise);
}

#[test]
fn fit_of_a_function_outside_the_family() {
    let grid = other_grid();
    let (_, report) = FittedInfluence::fit(&grid, B0).expect("fit succeeds");
    eprintln!("two-Gaussian data: {report:?}");
    assert!(report.sigma_e_rel < 0.05, "σ(e_rel) = {}", report.sigma_e_rel);
    assert!(report.max_abs_e_rel < 0.3, "max |e_rel| = {}", report.max_abs_e_rel);
}

#[test]
fn fit_with_sub_sampling() {
    use helical_gear_mesh::compliance::fitted::FitOptions;
    let grid = family_grid();
    let opts = FitOptions { pair_stride: 7, ..FitOptions::default() };
    let (_, report) = FittedInfluence::fit_with(&grid, B0, &opts).expect("fit succeeds");
    eprintln!("exact data, every 7th pair: {report:?}");
    assert!(report.fitted_values < grid.points() * grid.points() / 5);
    assert!(report.sigma_e_rel < 1e-3);
}

/// Same-row selection and the τ limit: the fitted pair count is exactly the selected one, the
/// family is still recovered, and `deviation` reproduces the report on the fitted pairs.
#[test]
fn fit_on_contact_line_pairs_and_limited_rounding() {
    use helical_gear_mesh::compliance::fitted::{FitOptions, PairSelection};
    let grid = family_grid();
    let (nr, nc) = (grid.profile.len(), grid.zeta.len());
    // Rows with τ ≤ 0.15 rad: the lowest rounding row (τ = 0.1) and the involute rows.
    let kept = grid.tau.iter().filter(|&&t| t <= 0.15).count();
    assert_eq!(kept, nr - 2);
    let opts = FitOptions { pairs: PairSelection::SameRow, max_tau: 0.15, ..FitOptions::default() };
    let (fit, report) = FittedInfluence::fit_with(&grid, B0, &opts).expect("fit succeeds");
    eprintln!("exact data, same-row pairs, τ ≤ 0.15: {report:?}");
    assert_eq!(report.fitted_values, kept * nc * nc);
    assert!(report.sigma_e_rel < 1e-3, "σ(e_rel) = {}", report.sigma_e_rel);
    let used = |i: usize| grid.tau[i / nc] <= 0.15;
    let dev =
        fit.deviation(&grid, |i, j| used(i) && used(j) && i / nc == j / nc).expect("valid grid");
    assert_eq!(dev.count, report.fitted_values);
    assert!((dev.std - report.sigma_e_rel).abs() <= 1e-9, "{dev:?} vs {report:?}");
    assert!((dev.mean - report.mean_e_rel).abs() <= 1e-9);
    // Exact family data: also right off the fitted pairs (other rows, τ = 0.3 extrapolated).
    let all = fit.deviation(&grid, |_, _| true).expect("valid grid");
    assert_eq!(all.count, grid.points() * grid.points());
    assert!(all.max_abs < 1e-2, "{all:?}");
    // A limit that leaves fewer than two rows is an error naming max_tau.
    let bad = FitOptions { max_tau: -1.0, ..FitOptions::default() };
    match FittedInfluence::fit_with(&grid, B0, &bad) {
        Err(FitError::Input(m)) => assert!(m.contains("max_tau"), "{m}"),
        other => panic!("expected an input error, got {other:?}"),
    }
}

/// A fit rebuilt from its constants with `with_neighbours` equals the original.
#[test]
fn fitted_influence_rebuilt_from_constants() {
    let grid = family_grid();
    let (fit, _) = FittedInfluence::fit(&grid, B0).expect("fit succeeds");
    let back = FittedInfluence::with_neighbours(fit.params, fit.b0, fit.alpha_ref, grid.clone())
        .expect("valid grid");
    assert_eq!(back, fit);
    let (o, l) = (grid.coord(12), grid.coord(77));
    for t in [-1, 0, 1] {
        assert_eq!(back.alpha(o, l, t), fit.alpha(o, l, t));
    }
}

#[test]
fn fitted_influence_delegates_neighbour_teeth_and_serialises() {
    let grid = family_grid();
    let (fit, _) = FittedInfluence::fit(&grid, B0).expect("fit succeeds");
    assert_eq!(fit.max_tooth_offset(), 1);
    assert_eq!(fit.depth(), grid.depth_h);
    let n = grid.points();
    for (t, &tooth) in grid.teeth.iter().enumerate() {
        if tooth == 0 {
            continue;
        }
        for (i, j) in [(0, 0), (5, 17), (n - 1, 3), (40, n - 2)] {
            let want = grid.value(t, i, j);
            let got = fit.alpha(grid.coord(i), grid.coord(j), tooth);
            assert!((got - want).abs() <= 1e-12 * want.abs(), "tooth {tooth}: {got} vs {want}");
        }
    }
    assert_eq!(fit.alpha(grid.coord(0), grid.coord(0), 2), 0.0);
    let json = serde_json::to_string(&fit).expect("serialises");
    let back: FittedInfluence = serde_json::from_str(&json).expect("deserialises");
    let (o, l) = (grid.coord(10), grid.coord(50));
    for t in [0, 1] {
        let (a, b) = (back.alpha(o, l, t), fit.alpha(o, l, t));
        assert!((a - b).abs() <= 1e-14 * b.abs(), "tooth {t}: {a} vs {b}");
    }
}

#[test]
fn invalid_grids_are_errors() {
    let good = family_grid();
    let mut cases = Vec::new();
    let mut g = good.clone();
    g.zeta.swap(1, 2);
    cases.push(("zeta not increasing", g));
    let mut g = good.clone();
    g.alpha[1].pop();
    cases.push(("short block", g));
    let mut g = good.clone();
    g.alpha[1][3] = f64::NAN;
    cases.push(("NaN", g));
    let mut g = good.clone();
    g.teeth = vec![-1, 2, 1];
    cases.push(("no tooth 0", g));
    let mut g = good.clone();
    g.depth_h = 0.0;
    cases.push(("h = 0", g));
    for (what, g) in cases {
        let e = InterpolatedInfluence::new(g.clone()).expect_err(what);
        eprintln!("{what}: {e}");
        assert!(matches!(FittedInfluence::fit(&g, B0), Err(FitError::Grid(_))), "{what}");
    }
    assert!(matches!(FittedInfluence::fit(&good, -1.0), Err(FitError::Input(_))));
    // A cached interpolant is validated when it is read back.
    let mut bad = good.clone();
    bad.profile.reverse();
    let json = serde_json::to_string(&bad).expect("serialises");
    assert!(serde_json::from_str::<InterpolatedInfluence>(&json).is_err());
    let ok = serde_json::to_string(&InterpolatedInfluence::new(good.clone()).expect("valid"));
    let back: InterpolatedInfluence =
        serde_json::from_str(&ok.expect("serialises")).expect("valid grid reads back");
    assert_eq!(back.grid().teeth, good.teeth);
    let mut g = good.clone();
    g.alpha[1][0] = -1e-11;
    assert!(matches!(FittedInfluence::fit(&g, B0), Err(FitError::Input(_))));
}

// ---------------------------------------------------------------------------------------------
// Interpolated influence
// ---------------------------------------------------------------------------------------------

#[test]
fn interpolation_is_exact_at_nodes_and_symmetric() {
    let grid = other_grid();
    let interp = InterpolatedInfluence::new(grid.clone()).expect("valid grid");
    let n = grid.points();
    let mut worst: f64 = 0.0;
    for (t, &tooth) in grid.teeth.iter().enumerate() {
        for i in (0..n).step_by(3) {
            for j in (0..n).step_by(5) {
                let want = grid.value(t, i, j);
                let got = interp.alpha(grid.coord(i), grid.coord(j), tooth);
                worst = worst.max((got - want).abs() / want.abs());
            }
        }
    }
    eprintln!("interpolation at nodes: max relative error {worst:.2e}");
    assert!(worst <= 1e-12);
    // Maxwell–Betti: symmetric data give a symmetric interpolant at arbitrary points.
    let mut rng = Lcg(3);
    let mut asym: f64 = 0.0;
    for _ in 0..2000 {
        let c = |r: &mut Lcg| FlankCoord {
            eta_star: -0.1 + 2.3 * r.uniform(),
            tau: if r.uniform() < 0.2 { 0.3 * r.uniform() } else { 0.0 },
            zeta: B0 * r.uniform(),
        };
        let (a, b) = (c(&mut rng), c(&mut rng));
        let (ab, ba) = (interp.alpha(a, b, 0), interp.alpha(b, a, 0));
        asym = asym.max((ab - ba).abs() / ab.abs().max(ba.abs()));
    }
    eprintln!("interpolation: max relative asymmetry {asym:.2e}");
    assert!(asym <= 1e-12);
    // Clamped outside the grid: beyond the last column equals the boundary value.
    let (o, l) = (grid.coord(7), grid.coord(20));
    let outside = FlankCoord { zeta: B0 + 1.0, ..o };
    let edge = FlankCoord { zeta: B0, ..o };
    assert_eq!(interp.alpha(outside, l, 0), interp.alpha(edge, l, 0));
    assert_eq!(interp.alpha(o, l, 5), 0.0);
    assert_eq!(interp.max_tooth_offset(), 1);
}

/// A smooth analytic α for the convergence study (m/N).
fn smooth_alpha(o: FlankCoord, l: FlankCoord) -> f64 {
    let g = |c: FlankCoord| 0.5 + (-0.8 * c.eta_star).exp() + 0.3 * (-1.5 * c.zeta).exp();
    let d = o.zeta - l.zeta;
    ALPHA_REF
        * (g(o) * g(l)).sqrt()
        * (-0.3 * d * d).exp()
        * (0.2 * (o.eta_star - l.eta_star)).cos()
}

#[test]
fn interpolation_converges_under_refinement() {
    // Involute rows only (τ = 0) so that the profile coordinate is η*; non-uniform base grid.
    let base_rows: Vec<f64> = vec![0.0, 0.3, 0.7, 1.0, 1.5, 2.2];
    let base_cols: Vec<f64> = vec![0.0, 0.8, 1.5, 2.5, 3.2, 4.2, 5.0];
    let refine = |v: &[f64]| {
        let mut out = vec![v[0]];
        for w in v.windows(2) {
            out.push(0.5 * (w[0] + w[1]));
            out.push(w[1]);
        }
        out
    };
    let mut rng = Lcg(11);
    let samples: Vec<(FlankCoord, FlankCoord)> = (0..3000)
        .map(|_| {
            let mut c = || FlankCoord {
                eta_star: 2.2 * rng.uniform(),
                tau: 0.0,
                zeta: 5.0 * rng.uniform(),
            };
            (c(), c())
        })
        .collect();
    let (mut rows, mut cols) = (base_rows, base_cols);
    let mut errors = Vec::new();
    for level in 0..4 {
        let grid = grid_from(
            (rows.clone(), rows.clone(), vec![0.0; rows.len()], cols.clone()),
            &[0],
            |o, l, _| smooth_alpha(o, l),
        );
        let interp = InterpolatedInfluence::new(grid).expect("valid grid");
        let err = samples
            .iter()
            .map(|&(o, l)| ((interp.alpha(o, l, 0) - smooth_alpha(o, l)) / ALPHA_REF).abs())
            .fold(0.0, f64::max);
        eprintln!(
            "refinement level {level}: {}×{} grid, max error / α_ref = {err:.3e}",
            rows.len(),
            cols.len()
        );
        errors.push(err);
        rows = refine(&rows);
        cols = refine(&cols);
    }
    let orders: Vec<f64> = errors.windows(2).map(|w| (w[0] / w[1]).log2()).collect();
    eprintln!("observed orders: {orders:?}");
    // Cubic Hermite with second-order slopes: O(h³), error ratio → 8 per halving.
    assert!(orders[2] >= 2.85, "order {orders:?}");
    assert!(errors[3] < 1e-4);
}

#[test]
fn interpolation_cost_of_a_200_by_200_matrix() {
    let grid = other_grid();
    let interp = InterpolatedInfluence::new(grid).expect("valid grid");
    let pts: Vec<FlankCoord> = (0..200)
        .map(|k| {
            let s = k as f64 / 199.0;
            FlankCoord { eta_star: 0.1 + 1.8 * s, tau: 0.0, zeta: 5.0 * s }
        })
        .collect();
    let t = Instant::now();
    let mut direct = vec![0.0; 200 * 200];
    for (i, &o) in pts.iter().enumerate() {
        for (j, &l) in pts.iter().enumerate() {
            direct[i * 200 + j] = interp.alpha(o, l, 0);
        }
    }
    let t_direct = t.elapsed();
    let t = Instant::now();
    let batch = interp.matrix(&pts, &pts, 0);
    let t_batch = t.elapsed();
    eprintln!(
        "200×200 α* matrix: {t_direct:.2?} pairwise ({:.0} ns/evaluation), {t_batch:.2?} batched",
        t_direct.as_nanos() as f64 / 40_000.0
    );
    for (a, b) in direct.iter().zip(&batch) {
        assert!((a - b).abs() <= 1e-12 * a.abs().max(1e-30));
    }
    // Generous bound (unoptimised test builds, other processes running): well under a second.
    assert!(t_direct.as_secs_f64() < 0.5 && t_batch.as_secs_f64() < 0.5);
}

/// The slice kernel's vectorised block (AVX2, where the CPU has it) is the portable kernel bit
/// for bit: same operations, same order, no fused multiply-adds. On a synthetic grid and on the
/// embedded Table 1 pinion grid, random observation and load slices over the whole profile
/// (the rounding included) and every tooth offset, blocks placed off the matrix origin.
#[test]
fn slice_kernel_blocks_are_the_portable_kernel_bit_for_bit() {
    let table1 = ComplianceData::embedded_table1().expect("embedded data");
    let grids = [other_grid(), table1.interpolated(Member::Pinion).expect("grid").grid().clone()];
    let mut rng = Lcg(11);
    for grid in grids {
        let (p_lo, p_hi) = (grid.profile[0], grid.profile[grid.profile.len() - 1]);
        let z_hi = grid.zeta[grid.zeta.len() - 1];
        let teeth = grid.teeth.clone();
        let interp = InterpolatedInfluence::new(grid).expect("valid grid");
        let zetas: Vec<f64> = (0..60).map(|k| (k as f64 + 0.5) / 60.0 * z_hi).collect();
        let kernel = SliceInfluence::new(&interp, &zetas).expect("at least four nodes");
        let points = |n: usize, r: &mut Lcg| -> Vec<_> {
            (0..n)
                .map(|_| {
                    let k = (r.uniform() * zetas.len() as f64) as usize;
                    // A little beyond both ends: clamped weights are covered too.
                    let eta = p_lo - 0.05 + (p_hi - p_lo + 0.1) * r.uniform();
                    kernel.weights(FlankCoord { eta_star: eta, tau: 0.0, zeta: zetas[k] }, k)
                })
                .collect()
        };
        let (obs, load) = (points(41, &mut rng), points(37, &mut rng));
        for &t in &teeth {
            let mut fast = faer::Mat::<f64>::zeros(50, 45);
            let mut slow = fast.clone();
            let mut partial = Vec::new();
            kernel.add_block(&obs, &load, t, &mut partial, &mut fast, (5, 3));
            kernel.add_block_portable(&obs, &load, t, &mut partial, &mut slow, (5, 3));
            for j in 0..45 {
                for i in 0..50 {
                    assert_eq!(fast[(i, j)].to_bits(), slow[(i, j)].to_bits(), "({i}, {j}) t {t}");
                }
            }
            assert!(fast[(5, 3)] != 0.0);
        }
    }
}
