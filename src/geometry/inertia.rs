//! Mass moment of inertia of a gear body about its axis from its transverse outline.
//!
//! The body is the toothed disc of face width b between the bore and the teeth (teeth and web
//! down to the bore, no hub): J = ρ·b·(I_outline − π·r_bore⁴/2), with I_outline the polar second
//! moment of area of the closed outline about the axis (Green's theorem on the polygon).

use super::gear::GearGeometry;

/// Polar second moment of area ∫(x² + y²) dA of a closed counter-clockwise polygon about the
/// origin, m⁴.
pub fn polygon_polar_moment(pts: &[[f64; 2]]) -> f64 {
    let n = pts.len();
    let mut sum = 0.0;
    for i in 0..n {
        let [x0, y0] = pts[i];
        let [x1, y1] = pts[(i + 1) % n];
        let cross = x0 * y1 - x1 * y0;
        sum += cross * (x0 * x0 + x0 * x1 + x1 * x1 + y0 * y0 + y0 * y1 + y1 * y1);
    }
    sum / 12.0
}

/// Area of a closed counter-clockwise polygon, m².
pub fn polygon_area(pts: &[[f64; 2]]) -> f64 {
    let n = pts.len();
    let mut sum = 0.0;
    for i in 0..n {
        let [x0, y0] = pts[i];
        let [x1, y1] = pts[(i + 1) % n];
        sum += x0 * y1 - x1 * y0;
    }
    sum / 2.0
}

/// Inertia of the toothed body of `gear` (face width `b` m, bore radius `r_bore` m, density
/// `rho` kg/m³) about its axis, kg·m².
pub fn gear_body_inertia(gear: &GearGeometry, b: f64, r_bore: f64, rho: f64) -> f64 {
    let outline = gear.outline(120);
    let i_outline = polygon_polar_moment(&outline);
    let i_bore = std::f64::consts::PI * r_bore.powi(4) / 2.0;
    rho * b * (i_outline - i_bore)
}
