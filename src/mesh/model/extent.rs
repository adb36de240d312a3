//! The loaded axial extent of the contact lines, resolved within the slices.
//!
//! Eq. 14 damps in proportion to Σ(ζ_e − ζ_b), the axial extent of the loaded parts of the
//! contact lines (units of m_n), and the loaded contact length is its multiple m_n/cos θ.
//! Counting loaded slices puts every end of a loaded run on a slice boundary: an error of up
//! to Δζ/2 per end, first order in the slice width, and a staircase in the state. Here each
//! end is placed where the function
//!
//! ```text
//! σ(ζ) = d(ζ) − Σ_j C(ζ, ζ_j)·w_j·q_j          (m)
//! ```
//!
//! changes sign: the required approach less the global deformation of the loads. σ is smooth
//! along a line (the approach and the global kernel are), σ_i = u_c(q_i) − g_i on a loaded
//! slice (g_i = 0 there within the solver's tolerance, [`crate::load`], so σ_i ≈ u_c(q_i) > 0)
//! and σ_n = −g_n < 0 on an open one. With
//! σ_i at a run's last loaded slice (centre ζ_i) and σ_n at the next slice along the line, the
//! loaded part reaches
//!
//! ```text
//! x = Δζ·σ_i/(σ_i − σ_n)      clamped to [0, Δζ]
//! ```
//!
//! beyond ζ_i (the count takes Δζ/2; a σ_i ≤ 0, a load within the tolerance of zero, ends the
//! run at ζ_i): exact for a linear σ, so the extent, the damping torques,
//! their wrench and the contact length converge at second order in the slice width, and they
//! are continuous in the state (a newly loaded slice adds from zero) except where a newly
//! loaded slice is the last of its line at the face, whose half towards the face counts at
//! once (half the jump of a counted slice, once per line, not at every slice). σ_n comes from
//!
//! * the next slice a candidate of the problem (positive rigid overlap) left unloaded:
//!   σ_n = −g_n;
//! * the next slice outside the problem (rigid overlap d_n ≤ 0; its global deformation is not
//!   computed): the deformation taken as the loaded slice's, σ_n = d_n − (d_i − σ_i), so
//!   x = Δζ·σ_i/(d_i − d_n) follows the fall of the rigid approach there (the tip rounding, a
//!   relief);
//! * no contact point there: the count's Δζ/2. A run that reaches the face ends there exactly
//!   (the slices tile the face width).
//!
//! Without the local term σ_i = 0 on loaded slices; the solver's scale of the load,
//! c_i·q_i = C_ii·w_i·q_i (the approach that load closes alone, m), takes its place.
//!
//! [`resolve`] returns each loaded slice's extent to either side of its centre; with a list of
//! ends it also records, for each end that fell inside its bounds, what the exact Jacobian
//! needs to differentiate x ([`End::rate`]).

use super::Slice;

/// Where the σ beyond an end of a loaded run came from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Beyond {
    /// Slice `n` of the problem, unloaded: σ_n = −g_n.
    Candidate(usize),
    /// A slice outside the problem, of rigid approach d_n: σ_n = d_n − (d_i − σ_i).
    Outside,
}

/// One end of a loaded run inside its bounds: x = Δζ·σ_i/(σ_i − σ_n) with 0 < x < Δζ.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct End {
    /// The run's last loaded slice i.
    pub slice: usize,
    /// The end's direction along the line: 0 towards slice k − 1, 1 towards k + 1.
    pub toward: usize,
    /// σ_i, m.
    pub sigma: f64,
    /// σ_n, m.
    pub sigma_beyond: f64,
    /// Its source.
    pub beyond: Beyond,
}

impl End {
    /// ∂x (units of m_n per unit of the differentiation variable) from ∂σ_i, ∂σ_n for a
    /// [`Beyond::Candidate`], or ∂σ_i, ∂d_i and ∂d_n for a [`Beyond::Outside`]
    /// (`d_sigma_beyond` then holds ∂d_i − ∂d_n), slice width `dzeta`.
    pub fn rate(&self, dzeta: f64, d_sigma: f64, d_sigma_beyond: f64) -> f64 {
        let (si, sn) = (self.sigma, self.sigma_beyond);
        let den = si - sn;
        match self.beyond {
            // x = Δζ·σ_i/(σ_i − σ_n).
            Beyond::Candidate(_) => dzeta * (si * d_sigma_beyond - sn * d_sigma) / (den * den),
            // x = Δζ·σ_i/(d_i − d_n), d_i − d_n = σ_i − σ_n.
            Beyond::Outside => dzeta * (d_sigma * den - si * d_sigma_beyond) / (den * den),
        }
    }
}

/// The loaded extent of every slice to either side of its centre (units of m_n, [0, Δζ]
/// each; both zero on unloaded slices) into `widths`, from the loads `q`, gaps `gap`, rigid
/// approaches `approach` (m), σ of the loaded slices `sigma` (m) and the slice width `dzeta`
/// of `n_line` slices per line; `cos_theta` turns the neighbours' overlaps into approaches.
/// Ends inside their bounds are pushed to `ends` when given (module docs).
#[allow(clippy::too_many_arguments)]
pub(crate) fn resolve(
    slices: &[Slice],
    q: &[f64],
    gap: &[f64],
    approach: &[f64],
    sigma: impl Fn(usize) -> f64,
    (dzeta, n_line, cos_theta): (f64, usize, f64),
    widths: &mut Vec<[f64; 2]>,
    mut ends: Option<&mut Vec<End>>,
) {
    widths.clear();
    let half = 0.5 * dzeta;
    for (i, s) in slices.iter().enumerate() {
        if q[i] <= 0.0 {
            widths.push([0.0, 0.0]);
            continue;
        }
        // σ_i only where the slice ends a run (the local term costs a logarithm).
        let mut si = f64::NAN;
        let mut w = [half, half];
        for (dir, wd) in w.iter_mut().enumerate() {
            let (face_end, j) = if dir == 0 {
                (s.k == 0, i.checked_sub(1))
            } else {
                (s.k + 1 == n_line, Some(i + 1))
            };
            if face_end {
                continue;
            }
            // The same line's next slice, if it is in the problem (slices are ordered by
            // side, pair and slice index).
            let next = j.filter(|&j| {
                slices.get(j).is_some_and(|n| {
                    n.contact.pair == s.contact.pair
                        && n.contact.side == s.contact.side
                        && if dir == 0 { n.k + 1 == s.k } else { n.k == s.k + 1 }
                })
            });
            if next.is_some_and(|j| q[j] > 0.0) {
                continue;
            }
            if si.is_nan() {
                si = sigma(i);
            }
            let (sn, beyond) = match next {
                Some(j) => (-gap[j], Beyond::Candidate(j)),
                None => {
                    let dn = s.nb[dir] * cos_theta;
                    if !dn.is_finite() {
                        continue;
                    }
                    (dn - (approach[i] - si), Beyond::Outside)
                }
            };
            // A vanishing σ_i ends the run at the centre, a σ_n ≥ 0 beyond the next centre.
            let x = if si.is_nan() || si <= 0.0 {
                0.0
            } else if sn.is_nan() || sn >= 0.0 {
                dzeta
            } else {
                dzeta * si / (si - sn)
            };
            if x > 0.0 && x < dzeta {
                *wd = x;
                if let Some(e) = ends.as_deref_mut() {
                    e.push(End { slice: i, toward: dir, sigma: si, sigma_beyond: sn, beyond });
                }
            } else {
                *wd = x.clamp(0.0, dzeta);
            }
        }
        widths.push(w);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rates_are_the_derivatives_of_the_end() {
        let dz = 0.1;
        let x_c = |si: f64, sn: f64| dz * si / (si - sn);
        let x_o = |si: f64, di: f64, dn: f64| dz * si / (di - dn);
        let h = 1e-11;
        let e = End {
            slice: 0,
            toward: 1,
            sigma: 2e-6,
            sigma_beyond: -3e-6,
            beyond: Beyond::Candidate(1),
        };
        let (dsi, dsn) = (0.7, -1.3);
        let fd = (x_c(2e-6 + h * dsi, -3e-6 + h * dsn) - x_c(2e-6 - h * dsi, -3e-6 - h * dsn))
            / (2.0 * h);
        assert!((e.rate(dz, dsi, dsn) - fd).abs() <= 1e-6 * fd.abs());
        // Outside: σ_n = d_n − d_i + σ_i with d_i = 5e-6, d_n = −1e-6.
        let (di, dn) = (5e-6, -1e-6);
        let o = End {
            slice: 0,
            toward: 1,
            sigma: 2e-6,
            sigma_beyond: dn - di + 2e-6,
            beyond: Beyond::Outside,
        };
        let (ddi, ddn) = (0.4, 2.1);
        let fd = (x_o(2e-6 + h * dsi, di + h * ddi, dn + h * ddn)
            - x_o(2e-6 - h * dsi, di - h * ddi, dn - h * ddn))
            / (2.0 * h);
        assert!((o.rate(dz, dsi, ddi - ddn) - fd).abs() <= 1e-6 * fd.abs());
    }
}
