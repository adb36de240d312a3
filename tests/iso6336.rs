//! ISO 6336-3:2006 method B (`iso6336`): agreement with a published rating, the limits of the
//! helix angle factor, the critical section against the fillet the crate's own geometry
//! generates, linearity in the torque, and clear errors for what the method cannot rate.
//!
//! The published rating is the KISSsoft calculation report (Release 03/2017, "Calculation
//! method ISO 6336:2006 Method B") of the NREL 5 MW reference gearbox published with the
//! open-source `Drivetrain` model of G. F. dos Santos Rebouças (github.com/gfsReboucas/Drivetrain,
//! `@NREL_5MW/stage_03.rtf`: the helical parallel stage; `stage_02.rtf`: the spur sun–planet
//! mesh of the second planetary stage). Both use the ISO 53 profile A rack (h_fP = 1.25·m_n,
//! ρ_fP = 0.38·m_n, h_aP = 1.0·m_n, no protuberance) and report Y_F, Y_S and Y_β with the
//! intermediate s_Fn, ρ_F, h_F, α_Fen and (stage 3) d_en, q_s and σ_F0 of method B, "calculated
//! with profile shift x" (the nominal one, as here). The tip alteration k·m_n of the reports is
//! entered as the addendum, so that the tip diameters are the printed ones.

use helical_gear_mesh::iso6336::{IsoRootStress, nominal_root_stress};
use helical_gear_mesh::{GearPair, PairGeometry};

/// A pair with the ISO 53 profile A rack and no modifications (no relief, sharp tip, no
/// backlash).
#[allow(clippy::too_many_arguments)]
fn profile_a_pair(
    z: (u32, u32),
    mn: f64,
    beta_deg: f64,
    b: f64,
    x: (f64, f64),
    tip_alteration_m: f64,
    bore: f64,
) -> GearPair {
    GearPair {
        z_p: z.0,
        z_g: z.1,
        normal_module_m: mn,
        pressure_angle_rad: 20f64.to_radians(),
        helix_angle_rad: beta_deg.to_radians(),
        face_width_m: b,
        profile_shift_p: x.0,
        profile_shift_g: x.1,
        addendum_mn: 1.0 + tip_alteration_m / mn,
        dedendum_mn: 1.25,
        rack_fillet_radius_mn: 0.38,
        tip_relief_depth_mn: 0.0,
        tip_relief_height_mn: 0.0,
        tip_rounding_radius_mn: 0.0,
        normal_backlash_mn: 0.0,
        bore_diameter_m: bore,
        ..GearPair::paper_table1()
    }
}

fn rate(p: &GearPair, torque: f64) -> IsoRootStress {
    let g = PairGeometry::new(p).unwrap();
    nominal_root_stress(p, &g, torque).unwrap()
}

/// `|got − want| <= tol`, with a message naming the quantity.
fn near(what: &str, got: f64, want: f64, tol: f64) {
    assert!((got - want).abs() <= tol, "{what}: {got} vs published {want} (tolerance {tol})");
}

/// KISSsoft stage 3 (helical, z = 24/95, m_n = 14 mm, β = 10°, b = 360 mm, x = 0.48/0.6691,
/// k·m_n = −0.938 mm, T₁ = 40 953 N·m).
///
/// Tolerances: half a unit of the printed last digit where our value must reproduce the print
/// (s_Fn, ρ_F, q_s, Y_F, Y_β, ε_α, F_t), widened by the rounding of the printed inputs
/// (x to 4 decimals, k·m_n to 1 µm). The bending moment arm and the load angle differ more: the
/// report's h_F and α_Fen are 0.19 % and 0.015° off the closed form with the nominal x and the
/// printed d_en, which this test reproduces to 6 digits; a tooth thickness with the report's
/// manufacturing allowances in γ_e moves them by that order, so h_F is held to 0.3 %, α_Fen to
/// 0.02°, and Y_S and σ_F0 (which depend on h_F through L = s_Fn/h_F and Y_F) to 0.3 %.
#[test]
fn kisssoft_helical_stage_agrees_with_published_method_b_factors() {
    let mn = 14e-3;
    let p = profile_a_pair((24, 95), mn, 10.0, 0.36, (0.48, 0.6691), -0.938e-3, 0.1791);
    let geo = PairGeometry::new(&p).unwrap();
    near("d_a1 (mm)", 2e3 * geo.pinion.ra, 380.747, 0.001);
    near("d_a2 (mm)", 2e3 * geo.gear.ra, 1395.376, 0.001);
    near("eps_alpha", geo.eps_alpha, 1.463, 0.0005);
    near("eps_beta", geo.eps_beta, 1.421, 0.0005);
    let r = nominal_root_stress(&p, &geo, 40953.0).unwrap();
    near("F_t (N)", r.tangential_force_n, 240064.4, 1.0);
    for (g, gi, y_f, y_s, s_fn, rho_f, h_f, alpha_fen, q_s, sigma) in [
        (&r.pinion, &geo.pinion, 1.18, 2.28, 31.18, 5.95, 14.06, 23.89, 2.620, 117.92),
        (&r.gear, &geo.gear, 1.24, 2.35, 32.75, 5.39, 16.11, 22.20, 3.036, 127.69),
    ] {
        let z = gi.z;
        near(&format!("Y_F (z = {z})"), g.y_f, y_f, 0.005);
        near(&format!("Y_S (z = {z})"), g.y_s, y_s, 0.003 * y_s);
        near(&format!("Y_beta (z = {z})"), g.y_beta, 0.917, 0.0005);
        near(&format!("Y_B (z = {z})"), g.y_b, 1.0, 0.0);
        near(&format!("Y_DT (z = {z})"), g.y_dt, 1.0, 0.0);
        near(&format!("s_Fn (mm, z = {z})"), 1e3 * g.s_fn_m, s_fn, 0.006);
        near(&format!("rho_F (mm, z = {z})"), 1e3 * g.rho_f_m, rho_f, 0.006);
        near(&format!("q_s (z = {z})"), g.s_fn_m / (2.0 * g.rho_f_m), q_s, 0.0006);
        near(&format!("h_F (mm, z = {z})"), 1e3 * g.h_fe_m, h_f, 0.003 * h_f);
        near(&format!("alpha_Fen (deg, z = {z})"), g.alpha_fen_rad.to_degrees(), alpha_fen, 0.02);
        near(&format!("sigma_F0 (MPa, z = {z})"), 1e-6 * g.sigma_f0_pa, sigma, 0.003 * sigma);
    }
    near("z_n1", r.pinion.z_n, 25.037, 0.0005);
    near("z_n2", r.gear.z_n, 99.104, 0.0005);
}

/// KISSsoft stage 2, sun–planet (spur, z = 18/36, m_n = 21 mm, b = 550 mm, x = 0.389/0.5039,
/// k·m_n = −1.75 mm): the spur case, where the virtual gear is the gear itself (z_n = z) and
/// Y_β = 1. Tolerances as for stage 3 (the planet's printed α_Fen differs by 0.006°, its h_F
/// by 0.05 %).
#[test]
fn kisssoft_spur_stage_agrees_with_published_method_b_factors() {
    let p = profile_a_pair((18, 36), 21e-3, 0.0, 0.55, (0.389, 0.5039), -1.75e-3, 0.19432);
    let geo = PairGeometry::new(&p).unwrap();
    near("eps_alpha", geo.eps_alpha, 1.370, 0.0005);
    let r = nominal_root_stress(&p, &geo, 1.0).unwrap();
    for (g, z, y_f, y_s, s_fn, rho_f, h_f, alpha_fen) in [
        (&r.pinion, 18.0, 1.47, 2.04, 44.78, 9.52, 24.33, 25.74),
        (&r.gear, 36.0, 1.38, 2.18, 47.70, 8.69, 25.73, 24.68),
    ] {
        near(&format!("z_n (z = {z})"), g.z_n, z, 1e-12);
        near(&format!("Y_F (z = {z})"), g.y_f, y_f, 0.005);
        near(&format!("Y_S (z = {z})"), g.y_s, y_s, 0.003 * y_s);
        near(&format!("Y_beta (z = {z})"), g.y_beta, 1.0, 0.0);
        near(&format!("s_Fn (mm, z = {z})"), 1e3 * g.s_fn_m, s_fn, 0.006);
        near(&format!("rho_F (mm, z = {z})"), 1e3 * g.rho_f_m, rho_f, 0.006);
        near(&format!("h_F (mm, z = {z})"), 1e3 * g.h_fe_m, h_f, 0.003 * h_f);
        near(&format!("alpha_Fen (deg, z = {z})"), g.alpha_fen_rad.to_degrees(), alpha_fen, 0.02);
    }
}

/// Y_β (R19): exactly 1 for spur gears; 1 − β/120° once ε_β ≥ 1; β capped at 30°, so
/// Y_β = 0.75 for every β ≥ 30° with ε_β ≥ 1 (the smallest value the factor takes).
#[test]
fn y_beta_is_one_at_zero_helix_and_capped_at_overlap_one_and_thirty_degrees() {
    let table1 = GearPair::paper_table1();
    let spur = GearPair { helix_angle_rad: 0.0, ..table1.clone() };
    let r = rate(&spur, 100.0);
    assert_eq!((r.pinion.y_beta, r.gear.y_beta), (1.0, 1.0));

    // Table 1: ε_β = 15·sin 10°/(3π) = 0.276 < 1, Y_β = 1 − ε_β·10/120.
    let geo = PairGeometry::new(&table1).unwrap();
    let r = nominal_root_stress(&table1, &geo, 100.0).unwrap();
    near("Y_beta (Table 1)", r.pinion.y_beta, 1.0 - geo.eps_beta * 10.0 / 120.0, 1e-15);

    // A wide face: ε_β > 1 is capped at 1.
    let wide = GearPair { face_width_m: 0.06, ..table1.clone() };
    let geo = PairGeometry::new(&wide).unwrap();
    assert!(geo.eps_beta > 1.0);
    near("Y_beta (eps_beta > 1)", rate(&wide, 100.0).pinion.y_beta, 1.0 - 10.0 / 120.0, 1e-15);

    // β ≥ 30°: capped at 30°, Y_β = 0.75.
    for beta_deg in [30.0, 35.0, 40.0] {
        let steep = GearPair { helix_angle_rad: f64::to_radians(beta_deg), ..wide.clone() };
        let r = rate(&steep, 100.0);
        near(&format!("Y_beta (beta = {beta_deg}°)"), r.gear.y_beta, 0.75, 1e-12);
    }
}

/// The critical section of R14/R15 against the crate's own fillet: `geometry::gear` generates
/// the root fillet of a spur gear (there the virtual gear is the gear) by the rack's fillet
/// circle ([`helical_gear_mesh::geometry::rack::TransverseRack::generate`], the points of the
/// outline); bisection finds the point whose tangent makes 30° with the tooth centre line, and
/// there the chord 2·y and the radius of curvature must be ISO's s_Fn and ρ_F. The fillet is
/// evaluated exactly (no outline polygon), so the tolerance is set by the bisection (1e-14 rad
/// in the fillet parameter) and the central differences of the tangent (step 1e-5 rad) and of
/// the curvature (steps 1e-3 and 5e-4 rad, Richardson-extrapolated, error ~1e-9 relative):
/// 1e-9·m_n for s_Fn and 1e-7 relative for ρ_F, far below the 1e-3 an outline of a few hundred
/// points per segment would resolve.
#[test]
fn s_fn_and_rho_f_match_the_generated_fillet_at_the_30_degree_tangent() {
    let base =
        GearPair { normal_backlash_mn: 0.0, helix_angle_rad: 0.0, ..GearPair::paper_table1() };
    let cases = [
        base.clone(),
        GearPair { z_p: 18, profile_shift_p: 0.4, profile_shift_g: -0.2, ..base.clone() },
        GearPair { rack_fillet_radius_mn: 0.2, dedendum_mn: 1.4, addendum_mn: 1.0, ..base.clone() },
    ];
    for p in cases {
        let geo = PairGeometry::new(&p).unwrap();
        let r = nominal_root_stress(&p, &geo, 100.0).unwrap();
        for (gi, iso) in [(&geo.pinion, &r.pinion), (&geo.gear, &r.gear)] {
            let rack = gi.rack;
            let at = |chi: f64| {
                let (pt, n) = rack.fillet_point(chi);
                rack.generate(pt, n)
            };
            let h = 1e-5;
            let deriv = |chi: f64| {
                let (a, b) = (at(chi - h), at(chi + h));
                [(b[0] - a[0]) / (2.0 * h), (b[1] - a[1]) / (2.0 * h)]
            };
            // Angle of the tangent against the centre line (the +x axis), rad.
            let angle = |chi: f64| {
                let d = deriv(chi);
                d[1].abs().atan2(d[0].abs())
            };
            let target = 30f64.to_radians();
            let (mut lo, mut hi) = (2.0 * h, rack.chi_max() - 2.0 * h);
            assert!(
                (angle(lo) - target) * (angle(hi) - target) < 0.0,
                "no 30° tangent on the fillet of z = {}",
                gi.z
            );
            for _ in 0..200 {
                let mid = 0.5 * (lo + hi);
                if (angle(mid) - target) * (angle(lo) - target) > 0.0 {
                    lo = mid;
                } else {
                    hi = mid;
                }
                if hi - lo < 1e-14 {
                    break;
                }
            }
            let chi = 0.5 * (lo + hi);
            let s_fn = 2.0 * at(chi)[1];
            // Radius of curvature by central differences of step k, Richardson-extrapolated
            // from k and k/2 (error O(k⁴)).
            let radius = |k: f64| {
                let (a, c, b) = (at(chi - k), at(chi), at(chi + k));
                let d1 = [(b[0] - a[0]) / (2.0 * k), (b[1] - a[1]) / (2.0 * k)];
                let d2 =
                    [(a[0] - 2.0 * c[0] + b[0]) / (k * k), (a[1] - 2.0 * c[1] + b[1]) / (k * k)];
                (d1[0] * d1[0] + d1[1] * d1[1]).powf(1.5) / (d1[0] * d2[1] - d1[1] * d2[0]).abs()
            };
            let rho = (4.0 * radius(5e-4) - radius(1e-3)) / 3.0;
            let mn = p.normal_module_m;
            assert!(
                (s_fn - iso.s_fn_m).abs() <= 1e-9 * mn,
                "s_Fn of z = {}: fillet {s_fn:e} m, ISO {:e} m",
                gi.z,
                iso.s_fn_m
            );
            assert!(
                (rho - iso.rho_f_m).abs() <= 1e-7 * iso.rho_f_m,
                "rho_F of z = {}: fillet {rho:e} m, ISO {:e} m",
                gi.z,
                iso.rho_f_m
            );
        }
    }
}

/// σ_F0 (R2) is proportional to |T_p| (F_t = 2|T_p|/d₁; every factor is geometry), and the
/// factors do not depend on the torque; a negative torque gives the same rating.
#[test]
fn sigma_f0_is_linear_in_the_torque_and_even_in_its_sign() {
    let p = GearPair::paper_table1();
    let geo = PairGeometry::new(&p).unwrap();
    let base = nominal_root_stress(&p, &geo, 100.0).unwrap();
    near("F_t (N)", base.tangential_force_n, 100.0 / geo.pinion.r, 1e-9);
    for t in [1e-3, 1.0, 37.5, 100.0, 2500.0, 1e6] {
        let r = nominal_root_stress(&p, &geo, t).unwrap();
        for (a, b) in [(&r.pinion, &base.pinion), (&r.gear, &base.gear)] {
            let want = b.sigma_f0_pa * t / 100.0;
            assert!((a.sigma_f0_pa - want).abs() <= 1e-14 * want, "sigma_F0 at {t} N·m");
            assert_eq!((a.y_f, a.y_s, a.s_fn_m, a.h_fe_m), (b.y_f, b.y_s, b.s_fn_m, b.h_fe_m));
        }
        assert_eq!(nominal_root_stress(&p, &geo, -t).unwrap(), r);
    }
    let zero = nominal_root_stress(&p, &geo, 0.0).unwrap();
    assert_eq!((zero.pinion.sigma_f0_pa, zero.gear.sigma_f0_pa), (0.0, 0.0));
}

/// Y_B (R20): 1 for a solid gear (Table 1: s_R/h_t ≈ 5), 1.6·ln(2.242·h_t/s_R) for a rim
/// between 0.5 and 1.2 tooth depths, continuous at 1.2 to within the standard's rounding
/// (1.6·ln(2.242/1.2) = 0.99996), and a rim of 0.5 tooth depths or less an error naming the
/// bore.
#[test]
fn y_b_is_one_for_solid_gears_and_follows_the_rim_formula_for_thin_rims() {
    let p = GearPair::paper_table1();
    let r = rate(&p, 100.0);
    assert_eq!((r.pinion.y_b, r.gear.y_b), (1.0, 1.0));
    let geo = PairGeometry::new(&p).unwrap();
    let h_t = geo.pinion.ra - geo.pinion.rf;
    for ratio in [1.19, 0.9, 0.6] {
        let bore = 2.0 * (geo.pinion.rf - ratio * h_t);
        let q = GearPair { bore_diameter_m: bore, ..p.clone() };
        let r = rate(&q, 100.0);
        near(&format!("Y_B at s_R/h_t = {ratio}"), r.pinion.y_b, 1.6 * (2.242 / ratio).ln(), 1e-9);
        assert_eq!(r.gear.y_b, 1.0, "the gear's rim is thicker");
    }
    // s_R/h_t = 0.45: allowed by the geometry (rim ≥ m_n), outside ISO 6336-3.
    let q = GearPair { bore_diameter_m: 2.0 * (geo.pinion.rf - 0.45 * h_t), ..p.clone() };
    let geo_q = PairGeometry::new(&q).unwrap();
    let e = nominal_root_stress(&q, &geo_q, 100.0).unwrap_err();
    assert_eq!(e.name, "bore_diameter_m", "{e}");
    assert!(e.allowed.contains("0.5·h_t"), "{e}");
}

/// What method B cannot rate is a clear error naming the key to change, never a NaN: a
/// non-finite torque, a virtual contact ratio below 1 (short teeth on a wide helical face,
/// ε_α + ε_β ≥ 1 but ε_αn < 1).
#[test]
fn bad_input_is_a_clear_error_never_nan() {
    let p = GearPair::paper_table1();
    let geo = PairGeometry::new(&p).unwrap();
    for t in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let e = nominal_root_stress(&p, &geo, t).unwrap_err();
        assert_eq!(e.name, "torque_nm", "{e}");
    }
    let short = GearPair { addendum_mn: 0.5, face_width_m: 0.06, ..p.clone() };
    let geo = PairGeometry::new(&short).unwrap();
    assert!(geo.eps_alpha < 1.0 && geo.eps_alpha + geo.eps_beta >= 1.0);
    let e = nominal_root_stress(&short, &geo, 100.0).unwrap_err();
    assert_eq!(e.name, "addendum_mn", "{e}");
    assert!(e.to_string().contains("ε_αn"), "{e}");
    assert!(e.to_string().len() < 400, "short message: {e}");
}
