//! FE influence data of one gear (Vedmar's global compliance α*, paper §4.1) on the structured
//! flank grid of the whole-gear mesh ([`super::fe::gear_mesh`]).
//!
//! # Load cases and observations
//! The gear is meshed whole (all teeth, web to the bore) and fixed at the bore; K is factorised
//! once. Load case j is a unit force along the inward 3D unit normal −N(x_j) (pressing into the
//! tooth) at flank grid node x_j of tooth 0, all cases solved as blocks of right-hand sides.
//! The global compliance is
//!
//! α*(i, j) = −N(x_i) · u_j(x_i − h·N(x_i))   (m/N),
//!
//! the displacement of the point at depth h beneath observation node x_i (along the inward
//! normal), projected on the inward normal, for observation nodes on teeth −1, 0, +1 (the
//! gear's counter-clockwise numbering). N is the outward unit normal of the helicoidal flank,
//! N ∝ (Rot(θ + ωz)·n_t, −ω·(P × n_t)) with n_t the transverse normal, P the tooth-local
//! transverse point and ω the twist rate, so N has the axial component of the helix.
//!
//! Where the inward normal leaves the gear through an end face (at the columns ζ = 0 and
//! ζ = b₀ it has an axial component of magnitude sin β_b), the point at depth h is taken on
//! that end face: its axial coordinate is clamped to [0, b] (a shift of at most h·sin β_b).
//!
//! # Why interpolation at depth h
//! The point at depth h is found in its element by the inverse isoparametric map (Newton) and
//! u is interpolated with the hex20 shape functions. A node layer at depth h is impossible on
//! the tip rounding: its radius ρ_r (0.05·m_n for Table 1) is smaller than h, so the inward
//! offset curve folds over itself there, and on the fillet-side of the flank it would tie the
//! mesh to one h. Interpolation keeps h a free parameter and is exact to the element's order.
//!
//! # Choice of h
//! Default h = 0.2·m_n. By Saint-Venant the FE point load gives the right displacement at depth
//! h only if h is several Hertzian half-widths (≈ 0.1 mm at the Table 1 load, so h = 0.6 mm ≈ 6
//! half-widths), yet h must stay inside the tooth where it is thinnest: the point beneath a
//! node on the tip rounding lies about h − ρ_r beyond the rounding centre, well inside the tip
//! land (half thickness ≈ 0.3·m_n or more). The local part (Weber–Banaschek,
//! [`super::hertz`]) must use the same h.
//!
//! # Loads between the nodes ([`axial_gauss_resample`])
//! A unit force at a flank point between the nodes acts on the FE model through its
//! consistent nodal forces N_k (the element's shape functions at that point), so its influence
//! is Σ_k N_k·α*(·, k). Along ζ the grid columns are the node levels of quadratic elements
//! (corner, mid-side, corner, …). Forces at nodes are the worst-represented loads of the
//! model: with an element (2.5 mm axially for Table 1 at the default density) much longer than
//! h, the point at depth h beneath the load lies in the loaded element and sees its
//! discretised near field, so α* alternates between corner and mid-side load columns (±5 % of
//! the diagonal for Table 1). A line load q(ζ), the load of Eq. 12, does not see this: for q
//! linear in each element its consistent response Σ_k α*(·, k)·∫N_k q is integrated exactly by
//! the two-point Gauss rule of each element, whose abscissae ζ_g carry the kernel values
//! Σ_k N_k(ζ_g)·α*(·, k). [`axial_gauss_resample`] samples loads (and, with the same
//! interpolation, observations) there; the result is smooth in ζ and is what the fitted
//! formula is fitted to ([`super::data`]).
//!
//! # Root stress from the same solutions
//! Each solved displacement block is also observed at the tension-side root fillets of teeth
//! −1, 0, +1 ([`super::root_stress::FilletObserver`]): the stress influence of the same load
//! cases, with no second factorisation ([`FeInfluence::root_stress`]).
//!
//! # Cost ([`FeMethod`])
//! The gear is meshed whole and fixed at the bore; the mesh is not cyclically symmetric
//! (teeth −`fine_teeth` … +`fine_teeth` are meshed finer than the others, and the web's
//! transition rings group the rim's nodes by threes from tooth 0, with a pass-through where
//! the count is not a multiple of three), so a cyclic (discrete Fourier) decomposition does
//! not apply and the discretised problem K u = f is solved as it stands. [`FeMethod::Fast`]
//! (the default) and [`FeMethod::Reference`] solve the same K u = f for the same n load
//! cases; what differs is the work (Table 1 pinion at the default density: 67 590 DOFs, 143
//! load cases):
//!
//! * **Assembly.** Layer L of the extruded mesh is layer 0 turned by ω·z_L about the axis
//!   and moved up by z_L ([`GearMesh::layer_congruence`]), so its element stiffnesses are
//!   K_e = Q·K_{e₀}·Qᵀ with Q the block rotation: one layer of elements is integrated
//!   (27 Gauss points, 60 × 60), the others are turned (a few percent of the cost), each
//!   claimed congruence checked on the node coordinates
//!   ([`super::fe::assembly::assemble_lower_congruent`]).
//! * **Ordering.** Approximate minimum degree on the node graph instead of the DOF graph
//!   ([`super::fe::ordering`]): an order of the same quality (the same factor size) at half
//!   the analysis time.
//! * **Solves.** Only u at the nodes read by the observations (the stencil elements at depth
//!   h on teeth −1, 0, +1, the flank nodes of tooth 0, the fillet stress elements) is needed,
//!   and each load acts on one node. The forward substitution L y = P f is confined to the
//!   ancestors of the loaded supernodes in the elimination tree and the backward one to the
//!   ancestors of the observed supernodes ([`super::fe::solver`], "Selected solves"): the
//!   other entries of y are exact zeros and the other entries of u are not read. The
//!   reference substitutes over the whole factor and recovers u everywhere.
//!
//! The factorisation itself (≈ 16 GFlop for the pinion, ≈ 19 GFlop for the gear) is the
//! same work in both and is what remains. The two methods agree to rounding: α* within a
//! few 10⁻¹² of each block's largest value, root-stress units identical
//! (`tests/compliance_influence_fe.rs`). [`super::data::ComplianceData::compute`] runs the
//! two gears side by side.
//!
//! # Grid coordinates
//! Rows are the flank grid's profile rows, tip → root: η* = (x_ref − x)/m_n with x the
//! row's coordinate along the tooth centre line and x_ref = `eta_reference_x`; τ =
//! max(0, ν_q − ν) on rounding and tip (ν the tooth-local normal angle, ν_q its value at the
//! start of the rounding), else 0; the profile coordinate is [`super::FlankCoord::profile`].
//! Columns are the axial node levels, ζ = z/m_n ∈ [0, b₀].

use std::time::Instant;

use faer::Mat;

use super::fe::gear_mesh::{FlankGrid, GearMesh, GearMeshDensity};
use super::fe::{FeError, FeModel, FeStats, Material, ModelOptions, dof, element};
use super::root_stress::{FilletObserver, RootStressGrid};
use super::{FlankCoord, InfluenceGrid};
use crate::geometry::{GearGeometry, Member, SegmentKind};
use crate::params::GearPair;

/// Default depth h of Vedmar's division, in units of m_n.
pub const DEFAULT_DEPTH_MN: f64 = 0.2;

/// Number of load cases solved per block of right-hand sides.
const CHUNK: usize = 64;

/// Result of [`fe_influence`]: the influence grid, the surface-to-surface matrix of tooth 0
/// and the sizes and timings of the FE run.
#[derive(Debug, Clone)]
pub struct FeInfluence {
    /// α* on the flank grid (observations on teeth −1, 0, +1, loads on tooth 0).
    pub grid: InfluenceGrid,
    /// Surface-to-surface compliance of tooth 0, m/N: `surface[obs * n + load]` is the
    /// displacement along the inward normal at flank node `obs` (no depth) due to a unit
    /// inward normal force at flank node `load`; symmetric by Maxwell–Betti.
    pub surface: Vec<f64>,
    /// Stress influence at the tension-side root fillets of teeth −1, 0, +1 for the same load
    /// cases ([`super::root_stress`]).
    pub root_stress: RootStressGrid,
    /// FE sizes and timings (assembly, factorisation, solves).
    pub stats: FeStats,
    /// Mesh generation time, s.
    pub mesh_s: f64,
    /// Time to locate the observation points and interpolate, s.
    pub observe_s: f64,
}

/// The interpolation stencil of an observation point: element nodes and shape-function values,
/// and the inward unit normal the displacement is projected on.
struct Stencil {
    nodes: [usize; element::NODES],
    weights: [f64; element::NODES],
    inward: [f64; 3],
}

/// How [`fe_influence_with`] assembles and solves the same discretised problem; both give the
/// same values to rounding (see the module docs, "Cost").
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FeMethod {
    /// Every element integrated; forward and backward substitution of every load case over
    /// the whole factor, the displacements of all nodes recovered. The reference.
    Reference,
    /// The elements of one axial layer integrated, the other layers' stiffnesses turned from
    /// them ([`GearMesh::layer_congruence`]); selected solves ([`super::fe::solver`]): only
    /// the substitution steps that reach the loaded nodes or the nodes the observations read.
    /// The default.
    Fast,
}

/// FE influence data of gear `g` of pair `p` with mesh density `density` and depth `depth_h`
/// (m): builds the mesh, factorises once, solves the unit normal loads at all flank grid nodes
/// of tooth 0 and records α* for observations on teeth −1, 0, +1 (see the module docs).
/// Assembled and solved by [`FeMethod::Fast`].
///
/// Progress goes to stderr when `progress` is true. Errors: invalid density or depth, an FE
/// failure, or an observation point at depth h that lies outside the mesh (h too large).
pub fn fe_influence(
    g: &GearGeometry,
    p: &GearPair,
    density: &GearMeshDensity,
    depth_h: f64,
    progress: bool,
) -> Result<FeInfluence, FeError> {
    fe_influence_with(g, p, density, depth_h, FeMethod::Fast, progress)
}

/// [`fe_influence`] assembled and solved by `method`.
pub fn fe_influence_with(
    g: &GearGeometry,
    p: &GearPair,
    density: &GearMeshDensity,
    depth_h: f64,
    method: FeMethod,
    progress: bool,
) -> Result<FeInfluence, FeError> {
    let mn = p.normal_module_m;
    if !(depth_h.is_finite() && depth_h > 0.0 && depth_h < 2.0 * mn) {
        return Err(FeError::InvalidInput(format!(
            "depth h = {depth_h} m, allowed 0 < h < 2·m_n = {} m",
            2.0 * mn
        )));
    }
    let t0 = Instant::now();
    let gm = GearMesh::build(g, p, density)?;
    let mesh_s = t0.elapsed().as_secs_f64();
    let congruence = match method {
        FeMethod::Reference => Vec::new(),
        FeMethod::Fast => gm.layer_congruence(),
    };
    let GearMesh { mesh, bore_nodes, flanks, level_z, ties, .. } = gm;
    let grids: Vec<FlankGrid> = [-1i64, 0, 1]
        .iter()
        .map(|&o| {
            let z = flanks.len() as i64;
            flanks
                .get(o.rem_euclid(z) as usize)
                .cloned()
                .ok_or_else(|| FeError::InvalidInput("gear mesh has no flank grids".into()))
        })
        .collect::<Result<_, _>>()?;
    let load = &grids[1];
    let n = load.rows * load.cols;
    // The loaded tooth keeps its layers, so every point of its grid is a node.
    let load_nodes: Vec<usize> =
        load.nodes.iter().copied().collect::<Option<_>>().ok_or_else(|| {
            FeError::InvalidInput(
                "gear mesh: internal: the loaded tooth's flank grid lacks nodes".into(),
            )
        })?;
    if grids.iter().any(|f| f.rows != load.rows || f.cols != load.cols) {
        return Err(FeError::InvalidInput(
            "flank grids of teeth −1, 0, +1 differ (fine_teeth must be ≥ 1)".into(),
        ));
    }
    let material = match g.member {
        Member::Pinion => Material::from(&p.material_p),
        Member::Gear => Material::from(&p.material_g),
    };
    if progress {
        eprintln!(
            "fe_influence z = {}: {} nodes, {} elements, meshed in {mesh_s:.2} s; factorising",
            g.z,
            mesh.nodes.len(),
            mesh.elements.len()
        );
    }
    let options = ModelOptions {
        congruent: &congruence,
        node_ordering: method == FeMethod::Fast,
        ties: &ties,
    };
    let model = FeModel::with_options(mesh, material, &bore_nodes, &options)?;
    let st = model.stats();
    if progress {
        eprintln!(
            "fe_influence: {} DOFs, assembly {:.2} s, factorisation {:.2} s",
            st.dofs,
            st.assembly_s,
            st.factorisation_s()
        );
    }

    // Observation stencils at depth h.
    let t1 = Instant::now();
    let boxes = model.mesh().element_boxes();
    let mut stencils: Vec<Vec<Stencil>> = Vec::with_capacity(3);
    for f in &grids {
        let mut list = Vec::with_capacity(n);
        for (i, &x) in f.points.iter().enumerate() {
            let nv = f.normals[i];
            // On the end faces the inward normal of the helicoid leaves the gear axially by
            // h·sin β_b; the point is then taken on the end face (z clamped to [0, b]).
            let target = [
                x[0] - depth_h * nv[0],
                x[1] - depth_h * nv[1],
                (x[2] - depth_h * nv[2]).clamp(0.0, p.face_width_m),
            ];
            let (e, xi) = model.mesh().locate_with(&boxes, target).ok_or_else(|| {
                FeError::InvalidInput(format!(
                    "point at depth h = {depth_h} m beneath flank point {i} ({:?}) is outside \
                     the mesh",
                    x
                ))
            })?;
            list.push(Stencil {
                nodes: model.mesh().elements[e],
                weights: element::shape(xi),
                inward: [-nv[0], -nv[1], -nv[2]],
            });
        }
        stencils.push(list);
    }
    let mut fillet = FilletObserver::new(g, model.mesh(), &material, &level_z, &[-1, 0, 1], n)?;
    let fillet_nodes = fillet.nodes();
    let mut observe_s = t1.elapsed().as_secs_f64();

    let mut alpha = vec![vec![0.0; n * n]; 3];
    let mut surface = vec![0.0; n * n];
    // Records load case j from the displacement field u(node, d) (m).
    let mut record = |j: usize, u: &dyn Fn(usize, usize) -> f64| {
        for (t, list) in stencils.iter().enumerate() {
            for (i, s) in list.iter().enumerate() {
                let mut v = 0.0;
                for (a, &node) in s.nodes.iter().enumerate() {
                    for d in 0..3 {
                        v += s.weights[a] * s.inward[d] * u(node, d);
                    }
                }
                alpha[t][i * n + j] = v;
            }
        }
        for i in 0..n {
            let node = load_nodes[i];
            let mut v = 0.0;
            for d in 0..3 {
                v -= load.normals[i][d] * u(node, d);
            }
            surface[i * n + j] = v;
        }
        fillet.observe(j, u);
    };
    // The nodes read by `record` (selected solves only), and the row block of each node.
    let observed: Vec<usize> = match method {
        FeMethod::Reference => Vec::new(),
        FeMethod::Fast => {
            let mut v: Vec<usize> = stencils
                .iter()
                .flatten()
                .flat_map(|s| s.nodes)
                .chain(load_nodes.iter().copied())
                .chain(fillet_nodes.iter().copied())
                .collect();
            v.sort_unstable();
            v.dedup();
            v
        }
    };
    let mut slot = vec![usize::MAX; if observed.is_empty() { 0 } else { model.mesh().nodes.len() }];
    for (i, &node) in observed.iter().enumerate() {
        slot[node] = i;
    }
    let dofs = model.dofs();
    let mut start = 0;
    while start < n {
        let k = CHUNK.min(n - start);
        match method {
            FeMethod::Reference => {
                let mut f = Mat::<f64>::zeros(dofs, k);
                for c in 0..k {
                    let j = start + c;
                    let node = load_nodes[j];
                    for d in 0..3 {
                        f[(dof(node, d), c)] = -load.normals[j][d];
                    }
                }
                let u = model.solve_block(f.as_ref())?;
                let t2 = Instant::now();
                for c in 0..k {
                    record(start + c, &|node, d| u[(dof(node, d), c)]);
                }
                observe_s += t2.elapsed().as_secs_f64();
            }
            FeMethod::Fast => {
                let cases: Vec<Vec<(usize, f64)>> = (start..start + k)
                    .map(|j| {
                        let node = load_nodes[j];
                        (0..3).map(|d| (dof(node, d), -load.normals[j][d])).collect()
                    })
                    .collect();
                let u = model.solve_at_nodes(&cases, &observed)?;
                let t2 = Instant::now();
                for c in 0..k {
                    record(start + c, &|node, d| u[(3 * slot[node] + d, c)]);
                }
                observe_s += t2.elapsed().as_secs_f64();
            }
        }
        start += k;
        if progress {
            eprintln!(
                "fe_influence: {start}/{n} load cases, {:.1} s elapsed",
                t0.elapsed().as_secs_f64()
            );
        }
    }

    // Grid coordinates.
    let rho_mn = g.rounding_radius / mn;
    let x_q = g.rounding_center[0] + g.rounding_radius * g.nu_rounding_start.cos();
    let eta_q = (g.eta_reference_x - x_q) / mn;
    let mut eta_star = Vec::with_capacity(load.rows);
    let mut tau = Vec::with_capacity(load.rows);
    let mut profile = Vec::with_capacity(load.rows);
    for r in 0..load.rows {
        let e = (g.eta_reference_x - load.local[r][0]) / mn;
        let t = match load.kind[r] {
            SegmentKind::Rounding | SegmentKind::Tip => (g.nu_rounding_start - load.nu[r]).max(0.0),
            _ => 0.0,
        };
        eta_star.push(e);
        tau.push(t);
        profile.push(FlankCoord { eta_star: e, tau: t, zeta: 0.0 }.profile(eta_q, rho_mn));
    }
    let grid = InfluenceGrid {
        profile,
        eta_star,
        tau,
        zeta: level_z.iter().map(|z| z / mn).collect(),
        teeth: vec![-1, 0, 1],
        alpha,
        depth_h,
        eta_star_rounding_start: eta_q,
        rounding_radius_mn: rho_mn,
    };
    grid.validate().map_err(FeError::InvalidInput)?;
    let root_stress = fillet.finish(grid.profile.clone(), grid.zeta.clone(), eta_q, rho_mn, mn)?;
    Ok(FeInfluence { grid, surface, root_stress, stats: model.stats(), mesh_s, observe_s })
}

/// The influence grid resampled along ζ at the two Gauss abscissae of every axial element
/// (see the module docs): for each element with node columns (a, m, b) (corner, mid-side,
/// corner) the new columns are ζ_g = ζ_m ± (ζ_b − ζ_a)/(2√3), and
///
/// α̃(i_g, j_g) = Σ_a Σ_b N_a(ξ_i)·N_b(ξ_j)·α*(a, b)
///
/// with the quadratic Lagrange shape functions N of the element's three node levels, for the
/// observation column (i) and the load column (j) of every block (rows and teeth unchanged).
/// The load side is the FE response to a unit force at ζ_g applied through its consistent
/// nodal forces; the observation side interpolates the (smooth) depth-h displacements with
/// the same functions. The new columns lie strictly inside (0, b₀).
///
/// Errors: fewer than 3 or an even number of columns, or mid-side columns not midway between
/// their corner columns (relative tolerance 1e-9): the grid is then not from quadratic
/// elements.
pub fn axial_gauss_resample(grid: &InfluenceGrid) -> Result<InfluenceGrid, FeError> {
    grid.validate().map_err(FeError::InvalidInput)?;
    let nc = grid.zeta.len();
    if nc < 3 || nc.is_multiple_of(2) {
        return Err(FeError::InvalidInput(format!(
            "axial Gauss resampling needs an odd number (≥ 3) of node columns, grid has {nc}"
        )));
    }
    let elements = (nc - 1) / 2;
    let g = 1.0 / 3f64.sqrt();
    let mut zeta = Vec::with_capacity(2 * elements);
    let mut weights: Vec<[(usize, f64); 3]> = Vec::with_capacity(2 * elements);
    for e in 0..elements {
        let (a, m, b) = (2 * e, 2 * e + 1, 2 * e + 2);
        let (za, zm, zb) = (grid.zeta[a], grid.zeta[m], grid.zeta[b]);
        if ((za + zb) / 2.0 - zm).abs() > 1e-9 * (zb - za) {
            return Err(FeError::InvalidInput(format!(
                "column {m} (ζ = {zm}) is not midway between columns {a} (ζ = {za}) and {b} \
                 (ζ = {zb}): not the node levels of quadratic elements"
            )));
        }
        for xi in [-g, g] {
            zeta.push(zm + xi * (zb - za) / 2.0);
            weights.push([
                (a, 0.5 * xi * (xi - 1.0)),
                (m, 1.0 - xi * xi),
                (b, 0.5 * xi * (xi + 1.0)),
            ]);
        }
    }
    let nr = grid.profile.len();
    let ng = zeta.len();
    let n = grid.points();
    let m = nr * ng;
    let alpha = grid
        .alpha
        .iter()
        .map(|block| {
            let mut out = vec![0.0; m * m];
            for ri in 0..nr {
                for (ci, wi) in weights.iter().enumerate() {
                    for rj in 0..nr {
                        for (cj, wj) in weights.iter().enumerate() {
                            let mut s = 0.0;
                            for &(a, wa) in wi {
                                let base = (ri * nc + a) * n + rj * nc;
                                for &(b, wb) in wj {
                                    s += wa * wb * block[base + b];
                                }
                            }
                            out[(ri * ng + ci) * m + rj * ng + cj] = s;
                        }
                    }
                }
            }
            out
        })
        .collect();
    let out = InfluenceGrid { zeta, alpha, ..grid.clone() };
    out.validate().map_err(FeError::InvalidInput)?;
    Ok(out)
}
