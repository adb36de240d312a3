//! Hex20 mesh of a whole helical gear: all teeth and the body down to the hub bore.
//!
//! # Construction
//!
//! 1. **Transverse quadratic quad mesh (8-node quads).** Each tooth owns the pitch sector of
//!    polar angles θ_k − π/z … θ_k + π/z (θ_k = 2πk/z, teeth numbered counter-clockwise). Its
//!    upper half (tooth-local y ≥ 0) is made of two mapped blocks (transfinite/Coons
//!    interpolation of the four boundary curves):
//!    * the *tooth block*, bounded by the active flank from the form point F (top of the fillet)
//!      to the end R of the tip rounding, the tip land R → B (tip circle to the centre line), the
//!      tooth centre line, and the straight line F → M across the tooth (M on the centre line);
//!      rows of nodes along the flank (`involute` elements from F to the start of the rounding,
//!      uniform in arc length, then `rounding` elements, uniform in angle), `across` elements
//!      from the flank to the centre line;
//!    * the *root block* below it, bounded by F → M, the composite curve fillet F → G (generated
//!      by the basic rack's root rounding), root circle G → A (A at the middle of the tooth
//!      space, polar angle π/z) and radial cut line A → K down to the rim radius r_K = r_f −
//!      `rim_depth_mn`·m_n, the arc K → Q at r_K and the centre line Q → M.
//!
//!    The lower half is the mirror image (y → −y), so the node distributions on the two radial
//!    cut lines at ±π/z are identical and neighbouring sectors join conformingly. Teeth with
//!    offsets −`fine_teeth` … +`fine_teeth` from tooth 0 use the fine density; the others use
//!    one element across the half tooth, `coarse_involute` + 1 along the flank and one element
//!    each on fillet and root (the cut line, shared by neighbours, has `rim` elements in all
//!    sectors). Below r_K the *web* is meshed as rings down to the bore: transition rings
//!    (three outer elements into one inner, by the usual four-quad template; a remainder is
//!    passed through) while the number of elements around stays ≥ `web_min_divisions`, then
//!    plain rings with inner/outer radius ratio ≈ `web_ring_ratio`. Mid-edge nodes lie on the
//!    exact boundary curves (flank, fillet, root and tip circles, bore); in the web they are
//!    placed at the polar mid-point (on circles for circumferential edges).
//! 2. **Extrusion along the helix.** The quad mesh is extruded in `layers` equal axial layers
//!    over the face width b; a node at axial position z is the transverse node turned by
//!    `twist_rate`·z about the axis (so every transverse section is the gear's section at that
//!    z). Mid-layer nodes (only above quad corners, as hex20 requires) come from the same
//!    mapping at the half layer, so vertical edges are quadratic approximations of helices.
//!    Each quad × layer gives one hex20 element (C3D20 node order; quads counter-clockwise,
//!    z upward, so every element is right-handed).
//!
//! # Folded blocks
//! Two parts of the transverse mesh can fold (a quad with a negative Jacobian) when a count is
//! large, and each is repaired where, and only where, it folds, so that every mesh that was
//! valid keeps its nodes exactly:
//! * **The root block.** Its boundary turns by about 180° (down the fillet, along the root
//!   circle, down the cut line), and its Coons map folds when many thin rows run along it: with
//!   the other counts at their defaults the Table 1 gear's root block folds from `across` = 9 on
//!   (the spur variant's from 8, the 20° / 25 mm variant's from 12; with `fillet` = 16 the
//!   Table 1 gear's from 7); the pinions' did not up to 40. The block is checked at the 3 × 3
//!   Gauss points of its quads (the determinant of the quad8 map against the block's
//!   orientation). A folded block is relaxed: its interior corner nodes by Laplace smoothing
//!   (each to the mean of its four neighbours, Gauss–Seidel sweeps in a fixed order until no node
//!   moves by more than 10⁻¹³ of the block's extent), its interior mid-edge nodes to the middle
//!   of their edges; the boundary nodes stay on the exact curves.
//! * **A web transition group** (three outer intervals into one inner). Its two middle nodes
//!   lie at the thirds of the group's angle; where the outer intervals are very unequal (many
//!   fine intervals beside a coarse tooth's one, from `across` = 14 on for the Table 1 gear) a
//!   cell folds, and that group's middle nodes are put at the angles of its outer nodes instead.
//!
//! With both, none of the three designs' gears folds with any one count from 1 to 40 (the others at
//! their defaults), and the Table 1 gear meshes up to `across` = 20 with a positive Jacobian at
//! every Gauss point (`tests/compliance_gear_fe.rs`). Combinations can still fold: of the 81 with
//! `across` and `fillet` in {10, 20, 40} and `root` and `rim` in {1, 5, 20}, the Table 1 gear's
//! root block folds in 14 even relaxed, all with `root` = 20 (many short root-circle elements
//! beside a long fillet element; the pinion's in none). [`GearMesh::build`] checks both blocks of
//! every sector after the relaxation and refuses a fold with an error naming the block and the
//! counts, before anything else is built (a folded quad is a folded hex20 element at the same
//! points, which the FE would refuse without naming the density). The relaxed root block is a
//! slightly different discretisation: for the Table 1 gear from `across` 8 (Coons) to 9 (relaxed)
//! each α* block moves by 3–5·10⁻³ of its largest value (1–4·10⁻³ from 7 to 8), and the relaxation
//! forced on both Table 1 gears at `fillet` 16, `across` 6 (where the Coons map is valid) moved the
//! root stresses by −0.8 % (pinion) and −0.7 % (gear) and the static TE by +0.08 %.
//!
//! # Axial coarsening
//! With `coarse_layers` set, the quads away from the loaded tooth are extruded in fewer,
//! taller layers: those of the coarse teeth's sectors, the tooth blocks (above F → M) of the
//! fine teeth beyond `layered_teeth` (by default the loaded tooth's neighbours: their root
//! blocks, fillets and rim keep the layers), and the web quads whose polar angles do not
//! overlap the layered teeth's sectors (|θ| < (`layered_teeth` + ½)·2π/z), so the web under the
//! loaded tooth keeps the fine layers. A coarse layer is `layers`/`coarse_layers` fine layers
//! high;
//! node levels are counted on the fine grid and a transverse node carries the levels its
//! quads need. Where a fine and a coarse quad share a transverse node, the fine side has
//! nodes at levels the coarse element has no node at; each is tied to the coarse element
//! ([`super::assembly::Tie`]): on a vertical edge (a transverse corner) by the edge's quadratic
//! interpolation, u = ½ζ(ζ − 1)·u_a + (1 − ζ²)·u_m + ½ζ(ζ + 1)·u_b, ζ ∈ (−1, 1) the level
//! within the coarse layer; at a transverse mid-edge node by the serendipity face
//! interpolation on the line through it, u = ½(1 − ζ)·u_a + ½(1 + ζ)·u_b +
//! ½(1 − ζ²)·(u_{1,m} + u_{2,m}) − ¼(1 − ζ²)·(u_{1,a} + u_{1,b} + u_{2,a} + u_{2,b}), with 1, 2
//! the ends of the edge. The field is then continuous across the interface. The gear's far
//! side deforms smoothly along the axis (the load is carried to the bore through the web), and
//! so do the bodies of the loaded tooth's neighbours, which are only observed (α* at depth h
//! beneath their flank grid, in whatever element holds the point): interpolated from every
//! third level of the six-layer solution by the quadratic of a two-layer element, the
//! neighbour blocks of α* (Table 1) are reproduced to 2.6·10⁻³ of their largest value,
//! against 0.19 for the loaded tooth's own block, whose layers therefore stay. The
//! neighbours' root blocks keep the layers: coarsened as well, they moved the loaded tooth's
//! own fillet stress influence by 1.2·10⁻² of its largest value through the tooth space they
//! share (5·10⁻⁴ with them kept, at 0.05 s more factorisation per gear). The taller elements
//! change the compliance at the loaded tooth little: see [`GearMeshDensity::default`]. The
//! flank grid of a fine tooth keeps every level ([`FlankGrid::points`]); where its elements
//! have no node the grid names none ([`FlankGrid::nodes`]): such teeth are observed, never
//! loaded. Nodes on a helix (β ≠ 0) are not exactly where the coarse element's quadratic edge
//! puts them (a gap of third order in the twist ω·Δz over the layer, ω the twist rate); the
//! ties are exact for spur gears.
//!
//! # Size
//! Every count of [`GearMeshDensity`] lies in 1 … 1000, and their combination for the gear at
//! hand is bounded before anything is allocated. The estimate of the hex20 elements is
//!
//! `layers · (2·(F·(involute + rounding + fillet + root + rim)·across + C·(coarse_involute + 3
//! + rim)) + m·(2 + n))`,
//!
//! with F the fine teeth (2·`fine_teeth` + 1, at most z), C = z − F the coarse ones,
//! m = 2·(F·across + C) the divisions of the web's outer circle and n the plain web rings that
//! the ring ratio gives between the rim radius and the bore. It is an estimate from above:
//! 1.15–1.6 times the elements of the presets in one conforming extrusion for Table 1, more
//! with axial coarsening, which it ignores. It must not exceed [`MAX_ESTIMATED_ELEMENTS`]:
//! beyond it the FE's factorisation would need tens of gigabytes. [`GearMesh::build`] refuses
//! a larger estimate with both numbers, instead of the process running out of memory.
//!
//! # Boundary condition
//! All nodes on the bore surface r = d_bore/2 are fixed (all three components): the hub is
//! rigid and its rotation is the reference of the gear angle. Everything else is free.
//!
//! # Flank grids
//! On the active (positive) flank of every tooth the surface nodes at corner rows of the
//! profile (F … R) and at all axial node levels (corner and mid-layer, 2·`layers` + 1) form a
//! structured grid ([`FlankGrid`]), rows ordered tip → root (increasing profile coordinate,
//! as [`crate::compliance::InfluenceGrid`]) and columns by increasing z.

use std::collections::HashMap;
use std::f64::consts::PI;

use super::assembly::{Congruent, Tie};
use super::element::NODES;
use super::error::FeError;
use super::mesh::Mesh;
use crate::geometry::{GearGeometry, SegmentKind};
use crate::params::GearPair;

/// The largest [`GearMeshDensity::estimated_elements`] that [`GearMesh::build`] meshes (module
/// docs, "Size"): about 2.1 times the `refined` preset's estimate for the Table 1 gear
/// (18 688; the FE of both Table 1 gears at `refined` takes 14 s and 3.3 GB). Just below it,
/// `refined` in 16 layers (estimates 28 320 and 37 376, 23 040 and 28 816 elements) takes
/// 72 s and 9.6 GB for both gears computed together.
pub const MAX_ESTIMATED_ELEMENTS: usize = 40_000;

/// Mesh density of [`GearMesh`]. Element counts are per tooth (upper half of the pitch sector)
/// unless stated otherwise. Serialised with its field names (the provenance of cached
/// compliance data).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GearMeshDensity {
    /// Elements along the flank from the form circle to the start of the tip rounding (fine
    /// teeth).
    pub involute: usize,
    /// Elements on the tip rounding (fine teeth).
    pub rounding: usize,
    /// Elements across half a tooth, flank to centre line (fine teeth).
    pub across: usize,
    /// Elements along the fillet (fine teeth).
    pub fillet: usize,
    /// Elements along the root circle from the fillet to the middle of the tooth space (fine
    /// teeth).
    pub root: usize,
    /// Elements along the radial cut line from the root circle to the rim radius (all teeth).
    pub rim: usize,
    /// Depth of the rim below the root circle, in units of m_n; the web starts below it.
    pub rim_depth_mn: f64,
    /// Elements along the flank below the rounding on coarse teeth.
    pub coarse_involute: usize,
    /// Teeth with offsets −`fine_teeth` … `fine_teeth` from tooth 0 get the fine density (≥ 1).
    pub fine_teeth: usize,
    /// Ratio inner/outer radius of the plain web rings, in (0, 1).
    pub web_ring_ratio: f64,
    /// Smallest number of elements around the web after a transition ring.
    pub web_min_divisions: usize,
    /// Number of axial element layers over the face width.
    pub layers: usize,
    /// Axial element layers of the coarse part: the coarse teeth's sectors and the web
    /// elements outside the fine teeth's sectors (see "Axial coarsening" in the module docs);
    /// must divide `layers`. `None`: `layers` everywhere (one conforming extrusion).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coarse_layers: Option<usize>,
    /// With `coarse_layers`: the teeth with offsets −`layered_teeth` … `layered_teeth` from
    /// tooth 0, and the web beneath them, keep the `layers`; the other fine teeth (the
    /// loaded tooth's neighbours, observed but never loaded) have their tooth blocks (above
    /// the line F → M at the form circle) in `coarse_layers` like the coarse part (see "Axial
    /// coarsening" in the module docs); at most `fine_teeth`. `None`: `fine_teeth` (every
    /// fine tooth keeps the layers).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub layered_teeth: Option<usize>,
}

impl Default for GearMeshDensity {
    /// The default density for production influence data: 11 × 13 flank grid (rows × axial
    /// node levels); for the Table 1 pair 36k DOFs (pinion) and 46k DOFs (gear), about 0.35 s
    /// of factorisation each. Six axial layers on the loaded tooth and the web beneath it: the
    /// same-tooth α* is governed by the axial element length (4 → 6 → 8 layers change it by
    /// +4 % and +1.5 %), so the layers are spent there; with `layers: 4` the pair has 45k/61k
    /// DOFs (conforming) and α* ≈ 4 % lower. Two axial layers on the rest of the gear
    /// (`coarse_layers`, `layered_teeth`, "Axial coarsening" in the module docs): the coarse
    /// teeth, the web away from tooth 0 and the bodies of the loaded tooth's neighbours. Against
    /// [`GearMeshDensity::conforming`] (Table 1) that changes α* by at most 2.2·10⁻⁴ (same
    /// tooth) and 2.2·10⁻³ (neighbouring teeth) of each block's largest value, the stored root
    /// stress by 3.3·10⁻³ of its largest value, and the pair's static TE and root stresses
    /// (20, 100 and 250 N·m over a mesh cycle) by at most 3.8·10⁻⁴ and 2.7·10⁻³ of their
    /// largest values: a tenth of the default mesh's own error (α* +3 %, pinion root stress
    /// +5 % to the refined mesh), at 0.35–0.4 of the time.
    ///
    /// Four elements on the tip rounding: contacts reach the rounding only up to τ ≈ 0.18 rad
    /// (Table 1, TE up to 200 µm), and α* falls steeply there (pinion, mid face: 11.9, 9.0,
    /// 6.6·10⁻⁹ m/N at τ = 0, 0.27, 0.53 rad). With two elements the first grid row on the
    /// rounding was at τ = 0.53 rad, outside every contact, so both representations had to
    /// bridge the whole contact range from there; four put a row at τ = 0.27 rad (+5 % DOFs,
    /// +22 % load cases; the rows below the rounding are unchanged).
    fn default() -> Self {
        Self {
            involute: 6,
            rounding: 4,
            across: 3,
            fillet: 2,
            root: 1,
            rim: 1,
            rim_depth_mn: 2.0,
            coarse_involute: 1,
            fine_teeth: 1,
            web_ring_ratio: 0.6,
            web_min_divisions: 12,
            layers: 6,
            coarse_layers: Some(2),
            layered_teeth: Some(0),
        }
    }
}

impl GearMeshDensity {
    /// The default density extruded in six layers everywhere (no axial coarsening): 68k DOFs
    /// (pinion) and 91k DOFs (gear) for Table 1. The mesh of the embedded Table 1 data, and of
    /// the paper run's sensitivity case that is compared with them.
    pub fn conforming() -> Self {
        Self { coarse_layers: None, layered_teeth: None, ..Self::default() }
    }

    /// A coarse mesh for tests: 5 × 5 flank grid; for the Table 1 pair ≈ 20k DOFs (pinion)
    /// and 30k DOFs (gear), well under a second of factorisation.
    pub fn coarse() -> Self {
        Self {
            involute: 3,
            rounding: 1,
            across: 2,
            fillet: 1,
            root: 1,
            rim: 1,
            rim_depth_mn: 2.0,
            coarse_involute: 1,
            fine_teeth: 1,
            web_ring_ratio: 0.5,
            web_min_divisions: 8,
            layers: 2,
            coarse_layers: None,
            layered_teeth: None,
        }
    }

    /// A refined mesh for convergence checks: 16 × 17 flank grid, five fine teeth, every count
    /// at or above the default's; for the Table 1 pair 173k DOFs (pinion) and 220k DOFs (gear).
    /// It converges the compliance, not the root stress: the root fillet gets only one more
    /// element along it and across the half tooth than the default, and refining those two
    /// counts further moves the Table 1 root stresses by a few per cent
    /// (`docs/bench/root_stress.md`, "Refinement of the root fillet").
    pub fn refined() -> Self {
        Self {
            involute: 9,
            rounding: 6,
            across: 4,
            fillet: 3,
            root: 2,
            rim: 2,
            rim_depth_mn: 2.0,
            coarse_involute: 2,
            fine_teeth: 2,
            web_ring_ratio: 0.65,
            web_min_divisions: 16,
            layers: 8,
            coarse_layers: None,
            layered_teeth: None,
        }
    }

    /// The estimated number of hex20 elements of the mesh of a gear with `z` teeth and the ratio
    /// `rim_to_bore` of the rim radius r_K to the bore radius (module docs, "Size"): an
    /// estimate from above, exact in its form for the teeth, as a float so that no count can
    /// overflow it.
    pub fn estimated_elements(&self, z: usize, rim_to_bore: f64) -> f64 {
        let z = z as f64;
        let fine = (2.0 * self.fine_teeth as f64 + 1.0).min(z);
        let coarse = z - fine;
        let tooth = (self.involute + self.rounding + self.fillet + self.root + self.rim) as f64;
        let teeth = 2.0
            * (fine * tooth * self.across as f64
                + coarse * (self.coarse_involute as f64 + 3.0 + self.rim as f64));
        let m = 2.0 * (fine * self.across as f64 + coarse);
        let rings = (rim_to_bore.max(1.0).ln() / (1.0 / self.web_ring_ratio).ln()).ceil();
        self.layers as f64 * (teeth + m * (2.0 + rings))
    }

    fn validate(&self) -> Result<(), FeError> {
        let counts = [
            ("involute", self.involute),
            ("rounding", self.rounding),
            ("across", self.across),
            ("fillet", self.fillet),
            ("root", self.root),
            ("rim", self.rim),
            ("coarse_involute", self.coarse_involute),
            ("fine_teeth", self.fine_teeth),
            ("web_min_divisions", self.web_min_divisions),
            ("layers", self.layers),
        ];
        for (name, v) in counts {
            if v == 0 || v > 1000 {
                return Err(FeError::InvalidInput(format!(
                    "gear mesh density: {name} = {v}, allowed 1 … 1000"
                )));
            }
        }
        if let Some(c) = self.coarse_layers
            && (c == 0 || c > self.layers || !self.layers.is_multiple_of(c))
        {
            return Err(FeError::InvalidInput(format!(
                "gear mesh density: coarse_layers = {c} must divide layers = {}",
                self.layers
            )));
        }
        if let Some(t) = self.layered_teeth
            && t > self.fine_teeth
        {
            return Err(FeError::InvalidInput(format!(
                "gear mesh density: layered_teeth = {t} must not exceed fine_teeth = {}",
                self.fine_teeth
            )));
        }
        if !(self.web_ring_ratio > 0.05 && self.web_ring_ratio < 0.98) {
            return Err(FeError::InvalidInput(format!(
                "gear mesh density: web_ring_ratio = {}, allowed (0.05, 0.98)",
                self.web_ring_ratio
            )));
        }
        if !(self.rim_depth_mn.is_finite() && self.rim_depth_mn > 0.0) {
            return Err(FeError::InvalidInput(format!(
                "gear mesh density: rim_depth_mn = {} must be > 0",
                self.rim_depth_mn
            )));
        }
        Ok(())
    }
}

/// The structured grid of surface nodes on the active flank of one tooth.
#[derive(Debug, Clone, PartialEq)]
pub struct FlankGrid {
    /// Tooth index 0 … z − 1 (counter-clockwise).
    pub tooth: usize,
    /// Number of profile rows (tip → root).
    pub rows: usize,
    /// Number of axial columns (increasing z).
    pub cols: usize,
    /// Node level (index into [`GearMesh::level_z`]) of each column: every level on the fine
    /// teeth, the coarse part's levels on the others.
    pub levels: Vec<usize>,
    /// Mesh node of grid point `row * cols + col`; `None` where the tooth's elements have no
    /// node at that level (a neighbour of the loaded tooth in the coarse layers, see
    /// [`GearMeshDensity::layered_teeth`]).
    pub nodes: Vec<Option<usize>>,
    /// Position of grid point `row * cols + col` on the exact flank (the node's where there is
    /// one), m.
    pub points: Vec<[f64; 3]>,
    /// Tooth-local outward-normal angle ν of each row, rad (see [`crate::geometry::flank`]).
    pub nu: Vec<f64>,
    /// Tooth-local transverse position of each row, m (x along the tooth centre line).
    pub local: Vec<[f64; 2]>,
    /// Surface kind of each row.
    pub kind: Vec<SegmentKind>,
    /// Unit outward 3D surface normal at grid point `row * cols + col`.
    pub normals: Vec<[f64; 3]>,
}

/// A hex20 mesh of a whole gear with its bore nodes and flank grids.
#[derive(Debug, Clone)]
pub struct GearMesh {
    /// The mesh (m).
    pub mesh: Mesh,
    /// Nodes on the bore surface (to be fixed).
    pub bore_nodes: Vec<usize>,
    /// Flank grid of every tooth, indexed by tooth.
    pub flanks: Vec<FlankGrid>,
    /// Axial position of each node level (2·layers + 1 values), m.
    pub level_z: Vec<f64>,
    /// Radii of the web ring boundaries from the rim radius r_K down to the bore, m.
    pub web_radii: Vec<f64>,
    /// Bore radius, m.
    pub r_bore: f64,
    /// Number of quads of the transverse mesh (= elements per axial layer without axial
    /// coarsening).
    pub quads: usize,
    /// Hanging nodes where fine and coarse layers meet, tied to the coarse elements' faces
    /// (empty without axial coarsening).
    pub ties: Vec<Tie>,
    /// Per element: the element of the same quad in the bottom layer and the turn to it
    /// (read through [`GearMesh::layer_congruence`]); `None` in the bottom layer.
    congruence: Vec<Option<Congruent>>,
    /// Twist rate ω of the helix, rad/m: the node at axial position z is the transverse node
    /// turned by ω·z.
    pub twist_rate: f64,
}

/// 2D node pool with coincidence detection (spatial hash, absolute tolerance).
struct Pool {
    pts: Vec<[f64; 2]>,
    corner: Vec<bool>,
    mid: Vec<bool>,
    head: HashMap<(i64, i64), Vec<usize>>,
    tol: f64,
}

impl Pool {
    fn new(tol: f64) -> Self {
        Self { pts: Vec::new(), corner: Vec::new(), mid: Vec::new(), head: HashMap::new(), tol }
    }

    fn add(&mut self, p: [f64; 2], is_corner: bool) -> usize {
        let c = ((p[0] / self.tol).floor() as i64, (p[1] / self.tol).floor() as i64);
        let mut found = None;
        'outer: for dx in -1..=1 {
            for dy in -1..=1 {
                if let Some(list) = self.head.get(&(c.0 + dx, c.1 + dy)) {
                    for &i in list {
                        let q = self.pts[i];
                        if (q[0] - p[0]).hypot(q[1] - p[1]) <= self.tol {
                            found = Some(i);
                            break 'outer;
                        }
                    }
                }
            }
        }
        let i = match found {
            Some(i) => i,
            None => {
                let i = self.pts.len();
                self.pts.push(p);
                self.corner.push(false);
                self.mid.push(false);
                self.head.entry(c).or_default().push(i);
                i
            }
        };
        if is_corner {
            self.corner[i] = true;
        } else {
            self.mid[i] = true;
        }
        i
    }
}

type P2 = [f64; 2];

fn lerp2(a: P2, b: P2, t: f64) -> P2 {
    [a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t]
}

fn polar(r: f64, a: f64) -> P2 {
    [r * a.cos(), r * a.sin()]
}

/// Cumulative chord-length fractions of a polyline (0 … 1).
fn fractions(p: &[P2]) -> Vec<f64> {
    let mut s = vec![0.0; p.len()];
    for i in 1..p.len() {
        s[i] = s[i - 1] + (p[i][0] - p[i - 1][0]).hypot(p[i][1] - p[i - 1][1]);
    }
    let total = s.last().copied().unwrap_or(0.0);
    if total > 0.0 {
        for v in &mut s {
            *v /= total;
        }
    }
    s
}

/// 2n + 1 points (corners and mid-edge nodes of n elements) of the curve f(t), t ∈ [0, 1],
/// uniform in arc length; returns (t, point) pairs, each point evaluated exactly by f.
fn resample(f: &dyn Fn(f64) -> Result<P2, FeError>, n: usize) -> Result<Vec<(f64, P2)>, FeError> {
    const DENSE: usize = 2000;
    let mut table = Vec::with_capacity(DENSE + 1);
    for i in 0..=DENSE {
        let t = i as f64 / DENSE as f64;
        table.push(f(t)?);
    }
    let s = fractions(&table);
    let mut out = Vec::with_capacity(2 * n + 1);
    let mut k = 0usize;
    for i in 0..=2 * n {
        let target = i as f64 / (2 * n) as f64;
        let t = if i == 0 {
            0.0
        } else if i == 2 * n {
            1.0
        } else {
            while k + 1 < DENSE && s[k + 1] < target {
                k += 1;
            }
            let (s0, s1) = (s[k], s[k + 1]);
            let w = if s1 > s0 { (target - s0) / (s1 - s0) } else { 0.0 };
            (k as f64 + w) / DENSE as f64
        };
        out.push((t, f(t)?));
    }
    Ok(out)
}

/// Discrete transfinite (Coons) interpolation on the quadratic node grid.
///
/// `a` (j = 0) and `c` (j = max) have 2·ni + 1 points along i; `d` (i = 0) and `b` (i = max)
/// have 2·nj + 1 points along j; corners must agree. Boundary nodes are copied exactly.
fn coons(a: &[P2], c: &[P2], d: &[P2], b: &[P2]) -> Vec<Vec<P2>> {
    let (gi, gj) = (a.len(), d.len());
    let (fa, fc, fd, fb) = (fractions(a), fractions(c), fractions(d), fractions(b));
    let mut x = vec![vec![[0.0; 2]; gj]; gi];
    for i in 0..gi {
        for j in 0..gj {
            let u = 0.5 * (fa[i] + fc[i]);
            let v = 0.5 * (fd[j] + fb[j]);
            let mut p = [0.0; 2];
            for k in 0..2 {
                p[k] = (1.0 - v) * a[i][k] + v * c[i][k] + (1.0 - u) * d[j][k] + u * b[j][k]
                    - ((1.0 - u) * (1.0 - v) * a[0][k]
                        + (1.0 - u) * v * c[0][k]
                        + u * (1.0 - v) * a[gi - 1][k]
                        + u * v * c[gi - 1][k]);
            }
            x[i][j] = p;
        }
    }
    for i in 0..gi {
        x[i][0] = a[i];
        x[i][gj - 1] = c[i];
    }
    x[0].copy_from_slice(d);
    x[gi - 1].copy_from_slice(b);
    x
}

/// Whether one of the quads of a block (as [`grid_quads`] gives them) has a Jacobian
/// determinant (of the quad8 map) at one of its 3 × 3 Gauss points that is zero or of the
/// opposite sign to the block's orientation (the sign of its total signed corner area).
fn folds(quads: &[[P2; 8]]) -> bool {
    let sign = quads.iter().map(signed_area).sum::<f64>().signum();
    quads.iter().any(|q| quad_folds(q, sign))
}

/// Whether the quad8 map of `q` has a Jacobian determinant that is zero or of the sign
/// opposite to `sign` at one of its 3 × 3 Gauss points.
fn quad_folds(q: &[P2; 8], sign: f64) -> bool {
    let g = 0.6f64.sqrt();
    [-g, 0.0, g]
        .iter()
        .any(|&xi| [-g, 0.0, g].iter().any(|&eta| sign * quad8_det(q, xi, eta) <= 0.0))
}

/// Jacobian determinant of the quad8 (serendipity) map of `q` (corners, then mid-edge nodes, as
/// [`grid_quads`]) at (ξ, η) ∈ [−1, 1]², m².
fn quad8_det(q: &[P2; 8], xi: f64, eta: f64) -> f64 {
    const CORNERS: [(f64, f64); 4] = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)];
    const MIDS: [(f64, f64); 4] = [(0.0, -1.0), (1.0, 0.0), (0.0, 1.0), (-1.0, 0.0)];
    let mut j = [[0.0; 2]; 2];
    let mut add = |p: P2, d_xi: f64, d_eta: f64| {
        for k in 0..2 {
            j[k][0] += d_xi * p[k];
            j[k][1] += d_eta * p[k];
        }
    };
    for (&(a, b), &p) in CORNERS.iter().zip(&q[..4]) {
        add(
            p,
            0.25 * a * (1.0 + b * eta) * (2.0 * a * xi + b * eta),
            0.25 * b * (1.0 + a * xi) * (a * xi + 2.0 * b * eta),
        );
    }
    for (&(a, b), &p) in MIDS.iter().zip(&q[4..]) {
        if a == 0.0 {
            add(p, -xi * (1.0 + b * eta), 0.5 * b * (1.0 - xi * xi));
        } else {
            add(p, 0.5 * a * (1.0 - eta * eta), -eta * (1.0 + a * xi));
        }
    }
    j[0][0] * j[1][1] - j[0][1] * j[1][0]
}

/// Relaxes the interior of a folded quadratic grid (module docs, "Folded blocks"): the
/// interior corner nodes by Laplace smoothing, Gauss–Seidel sweeps in a fixed order until no
/// node moves by more than [`RELAX_TOLERANCE`] of the block's extent (at most [`RELAX_SWEEPS`]),
/// then every interior mid-edge node to the middle of its edge. Boundary nodes stay where they
/// are.
fn relax(x: &mut [Vec<P2>]) {
    let (gi, gj) = (x.len(), x.first().map_or(0, |r| r.len()));
    if gi < 5 || gj < 5 {
        return; // no interior corner node
    }
    let extent = x.iter().flatten().fold(0.0f64, |m, p| m.max(p[0].abs()).max(p[1].abs()));
    for _ in 0..RELAX_SWEEPS {
        let mut moved = 0.0f64;
        for i in (2..gi - 2).step_by(2) {
            for j in (2..gj - 2).step_by(2) {
                let n = [x[i - 2][j], x[i + 2][j], x[i][j - 2], x[i][j + 2]];
                let p = [
                    0.25 * (n[0][0] + n[1][0] + n[2][0] + n[3][0]),
                    0.25 * (n[0][1] + n[1][1] + n[2][1] + n[3][1]),
                ];
                moved = moved.max((p[0] - x[i][j][0]).hypot(p[1] - x[i][j][1]));
                x[i][j] = p;
            }
        }
        if moved <= RELAX_TOLERANCE * extent {
            break;
        }
    }
    for i in 1..gi - 1 {
        for j in 1..gj - 1 {
            x[i][j] = match (i % 2, j % 2) {
                (0, 0) => continue,
                (1, 0) => lerp2(x[i - 1][j], x[i + 1][j], 0.5),
                (0, _) => lerp2(x[i][j - 1], x[i][j + 1], 0.5),
                // The centre node of a quad, which the quad8 elements do not use.
                _ => lerp2(x[i - 1][j - 1], x[i + 1][j + 1], 0.5),
            };
        }
    }
}

/// Largest number of Gauss–Seidel sweeps of [`relax`].
const RELAX_SWEEPS: usize = 20_000;

/// [`relax`] stops when no node moved by more than this fraction of the block's extent in a
/// sweep.
const RELAX_TOLERANCE: f64 = 1e-13;

/// Quad8 points of the elements of a quadratic grid: corners (CCW or CW), then mid-edge nodes.
fn grid_quads(x: &[Vec<P2>]) -> Vec<[P2; 8]> {
    let (gi, gj) = (x.len(), x.first().map_or(0, |r| r.len()));
    let mut out = Vec::new();
    for ei in 0..(gi - 1) / 2 {
        for ej in 0..(gj - 1) / 2 {
            let (i, j) = (2 * ei, 2 * ej);
            out.push([
                x[i][j],
                x[i + 2][j],
                x[i + 2][j + 2],
                x[i][j + 2],
                x[i + 1][j],
                x[i + 2][j + 1],
                x[i + 1][j + 2],
                x[i][j + 1],
            ]);
        }
    }
    out
}

fn signed_area(q: &[P2; 8]) -> f64 {
    let mut s = 0.0;
    for k in 0..4 {
        let (a, b) = (q[k], q[(k + 1) % 4]);
        s += a[0] * b[1] - b[0] * a[1];
    }
    0.5 * s
}

/// Makes the quad counter-clockwise.
fn ccw(q: [P2; 8]) -> [P2; 8] {
    if signed_area(&q) >= 0.0 { q } else { [q[0], q[3], q[2], q[1], q[7], q[6], q[5], q[4]] }
}

/// Profile rows of one tooth flank (corner and mid rows, root → tip): (ν, point, kind).
fn flank_rows(
    g: &GearGeometry,
    involute: usize,
    rounding: usize,
) -> Result<Vec<(f64, P2, SegmentKind)>, FeError> {
    let nu_f = g.flank.nu_root();
    let nu_q = g.nu_rounding_start;
    let nu_r = g.tip_land_half_angle;
    let point = |nu: f64| -> Result<(P2, SegmentKind), FeError> {
        g.flank.point_at_normal(nu).map(|p| (p.position, p.kind)).ok_or_else(|| {
            FeError::InvalidInput(format!("normal angle {nu} not on the active flank"))
        })
    };
    let lower = resample(&|t: f64| point(nu_f + (nu_q - nu_f) * t).map(|(p, _)| p), involute)?;
    let mut rows = Vec::with_capacity(2 * (involute + rounding) + 1);
    for (t, _) in &lower {
        let nu = nu_f + (nu_q - nu_f) * t;
        let (p, k) = point(nu)?;
        rows.push((nu, p, k));
    }
    for i in 1..=2 * rounding {
        let nu = nu_q + (nu_r - nu_q) * i as f64 / (2 * rounding) as f64;
        let (p, _) = point(nu)?;
        rows.push((nu, p, SegmentKind::Rounding));
    }
    Ok(rows)
}

/// The quads of the upper half of one pitch sector (tooth-local frame) and the flank rows.
struct HalfSector {
    quads: Vec<[P2; 8]>,
    /// The first `tooth_quads` of `quads` are the tooth block's, the rest the root block's.
    tooth_quads: usize,
    rows: Vec<(f64, P2, SegmentKind)>,
}

fn half_sector(
    g: &GearGeometry,
    d: &GearMeshDensity,
    fine: bool,
    r_k: f64,
) -> Result<HalfSector, FeError> {
    let (involute, rounding, across, fillet, root) = if fine {
        (d.involute, d.rounding, d.across, d.fillet, d.root)
    } else {
        (d.coarse_involute, 1, 1, 1, 1)
    };
    let rows = flank_rows(g, involute, rounding)?;
    let a: Vec<P2> = rows.iter().map(|r| r.1).collect();
    let f_pt = a[0];
    let r_pt = a[a.len() - 1];
    let x_f = f_pt[0];
    let ra = g.ra;
    // Centre line of the tooth block: x scaled from the flank rows.
    let scale = (ra - x_f) / (r_pt[0] - x_f);
    let c: Vec<P2> = a.iter().map(|p| [x_f + (p[0] - x_f) * scale, 0.0]).collect();
    let m_pt = [x_f, 0.0];
    let nj = 2 * across + 1;
    let bottom: Vec<P2> = (0..nj).map(|j| lerp2(f_pt, m_pt, j as f64 / (nj - 1) as f64)).collect();
    let phi_t = g.tip_land_half_angle;
    let tip: Vec<P2> =
        (0..nj).map(|j| polar(ra, phi_t * (1.0 - j as f64 / (nj - 1) as f64))).collect();
    let tooth = coons(&a, &c, &bottom, &tip);
    let mut quads: Vec<[P2; 8]> = grid_quads(&tooth);
    let tooth_quads = quads.len();

    // Root block: composite side fillet F→G, root circle G→A, cut line A→K.
    let rack = g.rack;
    let chi_max = rack.chi_max();
    let fil = resample(
        &|t: f64| {
            let (p, n) = rack.fillet_point(chi_max * (1.0 - t));
            Ok(rack.generate(p, n))
        },
        fillet,
    )?;
    let mut side: Vec<P2> = fil.iter().map(|x| x.1).collect();
    side[0] = f_pt;
    let g_pt = side[side.len() - 1];
    let g_ang = g_pt[1].atan2(g_pt[0]);
    let half_pitch = PI / g.z as f64;
    for i in 1..=2 * root {
        let ang = g_ang + (half_pitch - g_ang) * i as f64 / (2 * root) as f64;
        side.push(polar(g.rf, ang));
    }
    let n_upper = side.len();
    for i in 1..=2 * d.rim {
        let rr = g.rf + (r_k - g.rf) * i as f64 / (2 * d.rim) as f64;
        side.push(polar(rr, half_pitch));
    }
    let frac_upper = fractions(&side[..n_upper]);
    let mut left: Vec<P2> = Vec::with_capacity(side.len());
    for (i, p) in side.iter().enumerate() {
        if i < n_upper {
            left.push([x_f + (g.rf - x_f) * frac_upper[i], 0.0]);
        } else {
            left.push([p[0].hypot(p[1]), 0.0]);
        }
    }
    let arc: Vec<P2> =
        (0..nj).map(|j| polar(r_k, half_pitch * (1.0 - j as f64 / (nj - 1) as f64))).collect();
    let mut rootb = coons(&side, &left, &bottom, &arc);
    let mut root_quads = grid_quads(&rootb);
    if folds(&root_quads) {
        relax(&mut rootb);
        root_quads = grid_quads(&rootb);
    }
    for (block, block_quads) in
        [("tooth block (flank to centre line)", &quads[..]), ("root block", &root_quads[..])]
    {
        if folds(block_quads) {
            return Err(FeError::InvalidInput(format!(
                "gear mesh density: the {block} of a {} tooth's sector folds (a quad with a \
                 non-positive Jacobian) for this gear (z = {}) at involute = {involute}, \
                 rounding = {rounding}, across = {across}, fillet = {fillet}, root = {root}, \
                 rim = {}: fewer elements across the tooth or along the root circle avoid it",
                if fine { "fine" } else { "coarse" },
                g.z,
                d.rim
            )));
        }
    }
    quads.extend(root_quads);
    Ok(HalfSector { quads, tooth_quads, rows })
}

/// Whether the polar angles covered by the quad with corners `q[0..4]` (a web quad, spanning
/// less than half a turn) overlap (−`range`, `range`) by more than rounding.
fn overlaps_angle(q: &[P2; 8], range: f64) -> bool {
    let a0 = q[0][1].atan2(q[0][0]);
    let (mut lo, mut hi) = (0.0f64, 0.0f64);
    for p in &q[1..4] {
        let d = (p[1].atan2(p[0]) - a0 + PI).rem_euclid(2.0 * PI) - PI;
        lo = lo.min(d);
        hi = hi.max(d);
    }
    let centre = (a0 + 0.5 * (lo + hi) + PI).rem_euclid(2.0 * PI) - PI;
    centre.abs() < range + 0.5 * (hi - lo) - 1e-9 * range
}

/// Rotates a 2D point by angle `a`.
fn rot2(p: P2, a: f64) -> P2 {
    let (s, c) = a.sin_cos();
    [c * p[0] - s * p[1], s * p[0] + c * p[1]]
}

/// Polar mid-point of two points.
fn polar_mid(p: P2, q: P2) -> P2 {
    let (r1, r2) = (p[0].hypot(p[1]), q[0].hypot(q[1]));
    let (a1, mut a2) = (p[1].atan2(p[0]), q[1].atan2(q[0]));
    if a2 - a1 > PI {
        a2 -= 2.0 * PI;
    } else if a1 - a2 > PI {
        a2 += 2.0 * PI;
    }
    polar(0.5 * (r1 + r2), 0.5 * (a1 + a2))
}

fn web_quad(c: [P2; 4]) -> [P2; 8] {
    [
        c[0],
        c[1],
        c[2],
        c[3],
        polar_mid(c[0], c[1]),
        polar_mid(c[1], c[2]),
        polar_mid(c[2], c[3]),
        polar_mid(c[3], c[0]),
    ]
}

impl GearMesh {
    /// Builds the mesh of gear `g` of pair `p` (face width and bore from `p`).
    ///
    /// Errors: an invalid density, a rim radius r_K not above the bore, or (should the
    /// geometry be unusual) a flank that cannot be sampled or a non-conforming transverse mesh.
    pub fn build(g: &GearGeometry, p: &GearPair, d: &GearMeshDensity) -> Result<Self, FeError> {
        d.validate()?;
        let mn = p.normal_module_m;
        let b = p.face_width_m;
        let r_bore = 0.5 * p.bore_diameter_m;
        let r_k = g.rf - d.rim_depth_mn * mn;
        if r_k.partial_cmp(&(1.05 * r_bore)) != Some(std::cmp::Ordering::Greater)
            || b.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater)
        {
            return Err(FeError::InvalidInput(format!(
                "gear mesh: rim radius r_f − rim_depth = {r_k} m must exceed 1.05 × the bore \
                 radius {r_bore} m (and b = {b} m > 0)"
            )));
        }
        let z = g.z as usize;
        let estimate = d.estimated_elements(z, r_k / r_bore);
        if estimate > MAX_ESTIMATED_ELEMENTS as f64 {
            return Err(FeError::InvalidInput(format!(
                "gear mesh density: about {estimate:.0} elements for this gear (z = {z}), \
                 allowed at most {MAX_ESTIMATED_ELEMENTS} (fewer layers or elements per tooth)"
            )));
        }
        let pitch = g.angular_pitch();
        let fine_half = half_sector(g, d, true, r_k)?;
        let coarse_half = half_sector(g, d, false, r_k)?;
        let mut pool = Pool::new(1e-9 * g.ra);
        let mut quads: Vec<[usize; 8]> = Vec::new();
        let mut push = |pool: &mut Pool, q: [P2; 8]| {
            let q = ccw(q);
            let mut ids = [0usize; 8];
            for (k, id) in ids.iter_mut().enumerate() {
                *id = pool.add(q[k], k < 4);
            }
            quads.push(ids);
        };
        let mut flank_ids: Vec<Vec<usize>> = Vec::with_capacity(z);
        // Whether each quad of the teeth's sectors belongs to a tooth that keeps the layers.
        let mut tooth_layered: Vec<bool> = Vec::new();
        let layered = d.layered_teeth.unwrap_or(d.fine_teeth);
        for k in 0..z {
            let offset = if k <= z / 2 { k as i64 } else { k as i64 - z as i64 };
            let fine = offset.unsigned_abs() as usize <= d.fine_teeth;
            let keeps = offset.unsigned_abs() as usize <= layered;
            let hs = if fine { &fine_half } else { &coarse_half };
            let th = pitch * k as f64;
            for (qi, q) in hs.quads.iter().enumerate() {
                push(&mut pool, q.map(|p| rot2(p, th)));
                push(&mut pool, q.map(|p| rot2([p[0], -p[1]], th)));
                // A fine tooth beyond `layered_teeth` keeps the layers below F → M.
                let keep = keeps || (fine && qi >= hs.tooth_quads);
                tooth_layered.extend([keep, keep]);
            }
            // Corner rows of the flank, tip → root.
            let ids: Vec<usize> =
                hs.rows.iter().step_by(2).rev().map(|r| pool.add(rot2(r.1, th), true)).collect();
            flank_ids.push(ids);
        }
        // Web rings: outer boundary = corner nodes on r_K.
        let tol = 1e-9 * g.ra;
        let mut angles: Vec<f64> = (0..pool.pts.len())
            .filter(|&i| pool.corner[i] && (pool.pts[i][0].hypot(pool.pts[i][1]) - r_k).abs() < tol)
            .map(|i| pool.pts[i][1].atan2(pool.pts[i][0]).rem_euclid(2.0 * PI))
            .collect();
        angles.sort_by(f64::total_cmp);
        let mut web_radii = vec![r_k];
        let mut r_o = r_k;
        let q = d.web_ring_ratio;
        let mut m = angles.len();
        while m / 3 >= d.web_min_divisions && r_o * q > r_bore * 1.02 {
            let r_i = r_o * q;
            let r_m = 0.5 * (r_o + r_i);
            let mut inner = Vec::new();
            let mut k = 0;
            while k < m {
                let a = |i: usize| {
                    if i >= m { angles[i - m] + 2.0 * PI } else { angles[i] }
                };
                if m - k >= 3 {
                    let (a0, a1, a2, a3) = (a(k), a(k + 1), a(k + 2), a(k + 3));
                    let o = [polar(r_o, a0), polar(r_o, a1), polar(r_o, a2), polar(r_o, a3)];
                    let (b0, b1) = (polar(r_i, a0), polar(r_i, a3));
                    let cells = |c1: P2, c2: P2| {
                        [
                            [o[0], o[1], c1, b0],
                            [o[1], o[2], c2, c1],
                            [o[2], o[3], b1, c2],
                            [c1, c2, b1, b0],
                        ]
                        .map(web_quad)
                    };
                    // The middle nodes at the thirds of the group's angle; where the outer
                    // intervals are so unequal that a cell folds, at the angles of the outer
                    // nodes (module docs, "Folded blocks").
                    let mut group = cells(
                        polar(r_m, a0 + (a3 - a0) / 3.0),
                        polar(r_m, a0 + 2.0 * (a3 - a0) / 3.0),
                    );
                    if group.iter().any(|c| quad_folds(c, 1.0)) {
                        group = cells(polar(r_m, a1), polar(r_m, a2));
                    }
                    for cq in group {
                        push(&mut pool, cq);
                    }
                    inner.push(a0);
                    k += 3;
                } else {
                    let (a0, a1) = (a(k), a(k + 1));
                    push(
                        &mut pool,
                        web_quad([polar(r_o, a0), polar(r_o, a1), polar(r_i, a1), polar(r_i, a0)]),
                    );
                    inner.push(a0);
                    k += 1;
                }
            }
            angles = inner;
            m = angles.len();
            r_o = r_i;
            web_radii.push(r_o);
        }
        let n_plain = ((r_o / r_bore).ln() / (1.0 / q).ln()).ceil().max(1.0) as usize;
        for ring in 0..n_plain {
            let r1 = r_o * (r_bore / r_o).powf(ring as f64 / n_plain as f64);
            let r2 = if ring + 1 == n_plain {
                r_bore
            } else {
                r_o * (r_bore / r_o).powf((ring + 1) as f64 / n_plain as f64)
            };
            for k in 0..m {
                let a0 = angles[k];
                let a1 = if k + 1 == m { angles[0] + 2.0 * PI } else { angles[k + 1] };
                push(
                    &mut pool,
                    web_quad([polar(r1, a0), polar(r1, a1), polar(r2, a1), polar(r2, a0)]),
                );
            }
            web_radii.push(r2);
        }
        if let Some(i) = (0..pool.pts.len()).find(|&i| pool.corner[i] && pool.mid[i]) {
            return Err(FeError::InvalidInput(format!(
                "gear mesh: transverse node at {:?} is a corner of one quad and a mid-edge node \
                 of another (non-conforming density)",
                pool.pts[i]
            )));
        }

        // Extrusion: fine quads in `layers` layers, coarse quads (axial coarsening) in
        // `coarse_layers`, each coarse layer `ratio` fine layers high. Node levels are counted
        // on the fine grid (2·layers + 1, corner and mid-layer).
        let levels = 2 * d.layers + 1;
        let level_z: Vec<f64> = (0..levels).map(|l| b * l as f64 / (levels - 1) as f64).collect();
        let ratio = d.coarse_layers.map_or(1, |c| d.layers / c);
        let fine_range = (layered as f64 + 0.5) * pitch;
        let quad_coarse: Vec<bool> = (0..quads.len())
            .map(|qi| {
                ratio > 1
                    && match tooth_layered.get(qi) {
                        Some(&keep) => !keep,
                        None => !overlaps_angle(&quads[qi].map(|i| pool.pts[i]), fine_range),
                    }
            })
            .collect();
        // Node (i, l) exists where l is a multiple of the smallest level step of the quads
        // using transverse node i: 1 at a fine corner, 2 at a fine mid-edge node, `ratio` and
        // 2·`ratio` on coarse quads.
        let n2 = pool.pts.len();
        let mut step = vec![usize::MAX; n2];
        for (qi, qd) in quads.iter().enumerate() {
            let h = if quad_coarse[qi] { ratio } else { 1 };
            for (k, &i) in qd.iter().enumerate() {
                step[i] = step[i].min(if k < 4 { h } else { 2 * h });
            }
        }
        for (i, s) in step.iter_mut().enumerate() {
            if *s == usize::MAX {
                *s = if pool.corner[i] { 1 } else { 2 };
            }
        }
        const NONE: usize = usize::MAX;
        let mut node_at = vec![NONE; n2 * levels];
        // The transverse point `p` at height z: turned with the helix by ω·z.
        let at_height = |p: P2, z: f64| {
            let t = rot2(p, g.twist_rate * z);
            [t[0], t[1], z]
        };
        let mut nodes = Vec::new();
        for (l, &zl) in level_z.iter().enumerate() {
            for (i, p) in pool.pts.iter().enumerate() {
                if l.is_multiple_of(step[i]) {
                    node_at[i * levels + l] = nodes.len();
                    nodes.push(at_height(*p, zl));
                }
            }
        }
        let missing =
            || FeError::InvalidInput("gear mesh: internal: a node level is missing".into());
        let at = |l: usize, i2: usize| -> Result<usize, FeError> {
            match node_at[i2 * levels + l] {
                NONE => Err(missing()),
                id => Ok(id),
            }
        };
        let mut elements = Vec::with_capacity(quads.len() * d.layers);
        let mut congruence = Vec::with_capacity(quads.len() * d.layers);
        let mut bottom = vec![NONE; quads.len()];
        for layer in 0..d.layers {
            for (qi, qd) in quads.iter().enumerate() {
                let (h, k) = if quad_coarse[qi] {
                    if !layer.is_multiple_of(ratio) {
                        continue;
                    }
                    (ratio, layer / ratio)
                } else {
                    (1, layer)
                };
                let (lb, lm, lt) = (2 * h * k, 2 * h * k + h, 2 * h * (k + 1));
                let mut conn = [0usize; NODES];
                for c in 0..4 {
                    conn[c] = at(lb, qd[c])?;
                    conn[4 + c] = at(lt, qd[c])?;
                    conn[8 + c] = at(lb, qd[4 + c])?;
                    conn[12 + c] = at(lt, qd[4 + c])?;
                    conn[16 + c] = at(lm, qd[c])?;
                }
                if k == 0 {
                    bottom[qi] = elements.len();
                    congruence.push(None);
                } else {
                    congruence.push(Some(Congruent {
                        source: bottom[qi],
                        angle: g.twist_rate * level_z[lb],
                    }));
                }
                elements.push(conn);
            }
        }
        // Hanging nodes: levels of a transverse node that a coarse quad uses but has no node
        // at, tied to that quad's element face ("Axial coarsening" in the module docs).
        let mut ties = Vec::new();
        if ratio > 1 {
            let mut coarse_at: Vec<Option<(usize, usize)>> = vec![None; n2];
            for (qi, qd) in quads.iter().enumerate() {
                if quad_coarse[qi] {
                    for (k, &i) in qd.iter().enumerate() {
                        coarse_at[i].get_or_insert((qi, k));
                    }
                }
            }
            for l in 0..levels {
                for (i, c) in coarse_at.iter().enumerate() {
                    let (Some((qi, k)), node) = (*c, node_at[i * levels + l]) else { continue };
                    let own = if k < 4 { ratio } else { 2 * ratio };
                    if node == NONE || l.is_multiple_of(own) {
                        continue;
                    }
                    let kk = l / (2 * ratio);
                    let (a, m, top) =
                        (2 * ratio * kk, 2 * ratio * kk + ratio, 2 * ratio * (kk + 1));
                    let zeta = (l as f64 - m as f64) / ratio as f64;
                    let masters = if k < 4 {
                        vec![
                            (at(a, i)?, 0.5 * zeta * (zeta - 1.0)),
                            (at(m, i)?, 1.0 - zeta * zeta),
                            (at(top, i)?, 0.5 * zeta * (zeta + 1.0)),
                        ]
                    } else {
                        let qd = &quads[qi];
                        let (c1, c2) = (qd[k - 4], qd[(k - 3) % 4]);
                        let bubble = 1.0 - zeta * zeta;
                        vec![
                            (at(a, i)?, 0.5 * (1.0 - zeta)),
                            (at(top, i)?, 0.5 * (1.0 + zeta)),
                            (at(m, c1)?, 0.5 * bubble),
                            (at(m, c2)?, 0.5 * bubble),
                            (at(a, c1)?, -0.25 * bubble),
                            (at(top, c1)?, -0.25 * bubble),
                            (at(a, c2)?, -0.25 * bubble),
                            (at(top, c2)?, -0.25 * bubble),
                        ]
                    };
                    ties.push(Tie { node, masters });
                }
            }
        }
        let mesh = Mesh::new(nodes, elements)?;
        let bore_nodes = mesh.nodes_where(|x| x[0].hypot(x[1]) < r_bore + tol);

        // Flank grids.
        let mut flanks = Vec::with_capacity(z);
        for (k, ids) in flank_ids.iter().enumerate() {
            let offset = if k <= z / 2 { k as i64 } else { k as i64 - z as i64 };
            let fine = offset.unsigned_abs() as usize <= d.fine_teeth;
            let hs = if fine { &fine_half } else { &coarse_half };
            let rows: Vec<&(f64, P2, SegmentKind)> = hs.rows.iter().step_by(2).rev().collect();
            let th = pitch * k as f64;
            // A fine tooth's grid has every level, also where its elements are coarse (the
            // loaded tooth's neighbours with `layered_teeth`): such points have no node.
            let tooth_levels: Vec<usize> = match ids.first() {
                Some(_) if fine => (0..levels).collect(),
                Some(&i0) => (0..levels).filter(|&l| l.is_multiple_of(step[i0])).collect(),
                None => Vec::new(),
            };
            let mut grid_nodes = Vec::with_capacity(rows.len() * tooth_levels.len());
            let mut points = Vec::with_capacity(rows.len() * tooth_levels.len());
            let mut normals = Vec::with_capacity(rows.len() * tooth_levels.len());
            for (row, &i2) in rows.iter().zip(ids.iter()) {
                let (nu, pl, _) = **row;
                // Outward normal of the helicoid X(s, z) = Rot(θ + ωz)·P(s) + z·e_z:
                // N ∝ (Rot·n_t, −ω·(P × n_t)).
                let cross = pl[0] * nu.sin() - pl[1] * nu.cos();
                let axial = -g.twist_rate * cross;
                let norm = (1.0 + axial * axial).sqrt();
                for &l in &tooth_levels {
                    let n_t = rot2([nu.cos(), nu.sin()], th + g.twist_rate * level_z[l]);
                    grid_nodes.push(Some(node_at[i2 * levels + l]).filter(|&n| n != NONE));
                    points.push(at_height(pool.pts[i2], level_z[l]));
                    normals.push([n_t[0] / norm, n_t[1] / norm, axial / norm]);
                }
            }
            flanks.push(FlankGrid {
                tooth: k,
                rows: rows.len(),
                cols: tooth_levels.len(),
                levels: tooth_levels,
                nodes: grid_nodes,
                points,
                nu: rows.iter().map(|r| r.0).collect(),
                local: rows.iter().map(|r| r.1).collect(),
                kind: rows.iter().map(|r| r.2).collect(),
                normals,
            });
        }
        Ok(Self {
            mesh,
            bore_nodes,
            flanks,
            level_z,
            web_radii,
            r_bore,
            quads: quads.len(),
            ties,
            congruence,
            twist_rate: g.twist_rate,
        })
    }

    /// The congruence of the axial layers: an element of layer L of its quad's layering is
    /// that quad's bottom element turned about the axis by ω·z_L (z_L the bottom of layer L)
    /// and moved up by z_L, since every node at height z is its transverse node turned by ω·z
    /// ([`Congruent`]; the bottom layer has no entry). [`super::assembly::assemble_lower_congruent`]
    /// then integrates the elements of the bottom layer only.
    pub fn layer_congruence(&self) -> Vec<Option<Congruent>> {
        self.congruence.clone()
    }

    /// The flank grid of the tooth `offset` teeth counter-clockwise from tooth 0 (negative:
    /// clockwise).
    pub fn flank(&self, offset: i32) -> Option<&FlankGrid> {
        let z = self.flanks.len() as i64;
        if z == 0 {
            return None;
        }
        self.flanks.get((offset as i64).rem_euclid(z) as usize)
    }
}
