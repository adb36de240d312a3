//! Building the table: the full model sampled on the (phase, TE) grid, the phase rows spread
//! over the cores, each row from a cold start; each TE axis cut where the full model stops
//! being well posed; the error check at cell centres (see the parent module's docs).
//!
//! The cores take the next row not yet taken ([`over_indices`]), not a fixed share of the
//! rows: a row costs what its contact lines do (22 to 86 ms per row of the default table on
//! Table 1, where two or three lines are in contact), and the two fixed halves of its 64 rows
//! took 1.26 and 1.90 s in one build on two cores. The range check at the last TE node and
//! the error check at cell centres, 64 full evaluations each, run over the cores the same
//! way. Each row and each checked state starts cold, so the table depends neither on the
//! number of cores nor on which core sampled a row.

use std::sync::Arc;

use super::super::model::{FullMesh, MeshModel, PairSum};
use super::super::statics::{EquilibriumSettings, equilibrium};
use super::super::{MeshError, MeshState, MeshTorques};
use super::{
    BackDesign, BackFlanks, FRICTION_NODE, MeshTable, NV, PairTable, TableTruncation, TeAxis,
};
use crate::error::ParamError;
use crate::modifications::Separation;

impl MeshTable {
    /// Builds the table from the full model `model` (see the module docs), each thread of the
    /// build with its own workspace, each phase row from a cold start. With `deviations` (the
    /// pair's separation with tooth-by-tooth deviations; `model` then holds its periodic part)
    /// the driving-flank values are also kept per tooth pair and evaluation shifts each pair
    /// by its deviation. Errors: a full evaluation fails, or the nominal static TE cannot be
    /// found.
    pub fn build(
        model: &Arc<MeshModel>,
        deviations: Option<Arc<Separation>>,
    ) -> Result<Self, MeshError> {
        let t0 = std::time::Instant::now();
        if deviations.is_some() && model.friction().is_some() {
            return Err(MeshError::Unsupported(
                "friction at table fidelity with pitch deviations or runout (the per-pair table \
                 carries no friction values): use fidelity full, or no friction",
            ));
        }
        let record = deviations.is_some();
        let new_full = || {
            let mut f = FullMesh::new(model.clone());
            f.record_pairs(record);
            f
        };
        let model = &mut new_full();
        let opts = *model.model().options();
        let geo = model.model().geometry().clone();
        let zp = geo.params.z_p as f64;
        let pitch = 2.0 * std::f64::consts::PI / zp;
        let np = opts.table_phase_points;
        let phase_h = pitch / np as f64;
        let phase_lo = -0.5 * pitch;
        // The design torque (an option, checked against TABLE_DESIGN_TORQUE_NM before the
        // build; `max(1)` keeps the old rule for a model built without that check).
        let torque = opts.table_design_torque_nm.abs().max(1.0);

        // Largest static TE at the design torque over a few phases.
        let mut te_nom: f64 = 0.0;
        let mut guess = 1e-5;
        for k in 0..8 {
            let phi_p = phase_lo + pitch * (k as f64 + 0.5) / 8.0;
            // A design torque the pair cannot carry within the model's validity range (flank
            // overlap 0.2·m_n) is an error of that option: the range TABLE_DESIGN_TORQUE_NM
            // is the same for every design, what a design carries is its own.
            let eq = equilibrium(model, phi_p, torque, guess, &EquilibriumSettings::default())
                .map_err(|e| match e {
                    MeshError::Equilibrium(why) => MeshError::Param(ParamError::new(
                        "table_design_torque_nm",
                        torque,
                        format!(
                            "a torque the pair carries within the model's validity range \
                             (flank overlap <= 0.2·m_n): {why}; lower the table's design \
                             torque (the drive line's torque_nm where it sizes the table)"
                        ),
                    )),
                    e => e,
                })?;
            guess = eq.te;
            te_nom = te_nom.max(eq.te);
        }
        let te_hi = 4.0 * te_nom;
        let nd = opts.table_te_points;
        let jt = geo.backlash_te;
        let back_lo = -jt - 0.5 * te_hi;
        let drive = TeAxis::new(0.0, 1.0, te_hi, nd, np);
        // The back-flank axis, as many TE points as the driving one over half its range, is
        // sampled at the first state that needs it (`sample_back`).
        let back_design = BackDesign { onset: -jt, range: -jt - back_lo, n: nd };

        // Sample the full model, phase rows over the available cores.
        let phases = (phase_lo, phase_h);
        let drive_rows = sample_rows(&new_full, phases, np, &drive)?;
        let mut truncations = Vec::new();
        let (drive, pair_samples) =
            assemble(&new_full, &drive, drive_rows, phases, te_nom, "driving", &mut truncations)?;
        let mut table = Self {
            phase_lo,
            phase_h,
            np,
            drive,
            back_design,
            back: std::sync::OnceLock::new(),
            model: model.model().clone(),
            backlash_te: jt,
            pitch_p: crate::numeric::Pitch::of_teeth(geo.pinion.z),
            rb_p: geo.pinion.rb,
            rb_g: geo.gear.rb,
            nominal_torque: torque,
            build_s: 0.0,
            max_rel_err: 0.0,
            checked_points: 0,
            pairs: None,
            truncations,
            pose: std::sync::OnceLock::new(),
        };

        // Error check at cell centres (a deterministic subset of cells on the drive axis). A
        // checked state out of the model's range cuts the driving axis below it (nothing
        // guarantees that the ill-posed region of heavy overload, with corner contacts on the
        // tip roundings, is monotone in TE and phase), and the check starts again on the
        // shorter axis.
        let (worst, checked) = loop {
            match table.self_check(&new_full, torque)? {
                Ok(found) => break found,
                Err((te, e)) => {
                    let m = (0..table.drive.n).take_while(|&k| table.drive.node_te(k) < te).count();
                    if m < 4 || table.drive.node_distance(m - 1) < te_nom {
                        return Err(e);
                    }
                    let designed = table.drive.range;
                    table.drive = table.drive.truncated(m);
                    let cut = TableTruncation {
                        flanks: "driving",
                        designed_m: designed,
                        covered_m: table.drive.range,
                        cause: e.to_string(),
                    };
                    match table.truncations.iter_mut().find(|t| t.flanks == "driving") {
                        Some(t) => {
                            t.covered_m = cut.covered_m;
                            t.cause = cut.cause;
                        }
                        None => table.truncations.push(cut),
                    }
                }
            }
        };
        table.max_rel_err = worst;
        table.checked_points = checked;
        if let Some(sep) = deviations {
            let n = table.drive.n;
            let kept: Vec<_> = pair_samples.into_iter().filter(|(_, it, _)| *it < n).collect();
            table.pairs = Some(PairTable::new(sep, &table.drive, np, &kept));
        }
        table.build_s = t0.elapsed().as_secs_f64();
        Ok(table)
    }

    /// Samples the back-flank axis (module docs, "Back flanks on demand"): the full model on
    /// the designed axis, phase rows over the available cores, each thread with its own
    /// workspace, each row from a cold start, cut at the model's range as the driving axis is.
    /// A sampling error leaves the table without a back-flank axis, recorded as a cut to
    /// nothing (every back-flank state then falls back to the full model, which reports its
    /// own error).
    pub(super) fn build_back(&self) -> BackFlanks {
        let t0 = std::time::Instant::now();
        let design = self.back_design;
        let proto = TeAxis::new(design.onset, -1.0, design.range, design.n, self.np);
        let phases = (self.phase_lo, self.phase_h);
        let new_full = || FullMesh::new(self.model.clone());
        let mut cut = Vec::new();
        let sampled = sample_rows(&new_full, phases, self.np, &proto)
            .and_then(|rows| assemble(&new_full, &proto, rows, phases, 0.0, "back", &mut cut));
        let (axis, truncation) = match sampled {
            Ok((axis, _)) => (Some(axis), cut.pop()),
            Err(e) => (
                None,
                Some(TableTruncation {
                    flanks: "back",
                    designed_m: design.range,
                    covered_m: 0.0,
                    cause: e.to_string(),
                }),
            ),
        };
        BackFlanks { axis, truncation, build_s: t0.elapsed().as_secs_f64() }
    }

    /// The build's error check: the full model against the table at the centres of a
    /// deterministic subset of 64 driving-axis cells, the full evaluations spread over the
    /// cores, each from a cold start ([`over_indices`]). Returns the largest relative error of
    /// M_F,p where |M_F,p| > 1 % of `torque` and the number of such cells, or the TE and the
    /// error of the first checked state (in the subset's order) out of the model's range.
    #[allow(clippy::type_complexity)]
    fn self_check(
        &self,
        new_full: &(impl Fn() -> FullMesh + Sync),
        torque: f64,
    ) -> Result<Result<(f64, usize), (f64, MeshError)>, MeshError> {
        let nd = self.drive.n;
        let cells: Vec<(f64, f64)> = (0..64usize)
            .map(|k| {
                let ip = (k * 7919) % self.np;
                let it = (k * 104_729) % (nd - 1);
                let phi_p = self.phase_lo + self.phase_h * (ip as f64 + 0.5);
                (phi_p, 0.5 * (self.drive.node_te(it.max(1)) + self.drive.node_te(it + 1)))
            })
            .collect();
        // An out-of-range state is a result here, not a failure: every cell is evaluated.
        let full = over_indices(cells.len(), "table check", new_full, |m, k| {
            let (phi_p, te) = cells[k];
            match m.evaluate(&state_at(m.model(), phi_p, te)) {
                Ok(o) => Ok(Ok(o.m_f_p)),
                Err(e @ MeshError::OutOfRange { .. }) => Ok(Err(e)),
                Err(e) => Err(e),
            }
        })?;
        let mut worst: f64 = 0.0;
        let mut checked = 0;
        for (k, full) in full {
            let (phi_p, te) = cells[k];
            let m_f_p = match full {
                Ok(m) => m,
                Err(e) => return Ok(Err((te, e))),
            };
            if m_f_p.abs() > 0.01 * torque
                && let Some(t) = self.evaluate(&self.model, &state_at(&self.model, phi_p, te))
            {
                worst = worst.max((t.m_f_p - m_f_p).abs() / m_f_p.abs());
                checked += 1;
            }
        }
        Ok(Ok((worst, checked)))
    }
}

/// A per-pair sample of the driving axis: (phase row, TE node, the pair's outputs).
type PairSample = (usize, usize, PairSum);

/// The full model sampled along `axis` at every phase row `phase_lo + ip·phase_h`, ip < `np`
/// ([`over_indices`]). Returns (row, samples) per row in row order.
fn sample_rows(
    new_full: &(impl Fn() -> FullMesh + Sync),
    (phase_lo, phase_h): (f64, f64),
    np: usize,
    axis: &TeAxis,
) -> Result<Vec<(usize, AxisRow)>, MeshError> {
    over_indices(np, "table build", new_full, |m, ip| {
        sample_row(m, phase_lo + phase_h * ip as f64, axis)
    })
}

/// `sample(model, ip)` for every index ip < `n` (a phase row, or a state of a check), spread
/// over the available cores, and returns (ip, result) in index order, or the error of the
/// smallest index that failed; a thread that panicked is reported as an error naming `what`.
///
/// Each thread has its own model from `new_full` and takes the next index not yet taken, so
/// the cores stay busy however the cost varies between indices (the default table's rows cost
/// from 22 to 86 ms: two or three contact lines). Every index starts from a cold start (the
/// model's warm start is cleared before it), so a result depends neither on the thread nor
/// on the number of cores. After a failure no thread takes a new index; the indices taken
/// before it, all the smaller ones among them, are finished, so the error reported is that of
/// the smallest failing index, as in a serial loop.
pub(super) fn over_indices<T: Send>(
    n: usize,
    what: &str,
    new_full: &(impl Fn() -> FullMesh + Sync),
    sample: impl Fn(&mut FullMesh, usize) -> Result<T, MeshError> + Sync,
) -> Result<Vec<(usize, T)>, MeshError> {
    use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
    let threads = std::thread::available_parallelism().map_or(1, |c| c.get()).min(n);
    let next = AtomicUsize::new(0);
    let failed = AtomicBool::new(false);
    let (next, failed, sample) = (&next, &failed, &sample);
    type Part<T> = (Vec<(usize, T)>, Option<(usize, MeshError)>);
    let parts: Vec<Result<Part<T>, MeshError>> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..threads)
            .map(|_| {
                let mut m = new_full();
                s.spawn(move || {
                    let mut out = Vec::new();
                    while !failed.load(Ordering::Relaxed) {
                        let ip = next.fetch_add(1, Ordering::Relaxed);
                        if ip >= n {
                            break;
                        }
                        m.forget_history();
                        match sample(&mut m, ip) {
                            Ok(v) => out.push((ip, v)),
                            Err(e) => {
                                failed.store(true, Ordering::Relaxed);
                                return (out, Some((ip, e)));
                            }
                        }
                    }
                    (out, None)
                })
            })
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().map_err(|_| MeshError::Compliance(format!("{what} thread panicked"))))
            .collect()
    });
    let mut out = Vec::with_capacity(n);
    let mut first_error: Option<(usize, MeshError)> = None;
    for part in parts {
        let (done, error) = part?;
        out.extend(done);
        if let Some((ip, e)) = error
            && first_error.as_ref().is_none_or(|(k, _)| ip < *k)
        {
            first_error = Some((ip, e));
        }
    }
    if let Some((_, e)) = first_error {
        return Err(e);
    }
    out.sort_unstable_by_key(|(ip, _)| *ip);
    Ok(out)
}

/// State with pinion angle `phi_p` and transmission error `te`, at rest.
fn state_at(model: &MeshModel, phi_p: f64, te: f64) -> MeshState {
    let geo = model.geometry();
    MeshState {
        phi_p,
        phi_g: geo.phi_g_for_te(phi_p, te),
        w_p: 0.0,
        w_g: 0.0,
        ..Default::default()
    }
}

/// Packs the phase rows of one TE axis into the axis and cuts it at the model's range (see
/// [`TableTruncation`]):
///
/// 1. when a row ended early (the next node out of range), the axis keeps the nodes every row
///    reached;
/// 2. then, while the full model is out of range at the last node's TE at some phase-cell
///    centre (between the sampled phases, where the ill-posed region can reach below the
///    nodes), the last node is dropped.
///
/// It is an error (the out-of-range state) when fewer than 4 nodes would remain or the axis
/// would end short of `min_range` (for the driving flanks the nominal static TE). Returns the
/// axis and the per-pair samples (phase row, TE node, pair outputs) of the kept nodes.
#[allow(clippy::too_many_arguments)]
fn assemble(
    new_full: &(impl Fn() -> FullMesh + Sync),
    proto: &TeAxis,
    rows: Vec<(usize, AxisRow)>,
    (phase_lo, phase_h): (f64, f64),
    min_range: f64,
    flanks: &'static str,
    truncations: &mut Vec<TableTruncation>,
) -> Result<(TeAxis, Vec<PairSample>), MeshError> {
    let np = proto.values.len() / (proto.n * NV);
    let mut axis = TeAxis::new(proto.onset, proto.dir, proto.range, proto.n, np);
    let mut pairs = Vec::new();
    let mut cause = None;
    for (ip, row) in rows {
        let k = row.flags.len();
        let (lo, hi) = (ip * proto.n, ip * proto.n + k);
        axis.values[lo * NV..hi * NV].copy_from_slice(&row.values);
        axis.flags[lo..hi].copy_from_slice(&row.flags);
        if !row.friction.is_empty() {
            axis.friction.resize(np * proto.n, [0.0; FRICTION_NODE]);
            axis.friction[lo..hi].copy_from_slice(&row.friction);
        }
        pairs.extend(row.pairs.into_iter().map(|(it, ps)| (ip, it, ps)));
        if k < proto.n && cause.as_ref().is_none_or(|(m, _)| k < *m) {
            cause = row.out_of_range.map(|e| (k, e));
        }
    }
    let mut m = cause.as_ref().map_or(proto.n, |(k, _)| *k);
    let mut cause = cause.map(|(_, e)| e);
    loop {
        if m < 4 || proto.node_distance(m - 1) < min_range {
            return Err(cause.expect("the axis is cut only at an out-of-range state"));
        }
        let te = proto.node_te(m - 1);
        // The cell centres at the last node, over the cores; the first failure in phase
        // order decides.
        let checked = over_indices(np, "table range check", new_full, |model, ip| {
            let phi_p = phase_lo + phase_h * (ip as f64 + 0.5);
            model.evaluate(&state_at(model.model(), phi_p, te)).map(|_| ())
        });
        let beyond = match checked {
            Ok(_) => None,
            Err(e @ MeshError::OutOfRange { .. }) => Some(e),
            Err(e) => return Err(e),
        };
        match beyond {
            None => break,
            Some(e) => {
                cause = Some(e);
                m -= 1;
            }
        }
    }
    if m < proto.n {
        axis = axis.truncated(m);
        truncations.push(TableTruncation {
            flanks,
            designed_m: proto.range,
            covered_m: axis.range,
            cause: cause.map(|e| e.to_string()).unwrap_or_default(),
        });
        pairs.retain(|(_, it, _)| *it < m);
    }
    axis.pack();
    Ok((axis, pairs))
}

/// Full-model samples of one phase row along one TE axis (see [`AxisRow`]): the row ends early
/// at the first node (after node 0) out of the model's range.
fn sample_row(model: &mut FullMesh, phi_p: f64, axis: &TeAxis) -> Result<AxisRow, MeshError> {
    let mut values = Vec::with_capacity(axis.n * NV);
    let mut flags = Vec::with_capacity(axis.n);
    let mut friction = Vec::new();
    let mut pairs = Vec::new();
    let per_extent = model.model().length_per_extent();
    for it in 0..axis.n {
        let te = axis.node_te(it);
        if it > 0 {
            // The previous node's loads, scaled by the distances from the onset (the loads grow
            // nearly in proportion): a closer start than the loads themselves (about 10 % less
            // build time for the default table; the solution is the same to the load solver's
            // tolerance).
            model.scale_warm(axis.node_distance(it) / axis.node_distance(it - 1));
        }
        let o = match model.evaluate(&state_at(model.model(), phi_p, te)) {
            Ok(o) => o,
            // Beyond the model's range: the row ends at the last node that was well posed.
            Err(e @ MeshError::OutOfRange { .. }) if it > 0 => {
                return Ok(AxisRow { values, flags, friction, pairs, out_of_range: Some(e) });
            }
            Err(e) => return Err(e),
        };
        let dist = axis.node_distance(it);
        pairs.extend(model.pair_sums().iter().map(|p| (it, *p)));
        values.extend_from_slice(&[
            o.m_f_p / dist,
            o.m_f_g / dist,
            o.f_n / dist,
            o.contact_length / per_extent,
            o.p_max * o.p_max / dist,
        ]);
        // The block of the force and moments (at rest: the elastic part alone).
        let (f, m) = (o.force_p, o.moment_p);
        values.extend_from_slice(&[
            f[0] / dist,
            f[1] / dist,
            f[2] / dist,
            m[0] / dist,
            m[1] / dist,
            model.workspace().first_moment(),
        ]);
        // The block of the root stresses.
        values.extend_from_slice(&[o.root_stress_p / dist, o.root_stress_g / dist]);
        if model.model().friction().is_some() {
            friction.push(model.model().unit_friction(model.workspace()).map(|x| x / dist));
        }
        flags.push(
            (o.n_pairs.min(255) as u16)
                | if o.tip_contact { 0x100 } else { 0 }
                | if o.back_contact { 0x200 } else { 0 },
        );
    }
    Ok(AxisRow { values, flags, friction, pairs, out_of_range: None })
}

/// The samples of one phase row along one TE axis: the node values and flags of the first
/// `flags.len()` nodes, the per-pair sums, and, when the row ended early, the out-of-range
/// error of its first node beyond the model's range.
struct AxisRow {
    values: Vec<f64>,
    flags: Vec<u16>,
    /// The friction block of each node (empty without friction).
    friction: Vec<[f64; FRICTION_NODE]>,
    pairs: Vec<(usize, PairSum)>,
    out_of_range: Option<MeshError>,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::GearPair;

    /// Every index once, in index order, each from a cold start whatever the thread did
    /// before; a failure reports the smallest failing index.
    #[test]
    fn over_indices_keeps_order_starts_cold_and_reports_the_first_failure() {
        let pair = GearPair::paper_table1();
        let options = crate::mesh::MeshOptions { slices: 40, ..Default::default() };
        let model = Arc::new(MeshModel::new(&pair, options).expect("model"));
        let new_full = || FullMesh::new(model.clone());
        let loaded = |m: &FullMesh, k: usize| state_at(m.model(), 1e-3 * k as f64, 20e-6);
        let out = over_indices(9, "test", &new_full, |m, k| {
            let cold = m.warm().is_empty();
            m.evaluate(&loaded(m, k))?;
            // The evaluation leaves loads for a warm start: the next index on this thread
            // starts cold only because over_indices clears them.
            assert!(!m.warm().is_empty());
            Ok((cold, k * k))
        })
        .expect("no failure");
        assert_eq!(out, (0..9).map(|k| (k, (true, k * k))).collect::<Vec<_>>());

        let fail = |k: usize| k == 5 || k >= 7;
        let err = over_indices(40, "test", &new_full, |_, k| {
            if fail(k) { Err(MeshError::Compliance(format!("index {k}"))) } else { Ok(k) }
        })
        .expect_err("indices 5 and 7.. fail");
        assert_eq!(err.to_string(), MeshError::Compliance("index 5".into()).to_string());
    }
}
