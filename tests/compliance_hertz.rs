//! Tests of the local contact deformation (Eq. 10), the contact half width (Eq. 11) and the
//! Hertz pressure (Eq. 15).

mod common;

use std::f64::consts::PI;

use helical_gear_mesh::Material;
use helical_gear_mesh::compliance::hertz::{
    HertzError, LocalContact, body_deformation, compliance_sum, half_width, max_pressure,
    reduced_radius, weber_banaschek_bracket,
};

use common::rel_diff as rel;

fn cast_iron() -> Material {
    Material { youngs_modulus_pa: 110e9, poisson_ratio: 0.27, density_kg_m3: 7200.0 }
}

/// The direct (textbook) form of the bracket of Eq. 10, x = h/L.
fn bracket_direct(x: f64, nu: f64) -> f64 {
    (x + (1.0 + x * x).sqrt()).ln()
        - nu / (1.0 - nu) * x * x * ((1.0 + (1.0 / x) * (1.0 / x)).sqrt() - 1.0)
}

#[test]
fn hand_computed_steel_example() {
    // Steel on steel, E = 206 GPa, ν = 0.3; q = 2e5 N/m; ρ = 10 mm (ρ_p = ρ_g = 20 mm); h = 1 mm.
    //
    // (1 − ν²)/E = 0.91/206e9 = 4.417476e-12 1/Pa; C = 2·that = 8.834951e-12 1/Pa.
    // Eq. 11: L² = (4/π)·C·q·ρ = 1.2732395·8.834951e-12·2e5·0.01 = 1.2732395·1.766990e-8
    //         = 2.249802e-8 m²  →  L = 1.499934e-4 m (0.150 mm).
    // x = h/L = 1e-3/1.499934e-4 = 6.666960; x² = 44.44836.
    // ln(x + sqrt(1 + x²)) = ln(6.666960 + 6.741540) = ln(13.408500) = 2.595889.
    // ν/(1 − ν) = 0.3/0.7 = 0.4285714; sqrt(1 + 1/x²) = sqrt(1.0224980) = 1.0111864;
    //   x²·(sqrt(1 + 1/x²) − 1) = 44.44836·0.0111864 = 0.4972189.
    // Bracket B = 2.595889 − 0.4285714·0.4972189 = 2.595889 − 0.2130938 = 2.382795.
    // 2(1 − ν²)/(πE) = 1.82/(π·206e9) = 2.812252e-12 1/Pa; ·q = 5.624505e-7 m.
    // u_c (one body) = 5.624505e-7·2.382795 = 1.340204e-6 m (1.34 µm); both bodies 2.680408e-6 m.
    // Eq. 15: p = sqrt(q/(π·C·ρ)) = sqrt(2e5/(π·8.834951e-12·0.01)) = sqrt(7.205697e17)
    //         = 8.488637e8 Pa (849 MPa).
    let steel = Material::steel();
    let c = compliance_sum(&steel, &steel).unwrap();
    assert!(rel(c, 8.834951e-12) < 1e-6);
    let rho = reduced_radius(0.02, 0.02).unwrap();
    assert!(rel(rho, 0.01) < 1e-15);
    let q = 2e5;
    let l = half_width(q, rho, c).unwrap();
    eprintln!("L = {l:.7e} m (hand 1.499934e-4)");
    assert!(rel(l, 1.499934e-4) < 1e-6);
    let u = body_deformation(q, l, 1e-3, &steel).unwrap();
    eprintln!("u_c one body = {u:.7e} m (hand 1.340204e-6)");
    assert!(rel(u, 1.340204e-6) < 1e-6);
    let contact = LocalContact::new(&steel, &steel, 1e-3, 1e-3).unwrap();
    let d = contact.deformation(q, rho).unwrap();
    eprintln!("u_c pinion + gear = {:.7e} m (hand 2.680408e-6)", d.total);
    assert!(rel(d.total, 2.680408e-6) < 1e-6);
    assert_eq!(d.pinion, d.gear);
    assert!(rel(d.pinion, u) < 1e-14);
    let p = max_pressure(q, rho, c).unwrap();
    eprintln!("p = {p:.7e} Pa (hand 8.488637e8)");
    assert!(rel(p, 8.488637e8) < 1e-6);
    assert!(rel(contact.max_pressure(q, rho).unwrap(), p) < 1e-15);
    assert!(rel(contact.half_width(q, rho).unwrap(), l) < 1e-15);
}

#[test]
fn different_materials_sum_of_bodies() {
    let (steel, iron) = (Material::steel(), cast_iron());
    let c = compliance_sum(&steel, &iron).unwrap();
    assert!(rel(c, 0.91 / 206e9 + (1.0 - 0.27 * 0.27) / 110e9) < 1e-15);
    let contact = LocalContact::new(&steel, &iron, 1.2e-3, 0.8e-3).unwrap();
    let (q, rho) = (1.5e5, reduced_radius(0.015, 0.04).unwrap());
    assert!(rel(rho, 0.015 * 0.04 / 0.055) < 1e-15);
    let l = half_width(q, rho, c).unwrap();
    let d = contact.deformation(q, rho).unwrap();
    assert!(rel(d.pinion, body_deformation(q, l, 1.2e-3, &steel).unwrap()) < 1e-13);
    assert!(rel(d.gear, body_deformation(q, l, 0.8e-3, &iron).unwrap()) < 1e-13);
    assert_eq!(d.total, d.pinion + d.gear);
    // The softer gear deforms more.
    assert!(d.gear > d.pinion);
}

#[test]
fn reduced_radius_flat_side_and_errors() {
    assert_eq!(reduced_radius(f64::INFINITY, 0.012).unwrap(), 0.012);
    assert_eq!(reduced_radius(0.03, f64::INFINITY).unwrap(), 0.03);
    assert_eq!(reduced_radius(f64::INFINITY, f64::INFINITY), Err(HertzError::BothFlat));
    assert!(matches!(
        reduced_radius(0.0, 0.01),
        Err(HertzError::NonPositiveRadius { name: "rho_p", .. })
    ));
    assert!(matches!(
        reduced_radius(0.01, -0.02),
        Err(HertzError::NonPositiveRadius { name: "rho_g", .. })
    ));
    assert!(reduced_radius(f64::NAN, 0.01).is_err());
    let steel = Material::steel();
    let contact = LocalContact::new(&steel, &steel, 1e-3, 1e-3).unwrap();
    assert!(matches!(contact.deformation(1e5, 0.0), Err(HertzError::NonPositiveRadius { .. })));
    assert!(matches!(contact.deformation(1e5, -1.0), Err(HertzError::NonPositiveRadius { .. })));
    assert!(contact.half_width(1e5, 0.0).is_err());
    assert!(contact.max_pressure(1e5, f64::NAN).is_err());
    assert!(matches!(contact.deformation(-1.0, 0.01), Err(HertzError::InvalidLoad { .. })));
    assert!(contact.deformation(f64::NAN, 0.01).is_err());
    assert!(LocalContact::new(&steel, &steel, 0.0, 1e-3).is_err());
    let bad = Material { poisson_ratio: 0.7, ..steel };
    assert!(LocalContact::new(&steel, &bad, 1e-3, 1e-3).is_err());
    let bad = Material { youngs_modulus_pa: -1.0, ..steel };
    assert!(compliance_sum(&bad, &steel).is_err());
}

#[test]
fn deformation_vanishes_at_zero_load_with_the_right_limit() {
    let steel = Material::steel();
    let h = 1e-3;
    let contact = LocalContact::new(&steel, &steel, h, h).unwrap();
    let rho = 0.01;
    let d0 = contact.deformation(0.0, rho).unwrap();
    assert_eq!(d0.total, 0.0);
    assert_eq!(d0.d_total_dq, f64::INFINITY);
    let a = 2.0 * 0.91 / (PI * 206e9);
    let kappa = 0.3 / 0.7;
    let mut prev = f64::INFINITY;
    for q in [1e-3, 1e-6, 1e-9, 1e-12, 1e-20, 1e-100, 1e-300, 5e-324] {
        let d = contact.deformation(q, rho).unwrap();
        assert!(d.total.is_finite() && d.total >= 0.0 && d.total < prev, "q = {q}: {d:?}");
        assert!(d.d_total_dq.is_finite() && d.d_total_dq > 0.0);
        prev = d.total;
        // Asymptote for h/L → ∞: u_c ≈ a·q·(ln(2h/L) − κ/2) per body, ~ q·ln(1/√q).
        let l = contact.half_width(q, rho).unwrap();
        let asym = 2.0 * a * q * ((2.0 * h / l).ln() - kappa / 2.0);
        if q >= 1e-300 {
            assert!(rel(d.total, asym) < 1e-6, "q = {q}: {} vs {asym}", d.total);
        }
    }
    assert!(prev < 1e-320);
}

#[test]
fn deformation_is_monotone_in_load() {
    let contact = LocalContact::new(&Material::steel(), &cast_iron(), 1e-3, 1e-3).unwrap();
    let rho = 0.008;
    let mut prev = 0.0;
    for i in 0..=1000 {
        let q = 10f64.powf(-3.0 + 10.0 * i as f64 / 1000.0); // 1e-3 … 1e7 N/m
        let d = contact.deformation(q, rho).unwrap();
        assert!(d.total > prev, "not increasing at q = {q}");
        assert!(d.d_total_dq > 0.0);
        prev = d.total;
    }
}

#[test]
fn derivative_matches_central_difference() {
    let contact = LocalContact::new(&Material::steel(), &cast_iron(), 1.5e-3, 1e-3).unwrap();
    let rho = 0.012;
    let mut worst: f64 = 0.0;
    for q in [1e-2, 1.0, 1e2, 1e4, 1e5, 3e5, 1e6, 1e7, 1e8] {
        let step = 1e-5 * q;
        let up = contact.deformation(q + step, rho).unwrap().total;
        let dn = contact.deformation(q - step, rho).unwrap().total;
        let fd = (up - dn) / (2.0 * step);
        let an = contact.deformation(q, rho).unwrap().d_total_dq;
        worst = worst.max(rel(an, fd));
        assert!(rel(an, fd) < 1e-7, "q = {q}: analytic {an:e}, fd {fd:e}");
    }
    eprintln!("du_c/dq: worst relative deviation from central difference {worst:.1e}");
}

#[test]
fn stable_bracket_agrees_with_direct_formula_and_asymptotes() {
    for nu in [0.0, 0.27, 0.3, 0.5] {
        let kappa = nu / (1.0 - nu);
        // Both forms accurate for moderate x (the direct form loses about 2·log10(x) digits).
        for i in 0..=40 {
            let x = 10f64.powf(-2.0 + 4.0 * i as f64 / 40.0);
            let (s, d) = (weber_banaschek_bracket(x, nu), bracket_direct(x, nu));
            assert!((s - d).abs() < 1e-12 * s.abs().max(1.0), "x = {x}, ν = {nu}: {s} vs {d}");
        }
        // h/L ≫ 1: ln(2x) + 1/(4x²) − κ·(1/2 − 1/(8x²)) + O(x⁻⁴). The direct form fails here
        // (sqrt(1 + 1/x²) − 1 cancels completely for x > 1e8).
        for x in [1e4f64, 1e6, 1e8, 1e9, 1e12, 1e100, 1e300] {
            let asym = (2.0 * x).ln() + 0.25 / (x * x) - kappa * (0.5 - 0.125 / (x * x));
            let s = weber_banaschek_bracket(x, nu);
            assert!((s - asym).abs() < 1e-14 * asym, "x = {x}: {s} vs {asym}");
        }
        assert!(bracket_direct(1e9, 0.3).is_finite());
        // h/L ≪ 1: B ≈ (1 − κ)·x + κ·x² + O(x³).
        for x in [1e-4, 1e-8, 1e-12, 1e-200] {
            let series = (1.0 - kappa) * x + kappa * x * x;
            let s = weber_banaschek_bracket(x, nu);
            assert!((s - series).abs() <= 1e-7 * x, "x = {x}: {s} vs {series}");
        }
    }
    assert_eq!(weber_banaschek_bracket(0.0, 0.3), 0.0);
    assert_eq!(weber_banaschek_bracket(f64::INFINITY, 0.3), f64::INFINITY);
    assert!(weber_banaschek_bracket(-1.0, 0.3).is_nan());
    // The direct form is wrong at large x: it shows the cancellation the stable form avoids.
    let x = 1e9;
    let direct = bracket_direct(x, 0.3);
    let stable = weber_banaschek_bracket(x, 0.3);
    eprintln!("bracket at h/L = 1e9: stable {stable:.15}, direct {direct:.15}");
    assert!((direct - stable - 0.3 / 0.7 * 0.5).abs() < 1e-6);
}

#[test]
fn hertz_relation_between_eq_11_and_eq_15() {
    // Elliptic pressure p(s) = p_max·sqrt(1 − (s/L)²) over |s| ≤ L carries q = (π/2)·p_max·L.
    let c = compliance_sum(&Material::steel(), &cast_iron()).unwrap();
    for q in [1e-3, 1.0, 1e3, 2e5, 1e7] {
        for rho in [1e-4, 5e-3, 0.02, 1.0] {
            let l = half_width(q, rho, c).unwrap();
            let p = max_pressure(q, rho, c).unwrap();
            assert!(rel(PI / 2.0 * p * l, q) < 1e-14, "q = {q}, ρ = {rho}");
        }
    }
    assert_eq!(half_width(0.0, 0.01, c).unwrap(), 0.0);
    assert_eq!(max_pressure(0.0, 0.01, c).unwrap(), 0.0);
}
