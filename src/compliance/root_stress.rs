//! Tooth-root stress from the FE model: the stress influence of one gear at its tension-side
//! root fillets ([`RootStressGrid`], computed with the compliance from the same FE solutions)
//! and its superposition over the loaded slices of a mesh evaluation ([`SliceStress`]).
//!
//! # Where the stress is observed
//! The loaded (active, positive) flank of a tooth is pressed along its inward normal; the tooth
//! bends away from it, so the root fillet below the loaded flank is the tension side. On that
//! fillet of teeth −1, 0, +1 (counter-clockwise numbering, as the compliance) the stress is
//! observed at [`FILLET_TANGENT_ANGLES_DEG`].len() points of the transverse section, at every
//! axial node level of the FE mesh (2·layers + 1 levels over the face width). The points are
//! placed by the angle between the fillet's tangent and the tooth centre line: ISO 6336-3
//! takes the critical section where that angle is 30° (external gears); the points span
//! 20° … 50° around it and the model takes the largest stress over all of them, so the
//! location of the maximum is not assumed. A point is the exact generated fillet (the basic
//! rack's root rounding, [`crate::geometry::rack::TransverseRack::fillet_point`]), turned with
//! the helix to its axial level; it is located in the FE mesh by the inverse isoparametric map
//! and its stress recovered there ([`super::fe::stress`]).
//!
//! # What is stored: the surface stress tensor
//! The fillet is a free surface: the traction σ·N vanishes there (N the outward unit normal of
//! the helicoidal surface, N ∝ (Rot(θ + ωz)·n_t, −ω·(P × n_t)) as for the flank), so the stress
//! tensor at the surface is a plane tensor in its tangent plane. With t₁ the unit tangent of
//! the fillet curve in the transverse section and t₂ = N × t₁ (about axial) the grid stores its
//! three components
//!
//! (σ₁₁, σ₂₂, σ₁₂) = (t₁·σ·t₁, t₂·σ·t₂, t₁·σ·t₂)   (Pa per N of load),
//!
//! and the largest principal stress at the point is
//! σ₁ = (σ₁₁ + σ₂₂)/2 + √(((σ₁₁ − σ₂₂)/2)² + σ₁₂²) (the surface-normal principal stress is 0).
//! The FE field satisfies σ·N = 0 only approximately; those components are its discretisation
//! error and are left out.
//!
//! Load case j is the compliance's: a unit force along the inward normal −N at flank grid node
//! j of tooth 0 (rows tip → root, columns the axial node levels), so the values are a linear
//! function of the load: `sigma[t][(j·P + o)·3 + c]` for observation point o = f·L + l (fillet
//! point f, axial level l, L levels, P points per tooth) on tooth `teeth[t]`, component c.
//! They are stored as integer multiples of [`RootStressGrid::quantum_pa_per_n`], 10⁻⁴ of the
//! largest magnitude of the gear (far below the FE discretisation error), which keeps the
//! embedded Table 1 resource small.
//!
//! # Superposition in the mesh model ([`SliceStress`])
//! A slice i of a tooth pair carries the normal force F_i = q_i·w_i (N, line load times line
//! length) at its flank coordinates (profile coordinate p_i, ζ_k). Its consistent effect on the
//! FE model is that of the flank grid's nodal loads: along ζ the three node levels of the
//! quadratic element containing ζ_k with the element's Lagrange shape functions (the exact FE
//! response to a force at ζ_k on the element edge), along the profile the cubic Hermite weights
//! of the compliance's interpolation ([`super::interpolated`]) over the corner rows. Per model
//! the ζ weights of every slice are computed once; an evaluation accumulates, per gear and per
//! loaded tooth pair b, the load vector L_b on the flank grid (12 entries per slice), then for
//! every loaded tooth a the stress S_a = Σ_b σ(offset(a, b))ᵀ·L_b over the pairs b with
//! |offset| ≤ 1 (pinion offset a − b, gear b − a, as in the compliance), so a tooth's stress
//! includes the loads on its neighbours. The reported root stress of a gear is the largest σ₁
//! over the fillet points, the axial levels and the loaded teeth. Back-flank loads are mirrored
//! as the compliance does (ζ → b₀ − ζ, offsets reversed) and stress the back flank's fillet;
//! the compressive effect of one flank's load on the other fillet is not reported.

use serde::{Deserialize, Serialize};

use super::FlankCoord;
use super::fe::stress::{StressPoint, locate_near_surface_with, project};
use super::fe::{FeError, Material, Mesh};
use super::interpolated::Axis;
use crate::geometry::GearGeometry;

/// Angles (degrees) between the fillet tangent and the tooth centre line at which the stress is
/// observed (clamped to the fillet's range); ISO 6336-3's critical section is at 30°.
pub const FILLET_TANGENT_ANGLES_DEG: [f64; 4] = [20.0, 30.0, 40.0, 50.0];

/// Quantum of the stored values relative to the largest magnitude of a gear.
pub const QUANTUM_RELATIVE: f64 = 1e-4;

/// Stress influence of one gear at its tension-side root fillets (see the module docs).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RootStressGrid {
    /// Angle between fillet tangent and tooth centre line at each fillet point, degrees.
    pub tangent_angle_deg: Vec<f64>,
    /// Rack fillet parameter χ of each fillet point, rad.
    pub fillet_chi_rad: Vec<f64>,
    /// ζ of each axial observation level, units of m_n.
    pub levels_zeta: Vec<f64>,
    /// Tooth offsets of the observation blocks, `[-1, 0, 1]`.
    pub teeth: Vec<i32>,
    /// Profile coordinate of each load row (units of m_n, [`FlankCoord::profile`]), as the
    /// compliance grid's.
    pub load_profile: Vec<f64>,
    /// ζ of each load column (the axial node levels), units of m_n.
    pub load_zeta: Vec<f64>,
    /// η* at the start of the tip rounding (units of m_n), for [`FlankCoord::profile`].
    pub eta_star_rounding_start: f64,
    /// Tip-rounding radius in units of m_n, for [`FlankCoord::profile`].
    pub rounding_radius_mn: f64,
    /// Value of one unit of `sigma`, Pa/N.
    pub quantum_pa_per_n: f64,
    /// Surface stress components per unit inward normal load, in units of the quantum:
    /// `sigma[t][(j * points + o) * 3 + c]` (see the module docs).
    pub sigma: Vec<Vec<i64>>,
}

impl RootStressGrid {
    /// Observation points per tooth (fillet points × axial levels).
    pub fn points(&self) -> usize {
        self.tangent_angle_deg.len() * self.levels_zeta.len()
    }

    /// Load points (flank grid rows × columns).
    pub fn loads(&self) -> usize {
        self.load_profile.len() * self.load_zeta.len()
    }

    /// The stored component `c` (0: σ₁₁, 1: σ₂₂, 2: σ₁₂) at observation point `o` of tooth
    /// block `t` for a unit load at load point `j`, Pa/N.
    pub fn value(&self, t: usize, j: usize, o: usize, c: usize) -> f64 {
        self.sigma[t][(j * self.points() + o) * 3 + c] as f64 * self.quantum_pa_per_n
    }

    /// Checks shapes and values; the message names the first problem.
    pub fn validate(&self) -> Result<(), String> {
        let nf = self.tangent_angle_deg.len();
        if nf == 0 || self.fillet_chi_rad.len() != nf || self.levels_zeta.is_empty() {
            return Err("root-stress grid: no fillet points or levels".into());
        }
        if self.load_profile.len() < 2
            || self.load_zeta.len() < 3
            || self.load_zeta.len().is_multiple_of(2)
        {
            return Err(format!(
                "root-stress grid: {} load rows × {} columns, need ≥ 2 rows and an odd number \
                 ≥ 3 of columns (node levels of quadratic elements)",
                self.load_profile.len(),
                self.load_zeta.len()
            ));
        }
        if !self.load_profile.windows(2).all(|w| w[1] > w[0])
            || !self.load_zeta.windows(2).all(|w| w[1] > w[0])
        {
            return Err("root-stress grid: load coordinates not strictly increasing".into());
        }
        if !(self.quantum_pa_per_n.is_finite() && self.quantum_pa_per_n > 0.0) {
            return Err(format!(
                "root-stress grid: quantum {:.3e} Pa/N must be finite and > 0",
                self.quantum_pa_per_n
            ));
        }
        if self.teeth.len() != self.sigma.len() || !self.teeth.contains(&0) {
            return Err(
                "root-stress grid: teeth/sigma blocks inconsistent or tooth 0 missing".into()
            );
        }
        let len = self.loads() * self.points() * 3;
        if let Some(t) = self.sigma.iter().position(|b| b.len() != len) {
            return Err(format!(
                "root-stress grid: block {t} has {} values, expected {len}",
                self.sigma[t].len()
            ));
        }
        Ok(())
    }

    /// The surface stress components (Pa; (σ₁₁, σ₂₂, σ₁₂) of every observation point, point
    /// o at `3·o`) of tooth block `t` for the flank-grid load vector `loads` (N at each load
    /// point, along the inward normal). For tests and reports; the mesh model uses
    /// [`SliceStress`].
    pub fn stress(&self, t: usize, loads: &[f64]) -> Vec<f64> {
        let m = self.points() * 3;
        let mut acc = vec![0.0; m];
        for (j, &f) in loads.iter().enumerate().take(self.loads()) {
            if f != 0.0 {
                for (a, &v) in acc.iter_mut().zip(&self.sigma[t][j * m..(j + 1) * m]) {
                    *a += f * (v as f64 * self.quantum_pa_per_n);
                }
            }
        }
        acc
    }

    /// The largest principal surface stress σ₁ (Pa, [`principal`]) over the observation
    /// points of tooth block `t` for the load vector `loads` (as [`RootStressGrid::stress`]).
    pub fn max_principal(&self, t: usize, loads: &[f64]) -> f64 {
        self.stress(t, loads)
            .chunks_exact(3)
            .map(|s| principal(s[0], s[1], s[2]))
            .fold(f64::NEG_INFINITY, f64::max)
    }
}

/// Largest principal stress (Pa) of the plane tensor (σ₁₁, σ₂₂, σ₁₂) (Pa).
pub fn principal(s11: f64, s22: f64, s12: f64) -> f64 {
    let mean = 0.5 * (s11 + s22);
    let half = 0.5 * (s11 - s22);
    mean + (half * half + s12 * s12).sqrt()
}

/// A fillet point in the tooth-local transverse frame (tooth centre line along +x, the loaded
/// flank at y > 0): rack parameter χ (rad), point (m), outward unit normal, and the angle
/// between the tangent and the centre line (rad).
fn fillet_local(g: &GearGeometry, chi: f64) -> (f64, [f64; 2], [f64; 2], f64) {
    let rack = &g.rack;
    let (p, n) = rack.fillet_point(chi);
    let point = rack.generate(p, n);
    // The generating rotation of `generate` turns the rack normal into the gear normal.
    let k = p[0] * n[1] / n[0];
    let u = (k - p[1]) / rack.r;
    let (s, c) = u.sin_cos();
    let len = n[0].hypot(n[1]);
    let normal = [(c * n[0] + s * n[1]) / len, (-s * n[0] + c * n[1]) / len];
    let psi = normal[1].atan2(normal[0]);
    (chi, point, normal, (std::f64::consts::FRAC_PI_2 - psi).abs())
}

/// The fillet point whose tangent makes `angle` (rad) with the centre line, by bisection in χ
/// (the angle falls from about 90° on the root circle to the flank's at the form point); the
/// nearer end of the fillet when the angle is outside its range.
fn fillet_at_angle(g: &GearGeometry, angle: f64) -> (f64, [f64; 2], [f64; 2], f64) {
    let chi_max = g.rack.chi_max();
    let (lo, hi) = (fillet_local(g, 0.0), fillet_local(g, chi_max));
    if angle >= lo.3 {
        return lo;
    }
    if angle <= hi.3 {
        return hi;
    }
    let (mut a, mut b) = (0.0, chi_max);
    for _ in 0..60 {
        let m = 0.5 * (a + b);
        if fillet_local(g, m).3 > angle {
            a = m;
        } else {
            b = m;
        }
    }
    fillet_local(g, 0.5 * (a + b))
}

/// The stress stencils of the fillet points of one gear's FE model (see the module docs), and
/// the recorded values as the load cases are solved.
#[derive(Debug)]
pub struct FilletObserver {
    /// Stencil and surface frame (t₁, t₂) of every observation point, tooth-major.
    points: Vec<(StressPoint, [f64; 3], [f64; 3])>,
    tangent_angle_deg: Vec<f64>,
    chi: Vec<f64>,
    levels: Vec<f64>,
    teeth: Vec<i32>,
    values: Vec<Vec<f64>>,
}

impl FilletObserver {
    /// Locates the fillet points of teeth `teeth` (offsets from tooth 0) at the axial levels
    /// `level_z` (m) in `mesh` of gear `g` with `material`, for `loads` load cases. Errors: a
    /// point outside the mesh (beyond 5 % of an element in natural coordinates) or a bad
    /// element there.
    pub fn new(
        g: &GearGeometry,
        mesh: &Mesh,
        material: &Material,
        level_z: &[f64],
        teeth: &[i32],
        loads: usize,
    ) -> Result<Self, FeError> {
        let local: Vec<_> =
            FILLET_TANGENT_ANGLES_DEG.iter().map(|a| fillet_at_angle(g, a.to_radians())).collect();
        let pitch = g.angular_pitch();
        let boxes = mesh.element_boxes();
        let mut points = Vec::with_capacity(teeth.len() * local.len() * level_z.len());
        for &t in teeth {
            let th0 = pitch * f64::from(t).rem_euclid(f64::from(g.z));
            for &(_, p, n_t, _) in &local {
                let cross = p[0] * n_t[1] - p[1] * n_t[0];
                let axial = -g.twist_rate * cross;
                let norm = (1.0 + axial * axial).sqrt();
                for &z in level_z {
                    let (s, c) = (th0 + g.twist_rate * z).sin_cos();
                    let x = [c * p[0] - s * p[1], s * p[0] + c * p[1], z];
                    let nn = [(c * n_t[0] - s * n_t[1]) / norm, (s * n_t[0] + c * n_t[1]) / norm];
                    let normal = [nn[0], nn[1], axial / norm];
                    let t1 = [-(s * n_t[0] + c * n_t[1]), c * n_t[0] - s * n_t[1], 0.0];
                    let t2 = cross3(normal, t1);
                    let l2 = (t2[0] * t2[0] + t2[1] * t2[1] + t2[2] * t2[2]).sqrt();
                    let t2 = [t2[0] / l2, t2[1] / l2, t2[2] / l2];
                    let (e, xi) =
                        locate_near_surface_with(mesh, &boxes, x, 0.05).ok_or_else(|| {
                            FeError::InvalidInput(format!(
                                "root fillet point ({:.4e}, {:.4e}, {:.4e}) m of tooth {t} is \
                             outside the mesh",
                                x[0], x[1], x[2]
                            ))
                        })?;
                    let sp =
                        StressPoint::new(mesh, material, e, xi).map_err(|j| j.in_element(e))?;
                    points.push((sp, t1, t2));
                }
            }
        }
        let per_tooth = local.len() * level_z.len() * 3;
        Ok(Self {
            points,
            tangent_angle_deg: local.iter().map(|v| v.3.to_degrees()).collect(),
            chi: local.iter().map(|v| v.0).collect(),
            levels: level_z.to_vec(),
            teeth: teeth.to_vec(),
            values: vec![vec![0.0; loads * per_tooth]; teeth.len()],
        })
    }

    /// Records the surface stress of load case `case` from the displacement field `u`
    /// (`u(node, d)`: displacement of mesh node `node` in direction d, m).
    pub fn observe(&mut self, case: usize, u: impl Fn(usize, usize) -> f64) {
        let per_tooth = self.points.len() / self.teeth.len().max(1);
        for (i, (sp, t1, t2)) in self.points.iter().enumerate() {
            let s = sp.stress(&u);
            let (t, o) = (i / per_tooth, i % per_tooth);
            let base = (case * per_tooth + o) * 3;
            let v = &mut self.values[t][base..base + 3];
            v[0] = project(&s, *t1, *t1);
            v[1] = project(&s, *t2, *t2);
            v[2] = project(&s, *t1, *t2);
        }
    }

    /// The mesh nodes whose displacements [`FilletObserver::observe`] reads (each once).
    pub fn nodes(&self) -> Vec<usize> {
        let mut v: Vec<usize> = self.points.iter().flat_map(|p| p.0.nodes).collect();
        v.sort_unstable();
        v.dedup();
        v
    }

    /// The grid of the recorded values with the load grid's coordinates (profile rows, ζ
    /// columns, both units of m_n) and the mesh's normal module `mn` (m).
    pub fn finish(
        self,
        load_profile: Vec<f64>,
        load_zeta: Vec<f64>,
        eta_star_rounding_start: f64,
        rounding_radius_mn: f64,
        mn: f64,
    ) -> Result<RootStressGrid, FeError> {
        let max = self.values.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
        if !max.is_finite() {
            return Err(FeError::InvalidInput("root stress: non-finite FE stress".into()));
        }
        let quantum = if max > 0.0 { max * QUANTUM_RELATIVE } else { 1.0 };
        let grid = RootStressGrid {
            tangent_angle_deg: self.tangent_angle_deg,
            fillet_chi_rad: self.chi,
            levels_zeta: self.levels.iter().map(|z| z / mn).collect(),
            teeth: self.teeth,
            load_profile,
            load_zeta,
            eta_star_rounding_start,
            rounding_radius_mn,
            quantum_pa_per_n: quantum,
            sigma: self
                .values
                .iter()
                .map(|b| b.iter().map(|v| (v / quantum).round() as i64).collect())
                .collect(),
        };
        grid.validate().map_err(FeError::InvalidInput)?;
        Ok(grid)
    }
}

fn cross3(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

/// The ζ weights of one axial slice: the three load columns of the quadratic element that
/// contains it and their Lagrange shape functions.
type ColumnWeights = [(usize, f64); 3];

/// A [`RootStressGrid`] prepared for the slices ζ_k of one mesh model (see the module docs).
#[derive(Debug, Clone)]
pub struct SliceStress {
    teeth: Vec<i32>,
    /// Observation values per load point: 3 × points.
    m: usize,
    loads: usize,
    cols: usize,
    rows: Axis,
    col_w: Vec<ColumnWeights>,
    /// σ (Pa/N), `sigma[t][j * m + o * 3 + c]`.
    sigma: Vec<Vec<f64>>,
    eta_star_rounding_start: f64,
    rounding_radius_mn: f64,
}

impl SliceStress {
    /// Prepares `grid` for slice centres `zetas` (units of m_n); the grid must pass
    /// [`RootStressGrid::validate`].
    pub fn new(grid: &RootStressGrid, zetas: &[f64]) -> Result<Self, String> {
        grid.validate()?;
        let z = &grid.load_zeta;
        let elements = (z.len() - 1) / 2;
        let col_w = zetas
            .iter()
            .map(|&zk| {
                let zk = zk.clamp(z[0], z[z.len() - 1]);
                let e = (0..elements).find(|&e| zk <= z[2 * e + 2]).unwrap_or(elements - 1);
                let (a, b) = (z[2 * e], z[2 * e + 2]);
                let xi = (2.0 * (zk - a) / (b - a) - 1.0).clamp(-1.0, 1.0);
                [
                    (2 * e, 0.5 * xi * (xi - 1.0)),
                    (2 * e + 1, 1.0 - xi * xi),
                    (2 * e + 2, 0.5 * xi * (xi + 1.0)),
                ]
            })
            .collect();
        Ok(Self {
            teeth: grid.teeth.clone(),
            m: grid.points() * 3,
            loads: grid.loads(),
            cols: z.len(),
            rows: Axis::new(&grid.load_profile),
            col_w,
            sigma: grid
                .sigma
                .iter()
                .map(|b| b.iter().map(|&v| v as f64 * grid.quantum_pa_per_n).collect())
                .collect(),
            eta_star_rounding_start: grid.eta_star_rounding_start,
            rounding_radius_mn: grid.rounding_radius_mn,
        })
    }

    /// Adds the consistent flank-grid loads of a force `force` (N) at the profile position of
    /// `c` on axial slice `k` to `loads` (one entry per load point).
    fn add_load(&self, c: FlankCoord, k: usize, force: f64, loads: &mut [f64]) {
        let p = c.profile(self.eta_star_rounding_start, self.rounding_radius_mn);
        let rw = self.rows.weights(p);
        for (a, &wr) in rw.w.iter().enumerate().take(rw.width) {
            let row = (rw.start + a) * self.cols;
            for &(col, wc) in &self.col_w[k] {
                loads[row + col] += force * wr * wc;
            }
        }
    }

    /// Adds σ(offset)ᵀ·`loads` (Pa) to `acc` (3 × points); nothing for an offset without data.
    fn add_stress(&self, offset: i32, loads: &[f64], acc: &mut [f64]) {
        let Some(t) = self.teeth.iter().position(|&o| o == offset) else {
            return;
        };
        let m = self.m;
        for (j, &f) in loads.iter().enumerate() {
            if f != 0.0 {
                for (a, &v) in acc.iter_mut().zip(&self.sigma[t][j * m..(j + 1) * m]) {
                    *a += f * v;
                }
            }
        }
    }
}

/// One loaded slice as the root stress needs it: flank side (true: back), tooth pair, axial
/// slice index in the grid's orientation (mirrored for back flanks), flank coordinates on
/// pinion and gear, normal force (N).
#[derive(Debug, Clone, Copy)]
pub struct LoadedSlice {
    /// True on the back flanks.
    pub back: bool,
    /// Tooth pair number.
    pub pair: i64,
    /// Axial slice index (mirrored for back flanks: n_line − 1 − k).
    pub k: usize,
    /// Flank coordinates on the pinion.
    pub pinion: FlankCoord,
    /// Flank coordinates on the gear.
    pub gear: FlankCoord,
    /// Normal force q·w, N.
    pub force: f64,
}

/// Scratch memory of [`root_stress`] (grown on first use, then reused).
#[derive(Debug, Clone, Default)]
pub struct RootStressWorkspace {
    keys: Vec<(bool, i64)>,
    loads: Vec<f64>,
    acc: Vec<f64>,
    /// Root stress (pinion, gear) of each tooth pair of `keys`, Pa.
    per_pair: Vec<[f64; 2]>,
}

impl RootStressWorkspace {
    /// Scratch memory for `pairs` loaded tooth pairs of the two gears of `kernel`.
    pub fn with_capacity(kernel: &[SliceStress; 2], pairs: usize) -> Self {
        let n = kernel[0].loads.max(kernel[1].loads);
        let m = kernel[0].m.max(kernel[1].m);
        Self {
            keys: Vec::with_capacity(pairs),
            loads: Vec::with_capacity(2 * pairs * n),
            acc: Vec::with_capacity(m),
            per_pair: Vec::with_capacity(pairs),
        }
    }

    /// The root stress (pinion, gear; Pa) of the teeth of tooth pair `pair` on the driving
    /// (`back` false) or back flanks in the last [`root_stress`] call; zero for a pair that
    /// carried no load.
    pub fn pair_stress(&self, back: bool, pair: i64) -> [f64; 2] {
        self.keys.iter().position(|&k| k == (back, pair)).map_or([0.0; 2], |i| self.per_pair[i])
    }
}

/// Largest tooth pairs (flank side and pair) one evaluation keeps apart for the root stress.
const MAX_PAIRS: usize = 8;

/// The root stress (Pa) of pinion and gear for the loaded slices `slices` (see the module
/// docs): the largest principal surface stress over the fillet points, axial levels and
/// loaded teeth, tension positive; (0, 0) without load.
pub fn root_stress(
    kernel: &[SliceStress; 2],
    slices: impl Iterator<Item = LoadedSlice> + Clone,
    ws: &mut RootStressWorkspace,
) -> (f64, f64) {
    ws.keys.clear();
    ws.per_pair.clear();
    for s in slices.clone() {
        let key = (s.back, s.pair);
        if s.force > 0.0 && !ws.keys.contains(&key) && ws.keys.len() < MAX_PAIRS {
            ws.keys.push(key);
        }
    }
    let np = ws.keys.len();
    if np == 0 {
        return (0.0, 0.0);
    }
    ws.per_pair.resize(np, [0.0; 2]);
    let n = kernel[0].loads.max(kernel[1].loads);
    ws.loads.clear();
    ws.loads.resize(2 * np * n, 0.0);
    for s in slices {
        let Some(b) = ws.keys.iter().position(|&k| k == (s.back, s.pair)) else {
            continue;
        };
        if s.force > 0.0 {
            for (g, c) in [(0, s.pinion), (1, s.gear)] {
                let at = (g * np + b) * n;
                kernel[g].add_load(c, s.k, s.force, &mut ws.loads[at..at + kernel[g].loads]);
            }
        }
    }
    let mut out = [0.0f64; 2];
    for (g, sk) in kernel.iter().enumerate() {
        let sign = if g == 0 { 1 } else { -1 };
        for a in 0..np {
            ws.acc.clear();
            ws.acc.resize(sk.m, 0.0);
            let (back_a, pair_a) = ws.keys[a];
            for b in 0..np {
                let (back_b, pair_b) = ws.keys[b];
                if back_a != back_b || (pair_a - pair_b).abs() > 1 {
                    continue;
                }
                let mirror = if back_a { -1 } else { 1 };
                let offset = sign * mirror * (pair_a - pair_b) as i32;
                let at = (g * np + b) * n;
                sk.add_stress(offset, &ws.loads[at..at + sk.loads], &mut ws.acc);
            }
            let tooth =
                ws.acc.chunks_exact(3).map(|s| principal(s[0], s[1], s[2])).fold(0.0, f64::max);
            ws.per_pair[a][g] = tooth;
            out[g] = out[g].max(tooth);
        }
    }
    (out[0], out[1])
}
