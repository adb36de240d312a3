//! The `table` fidelity: a surrogate of the full mesh model over (mesh phase, TE).
//!
//! With rigid bearings the elastic mesh outputs depend on the two hub angles only through the
//! mesh phase (the pinion angle reduced to one pitch, [`crate::contact::ContactSolver::reduce`])
//! and the transmission error: M_F,p = f(phase, TE). The table samples the full model once
//! per parameter set on a grid
//!
//! * phase: `table_phase_points` uniform nodes over one pinion pitch, periodic;
//! * TE, driving flanks: `table_te_points` nodes on [0, TE_hi] with TE_hi = 4× the largest
//!   static TE (over 8 phases) at the design torque `table_design_torque_nm` of
//!   [`MeshOptions`](super::MeshOptions) (default 100 N·m, Table 1's torque; the drive-line
//!   units set it to max(|M|, 1 N·m) of their torque M), the table's nominal torque (heavy
//!   overload: about 4–5× the torque);
//! * TE, back flanks: `table_te_points` nodes on [−j_t − TE_hi/2, −j_t] (j_t the backlash
//!   along the line of action), sampled at the first state that needs them (see "Back flanks
//!   on demand" below).
//!
//! The TE nodes are graded quadratically towards the onset (distance δ_k ∝ k²), uniform in
//! u = √δ: the first cells, where the load is a small fraction of nominal and the Hertzian
//! logarithm bends the curve most, are fine, the last ones twice the uniform size.
//!
//! **Where the model stops holding.** Under heavy overload the flanks of the neighbouring pairs
//! overlap at the tip roundings, and beyond some TE the load problem is no longer well posed:
//! the load solver proves the compliance of the slices it has to load is not a P-matrix, even
//! after its continuation retry, and the full model reports the state out of range
//! ([`MeshError::OutOfRange`]). A table row that meets such a node
//! ends there, and the axis keeps the nodes every phase row reached; the first m of the n
//! graded nodes are exactly an m-node axis, so nothing is resampled. The last node is then
//! checked at every phase-cell centre, and the error check's cell centres are evaluated too; an
//! out-of-range state there cuts the axis below it. The cut is recorded
//! ([`MeshTable::truncations`]); it is an error only when the driving axis would end below the
//! nominal static TE or keep fewer than 4 nodes. States beyond the cut fall back to the full
//! model as any state outside the table does. Measured for β = 18.5°, b = 10.7 mm at 200 N·m
//! (`tests/mesh.rs`, coarse FE): the driving axis ends at 2.1× the nominal static TE (designed
//! 4×) and agrees with the full model within 2 % below; at 100 N·m the whole designed range
//! is well posed and nothing is cut (default FE: 253 µm, no cut; 200 N·m: 345 of 500 µm).
//!
//! # Back flanks on demand
//! A drive line that keeps its flanks in contact never reaches the back flanks; only a loss of
//! contact deeper than the backlash (rattle, a torque reversal) does. The build therefore
//! samples the driving axis alone, and the back-flank axis is sampled, whole and in the same
//! way (phase rows over the cores, each row from a cold start, cut at the model's range),
//! the first time a state with TE < −j_t is evaluated or a caller asks for the covered range
//! ([`MeshTable::te_range`], [`MeshTable::truncations`], [`MeshTable::sizes`]). That takes
//! about the time of the driving axis, once per table (every mesh sharing the table shares
//! it); the values do not depend on when it happens, so results do not depend on the call
//! history. The build does half the work: the default table samples 96 × 24 nodes instead of
//! 96 × 48. A back-flank axis whose sampling fails (not four well-posed nodes) is
//! recorded as a cut to nothing: back-flank states then fall back to the full model, which
//! reports its own error where it has one.
//! The pose sensitivities ([`PoseTable`]) follow the same rule: their build samples the driving
//! flanks, and their back-flank part waits for the first posed state on the back flanks.
//!
//! Between −j_t and 0 no flank can touch (the real flanks lie inside the full involutes, whose
//! overlap is TE, resp. −TE − j_t), so the outputs there are exactly zero and need no nodes.
//! Outside [−j_t − TE_hi/2, TE_hi] the model falls back to the full solve.
//!
//! Interpolated per node: the secant quantities M_F,p/δ, M_F,g/δ, F_n/δ, p_max²/δ and the
//! tooth-root stresses σ_F,p/δ, σ_F,g/δ ([`MeshOutputs::root_stress_p`]), with
//! δ = |TE − TE_onset| the distance from the TE at which the flanks of that axis start to
//! touch (0, resp. −j_t), and the loaded axial extent Σ(ζ_e − ζ_b) (from which the contact
//! length and, with the current speeds, the damping torques of Eq. 14 follow exactly as in the
//! full model). The secant form matters at light load: M_F(TE) starts at the onset with a
//! logarithmic Hertzian correction (u_c ∝ q·ln q) that a cubic in TE cannot follow in
//! relative terms, whereas M_F/δ varies slowly and smoothly; the node at the onset takes the
//! limit from the loaded side. The interpolant is the
//! tensor product of cubic Hermite interpolants with finite-difference slopes (periodic in the
//! phase, one-sided at the TE ends): C¹, exact at the nodes, O(h³) on smooth data, 16 node
//! values per output. The discrete outputs (number of pairs, tip and back contact) are taken
//! from the nearest node.
//!
//! # Force and moments
//! The 3D force and tilting moments ([`super::forces`]) are one block of node values beside
//! the torques: the elastic force on the pinion F_p (x, y, z) and its tilting moment about the
//! pinion centre (x, y), as secants over δ like M_F, and the first axial moment of the loaded
//! extent Z₁ = Σ ζ·Δζ (no δ factor, like the extent). The damping part follows from the
//! current speeds, the extent and Z₁ exactly as in the full model (its flank side is the
//! axis's), and the gear's moments from the transfer formula M_g = −M_p − (C_p − C_g) × F_p.
//! Being linear in the node values, the interpolated force keeps every linear relation that
//! holds at all the nodes it uses (on the involute: F_x/F_y = tan α_wt, F_z/|F_t| = tan β_b).
//! The right-hand side's torques-only path does not read the block. With tooth deviations
//! the block is kept per tooth pair like the torques; the neglected coupling between pairs
//! moves load between pairs, which lie at different places on the face, so the tilting
//! moments are less accurate than the torques there (Table 1's pitch errors: 2.3e-2 of
//! F_nominal·b against 7.2e-3 of the nominal torque, `tests/mesh_forces.rs`).
//!
//! # Friction
//! With friction ([`super::friction`]) each TE axis carries a block of 9 node values beside
//! the others (over δ like the torques): the friction torques, force and tilting moments for
//! μ = 1 with the pinion turning at +1 rad/s and the gear at the rigid ratio −g_p/g_g, pure
//! Coulomb (each slice's force along its sliding direction), and
//! the loss per unit pinion speed L = Σ F_i·|v_t,i| with the part L_p that heats the pinion.
//! The build samples at rest, so the block comes from the loads of the same solves. An
//! evaluation scales the block by κ = μ·g(v̄/v₀)·sign φ̇p: μ from the interpolated elastic
//! M_F,p (ISO/TR 14179-2) or constant, and the regularisation at the load-weighted mean
//! sliding speed v̄ = |φ̇p|·L/F_n. P_loss is the power the friction torques take from the
//! gears, M_R,p·φ̇p + M_R,g·φ̇g (never below 0), which at the rigid ratio is μ·g(v̄/v₀)·|φ̇p|·L
//! and with a TE rate keeps the drive line's energy balance closed. This differs from the full
//! model in two stated ways: the sliding direction is that of the rigid ratio (the full model
//! adds the TE rate, which changes the sliding by (φ̇p·g_p + φ̇g·g_g) against speeds of m/s),
//! and the regularisation acts on the mean sliding speed instead of each slice's (at running
//! speeds only the slices within v₀ of the pitch line differ; near standstill both vanish
//! linearly with the speed). The torques-only path evaluates the whole periodic table when
//! the model has friction. With tooth deviations (the per-pair table) friction is refused at
//! build ([`MeshError::Unsupported`]): use the full fidelity.
//!
//! # Tooth deviations
//! Pitch deviations and runout (`crate::modifications`) make the mesh repeat only after the
//! hunting period, but they are constant over each tooth's flank: tooth pair k is moved as a
//! whole by its deviation e_k along the line of action. The table is therefore built from the
//! periodic part of the modifications (the same on every tooth) and keeps the driving-flank
//! node values **per tooth pair** (M_F,p, M_F,g, F_n, p_max² of each pair's slices, its
//! loaded extent and the root stresses of its teeth, pairs numbered in the table's phase
//! frame). An evaluation interpolates every pair that can be in mesh at its own TE − e_k and
//! sums (p_max and the root stresses: the largest). This is exact
//! where the pairs are uncoupled and their contacts lie in the plane of action, whatever the
//! deviations (loss of contact of a single pair included), and exact for equal deviations
//! (a TE shift). It neglects (a) the coupling between pairs through the gear bodies beyond
//! first order (to first order the symmetric compliance makes the per-pair split exact), and
//! (b) for contacts off the plane of action (tips, relief corners), the difference between
//! moving the tooth (the table: contacts at TE − e_k) and subtracting e_k from the overlap at
//! TE (the full model). Measured against the full model for Table 1 with the pitch errors of
//! `docs/modifications/table1_pitch_errors.json` (`tests/modifications.rs`): at most 1.2 % of
//! the nominal torque at light load (TE = 12 µm) and 0.4–0.7 % at 30–60 µm. The cost is one
//! interpolation per pair that can be in mesh (about 4 for Table 1). `evaluate_jacobian`
//! differentiates the same sum pair by pair (each term as on the periodic table, at the pair's
//! TE − e_k).
//!
//! # Default size
//! 96 phase points × 24 TE points on each flank side. On Table 1 against the converged model
//! (800 slices; the errors are the interpolation's, the 100 sample slices add 4.4·10⁻⁵), the
//! largest relative error of M_F,p where |M_F,p| > 1 N·m of the default and of other grids
//! (the build time goes with the nodes):
//!
//! | grid | nodes | benchmark's 192 states | 2 000 random states, TE ≤ 51 µm (RMS) | 2 000 random states, TE ≤ 120 µm (RMS) | own check |
//! | --- | --- | --- | --- | --- | --- |
//! | 64 × 48 (the default before) | 3 072 | 2.70·10⁻⁴ | 1.30·10⁻³ (8.2·10⁻⁵) | 1.28·10⁻³ (4.8·10⁻⁵) | 7.3·10⁻⁴ |
//! | 96 × 24 (default) | 2 304 | 1.99·10⁻⁴ | 7.3·10⁻⁴ (5.4·10⁻⁵) | 4.2·10⁻⁴ (3.0·10⁻⁵) | 3.4·10⁻⁴ |
//! | 96 × 32 | 3 072 | 1.17·10⁻⁴ | 5.7·10⁻⁴ (3.9·10⁻⁵) | 4.4·10⁻⁴ (2.2·10⁻⁵) | 3.1·10⁻⁴ |
//! | 80 × 24 | 1 920 | 1.48·10⁻⁴ | 1.86·10⁻³ (7.8·10⁻⁵) | | 4.6·10⁻⁴ |
//! | 112 × 16 | 1 792 | 4.08·10⁻⁴ | 2.13·10⁻³ (1.1·10⁻⁴) | 7.3·10⁻⁴ (6.6·10⁻⁵) | 6.2·10⁻⁴ |
//! | 96 × 16 | 1 536 | 4.10·10⁻⁴ | 1.88·10⁻³ (1.0·10⁻⁴) | 1.42·10⁻³ (7.3·10⁻⁵) | 9.9·10⁻⁴ |
//!
//! For M_F,p the phase direction sets the error (the kinks where a contact line starts or
//! ends on a relief or a tip) and 24 TE points are enough: 96 × 24 is more accurate on every
//! measure above than 64 × 48 with three quarters of the nodes (fewer than 24 TE points lose
//! the benchmark's accuracy, 80 phase points the random states'). The damping torque M_D
//! follows the loaded extent, resolved within the slices ([`super::model`], "Slices"), whose
//! remaining table error is the interpolation's at the kinks where a line's loaded part
//! starts to shorten. Against 800 slices, M_D,p with a TE rate (φ̇p = 200, φ̇g = −120 rad/s)
//! is off by up to 5.5·10⁻³ on the benchmark's states and 8.2·10⁻³ on 2 000 random states at
//! 96 × 24, against 8.1·10⁻³ and 1.06·10⁻² at 64 × 48. The back-flank axis has as many TE
//! points as the driving one over half its range: over 1 000 random back-flank states
//! (depth 1–100 % of the axis) M_F,p is off by up to 7.3·10⁻⁴ (RMS 4.5·10⁻⁵) at 96 × 24,
//! against 9.9·10⁻⁴ (6.1·10⁻⁵) on the back axis of 64 × 24 that the 64 × 48 default had.
//!
//! Other designs and the model variant with the neighbour coupling off, each against its own
//! 800-slice model over 400 random states (TE up to half the driving axis, about twice the
//! nominal static TE; the errors are larger than Table 1's, the grids rank differently), the
//! largest relative error of M_F,p (RMS):
//!
//! | design | 64 × 48 | 96 × 24 (default) | 96 × 32 |
//! | --- | --- | --- | --- |
//! | Table 1, neighbour coupling off | 4.5·10⁻³ (4.0·10⁻⁴) | 7.3·10⁻³ (7.6·10⁻⁴) | 3.0·10⁻³ (4.0·10⁻⁴) |
//! | spur (β = 0) | 1.4·10⁻² (9.8·10⁻⁴) | 9.7·10⁻³ (6.7·10⁻⁴) | 7.5·10⁻³ (4.7·10⁻⁴) |
//! | β = 20°, b = 25 mm | 3.0·10⁻³ (3.9·10⁻⁴) | 2.8·10⁻³ (4.3·10⁻⁴) | 2.8·10⁻³ (4.3·10⁻⁴) |
//!
//! Without the neighbour coupling 24 TE points lose the 64 × 48 table's accuracy (the
//! linearised stiffness at φp = 0 of the paper run's sensitivity case is 96.31 N/µm on the
//! default table, 96.48 at 64 × 48, 96.45 in the full model); a study of that variant, or of
//! a design whose own check ([`MeshTable::max_rel_err`]) is too large, wants more TE points
//! (96 × 32, with as many nodes as 64 × 48, has the smaller largest error on every row above).
//!
//! # Sample slices
//! The table samples the full model at min(`slices`, `table_slices`) total slices
//! ([`MeshOptions::table_sample_slices`](super::MeshOptions::table_sample_slices), default
//! min(200, 100)): the full model built again at that count ([`MeshModel::with_slices`]), the
//! same compliance data, its pose sensitivities and back-flank axis too. The full model
//! outside the table keeps `slices`. The reason is the balance of the two errors in a table
//! value against the converged model (800 slices). Measured on the 64 × 48 table (the
//! default then), the interpolation's error is 2.8·10⁻⁴ of
//! M_F,p on the benchmark's 192 states and 1.1·10⁻³ on random states; the
//! discretisation's is 4.4·10⁻⁵ at 100 slices and 9.3·10⁻⁶ at 200. Sampling at 200 slices
//! therefore buys nothing the interpolation keeps, at three times the cost per node (the
//! performance page's full evaluations: 231 µs at 100 slices, 706 µs at 200). Measured for
//! Table 1 against 800 slices, the largest relative error of M_F,p (`tests/table_slices.rs`
//! holds the default's row):
//!
//! | table | sampled at 200 slices | at 100 | at 75 | at 50 |
//! | --- | --- | --- | --- | --- |
//! | 32 × 24, benchmark states | 1.36·10⁻³ | 1.35·10⁻³ | | 1.38·10⁻³ |
//! | 96 × 24 (default), benchmark states | 1.93·10⁻⁴ | 1.99·10⁻⁴ | 3.37·10⁻⁴ | 4.16·10⁻⁴ |
//! | 96 × 24, 300 random states, TE ≤ 51 µm | 4.05·10⁻⁴ | 4.17·10⁻⁴ | 4.02·10⁻⁴ | |
//! | 64 × 48, benchmark states | 2.76·10⁻⁴ | 2.70·10⁻⁴ | 2.66·10⁻⁴ | 3.34·10⁻⁴ |
//! | 64 × 48, 300 random states, TE ≤ 51 µm | 1.12·10⁻³ | 1.13·10⁻³ | 1.03·10⁻³ | |
//! | 64 × 48, 400 random states, TE ≤ 120 µm | 4.7·10⁻⁴ | 6.5·10⁻⁴ | | |
//! | 128 × 96, benchmark states | 8.76·10⁻⁵ | 8.71·10⁻⁵ | 1.31·10⁻⁴ | |
//!
//! 100 slices is the default because it leaves the benchmark's error of every table size up to
//! 128 × 96 where it was, and the largest error over random states (1.1·10⁻³ at 64 × 48, set by
//! the phase interpolation) too; 75 already moves the 128 × 96 table's and the default
//! 96 × 24's. At heavy load the 100 slices show (6.5·10⁻⁴ against 4.7·10⁻⁴ at TE up to 120 µm,
//! still below that largest error). The damping torque M_D and the contact length follow the
//! loaded extent, resolved within the slices and second order in the slice width: the full
//! model's M_D is off by up to 8.2·10⁻⁴ at 100 slices and 2.0·10⁻⁴ at 200 against 1 600
//! (benchmark states with a TE rate), so the table's M_D error is its interpolation's (5.5·10⁻³
//! sampled at 100 slices and 5.6·10⁻³ at 200 on the default 96 × 24; 8.1·10⁻³ at 100, 8.2·10⁻³
//! at 80 and 8.7·10⁻³ at 64 on 64 × 48). A finer table than 128 × 96, a table that stands for a
//! full model of more than 100 slices at its nodes, or a study of the damping's share wants a
//! larger `table_slices`; `table_slices = slices` gives the table of the full model's slices
//! bit for bit.
//!
//! After the build the table measures its own error: it evaluates the full model at cell
//! centres (where the interpolation error is largest) and records the largest relative error
//! of M_F,p where |M_F,p| exceeds 1 % of the nominal torque ([`MeshTable::max_rel_err`]). It
//! is the interpolation's error against the sampled model (at the sample slices).
//!
//! # Vector code
//! An evaluation of every output is a few hundred floating-point operations: the cell's 4 × 4
//! nodes weighted, 13 values each, the wrench and the damping, plus the exact TE and phase
//! reduction ([`crate::numeric`]). The library is built for the baseline x86-64 (SSE2), where
//! the weighted sums run two lanes wide and each exact product calls the C library's `fma`.
//! Where the CPU has AVX2 and FMA (checked per call against the standard library's cached
//! answer, [`crate::numeric::has_avx2_fma`]), [`TableMesh::evaluate`]
//! runs the same code compiled for those extensions: four lanes, `fma` as one instruction.
//! The operations and their order are the same, and no multiply and add is fused that the
//! portable code rounds twice (Rust never contracts them), so the outputs are the same bit for
//! bit (unit test below); a CPU without them runs the portable code. On Table 1's default table
//! this takes about a sixth off an evaluation of every output (CHANGELOG, 2026-11-28).
//!
//! The right-hand side's [`MeshTorques::torques_into`] reads four values per node: the lanes
//! have little to do, and its time is the latency of one chain of dependent operations (TE,
//! phase reduction, cell, weights, loads, sums). Where the CPU has FMA and SSE4.1 (detected
//! once, when the mesh is made) that path runs compiled for them, with the whole chain inlined
//! into it: the exact products of the TE and of the phase reduction as one `fma` instruction
//! each instead of a call into the C library (which also spills every float register of the
//! caller), and the floors and roundings of the cell search ([`crate::numeric::floor_with`],
//! [`crate::numeric::round_with`]) as the SSE4.1 rounding instructions instead of their
//! portable equivalents (a conversion to an integer and back, and a compare). The evaluation
//! of every output uses the same floors in its AVX2 path. Floors, roundings and fused
//! multiply-adds are exact, so the values are the same bit for bit (the same unit test). The
//! cell's coordinates multiply by the reciprocal of the phase spacing and of the TE axis's
//! range (`TeAxis::coordinate`), computed beside the chain, instead of dividing inside it
//! (a rounding of the coordinate, 10⁻¹⁶ of a node spacing, against the division's).
//! Together, on Table 1's default table: the torques path 69 → 54 ns, every output
//! 118 → 105 ns, the Drive unit at 96 RK4 sub-steps 9.3 → 11.0× real time (CHANGELOG,
//! 2026-11-29). An earlier attempt, the torques path compiled for AVX2 without inlining its
//! chain, lost its inlining into the drive line's evaluation cache and ran slower.

use std::sync::Arc;

use super::forces::MeshWrench;
use super::friction::{FrictionConst, add_friction_jacobian, set_efficiency};
use super::model::{FRICTION_NODE, FullMesh, MeshModel, PairSum, WarmStart, damping_rows};
use super::pose::{RelativePose, approach_rate, to_housing};
use super::{MeshError, MeshJacobian, MeshOutputs, MeshState, MeshTorques};
use crate::contact::FlankSide;
use crate::modifications::Separation;
use crate::numeric::floor_with;

mod build;
mod pose;

pub use pose::{POSE_STEP_MN, PoseTable, TABLE_POSE_BOUND_MN};

/// Most nodes of one table, `table_phase_points` × `table_te_points` (each axis 8 … 4096):
/// the build evaluates the full model about once per node (the driving axis and its checks),
/// the back-flank axis as many nodes again at its first need.
/// 65 536 nodes (e.g. 256 × 256) take about a minute in all.
/// A 4096 × 4096 table (1.7·10⁷ nodes) would take hours and GB.
pub const MAX_TABLE_NODES: usize = 65_536;

/// Points of either table axis (`table_phase_points`, `table_te_points`): 8 … 4096, and at most
/// [`MAX_TABLE_NODES`] nodes together (checked by [`check_table_size`]).
pub const TABLE_POINTS: crate::params::Bounds<i64> = crate::params::Bounds::new(8, 4096, "");

/// Checks the table's size: each axis [`TABLE_POINTS`] and at most [`MAX_TABLE_NODES`] nodes
/// (phase × TE points). The error names the option, its value and the bound.
pub fn check_table_size(
    phase_points: usize,
    te_points: usize,
) -> Result<(), crate::error::ParamError> {
    use crate::error::ParamError;
    let int = |n: usize| i64::try_from(n).unwrap_or(i64::MAX);
    TABLE_POINTS.check_int("table_phase_points", int(phase_points))?;
    TABLE_POINTS.check_int("table_te_points", int(te_points))?;
    let nodes = phase_points * te_points;
    if nodes > MAX_TABLE_NODES {
        return Err(ParamError::new(
            "table_phase_points",
            phase_points as f64,
            format!(
                "table_phase_points × table_te_points <= {MAX_TABLE_NODES} (about a minute of \
                 build; {phase_points} × {te_points} = {nodes:.3e} nodes would take about \
                 {:.0} minutes)",
                nodes as f64 / MAX_TABLE_NODES as f64
            ),
        ));
    }
    Ok(())
}

/// Most node × slice evaluations of one table build: [`MAX_TABLE_NODES`] at 100 slices. A
/// node's full evaluations cost at least in proportion to the slices (contact search, load
/// solve): 65 536 nodes took 127 s at 200 slices, so the bound is about a minute whatever the
/// slices, where the node bound alone allowed two minutes at 200 slices and more beyond.
pub const MAX_TABLE_SLICE_NODES: f64 = 65_536.0 * 100.0;

/// Checks `table_slices` against [`super::model::SLICES`] (at every fidelity) and the work
/// of building the table of `options` (at [`super::Fidelity::Table`] only):
/// `table_phase_points` × `table_te_points` × the sample slices
/// ([`super::MeshOptions::table_sample_slices`]) ≤ [`MAX_TABLE_SLICE_NODES`]. The error names
/// the option, the value or the work, and the bound.
pub fn check_table_work(options: &super::MeshOptions) -> Result<(), crate::error::ParamError> {
    let cap = options.table_slices;
    super::model::SLICES.check_int("table_slices", i64::try_from(cap).unwrap_or(i64::MAX))?;
    if options.fidelity != super::Fidelity::Table {
        return Ok(());
    }
    let slices = options.table_sample_slices();
    let (np, nt) = (options.table_phase_points, options.table_te_points);
    let work = np as f64 * nt as f64 * slices as f64;
    if work > MAX_TABLE_SLICE_NODES {
        return Err(crate::error::ParamError::new(
            "table_phase_points",
            np as f64,
            format!(
                "table_phase_points × table_te_points × min(slices, table_slices) <= \
                 {MAX_TABLE_SLICE_NODES:.4e} node-slices (about a minute of build; {np} × {nt} \
                 × {slices} = {work:.3e} would take about {:.1} minutes): fewer table points or \
                 fewer slices",
                work / MAX_TABLE_SLICE_NODES
            ),
        ));
    }
    Ok(())
}

/// Design torque of the table `table_design_torque_nm` ([`super::MeshOptions`]): 1 N·m …
/// 1e9 N·m (the drive line's torque limit, [`crate::params::DRIVE_TORQUE_NM`]; below 1 N·m
/// the static TE of most designs is lost in the light-load grading, and the units round a
/// smaller |M| up to 1 N·m), N·m.
pub const TABLE_DESIGN_TORQUE_NM: crate::params::Bounds<f64> =
    crate::params::Bounds::new(1.0, 1e9, "N.m");

/// Checks the table's design torque against [`TABLE_DESIGN_TORQUE_NM`]; the error names the
/// option `table_design_torque_nm`, its value and the range.
pub fn check_design_torque(torque_nm: f64) -> Result<(), crate::error::ParamError> {
    TABLE_DESIGN_TORQUE_NM.check("table_design_torque_nm", torque_nm)
}

// Node values: 0 M_F,p/δ, 1 M_F,g/δ, 2 F_n/δ, 3 loaded extent, 4 p_max²/δ, then the block of
// the 3D force and moments (module docs, "Force and moments").
/// Node values 5, 6, 7: the elastic force on the pinion F_p (x, y, z) over δ.
const V_FORCE_P: usize = 5;
/// Node values 8, 9: the elastic tilting moment on the pinion M_p (x, y) over δ.
const V_MOMENT_P: usize = 8;
/// Node value 10: the first axial moment of the loaded extent Z₁ = Σζ·Δζ (no δ factor).
const V_FIRST_MOMENT: usize = 10;
/// Node values 11, 12: the tooth-root stresses σ_F,p/δ and σ_F,g/δ (Pa/m), secant as the
/// torques ([`crate::compliance::root_stress`]).
const V_ROOT_STRESS_P: usize = 11;
/// See [`V_ROOT_STRESS_P`].
const V_ROOT_STRESS_G: usize = 12;
/// Number of interpolated real-valued outputs per node.
const NV: usize = 13;

/// One TE axis (driving or back flanks) of the table: nodes graded towards the onset and the
/// node values. Node k lies at distance δ_k = range·(k/(n − 1))² from the onset.
#[derive(Debug, Clone)]
struct TeAxis {
    /// TE at which the flanks of this axis start to touch (0 driving, −j_t back), m.
    onset: f64,
    /// Direction of loading from the onset: +1 (driving, TE > 0) or −1 (back flanks).
    dir: f64,
    /// Distance from the onset to the last node, m.
    range: f64,
    n: usize,
    /// `values[(ip * n + it) * NV + v]`.
    values: Vec<f64>,
    /// The node values a right-hand side reads, packed per node: `torques[ip * n + it]` =
    /// [M_F,p/δ, M_F,g/δ, loaded extent, 0], copies of `values` 0, 1 and 3 ([`Self::pack`]).
    /// The torques-only evaluation reads 16 of these 32-byte records instead of 16 records
    /// of [`NV`] values spread over 1.7 kB.
    torques: Vec<[f64; 4]>,
    /// `flags[ip * n + it]`: n_pairs | tip << 8 | back << 9.
    flags: Vec<u16>,
    /// The friction block (module docs, "Friction"), `friction[ip * n + it]`: the node values
    /// of [`MeshModel::unit_friction`] over δ; empty when the model has no friction.
    friction: Vec<[f64; FRICTION_NODE]>,
    /// The friction values the torques need, packed per node like [`Self::torques`]:
    /// [M_R,p/δ, M_R,g/δ, L/δ, F_n/δ] ([`Self::pack`]); empty without friction.
    friction_torques: Vec<[f64; 4]>,
}

impl TeAxis {
    /// The axis coordinate (node units, not clamped) of a state at distance `dist` ≥ 0 (m)
    /// from the onset: √(δ/range)·(n − 1) (the graded grid). The reciprocal of the range does
    /// not wait for δ, so the look-up's chain of dependent operations holds a multiply where a
    /// division was.
    #[inline(always)]
    fn coordinate(&self, dist: f64) -> f64 {
        (dist * (1.0 / self.range)).sqrt() * (self.n - 1) as f64
    }

    fn new(onset: f64, dir: f64, range: f64, n: usize, np: usize) -> Self {
        Self {
            onset,
            dir,
            range,
            n,
            values: vec![0.0; np * n * NV],
            torques: vec![[0.0; 4]; np * n],
            flags: vec![0; np * n],
            friction: Vec::new(),
            friction_torques: Vec::new(),
        }
    }

    /// Copies the node values of the torques-only evaluation into [`Self::torques`]; called
    /// whenever `values` is complete.
    fn pack(&mut self) {
        for (t, v) in self.torques.iter_mut().zip(self.values.chunks_exact(NV)) {
            *t = [v[0], v[1], v[3], 0.0];
        }
        self.friction_torques = self
            .friction
            .iter()
            .zip(self.values.chunks_exact(NV))
            .map(|(f, v)| [f[0], f[1], f[7], v[2]])
            .collect();
    }

    /// The packed records `recs` (per node, as [`Self::torques`]) interpolated with the
    /// weights of a cell: the one sum behind both periodic table paths, so that they agree
    /// bit for bit.
    #[inline(always)]
    fn interpolate_packed(
        &self,
        recs: &[[f64; 4]],
        np: i64,
        (wp, ip0): (&[f64; 4], i64),
        (it0, wt, nt): (usize, &[f64; 4], usize),
    ) -> [f64; 4] {
        let mut v = [0.0; 4];
        for (a, &wa) in wp.iter().enumerate() {
            let ip = wrap_index(ip0 + a as i64, np);
            let base = ip * self.n + it0;
            if nt == 4 {
                let row: &[[f64; 4]; 4] = recs[base..base + 4].try_into().expect("4 TE nodes");
                let mut r = [0.0; 4];
                for (x, &wb) in row.iter().zip(wt) {
                    for (rk, &xk) in r.iter_mut().zip(x) {
                        *rk += wb * xk;
                    }
                }
                for (vk, &rk) in v.iter_mut().zip(&r) {
                    *vk += wa * rk;
                }
                continue;
            }
            for (x, &wb) in recs[base..base + nt].iter().zip(wt) {
                let w = wa * wb;
                for (vk, &xk) in v.iter_mut().zip(x) {
                    *vk += w * xk;
                }
            }
        }
        v
    }

    /// Distance of node `k` from the onset, m (node 0 is taken a tenth of the first cell in,
    /// as the limit from the loaded side).
    fn node_distance(&self, k: usize) -> f64 {
        let u = k as f64 / (self.n - 1) as f64;
        if k == 0 {
            0.1 * self.range / ((self.n - 1) * (self.n - 1)) as f64
        } else {
            self.range * u * u
        }
    }

    /// TE of node `k`, m.
    fn node_te(&self, k: usize) -> f64 {
        self.onset + self.dir * self.node_distance(k)
    }

    /// Highest (driving) or lowest (back) TE covered, m.
    fn end(&self) -> f64 {
        self.onset + self.dir * self.range
    }

    /// The axis of the first `m` nodes (2 ≤ m ≤ n): on the graded grid these are exactly the
    /// nodes of an m-node axis over δ_{m−1} (node 0 included), so nothing is resampled.
    fn truncated(&self, m: usize) -> Self {
        let np = self.values.len() / (self.n * NV);
        let mut axis = Self::new(self.onset, self.dir, self.node_distance(m - 1), m, np);
        for ip in 0..np {
            let src = ip * self.n;
            axis.values[ip * m * NV..(ip + 1) * m * NV]
                .copy_from_slice(&self.values[src * NV..(src + m) * NV]);
            axis.flags[ip * m..(ip + 1) * m].copy_from_slice(&self.flags[src..src + m]);
            if !self.friction.is_empty() {
                axis.friction.extend_from_slice(&self.friction[src..src + m]);
            }
        }
        axis.pack();
        axis
    }
}

/// The surrogate table (see the module docs).
#[derive(Debug, Clone)]
pub struct MeshTable {
    phase_lo: f64,
    phase_h: f64,
    np: usize,
    drive: TeAxis,
    /// The back-flank axis as designed (onset −j_t, extent, nodes); it is sampled at the
    /// first state that needs it ([`MeshTable::back_axis`]).
    back_design: BackDesign,
    /// The sampled back-flank axis, once a state on the back flanks (or a caller) needed it.
    back: std::sync::OnceLock<BackFlanks>,
    /// The full model the table samples (kept for the back-flank axis).
    model: Arc<MeshModel>,
    backlash_te: f64,
    /// Pinion pitch (double-double, for the exact phase reduction) and base radii.
    pitch_p: crate::numeric::Pitch,
    rb_p: f64,
    rb_g: f64,
    nominal_torque: f64,
    build_s: f64,
    max_rel_err: f64,
    checked_points: usize,
    /// Per-tooth-pair driving-flank values, with the tooth deviations they are shifted by.
    pairs: Option<PairTable>,
    /// The driving axis cut short at the model's range (see [`TableTruncation`]; the back
    /// flanks' cut is in [`BackFlanks`]).
    truncations: Vec<TableTruncation>,
    /// The pose sensitivities ([`PoseTable`]), built at the first need and shared by every
    /// mesh that shares this table ([`MeshTable::pose_table`]).
    pose: std::sync::OnceLock<Result<Arc<PoseTable>, MeshError>>,
}

/// The back-flank TE axis as designed: `n` nodes over `range` (m) below the onset `onset` = −j_t.
#[derive(Debug, Clone, Copy)]
struct BackDesign {
    onset: f64,
    range: f64,
    n: usize,
}

/// The sampled back-flank axis: `None` when not even four nodes are well posed (no back-flank
/// state is then on the table; every one falls back to the full model), with the cut, if
/// any, and the time its sampling took.
#[derive(Debug, Clone)]
struct BackFlanks {
    axis: Option<TeAxis>,
    truncation: Option<TableTruncation>,
    build_s: f64,
}

/// A TE axis of the table that ends short of its designed extent because the full model is
/// not well posed beyond ([`MeshError::OutOfRange`] at the next node of some phase row). The
/// axis keeps the nodes every phase row reached, on the same graded grid; states beyond fall
/// back to the full model, which reports them out of range.
#[derive(Debug, Clone, PartialEq)]
pub struct TableTruncation {
    /// Which flanks: `"driving"` (TE > 0) or `"back"` (TE < −j_t).
    pub flanks: &'static str,
    /// Distance from the contact onset the axis was designed to cover, m.
    pub designed_m: f64,
    /// Distance from the contact onset it covers, m.
    pub covered_m: f64,
    /// Message of the first out-of-range state beyond the covered extent.
    pub cause: String,
}

/// The driving-flank node values split by tooth pair (see the module docs, "Tooth
/// deviations"): the pair with number `r_lo + r` relative to the table's phase frame at node
/// (ip, it) has its secant values at `values[((ip * n + it) * nr + r) * NV ..]`.
#[derive(Debug, Clone)]
struct PairTable {
    /// The tooth-by-tooth deviations ([`Separation::tooth_offset`]).
    sep: Arc<Separation>,
    r_lo: i64,
    nr: usize,
    values: Vec<f64>,
    /// Bit 0: the pair carries load; bit 1: on a tip (nearest node).
    flags: Vec<u8>,
}

/// A state's place on the periodic table ([`MeshTable::cell`]).
struct Cell<'a> {
    /// The TE axis (driving or back flanks).
    axis: &'a TeAxis,
    /// Phase coordinate in node units, and the weights of phase rows `ip0 … ip0 + 3` (mod np).
    xp: f64,
    wp: [f64; 4],
    ip0: i64,
    /// Distance from the axis's onset, m, and the TE coordinate in node units.
    dist: f64,
    xt: f64,
    /// First TE node, its weights and how many of them (3 at an axis end, else 4).
    it0: usize,
    wt: [f64; 4],
    nt: usize,
}

impl PairTable {
    /// Packs the per-pair samples `(phase row, TE node, pair outputs)` of the driving axis
    /// (pair numbers in the table's phase frame, where the sampled angles need no reduction).
    fn new(
        sep: Arc<Separation>,
        drive: &TeAxis,
        np: usize,
        samples: &[(usize, usize, PairSum)],
    ) -> Self {
        let r_lo = samples.iter().map(|s| s.2.pair).min().unwrap_or(0);
        let r_hi = samples.iter().map(|s| s.2.pair).max().unwrap_or(0);
        let nr = (r_hi - r_lo + 1) as usize;
        let n = drive.n;
        let mut values = vec![0.0; np * n * nr * NV];
        let mut flags = vec![0u8; np * n * nr];
        for &(ip, it, ps) in samples {
            let dist = drive.node_distance(it);
            let slot = (ip * n + it) * nr + (ps.pair - r_lo) as usize;
            let v = &ps.values;
            values[slot * NV..slot * NV + 5].copy_from_slice(&[
                v[0] / dist,
                v[1] / dist,
                v[2] / dist,
                v[3],
                v[4] / dist,
            ]);
            values[slot * NV + V_ROOT_STRESS_P] = v[5] / dist;
            values[slot * NV + V_ROOT_STRESS_G] = v[6] / dist;
            for (k, w) in ps.wrench.iter().enumerate() {
                values[slot * NV + V_FORCE_P + k] = w / dist;
            }
            values[slot * NV + V_FIRST_MOMENT] = ps.first_moment;
            flags[slot] = 1 | if ps.tip { 2 } else { 0 };
        }
        Self { sep, r_lo, nr, values, flags }
    }
}

/// `i.rem_euclid(n)` as an index, without the integer division where `i` lies within one
/// period of the range (the phase rows of a cell: −1 … n + 2); the same value for every `i`.
#[inline(always)]
fn wrap_index(i: i64, n: i64) -> usize {
    let j = if i < 0 {
        i + n
    } else if i >= n {
        i - n
    } else {
        i
    };
    if (0..n).contains(&j) { j as usize } else { i.rem_euclid(n) as usize }
}

/// The cubic Hermite basis (h00, h10, h01, h11) at t ∈ [0, 1].
#[inline(always)]
fn hermite(t: f64) -> [f64; 4] {
    let t2 = t * t;
    let t3 = t2 * t;
    [2.0 * t3 - 3.0 * t2 + 1.0, t3 - 2.0 * t2 + t, -2.0 * t3 + 3.0 * t2, t3 - t2]
}

/// d/dt of the cubic Hermite basis of [`hermite`] at t ∈ [0, 1].
#[inline]
fn hermite_dt(t: f64) -> [f64; 4] {
    let t2 = t * t;
    [6.0 * t2 - 6.0 * t, 3.0 * t2 - 4.0 * t + 1.0, -6.0 * t2 + 6.0 * t, 3.0 * t2 - 2.0 * t]
}

/// Catmull–Rom-type cubic Hermite weights at t ∈ [0, 1] for the four nodes i−1, i, i+1, i+2
/// with central-difference slopes (uniform spacing).
#[inline(always)]
fn weights_central(t: f64) -> [f64; 4] {
    weights_central_of(hermite(t))
}

/// [`weights_central`] for a given basis (the Hermite basis, or its derivative for the
/// derivative of the interpolant).
#[inline(always)]
fn weights_central_of([h00, h10, h01, h11]: [f64; 4]) -> [f64; 4] {
    // d_i = (v_{i+1} − v_{i−1})/2, d_{i+1} = (v_{i+2} − v_i)/2 (in units of the spacing).
    [-0.5 * h10, h00 - 0.5 * h11, h01 + 0.5 * h10, 0.5 * h11]
}

/// Weights on a non-periodic uniform axis of `n` ≥ 4 nodes at coordinate `x` (in node units):
/// returns the first node index, the weights and how many of them are used (one-sided
/// second-order slopes at the ends).
#[inline(always)]
fn axis_weights(x: f64, n: usize) -> (usize, [f64; 4], usize) {
    axis_weights_with::<false>(x, n)
}

/// [`axis_weights`] with the cell found by [`floor_with`].
#[inline(always)]
fn axis_weights_with<const NATIVE: bool>(x: f64, n: usize) -> (usize, [f64; 4], usize) {
    let i = axis_cell_with::<NATIVE>(x, n);
    axis_weights_of(i, n, hermite(x - i as f64))
}

/// Cell of coordinate `x` (node units) on a non-periodic axis of `n` nodes.
#[inline(always)]
fn axis_cell(x: f64, n: usize) -> usize {
    axis_cell_with::<false>(x, n)
}

/// [`axis_cell`] with the floor of [`floor_with`].
#[inline(always)]
fn axis_cell_with<const NATIVE: bool>(x: f64, n: usize) -> usize {
    (floor_with::<NATIVE>(x) as isize).clamp(0, n as isize - 2) as usize
}

/// [`axis_weights`] in cell `i` for a given basis (the Hermite basis, or its derivative).
#[inline(always)]
fn axis_weights_of(i: usize, n: usize, [h00, h10, h01, h11]: [f64; 4]) -> (usize, [f64; 4], usize) {
    // Slopes as combinations of nodes (start index s, 4 coefficients relative to s).
    // d_i: central if 0 < i, else one-sided (−3v0 + 4v1 − v2)/2.
    // d_{i+1}: central if i + 1 < n − 1, else one-sided (v_{n−3} − 4v_{n−2} + 3v_{n−1})/2.
    let mut w = [0.0; 5]; // nodes i−1 … i+3 → index 0 … 4 relative to i − 1
    w[1] += h00;
    w[2] += h01;
    if i > 0 {
        w[0] -= 0.5 * h10;
        w[2] += 0.5 * h10;
    } else {
        w[1] -= 1.5 * h10;
        w[2] += 2.0 * h10;
        w[3] -= 0.5 * h10;
    }
    if i + 2 < n {
        w[1] -= 0.5 * h11;
        w[3] += 0.5 * h11;
    } else {
        w[0] += 0.5 * h11;
        w[1] -= 2.0 * h11;
        w[2] += 1.5 * h11;
    }
    if i == 0 {
        (0, [w[1], w[2], w[3], w[4]], 3)
    } else if i + 2 >= n {
        (i - 1, [w[0], w[1], w[2], 0.0], 3)
    } else {
        (i - 1, [w[0], w[1], w[2], w[3]], 4)
    }
}

impl MeshTable {
    /// The pose sensitivities of this table ([`PoseTable`]), built from the full model the
    /// table was built from (at [`super::MeshOptions::table_slices`]) at the first call and
    /// kept: every mesh that shares
    /// this table shares them. The call samples the driving flanks' sensitivities; the back
    /// flanks' follow at the first posed back-flank state ([`PoseTable`]).
    /// Errors: the table or the model has no pose sensitivities (tooth deviations, friction),
    /// or the build failed; the same error at every call.
    pub fn pose_table(&self) -> Result<&Arc<PoseTable>, MeshError> {
        self.pose
            .get_or_init(|| PoseTable::build(self, &self.model).map(Arc::new))
            .as_ref()
            .map_err(Clone::clone)
    }

    /// True when the table carries tooth-by-tooth deviations (per-pair values).
    pub fn has_tooth_deviations(&self) -> bool {
        self.pairs.is_some()
    }

    /// Wall time of the build including the error check, s.
    pub fn build_seconds(&self) -> f64 {
        self.build_s
    }

    /// Largest relative error of M_F,p against the full model found at the checked cell
    /// centres (where |M_F,p| > 1 % of the nominal torque).
    pub fn max_rel_err(&self) -> f64 {
        self.max_rel_err
    }

    /// Number of cell centres that entered [`MeshTable::max_rel_err`].
    pub fn checked_points(&self) -> usize {
        self.checked_points
    }

    /// TE range covered: (lowest back-flank TE, highest driving-flank TE), m. Samples the
    /// back-flank axis if no state has needed it yet (module docs, "Back flanks on demand");
    /// without a back-flank axis the lower end is the onset −j_t.
    pub fn te_range(&self) -> (f64, f64) {
        (self.back_axis().map_or(-self.backlash_te, TeAxis::end), self.drive.end())
    }

    /// The TE axes cut short at the model's range (empty when the table covers its designed
    /// range: 4× the nominal static TE on the driving flanks). Samples the back-flank axis if
    /// no state has needed it yet.
    pub fn truncations(&self) -> Vec<TableTruncation> {
        let back = self.back_flanks().truncation.clone();
        self.truncations.iter().cloned().chain(back).collect()
    }

    /// Grid sizes: (phase points, driving TE points, back TE points; 0 without a back-flank
    /// axis). Samples the back-flank axis if no state has needed it yet.
    pub fn sizes(&self) -> (usize, usize, usize) {
        (self.np, self.drive.n, self.back_axis().map_or(0, |a| a.n))
    }

    /// Wall time of sampling the back-flank axis, s, or `None` while no state has needed it.
    pub fn back_build_seconds(&self) -> Option<f64> {
        self.back.get().map(|b| b.build_s)
    }

    /// Whether the back-flank axis has been sampled (successfully or not; see
    /// [`MeshTable::truncations`]).
    pub fn back_flanks_sampled(&self) -> bool {
        self.back.get().is_some()
    }

    /// The back-flank axis, sampled from the full model at the first call (module docs,
    /// "Back flanks on demand"); `None` when it has no well-posed nodes.
    #[inline]
    fn back_axis(&self) -> Option<&TeAxis> {
        self.back_flanks().axis.as_ref()
    }

    #[inline]
    fn back_flanks(&self) -> &BackFlanks {
        match self.back.get() {
            Some(b) => b,
            None => self.sample_back(),
        }
    }

    #[cold]
    #[inline(never)]
    fn sample_back(&self) -> &BackFlanks {
        self.back.get_or_init(|| self.build_back())
    }

    /// The nominal torque the TE range was chosen for, N·m.
    pub fn nominal_torque(&self) -> f64 {
        self.nominal_torque
    }

    /// Table evaluation at `state`, or `None` when TE is outside the covered range (the
    /// caller then uses the full model).
    #[inline(always)]
    pub fn evaluate(&self, model: &MeshModel, state: &MeshState) -> Option<MeshOutputs> {
        self.evaluate_with::<false>(model, state)
    }

    /// [`MeshTable::evaluate`] with the floors and roundings of
    /// [`crate::numeric::floor_with`]: the same outputs.
    #[inline(always)]
    fn evaluate_with<const NATIVE: bool>(
        &self,
        model: &MeshModel,
        state: &MeshState,
    ) -> Option<MeshOutputs> {
        if let Some(pt) = &self.pairs {
            return self.evaluate_pairs(pt, model, state, None);
        }
        self.periodic_with_wrench::<NATIVE>(model, state, None)
    }

    /// The phase coordinate (node units) of a reduced pinion angle `phi_red` (rad), as
    /// [`TeAxis::coordinate`] with a multiply by the reciprocal spacing.
    #[inline(always)]
    fn phase_coordinate(&self, phi_red: f64) -> f64 {
        (phi_red - self.phase_lo) * (1.0 / self.phase_h)
    }

    /// The periodic table's cell of the state at pinion angle `phi_p` (rad) and TE `te` (m):
    /// `None` outside the covered TE range, `Some(None)` between the axes (no flank touches),
    /// otherwise the axis and the interpolation weights in phase (periodic, Catmull–Rom) and TE.
    /// The floors and roundings are those of [`floor_with`] (`NATIVE` in the paths compiled
    /// for FMA and SSE4.1, module docs "Vector code"): the same cell either way.
    #[inline(always)]
    fn cell_with<const NATIVE: bool>(&self, phi_p: f64, te: f64) -> Option<Option<Cell<'_>>> {
        let axis = if te > 0.0 {
            if te > self.drive.end() {
                return None;
            }
            &self.drive
        } else if te < -self.backlash_te {
            let back = self.back_axis()?;
            if te < back.end() {
                return None;
            }
            back
        } else {
            return Some(None);
        };
        // The reduction of ContactSolver::reduce (exact in the given doubles, see
        // crate::numeric), with the constants kept here.
        let (phi_p_red, _) = self.pitch_p.reduce_with::<NATIVE>(phi_p);
        let xp = self.phase_coordinate(phi_p_red);
        let ipf = floor_with::<NATIVE>(xp);
        let wp = weights_central(xp - ipf);
        let dist = (te - axis.onset).abs();
        let xt = axis.coordinate(dist).clamp(0.0, (axis.n - 1) as f64);
        let (it0, wt, nt) = axis_weights_with::<NATIVE>(xt, axis.n);
        Some(Some(Cell { axis, xp, wp, ip0: ipf as i64 - 1, dist, xt, it0, wt, nt }))
    }

    /// [`MeshTable::evaluate`] for a right-hand side ([`crate::mesh::MeshTorques::torques`]):
    /// on the periodic table only M_F, M_D, TE (and the extent behind M_D) are interpolated,
    /// from the packed node records (32 bytes per node) with the same operations in the same
    /// order as [`MeshTable::evaluate`], so they agree bit for bit; the flag says whether the
    /// outputs are complete. `te` is the state's TE, `dot2(φp, g_p, φg, g_g)`, as the caller
    /// has it from its validity check. Every output the table of outputs marks
    /// [`crate::mesh::outputs::OutputField::torques`] is written into `out`; with the flag
    /// `false` the other fields are left as they were (a caller that needs them at their
    /// defaults passes [`MeshOutputs::default`]), so a caller that keeps its record in place
    /// does not reset 216 bytes per call. Filled in place, the outputs are not built in one
    /// stack slot and copied to the next on the way out: that copy read back bytes just stored
    /// at another alignment, a store-forwarding stall on every call.
    #[inline(always)]
    pub fn evaluate_torques(
        &self,
        model: &MeshModel,
        state: &MeshState,
        te: f64,
        out: &mut MeshOutputs,
    ) -> Option<bool> {
        self.evaluate_torques_with::<false>(model, state, te, out)
    }

    /// [`MeshTable::evaluate_torques`] with the floors of [`floor_with`].
    #[inline(always)]
    fn evaluate_torques_with<const NATIVE: bool>(
        &self,
        model: &MeshModel,
        state: &MeshState,
        te: f64,
        out: &mut MeshOutputs,
    ) -> Option<bool> {
        if let Some(pt) = &self.pairs {
            *out = self.evaluate_pairs(pt, model, state, None)?;
            return Some(true);
        }
        let Some(Cell { axis, wp, ip0, dist, it0, wt, nt, .. }) =
            self.cell_with::<NATIVE>(state.phi_p, te)?
        else {
            *out = MeshOutputs { te, separated: true, ..MeshOutputs::default() };
            return Some(false);
        };
        let np = self.np as i64;
        let v = axis.interpolate_packed(&axis.torques, np, (&wp, ip0), (it0, &wt, nt));
        let extent = v[2].max(0.0);
        let (m_d_p, m_d_g) = model.damping_for(state, extent);
        out.m_f_p = v[0] * dist;
        out.m_f_g = v[1] * dist;
        out.m_d_p = m_d_p;
        out.m_d_g = m_d_g;
        out.te = te;
        out.contact_length = extent * model.length_per_extent();
        if let Some(fc) = model.friction() {
            let f = axis.interpolate_packed(&axis.friction_torques, np, (&wp, ip0), (it0, &wt, nt));
            friction_torques(fc, state, f.map(|x| x * dist), out);
        } else {
            (out.m_r_p, out.m_r_g, out.p_loss) = (0.0, 0.0, 0.0);
        }
        Some(false)
    }

    /// [`MeshTable::evaluate`] with tooth deviations: every tooth pair's driving-flank values
    /// interpolated at its own TE − e_k (module docs, "Tooth deviations").
    /// With `deriv`, also the derivatives of M_F,p, M_F,g and the loaded extent with respect
    /// to the mesh phase and TE (`[∂/∂phase, ∂/∂TE]` per quantity), as
    /// [`MeshTable::evaluate_jacobian`] derives them for one axis, summed over the pairs.
    fn evaluate_pairs(
        &self,
        pt: &PairTable,
        model: &MeshModel,
        state: &MeshState,
        mut deriv: Option<&mut [[f64; 2]; 3]>,
    ) -> Option<MeshOutputs> {
        let (phi_p_red, k) = self.pitch_p.reduce(state.phi_p);
        let k = k as i64;
        let te = crate::numeric::dot2(state.phi_p, self.rb_p, state.phi_g, self.rb_g);
        let axis = &self.drive;
        let xp = self.phase_coordinate(phi_p_red);
        let ipf = crate::numeric::floor(xp);
        let wp = weights_central(xp - ipf);
        let dwp = weights_central_of(hermite_dt(xp - ipf));
        let ip0 = ipf as i64 - 1;
        let ipn = xp.round() as i64;
        let np = self.np as i64;
        let nr = pt.nr as i64;
        let mut v = [0.0; NV];
        let mut n_pairs = 0u32;
        let mut tip = false;
        // Pair r (table frame) at phase row ip0 + a lies in the stored row (ip0 + a) mod np
        // as pair r + ⌊(ip0 + a)/np⌋: one pitch on is the next pair at the same phase.
        for rel in pt.r_lo - 1..=pt.r_lo + nr {
            let slot = |raw: i64| {
                let rr = rel - pt.r_lo + raw.div_euclid(np);
                (0..nr).contains(&rr).then(|| (raw.rem_euclid(np) as usize, rr as usize))
            };
            if (0..4).all(|a| slot(ip0 + a).is_none()) {
                continue;
            }
            let dist = te - pt.sep.tooth_offset(rel - k);
            if dist <= 0.0 {
                continue;
            }
            if dist > axis.range {
                return None;
            }
            let xt_raw = axis.coordinate(dist);
            let xt = xt_raw.clamp(0.0, (axis.n - 1) as f64);
            let (it0, wt, nt) = axis_weights(xt, axis.n);
            let mut u = [0.0; NV];
            for (a, &wa) in wp.iter().enumerate() {
                let Some((ip, rr)) = slot(ip0 + a as i64) else { continue };
                for (b, &wb) in wt.iter().enumerate().take(nt) {
                    let w = wa * wb;
                    let base = ((ip * axis.n + it0 + b) * pt.nr + rr) * NV;
                    for (kk, uk) in u.iter_mut().enumerate() {
                        *uk += w * pt.values[base + kk];
                    }
                }
            }
            if let Some(d) = deriv.as_deref_mut() {
                // ∂u/∂x_p and ∂u/∂x_t of M_F,p, M_F,g and the extent (values 0, 1, 3).
                let it = axis_cell(xt, axis.n);
                let (_, dwt, _) = axis_weights_of(it, axis.n, hermite_dt(xt - it as f64));
                let half_xt = if xt_raw == xt { 0.5 * xt } else { 0.0 };
                let (mut up, mut ut) = ([0.0; 3], [0.0; 3]);
                for a in 0..4 {
                    let Some((ip, rr)) = slot(ip0 + a as i64) else { continue };
                    for b in 0..nt {
                        let base = ((ip * axis.n + it0 + b) * pt.nr + rr) * NV;
                        for (q, kk) in [0usize, 1, 3].into_iter().enumerate() {
                            let x = pt.values[base + kk];
                            up[q] += dwp[a] * wt[b] * x;
                            ut[q] += wp[a] * dwt[b] * x;
                        }
                    }
                }
                for q in 0..2 {
                    d[q][0] += dist * up[q] / self.phase_h;
                    d[q][1] += u[if q == 0 { 0 } else { 1 }] + ut[q] * half_xt;
                }
                if u[3] > 0.0 {
                    d[2][0] += up[2] / self.phase_h;
                    d[2][1] += ut[2] * half_xt / dist;
                }
            }
            v[0] += u[0] * dist;
            v[1] += u[1] * dist;
            v[2] += u[2] * dist;
            v[3] += u[3].max(0.0);
            v[4] = v[4].max(u[4] * dist);
            for k in V_FORCE_P..V_FIRST_MOMENT {
                v[k] += u[k] * dist;
            }
            v[V_FIRST_MOMENT] += u[V_FIRST_MOMENT].max(0.0);
            for k in [V_ROOT_STRESS_P, V_ROOT_STRESS_G] {
                v[k] = v[k].max(u[k] * dist);
            }
            if let Some((ip, rr)) = slot(ipn) {
                let itn = (xt.round() as usize).min(axis.n - 1);
                let f = pt.flags[(ip * axis.n + itn) * pt.nr + rr];
                n_pairs += (f & 1) as u32;
                tip |= f & 2 != 0;
            }
        }
        let mut out = if te < -self.backlash_te {
            if n_pairs > 0 || v[0] != 0.0 {
                return None; // driving and back flanks at once: left to the full model
            }
            return self.evaluate_periodic(model, state);
        } else {
            MeshOutputs { te, ..MeshOutputs::default() }
        };
        let (m_d_p, m_d_g) = model.damping_for(state, v[3]);
        out.m_f_p = v[0];
        out.m_f_g = v[1];
        out.m_d_p = m_d_p;
        out.m_d_g = m_d_g;
        out.f_n = v[2];
        out.contact_length = v[3] * model.length_per_extent();
        out.p_max = if model.options().pressure { v[4].max(0.0).sqrt() } else { 0.0 };
        out.n_pairs = n_pairs;
        out.tip_contact = tip;
        out.separated = n_pairs == 0;
        let mut wrench = elastic_wrench(model, &v);
        if let Some(w) = model.damping_wrench(state, FlankSide::Drive, v[3], v[V_FIRST_MOMENT]) {
            wrench.add(&w);
        }
        wrench.write(&mut out);
        out.root_stress_p = v[V_ROOT_STRESS_P].max(0.0);
        out.root_stress_g = v[V_ROOT_STRESS_G].max(0.0);
        Some(out)
    }

    /// [`MeshTable::evaluate`] on the periodic table (no tooth deviations).
    #[inline(always)]
    fn evaluate_periodic(&self, model: &MeshModel, state: &MeshState) -> Option<MeshOutputs> {
        self.periodic_with_wrench::<false>(model, state, None)
    }

    /// [`Self::evaluate_periodic`]; with `wrench_out`, the wrench it wrote into the outputs
    /// goes there too (whole vectors, the moments' z components included; zero when no flank
    /// touches).
    #[inline(always)]
    fn periodic_with_wrench<const NATIVE: bool>(
        &self,
        model: &MeshModel,
        state: &MeshState,
        wrench_out: Option<&mut MeshWrench>,
    ) -> Option<MeshOutputs> {
        let te = crate::numeric::dot2(state.phi_p, self.rb_p, state.phi_g, self.rb_g);
        let Some(Cell { axis, xp, wp, ip0, dist, xt, it0, wt, nt }) =
            self.cell_with::<NATIVE>(state.phi_p, te)?
        else {
            if let Some(w) = wrench_out {
                *w = MeshWrench::default();
            }
            return Some(MeshOutputs { te, separated: true, ..MeshOutputs::default() });
        };
        let np = self.np as i64;
        let mut v = [0.0; NV];
        for (a, &wa) in wp.iter().enumerate() {
            let ip = wrap_index(ip0 + a as i64, np);
            let base = (ip * axis.n + it0) * NV;
            if nt == 4 {
                // The common case as fixed-size arrays: one bounds check per phase row, and
                // the 4 × NV products unrolled.
                let row: &[f64; 4 * NV] =
                    axis.values[base..base + 4 * NV].try_into().expect("4 TE nodes");
                let mut r = [0.0; NV];
                for (b, &wb) in wt.iter().enumerate() {
                    for (rk, &x) in r.iter_mut().zip(&row[b * NV..(b + 1) * NV]) {
                        *rk += wb * x;
                    }
                }
                for (vk, &rk) in v.iter_mut().zip(&r) {
                    *vk += wa * rk;
                }
                continue;
            }
            for (b, &wb) in wt.iter().enumerate().take(nt) {
                let w = wa * wb;
                let base = base + b * NV;
                for (vk, &x) in v.iter_mut().zip(&axis.values[base..base + NV]) {
                    *vk += w * x;
                }
            }
        }
        // Nearest node for the discrete outputs.
        let round = crate::numeric::round_with::<NATIVE>;
        let ipn = wrap_index(round(xp) as i64, np);
        let itn = (round(xt) as usize).min(axis.n - 1);
        let f = axis.flags[ipn * axis.n + itn];
        let extent = v[3].max(0.0);
        let (m_d_p, m_d_g) = model.damping_for(state, extent);
        let mut out = MeshOutputs {
            m_f_p: v[0] * dist,
            m_f_g: v[1] * dist,
            m_d_p,
            m_d_g,
            te,
            f_n: v[2] * dist,
            contact_length: extent * model.length_per_extent(),
            p_max: if model.options().pressure { (v[4] * dist).max(0.0).sqrt() } else { 0.0 },
            n_pairs: (f & 0xff) as u32,
            tip_contact: f & 0x100 != 0,
            separated: f & 0xff == 0,
            back_contact: f & 0x200 != 0,
            root_stress_p: (v[V_ROOT_STRESS_P] * dist).max(0.0),
            root_stress_g: (v[V_ROOT_STRESS_G] * dist).max(0.0),
            ..MeshOutputs::default()
        };
        {
            let mut scaled = v;
            for x in &mut scaled[V_FORCE_P..V_FIRST_MOMENT] {
                *x *= dist;
            }
            scaled[0] *= dist;
            let mut wrench = elastic_wrench(model, &scaled);
            let side = if axis.dir > 0.0 { FlankSide::Drive } else { FlankSide::Back };
            if let Some(w) = model.damping_wrench(state, side, extent, v[V_FIRST_MOMENT].max(0.0)) {
                wrench.add(&w);
            }
            if let Some(fc) = model.friction() {
                // Row by row (Σ_b w_b·x, then Σ_a w_a·row), scaled by δ once.
                let mut fv = [0.0; FRICTION_NODE];
                for (a, &wa) in wp.iter().enumerate() {
                    let base = wrap_index(ip0 + a as i64, np) * axis.n + it0;
                    let mut r = [0.0; FRICTION_NODE];
                    for (x, &wb) in axis.friction[base..base + nt].iter().zip(&wt) {
                        for (rk, &xk) in r.iter_mut().zip(x) {
                            *rk += wb * xk;
                        }
                    }
                    for (f, &rk) in fv.iter_mut().zip(&r) {
                        *f += wa * rk;
                    }
                }
                for f in &mut fv {
                    *f *= dist;
                }
                // The torques and the loss from the packed records, as the torques-only path.
                let f =
                    axis.interpolate_packed(&axis.friction_torques, np, (&wp, ip0), (it0, &wt, nt));
                let k = friction_torques(fc, state, f.map(|x| x * dist), &mut out);
                wrench.add(&friction_wrench(model, k, &fv, &mut out));
            }
            wrench.write(&mut out);
            set_efficiency(&mut out, state);
            if let Some(w) = wrench_out {
                *w = wrench;
            }
            Some(out)
        }
    }

    /// Table evaluation at `state` with the exact partial derivatives of the interpolant
    /// (see [`crate::mesh::MeshJacobian`]), or `None` when TE is outside the covered range.
    ///
    /// With M_F = v(x_p, x_t)·δ (v the interpolated secant, x_p = (phase − phase₀)/h_p,
    /// x_t = (n − 1)·√(δ/range), δ = |TE − TE_onset|): ∂M_F/∂phase = δ·∂v/∂x_p / h_p and
    /// ∂M_F/∂TE = dir·(v + ∂v/∂x_t·x_t/2); the loaded extent E = v₃ (no δ factor) has
    /// ∂E/∂TE = dir·∂v₃/∂x_t·x_t/(2δ), which grows like δ^(−1/2) towards the onset, as the
    /// interpolant does. Angles: ∂/∂φp = ∂/∂phase + g_p·∂/∂TE, ∂/∂φg = g_g·∂/∂TE. The
    /// damping torques (Eq. 14, [`crate::load::damping_torques`]) are differentiated exactly.
    /// The discrete outputs (nearest node) do not enter.
    pub fn evaluate_jacobian(
        &self,
        model: &MeshModel,
        state: &MeshState,
    ) -> Option<(MeshOutputs, MeshJacobian)> {
        if let Some(pt) = &self.pairs {
            let te = crate::numeric::dot2(state.phi_p, self.rb_p, state.phi_g, self.rb_g);
            if te >= -self.backlash_te {
                let mut d = [[0.0; 2]; 3];
                let out = self.evaluate_pairs(pt, model, state, Some(&mut d))?;
                let mut jac = MeshJacobian::default();
                let (rb_p, rb_g) = (self.rb_p, self.rb_g);
                for (row, q) in [(MeshJacobian::M_F_P, 0), (MeshJacobian::M_F_G, 1)] {
                    jac.d[row][MeshJacobian::PHI_P] = d[q][0] + rb_p * d[q][1];
                    jac.d[row][MeshJacobian::PHI_G] = rb_g * d[q][1];
                }
                let extent = out.contact_length / model.length_per_extent();
                if extent > 0.0 {
                    let de = [d[2][0] + rb_p * d[2][1], rb_g * d[2][1]];
                    damping_rows(model, state, extent, de, None, &mut jac);
                }
                return Some((out, jac));
            }
        }
        let out = self.evaluate(model, state)?;
        let te = out.te;
        let mut jac = MeshJacobian::default();
        let axis = if te > 0.0 {
            &self.drive
        } else if te < -self.backlash_te {
            self.back_axis()?
        } else {
            return Some((out, jac));
        };
        let (phi_p_red, _) = self.pitch_p.reduce(state.phi_p);
        let xp = self.phase_coordinate(phi_p_red);
        let ipf = crate::numeric::floor(xp);
        let tp = xp - ipf;
        let (wp, dwp) = (weights_central(tp), weights_central_of(hermite_dt(tp)));
        let ip0 = ipf as i64 - 1;
        let dist = (te - axis.onset).abs();
        let xt_raw = axis.coordinate(dist);
        let xt = xt_raw.clamp(0.0, (axis.n - 1) as f64);
        let it = axis_cell(xt, axis.n);
        let (it0, wt, nt) = axis_weights_of(it, axis.n, hermite(xt - it as f64));
        let (_, dwt, _) = axis_weights_of(it, axis.n, hermite_dt(xt - it as f64));
        // dx_t/dδ·δ = x_t/2 inside the axis, 0 where x_t is clamped.
        let half_xt = if xt_raw == xt { 0.5 * xt } else { 0.0 };
        let np = self.np as i64;
        // v, ∂v/∂x_p, ∂v/∂x_t for M_F,p, M_F,g and the extent.
        let (mut v, mut vp, mut vt) = ([0.0; NV], [0.0; NV], [0.0; NV]);
        for a in 0..4 {
            let ip = wrap_index(ip0 + a as i64, np);
            for b in 0..nt {
                let base = (ip * axis.n + it0 + b) * NV;
                for k in 0..NV {
                    let x = axis.values[base + k];
                    v[k] += wp[a] * wt[b] * x;
                    vp[k] += dwp[a] * wt[b] * x;
                    vt[k] += wp[a] * dwt[b] * x;
                }
            }
        }
        let (rb_p, rb_g) = (self.rb_p, self.rb_g);
        let mut fill = |row: usize, d_phase: f64, d_te: f64| {
            jac.d[row][MeshJacobian::PHI_P] = d_phase + rb_p * d_te;
            jac.d[row][MeshJacobian::PHI_G] = rb_g * d_te;
        };
        for (row, k) in [(MeshJacobian::M_F_P, 0), (MeshJacobian::M_F_G, 1)] {
            fill(row, dist * vp[k] / self.phase_h, axis.dir * (v[k] + vt[k] * half_xt));
        }
        // Damping: M_D,k = d·(φ̇p·g_p + φ̇g·g_g)·E·g_k with E = max(v₃, 0).
        if v[3] > 0.0 {
            let (de_phase, de_te) = (vp[3] / self.phase_h, axis.dir * vt[3] * half_xt / dist);
            damping_rows(
                model,
                state,
                v[3],
                [de_phase + rb_p * de_te, rb_g * de_te],
                None,
                &mut jac,
            );
        }
        Some((out, jac))
    }
}

/// The table fidelity as a [`MeshTorques`]: the table over (phase, TE) of a [`MeshModel`],
/// falling back to the full model (with its own workspace and warm start, [`FullMesh`])
/// outside the table's range. The table is shared by `Arc`; a clone shares table and model.
#[derive(Debug, Clone)]
pub struct TableMesh {
    table: Arc<MeshTable>,
    full: FullMesh,
    /// The CPU has FMA and SSE4.1 ([`crate::numeric::has_fma_sse41`], asked once, when the
    /// mesh is made): the torques path runs compiled for them.
    native: bool,
}

impl TableMesh {
    /// The table `table` of the model of `full` (built from it, or from its periodic part).
    pub fn new(table: Arc<MeshTable>, full: FullMesh) -> Self {
        #[cfg(target_arch = "x86_64")]
        let native = crate::numeric::has_fma_sse41();
        #[cfg(not(target_arch = "x86_64"))]
        let native = false;
        Self { table, full, native }
    }

    /// [`MeshTorques::torques_into`] compiled for FMA and SSE4.1 (`native`).
    ///
    /// # Safety
    /// The CPU must have FMA and SSE4.1.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "fma,sse4.1")]
    unsafe fn torques_into_native(
        &mut self,
        state: &MeshState,
        out: &mut MeshOutputs,
    ) -> Result<bool, MeshError> {
        self.torques_into_with::<true>(state, out)
    }

    /// [`MeshTorques::torques_into`] with the floors and roundings of
    /// [`crate::numeric::floor_with`] (`NATIVE` in the [`Self::torques_into_native`] path).
    #[inline(always)]
    fn torques_into_with<const NATIVE: bool>(
        &mut self,
        state: &MeshState,
        out: &mut MeshOutputs,
    ) -> Result<bool, MeshError> {
        let te = self.full.model().check_state_te(state)?;
        if !state.bodies_at_rest() {
            *out = self.evaluate_posed(state)?;
            return Ok(true);
        }
        if let Some(complete) =
            self.table.evaluate_torques_with::<NATIVE>(self.full.model(), state, te, out)
        {
            return Ok(complete);
        }
        *out = self.full.evaluate(state)?;
        Ok(true)
    }

    /// The outputs at a state with the bodies displaced (module docs of [`pose`]): the table
    /// at the shifted TE plus the first-order part, the wrench about the displaced centres in
    /// the housing frame; the full model outside the table's TE range. The first posed state
    /// builds the table's pose sensitivities ([`MeshTable::pose_table`]); refused beyond their
    /// bound, or where the table has none (tooth deviations, friction).
    #[cold]
    #[inline(never)]
    fn evaluate_posed(&mut self, state: &MeshState) -> Result<MeshOutputs, MeshError> {
        let pt = self.table.pose_table()?.clone();
        let model = self.full.model();
        let geo = model.geometry();
        let a = geo.center_distance;
        let rel = RelativePose::new(&state.pose_p, &state.pose_g, a);
        pt.check(&rel)?;
        let rate = RelativePose::new(&state.rate_p, &state.rate_g, a);
        let t = &self.table;
        let te = crate::numeric::dot2(state.phi_p, t.rb_p, state.phi_g, t.rb_g);
        let (dd, db) = (pose::te_shift(geo, &rel, 1.0), pose::te_shift(geo, &rel, -1.0));
        let (te_eq, axis) = if te + dd > 0.0 {
            (te + dd, Some(0))
        } else if te + db < -t.backlash_te {
            (te + db, Some(1))
        } else {
            (te + dd, None)
        };
        // The rigid-bearing state at the shifted TE, the body motion's approach in the gear speed
        // (as the full model damps it).
        let shifted = MeshState {
            phi_p: state.phi_p,
            phi_g: state.phi_g + (te_eq - te) / t.rb_g,
            w_p: state.w_p,
            w_g: state.w_g + approach_rate(geo, &rate) / geo.gear.rb,
            ..Default::default()
        };
        let mut wrench = MeshWrench::default();
        let Some(mut out) = t.periodic_with_wrench::<false>(model, &shifted, Some(&mut wrench))
        else {
            return self.full.evaluate(state);
        };
        out.te = te;
        if let Some(a) = axis {
            let (phi_red, _) = t.pitch_p.reduce(state.phi_p);
            let d = pt.correction(t, phi_red, te_eq, a, &rel)?;
            out.m_f_p += d[0];
            out.m_f_g += d[1];
            let dw = MeshWrench::from_pinion(
                model.force_frame(),
                [d[2], d[3], d[4]],
                [d[5], d[6], -d[0]],
            );
            wrench.add(&dw);
        }
        to_housing(&mut wrench, &rel, &state.pose_p);
        wrench.write(&mut out);
        Ok(out)
    }

    /// The table.
    pub fn table(&self) -> &Arc<MeshTable> {
        &self.table
    }

    /// The full model the table falls back to.
    pub fn full(&self) -> &FullMesh {
        &self.full
    }

    /// The full model the table falls back to, mutable.
    pub fn full_mut(&mut self) -> &mut FullMesh {
        &mut self.full
    }

    /// The outputs at `state`: the table's inside its range (the state checked against the
    /// model's validity range first), the full model's outside it.
    #[inline]
    pub fn evaluate(&mut self, state: &MeshState) -> Result<MeshOutputs, MeshError> {
        #[cfg(target_arch = "x86_64")]
        if crate::numeric::has_avx2_fma() {
            // SAFETY: the CPU has AVX2 and FMA (checked just above).
            return unsafe { self.evaluate_avx2(state) };
        }
        self.evaluate_body::<false>(state)
    }

    /// [`Self::evaluate`] compiled for AVX2 and FMA (module docs, "Vector code").
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn evaluate_avx2(&mut self, state: &MeshState) -> Result<MeshOutputs, MeshError> {
        self.evaluate_body::<true>(state)
    }

    /// [`Self::evaluate`] with the floors and roundings of [`crate::numeric::floor_with`]
    /// (`NATIVE` in the [`Self::evaluate_avx2`] path, where AVX2 brings SSE4.1's rounding).
    #[inline(always)]
    fn evaluate_body<const NATIVE: bool>(
        &mut self,
        state: &MeshState,
    ) -> Result<MeshOutputs, MeshError> {
        self.full.model().check_state(state)?;
        if !state.bodies_at_rest() {
            return self.evaluate_posed(state);
        }
        if let Some(o) = self.table.evaluate_with::<NATIVE>(self.full.model(), state) {
            return Ok(o);
        }
        self.full.evaluate(state)
    }
}

impl MeshTorques for TableMesh {
    fn forget_history(&mut self) {
        self.full.forget_history();
    }

    fn warm_start(&self, out: &mut WarmStart) {
        self.full.warm_start(out);
    }

    fn set_warm_start(&mut self, warm: &WarmStart) {
        self.full.set_warm_start(warm);
    }

    fn mesh(&mut self, state: &MeshState) -> Result<MeshOutputs, MeshError> {
        self.evaluate(state)
    }

    /// On the periodic table, inside its range, only the torques, TE and the contact extent
    /// the damping needs are interpolated (3 of the 13 node values, from their packed
    /// records; no flags, no pressure, no forces, no root stresses), and TE is computed once
    /// for the validity check and the lookup; everything else is complete.
    #[inline]
    fn torques(&mut self, state: &MeshState) -> Result<(MeshOutputs, bool), MeshError> {
        let mut out = MeshOutputs::default();
        let complete = self.torques_into(state, &mut out)?;
        Ok((out, complete))
    }

    #[inline]
    fn torques_into(
        &mut self,
        state: &MeshState,
        out: &mut MeshOutputs,
    ) -> Result<bool, MeshError> {
        #[cfg(target_arch = "x86_64")]
        if self.native {
            // SAFETY: the CPU has FMA and SSE4.1 (`native`, detected when the mesh was made).
            return unsafe { self.torques_into_native(state, out) };
        }
        self.torques_into_with::<false>(state, out)
    }

    fn base_radii(&self) -> (f64, f64) {
        self.full.base_radii()
    }

    fn te_range(&self) -> (f64, f64) {
        self.full.te_range()
    }

    fn has_friction(&self) -> bool {
        self.full.has_friction()
    }

    /// Builds the table's pose sensitivities ([`MeshTable::pose_table`]) now rather than at the
    /// first posed state; every mesh sharing the table shares them.
    fn prepare_poses(&mut self) -> Result<(), MeshError> {
        self.table.pose_table().map(|_| ())
    }

    /// Exact partial derivatives of the table's interpolant
    /// ([`MeshTable::evaluate_jacobian`]); outside the table those of the full model.
    fn mesh_jacobian(
        &mut self,
        state: &MeshState,
    ) -> Result<(MeshOutputs, MeshJacobian), MeshError> {
        self.full.model().check_state(state)?;
        refuse_pose(state)?;
        if let Some((out, mut jac)) = self.table.evaluate_jacobian(self.full.model(), state) {
            if self.full.model().friction().is_some() {
                add_friction_jacobian(&mut |s| self.evaluate(s), state, &mut jac)?;
            }
            return Ok((out, jac));
        }
        self.full.jacobian(state)
    }
}

/// The table's Jacobian holds the rigid-bearing mesh: a state with a gear body off its axis (a
/// pose or a pose rate, [`super::pose`]) is refused, not evaluated as if the bodies were at
/// rest.
#[inline]
fn refuse_pose(state: &MeshState) -> Result<(), MeshError> {
    if state.bodies_at_rest() {
        Ok(())
    } else {
        Err(MeshError::Unsupported(
            "the table's Jacobian with a gear body off its bearing axis (pose or pose rate): \
             use full fidelity for derivatives at a pose",
        ))
    }
}

/// Adds the friction torques of the interpolated packed friction values `f` =
/// [M_R,p, M_R,g, L, F_n] (node values times δ, for μ = 1 at +1 rad/s) at `state` to `out`
/// (module docs, "Friction"): μ from the elastic M_F,p (`out.m_f_p` on entry), the
/// regularisation at the load-weighted mean sliding speed v̄ = |φ̇p|·L/F_n, the sense of the
/// pinion's rotation; the loss is the power the friction torques take from the gears (never
/// below 0), the heat split by `out`'s caller. Returns the scale κ = μ·g·sign φ̇p.
#[inline]
fn friction_torques(
    fc: &FrictionConst,
    state: &MeshState,
    f: [f64; 4],
    out: &mut MeshOutputs,
) -> f64 {
    let mu = fc.mu(out.m_f_p, state.w_p);
    let loss_per_w = f[2].max(0.0);
    let mean_speed = if f[3] > 0.0 { state.w_p.abs() * loss_per_w / f[3] } else { 0.0 };
    let k = if state.w_p == 0.0 {
        0.0
    } else {
        mu * fc.regularisation(mean_speed) * state.w_p.signum()
    };
    out.m_r_p = k * f[0];
    out.m_r_g = k * f[1];
    out.m_f_p += out.m_r_p;
    out.m_f_g += out.m_r_g;
    // With a TE rate this is what the drive line's equations actually lose, so that its
    // energy balance closes; at the rigid ratio it is μ·g·|φ̇p|·L.
    out.p_loss = (out.m_r_p * state.w_p + out.m_r_g * state.w_g).max(0.0);
    k
}

/// The friction's wrench and heat split from the interpolated unit friction `fv` (node values
/// of [`MeshModel::unit_friction`] times δ) scaled by κ of [`friction_torques`], which put
/// the friction torques and loss in `out`: the force and tilting moments scaled as the torques, the
/// heat of the pinion in proportion L_p/L. Fills `out.q_p`, `out.q_g`.
fn friction_wrench(
    model: &MeshModel,
    k: f64,
    fv: &[f64; FRICTION_NODE],
    out: &mut MeshOutputs,
) -> MeshWrench {
    let heat_share = if fv[7] > 0.0 { (fv[8] / fv[7]).clamp(0.0, 1.0) } else { 0.5 };
    out.q_p = heat_share * out.p_loss;
    out.q_g = out.p_loss - out.q_p;
    let f = [k * fv[2], k * fv[3], k * fv[4]];
    MeshWrench::from_pinion(model.force_frame(), f, [k * fv[5], k * fv[6], -out.m_r_p])
}

/// The elastic wrench of interpolated node values `v` already multiplied by δ (force and
/// tilting moment of the pinion at [`V_FORCE_P`], [`V_MOMENT_P`]); the pinion's moment about
/// its axis is not carried, its z component is set from M_F,p (−M_F,p, `v[0]`), and the gear's
/// moment follows by the transfer formula ([`super::forces`]).
fn elastic_wrench(model: &MeshModel, v: &[f64; NV]) -> MeshWrench {
    let f = [v[V_FORCE_P], v[V_FORCE_P + 1], v[V_FORCE_P + 2]];
    let m = [v[V_MOMENT_P], v[V_MOMENT_P + 1], -v[0]];
    MeshWrench::from_pinion(model.force_frame(), f, m)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::friction::{Friction, FrictionModel};
    use crate::mesh::{Fidelity, Mesh, MeshOptions};
    use crate::params::GearPair;

    /// The vector code ([`TableMesh::evaluate`] where the CPU has AVX2 and FMA, the torques
    /// path where it has FMA and SSE4.1) gives the portable code's outputs bit for bit: both
    /// flank sides, the separated gap between them, with and without friction, at angles of
    /// a few pitches and of 10⁹ rad (whole pitches reduced exactly), and at states on the
    /// table's nodes (where a floor decides the cell).
    #[test]
    fn vector_code_is_bit_for_bit_the_portable_code() {
        for friction in [
            Friction::default(),
            Friction { model: FrictionModel::Constant, ..Friction::default() },
        ] {
            let o = MeshOptions {
                fidelity: Fidelity::Table,
                slices: 40,
                table_phase_points: 16,
                table_te_points: 12,
                friction,
                ..MeshOptions::default()
            };
            let Mesh::Table(mut t) = Mesh::new(&GearPair::paper_table1(), o).expect("table") else {
                panic!("table fidelity")
            };
            let geo = t.full().model().geometry().clone();
            let pitch = geo.pinion.angular_pitch();
            let table = t.table().clone();
            let backlash = table.backlash_te;
            let mut phis: Vec<f64> = (0..97).map(|k| (k as f64 * 0.613 - 7.0) * pitch).collect();
            phis.extend((0..16).map(|k| 1e9 + k as f64 * 0.37 * pitch));
            // On the phase nodes: φ = lo + k·h exactly reduces to a whole node coordinate.
            phis.extend((0..table.np).map(|k| table.phase_lo + k as f64 * table.phase_h));
            let mut tes = vec![1e-7, 9e-6, 31e-6, 62e-6, -0.5 * backlash, -backlash - 4e-6];
            tes.extend((1..table.drive.n).map(|k| table.drive.node_te(k)));
            for &phi_p in &phis {
                for &te in &tes {
                    let state = MeshState {
                        phi_p,
                        phi_g: geo.phi_g_for_te(phi_p, te),
                        w_p: 300.0,
                        w_g: -300.0 * geo.pinion.rb / geo.gear.rb + 0.37,
                        ..MeshState::default()
                    };
                    let a = t.evaluate(&state).expect("evaluate");
                    let b = t.evaluate_body::<false>(&state).expect("portable evaluate");
                    assert_eq!(format!("{a:?}"), format!("{b:?}"), "{state:?}");
                    let (mut a, mut b) = (MeshOutputs::default(), MeshOutputs::default());
                    let ca = t.torques_into(&state, &mut a).expect("torques");
                    let cb = t.torques_into_with::<false>(&state, &mut b).expect("portable");
                    assert_eq!((ca, format!("{a:?}")), (cb, format!("{b:?}")), "{state:?}");
                }
            }
        }
    }
}
