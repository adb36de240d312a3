//! Bodies of the fuzz targets in `fuzz/fuzz_targets/`, as plain functions of the fuzzer's bytes.
//!
//! The fuzz crate includes this file (`#[path]`), and `tests/fuzz_corpus.rs` calls the same
//! functions on every file of `fuzz/corpus/<target>/`, so every input ever kept is replayed on
//! stable Rust by `cargo test`.
//!
//! Each function reads its bytes as a small program (choices, numbers, text) and checks the
//! invariants of the public interfaces:
//!
//! * nothing panics out of the library (a caught panic reported as an internal error by the C
//!   API counts as a panic, too);
//! * every success status comes with finite outputs (each value read back is checked);
//! * an out-of-range C enum integer is refused.
//!
//! A violated invariant panics with a message naming the call and the value.
//!
//! # Bounds
//!
//! The inputs are bounded where a known cost would only slow the fuzzer down, not where the
//! interface must refuse them: no design other than Table 1 reaches a model constructor (the
//! FE compliance of a new design takes minutes), step sizes ≤ [`MAX_STEP_S`], at most
//! [`MAX_CALLS`] calls per input, RK4 sub-steps ≤ [`MAX_RK4_STEPS`] per mesh period, DOPRI5
//! tolerances ≥ [`MIN_RTOL`], speeds ≤ [`MAX_SPEED`], tables ≤ [`MAX_TABLE_POINTS`] points per
//! axis, slices ≤ [`MAX_SLICES`], inertias ≥ [`MIN_INERTIA`] of their default.
//!
//! The first byte chooses the float range ([`Bytes::new`]): 1 input in 8 may draw any double
//! (NaN, ±inf, 1e308, any bit pattern), the others stay finite and within [`BOUNDED`] of their
//! nominal value, so that the fuzzer does not spend its time on the few defects those
//! magnitudes reach at once.

#![allow(dead_code)]

use std::ffi::{CStr, CString, c_char};
use std::ptr::{null, null_mut};
use std::sync::{Mutex, OnceLock};

use helical_gear_mesh::capi::*;
use helical_gear_mesh::fmi2::exports::*;
use helical_gear_mesh::fmi2::model::ModelInfo;
use helical_gear_mesh::fmi2::models::MODELS;
use helical_gear_mesh::fmi2::types::*;
use helical_gear_mesh::fmi2::variables::{Causality, VarType, Variable, group};
use helical_gear_mesh::geometry::PairGeometry;
use helical_gear_mesh::mesh::{Fidelity, Mesh, MeshOptions, MeshOutputs, MeshState};
use helical_gear_mesh::params::GearPair;

/// Largest communication or unit step the harness asks for, s (about one mesh period of
/// Table 1 at 300 rad/s).
pub const MAX_STEP_S: f64 = 2e-4;
/// Most calls one input makes after the set-up.
pub const MAX_CALLS: usize = 24;
/// Most RK4 sub-steps per mesh period.
pub const MAX_RK4_STEPS: i32 = 32;
/// Smallest DOPRI5 relative tolerance.
pub const MIN_RTOL: f64 = 1e-6;
/// Largest speed given to a unit's start or input, rad/s.
pub const MAX_SPEED: f64 = 2000.0;
/// Largest table size per axis.
pub const MAX_TABLE_POINTS: i32 = 10;
/// Largest number of slices.
pub const MAX_SLICES: i32 = 40;
/// Smallest inertia, stiffness or damping as a fraction of its default.
pub const MIN_INERTIA: f64 = 1e-2;

// ---------------------------------------------------------------------------------------------
// Reading the bytes
// ---------------------------------------------------------------------------------------------

/// The fuzzer's bytes read front to back; past the end every read gives zeros.
pub struct Bytes<'a> {
    data: &'a [u8],
    pos: usize,
    /// Wide mode (first byte < [`WIDE_BELOW`]): floats may be any double, NaN, ±inf, 1e308.
    /// Otherwise they stay finite and within [`BOUNDED`] of their nominal value, below the
    /// magnitudes at which known defects fail at once, so most inputs explore further.
    wide: bool,
}

/// First bytes below this select wide mode (1 input in 8).
pub const WIDE_BELOW: u8 = 32;
/// Bounded mode: the largest |value| relative to max(|nominal|, 1).
pub const BOUNDED: f64 = 1e6;

/// Values a fuzzed float is often drawn from.
const SPECIAL: [f64; 20] = [
    0.0,
    -0.0,
    1.0,
    -1.0,
    f64::NAN,
    f64::INFINITY,
    f64::NEG_INFINITY,
    1e308,
    -1e308,
    f64::MIN_POSITIVE,
    5e-324,
    1e-300,
    1e300,
    1e18,
    2e18,
    -2e18,
    1e-12,
    1e12,
    f64::MAX,
    f64::EPSILON,
];

impl<'a> Bytes<'a> {
    /// Reads `data` from the start; its first byte chooses wide or bounded mode.
    pub fn new(data: &'a [u8]) -> Self {
        let mut b = Self { data, pos: 0, wide: false };
        b.wide = b.u8() < WIDE_BELOW;
        b
    }

    /// True in wide mode.
    pub fn wide(&self) -> bool {
        self.wide
    }

    /// True when every byte has been read.
    pub fn is_empty(&self) -> bool {
        self.pos >= self.data.len()
    }

    /// The next byte (0 past the end).
    pub fn u8(&mut self) -> u8 {
        let b = self.data.get(self.pos).copied().unwrap_or(0);
        self.pos += 1;
        b
    }

    /// The next little-endian u16.
    pub fn u16(&mut self) -> u16 {
        u16::from_le_bytes([self.u8(), self.u8()])
    }

    /// The next little-endian u32.
    pub fn u32(&mut self) -> u32 {
        u32::from_le_bytes([self.u8(), self.u8(), self.u8(), self.u8()])
    }

    /// A choice among `n` (> 0).
    pub fn pick(&mut self, n: usize) -> usize {
        self.u8() as usize % n
    }

    /// A boolean.
    pub fn bool(&mut self) -> bool {
        self.u8() & 1 == 1
    }

    /// Eight raw bytes as a double (any bit pattern).
    pub fn raw_f64(&mut self) -> f64 {
        let mut b = [0u8; 8];
        for x in &mut b {
            *x = self.u8();
        }
        f64::from_le_bytes(b)
    }

    /// A float near `nominal`: mostly `nominal` scaled by up to ±`spread` relative (or by
    /// `spread` absolute when `nominal` is 0), sometimes a special value (NaN, ±inf, 1e308,
    /// subnormals …) or any bit pattern.
    pub fn f64_near(&mut self, nominal: f64, spread: f64) -> f64 {
        let x = match self.u8() {
            0..=9 => SPECIAL[self.pick(SPECIAL.len())],
            10..=13 => self.raw_f64(),
            _ => {
                let u = f64::from(self.u16() as i16) / 32768.0;
                if nominal == 0.0 { u * spread } else { nominal * (1.0 + u * spread) }
            }
        };
        self.bound(x, nominal)
    }

    /// `x` itself in wide mode; in bounded mode `x` when finite and within [`BOUNDED`] of
    /// max(|nominal|, 1), else `nominal`.
    pub fn bound(&self, x: f64, nominal: f64) -> f64 {
        if self.wide || (x.is_finite() && x.abs() <= BOUNDED * nominal.abs().max(1.0)) {
            x
        } else {
            nominal
        }
    }

    /// A special value (NaN, ±inf, 1e308 … in wide mode; the finite small ones otherwise).
    pub fn special(&mut self, nominal: f64) -> f64 {
        let x = SPECIAL[self.pick(SPECIAL.len())];
        self.bound(x, nominal)
    }

    /// A finite float in [lo, hi].
    pub fn f64_in(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * f64::from(self.u16()) / 65535.0
    }

    /// Up to `max` bytes of what is left, as a slice.
    pub fn chunk(&mut self, max: usize) -> &'a [u8] {
        let n = self.u8() as usize % (max + 1);
        let start = self.pos.min(self.data.len());
        let end = (start + n).min(self.data.len());
        self.pos = start + n;
        &self.data[start..end]
    }
}

/// With `FUZZ_TRACE` set, prints each call and its result to stderr (to read a kept input).
fn trace(msg: impl FnOnce() -> String) {
    static ON: OnceLock<Option<std::time::Instant>> = OnceLock::new();
    if let Some(t0) =
        ON.get_or_init(|| std::env::var_os("FUZZ_TRACE").map(|_| std::time::Instant::now()))
    {
        eprintln!("{:9.3} s {}", t0.elapsed().as_secs_f64(), msg());
    }
}

/// Asserts that a value read back after a success status is finite.
fn finite(what: &str, v: f64) {
    assert!(v.is_finite(), "{what} = {v:e} with a success status");
}

fn check_mesh_outputs(what: &str, o: &MeshOutputs) {
    for (n, v) in [
        ("m_f_p", o.m_f_p),
        ("m_f_g", o.m_f_g),
        ("m_d_p", o.m_d_p),
        ("m_d_g", o.m_d_g),
        ("te", o.te),
        ("f_n", o.f_n),
        ("contact_length", o.contact_length),
        ("p_max", o.p_max),
    ] {
        finite(&format!("{what}: {n}"), v);
    }
}

// ---------------------------------------------------------------------------------------------
// gear_pair_json
// ---------------------------------------------------------------------------------------------

/// True when `p` has Table 1's compliance data (same geometry and materials): a model of it
/// needs no FE run.
fn same_compliance_as_table1(p: &GearPair) -> bool {
    let t = GearPair::paper_table1();
    let mut q = p.clone();
    q.d_mesh_n_s_per_m = t.d_mesh_n_s_per_m;
    q.modifications = t.modifications.clone();
    q == t
}

/// The gear-pair JSON of the bytes (as UTF-8, lossy), parsed and validated: geometry, the
/// modifications against it and a drivetrain with Table 1's drive line; the same bytes read
/// as a drive line. Stops before any FE run.
///
/// Checked: no panic; a pair that validates has a finite derived geometry and survives a JSON
/// round trip unchanged.
pub fn gear_pair_json(data: &[u8]) {
    let text = String::from_utf8_lossy(data);
    if let Ok(d) = helical_gear_mesh::DriveLine::from_json(&text) {
        let _ = d.check();
    }
    let Ok(pair) = GearPair::from_json(&text) else { return };
    let Ok(geo) = PairGeometry::new(&pair) else { return };
    pair.validate().expect("validate agrees with PairGeometry::new");
    for (n, v) in [
        ("center_distance", geo.center_distance),
        ("alpha_wt", geo.alpha_wt),
        ("path_start", geo.path_start),
        ("path_end", geo.path_end),
        ("j_p", geo.j_p),
        ("j_g", geo.j_g),
        ("rb_p", geo.pinion.rb),
        ("ra_p", geo.pinion.ra),
        ("rb_g", geo.gear.rb),
        ("ra_g", geo.gear.ra),
    ] {
        finite(&format!("geometry {n}"), v);
    }
    if let Ok(d) = helical_gear_mesh::dynamics::Drivetrain::from_pair(
        &pair,
        &helical_gear_mesh::DriveLine::paper_table1(),
    ) {
        let _ = d.validate();
    }
    let _ = helical_gear_mesh::modifications::Separation::new(&geo);
    let back = GearPair::from_json(&serde_json::to_string(&pair).expect("a pair serialises"))
        .expect("a serialised pair reads back");
    assert_eq!(back, pair, "JSON round trip");
}

// ---------------------------------------------------------------------------------------------
// mesh_evaluate
// ---------------------------------------------------------------------------------------------

/// The Table 1 model of the mesh target: table fidelity, 40 slices, an 8 × 8 table.
pub fn table1_coarse() -> &'static Mutex<Mesh> {
    static M: OnceLock<Mutex<Mesh>> = OnceLock::new();
    M.get_or_init(|| {
        let options = MeshOptions {
            fidelity: Fidelity::Table,
            slices: 40,
            table_phase_points: 8,
            table_te_points: 8,
            ..MeshOptions::default()
        };
        Mutex::new(Mesh::new(&GearPair::paper_table1(), options).expect("Table 1 model"))
    })
}

/// A loaded state of Table 1: TE = +20 µm, rolling at 100 rad/s.
const LOADED: [f64; 4] = [0.01, -0.0060851, 100.0, -100.0 * 30.0 / 47.0];

/// Evaluations of the Table 1 model (table fidelity) at fuzzed (φp, φg, ω_p, ω_g) and fuzzed
/// tunables (d_mesh, the detail flag), each either an error or finite outputs.
pub fn mesh_evaluate(data: &[u8]) {
    let mut b = Bytes::new(data);
    let mut m = table1_coarse().lock().unwrap_or_else(|e| e.into_inner());
    let d0 = GearPair::paper_table1().d_mesh_n_s_per_m;
    let _ = m.set_d_mesh(d0);
    m.set_detail(false);
    for _ in 0..MAX_CALLS {
        if b.is_empty() {
            break;
        }
        match b.pick(4) {
            0 => {
                let d = b.f64_near(d0, 4.0);
                if m.set_d_mesh(d).is_ok() {
                    assert!(m.d_mesh() == d, "d_mesh set to {d:e} reads {:e}", m.d_mesh());
                }
            }
            1 => {
                let on = b.bool();
                m.set_detail(on);
            }
            _ => {
                let s = MeshState {
                    phi_p: b.f64_near(LOADED[0], 100.0),
                    phi_g: b.f64_near(LOADED[1], 1e-2),
                    w_p: b.f64_near(LOADED[2], 20.0),
                    w_g: b.f64_near(LOADED[3], 20.0),
                    ..Default::default()
                };
                let phi_g = if b.bool() {
                    // Near the loaded TE: φg from φp so that TE is small (−50 … 100 µm).
                    let te = b.f64_in(-50e-6, 100e-6);
                    m.geometry().phi_g_for_te(s.phi_p, te)
                } else {
                    s.phi_g
                };
                let s = MeshState { phi_g, ..s };
                if let Ok(o) = m.evaluate(&s) {
                    let d = m.d_mesh();
                    check_mesh_outputs(&format!("evaluate({s:?}), d_mesh {d:.3e}"), &o);
                    for sl in m.slices() {
                        finite("slice overlap", sl.overlap_m);
                    }
                }
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// capi
// ---------------------------------------------------------------------------------------------

/// `hgm_unit_create` with its enums as plain integers, as a C caller may pass them.
type UnitCreateInts =
    unsafe extern "C" fn(i32, *const c_char, *const c_char, i32, u32, f64, f64) -> *mut HgmUnit;

/// Table 1 gear-pair JSON with d_mesh scaled by a fuzzed factor (never a new geometry: no FE
/// run), or the bytes' own text when it has Table 1's compliance data or does not read as a
/// pair at all.
fn pair_json(b: &mut Bytes) -> CString {
    if b.u8() < 32 {
        let text = String::from_utf8_lossy(b.chunk(200)).into_owned();
        let ok = match GearPair::from_json(&text) {
            Ok(p) => same_compliance_as_table1(&p),
            Err(_) => true,
        };
        if ok {
            return CString::new(text.replace('\0', " ")).unwrap_or_default();
        }
    }
    let mut p = GearPair::paper_table1();
    p.d_mesh_n_s_per_m = b.f64_near(p.d_mesh_n_s_per_m, 4.0);
    CString::new(serde_json::to_string(&p).expect("serialises")).expect("no NUL")
}

/// Table 1's drive-line JSON with every value scaled by fuzzed factors, or the bytes' own text
/// when it reads as a drive line within the harness's bounds or not at all.
fn drive_json(b: &mut Bytes) -> CString {
    use helical_gear_mesh::DriveLine;
    if b.u8() < 32 {
        let text = String::from_utf8_lossy(b.chunk(200)).into_owned();
        let ok = match DriveLine::from_json(&text) {
            Ok(d) => drive_is_bounded(&d),
            Err(_) => true,
        };
        if ok {
            return CString::new(text.replace('\0', " ")).unwrap_or_default();
        }
    }
    let mut line = DriveLine::paper_table1();
    let d = &mut line;
    for x in [&mut d.j1_kgm2, &mut d.j2_kgm2, &mut d.c1_nm_per_rad, &mut d.c2_nm_per_rad] {
        *x = bounded_scale(b, *x);
    }
    d.d1_nms_per_rad = bounded_scale(b, d.d1_nms_per_rad);
    d.d2_nms_per_rad = bounded_scale(b, d.d2_nms_per_rad);
    d.torque_nm = b.f64_near(d.torque_nm, 2.0);
    CString::new(serde_json::to_string(&line).expect("serialises")).expect("no NUL")
}

/// `x` scaled by a factor in [MIN_INERTIA, 1/MIN_INERTIA], or sometimes a value the
/// validation must refuse (0, negative, NaN, inf).
fn bounded_scale(b: &mut Bytes, x: f64) -> f64 {
    match b.u8() {
        0..=5 => {
            let v = [0.0, -x, f64::NAN, f64::INFINITY, -0.0, f64::NEG_INFINITY][b.pick(6)];
            b.bound(v, x)
        }
        _ => x * MIN_INERTIA.powf(b.f64_in(-1.0, 1.0)),
    }
}

/// True when the drive line `d` is within the harness's bounds (or invalid).
fn drive_is_bounded(d: &helical_gear_mesh::DriveLine) -> bool {
    let t = helical_gear_mesh::DriveLine::paper_table1();
    [
        (d.j1_kgm2, t.j1_kgm2),
        (d.j2_kgm2, t.j2_kgm2),
        (d.c1_nm_per_rad, t.c1_nm_per_rad),
        (d.c2_nm_per_rad, t.c2_nm_per_rad),
        (d.d1_nms_per_rad, t.d1_nms_per_rad),
        (d.d2_nms_per_rad, t.d2_nms_per_rad),
    ]
    .iter()
    .all(|&(v, n)| v.is_nan() || v <= 0.0 || !v.is_finite() || (v / n).abs().log10().abs() <= 2.0)
        && (d.torque_nm.is_nan() || d.torque_nm.abs() <= 1e4)
}

/// An enum integer: mostly in range, sometimes any i32.
fn enum_int(b: &mut Bytes, n: i32) -> i32 {
    if b.u8() < 248 { b.pick(n as usize) as i32 } else { b.u32() as i32 }
}

fn unit_outputs_finite(u: *mut HgmUnit) {
    let mut o = HgmUnitOutputs::default();
    // SAFETY: live unit, writable output.
    if unsafe { hgm_unit_outputs(u, &mut o) } == HgmStatus::Ok {
        for (n, v) in [
            ("t", o.t),
            ("phi_p", o.phi_p),
            ("w_p", o.w_p),
            ("a_p", o.a_p),
            ("phi_g", o.phi_g),
            ("w_g", o.w_g),
            ("a_g", o.a_g),
            ("phi_1", o.phi_1),
            ("w_1", o.w_1),
            ("phi_2", o.phi_2),
            ("w_2", o.w_2),
            ("tau_1", o.tau_1),
            ("tau_2", o.tau_2),
            ("tau_p", o.tau_p),
            ("tau_g", o.tau_g),
        ] {
            finite(&format!("hgm_unit_outputs {n}"), v);
        }
        let m = o.mesh;
        for (n, v) in [
            ("m_f_p", m.m_f_p),
            ("m_f_g", m.m_f_g),
            ("m_d_p", m.m_d_p),
            ("m_d_g", m.m_d_g),
            ("te", m.te),
            ("f_n", m.f_n),
            ("contact_length", m.contact_length),
            ("p_max", m.p_max),
        ] {
            finite(&format!("hgm_unit_outputs mesh.{n}"), v);
        }
    }
}

fn not_internal(what: &str, s: HgmStatus, msg: *const c_char) {
    if s == HgmStatus::InternalError {
        // SAFETY: a zero-terminated message from the library.
        let m = unsafe { CStr::from_ptr(msg) }.to_string_lossy();
        panic!("{what}: internal error: {m}");
    }
}

/// A sequence of C API calls: one mesh model (`hgm_*`, Table 1) and one unit (`hgm_unit_*`,
/// Table 1 with a fuzzed drive line, full fidelity), driven by the bytes: evaluations at any
/// doubles, d_mesh, unit inputs and rates, hub coupling, steps, outputs, snapshots and
/// restores of fuzzed or flipped text; enum integers out of range at creation.
pub fn capi(data: &[u8]) {
    let mut b = Bytes::new(data);
    // SAFETY: every handle below is live until freed at the end; pointers are to locals.
    unsafe {
        let m = match b.pick(4) {
            0 => null_mut(),
            1 => {
                let json = pair_json(&mut b);
                let m = hgm_create_from_json(json.as_ptr());
                if m.is_null() {
                    not_internal("hgm_create_from_json", HgmStatus::Ok, hgm_last_error(null()));
                }
                m
            }
            _ => hgm_create_default(),
        };
        let kind = enum_int(&mut b, 3);
        let fidelity = enum_int(&mut b, 2);
        let json = if b.bool() { Some(pair_json(&mut b)) } else { None };
        let drive = if b.bool() { Some(drive_json(&mut b)) } else { None };
        let drive_ptr = drive.as_ref().map_or(null(), |j| j.as_ptr());
        let steps = match b.u8() {
            0..=63 => 0,
            x => u32::from(x) % MAX_RK4_STEPS as u32,
        };
        let rtol = 10f64.powf(b.f64_in(MIN_RTOL.log10(), -2.0));
        let atol = 10f64.powf(b.f64_in(-14.0, -3.0));
        // Full fidelity stands for both in range: a table is built in seconds, too slow here.
        // (Named, not a code: the codes of the C API changed once, and a literal then meant the
        // table.)
        let fid_arg = if (0..2).contains(&fidelity) { HgmFidelity::Full as i32 } else { fidelity };
        let create: UnitCreateInts = hgm_unit_create;
        let u = if (0..3).contains(&kind) && (0..2).contains(&fid_arg) {
            let pair_ptr = json.as_ref().map_or(null(), |j| j.as_ptr());
            create(kind, pair_ptr, drive_ptr, fid_arg, steps, rtol, atol)
        } else if b.bool() {
            // Out of range: must be refused (NULL). The pair is Table 1's, so that a wrongly
            // accepted enum needs no FE run (a fidelity taken as the table still builds one).
            let u = create(kind, null(), null(), fid_arg, steps, rtol, atol);
            if !u.is_null() {
                hgm_unit_free(u);
                panic!("hgm_unit_create accepted kind {kind}, fidelity {fid_arg}");
            }
            null_mut()
        } else {
            null_mut()
        };
        trace(|| format!("hgm_unit_create({kind}, {fid_arg}, {steps}, {rtol:.1e}, {atol:.1e})"));
        if u.is_null() {
            not_internal("hgm_unit_create", HgmStatus::Ok, hgm_unit_last_error(null()));
        }
        let mut saved: Vec<CString> = Vec::new();
        for _ in 0..MAX_CALLS {
            if b.is_empty() {
                break;
            }
            let op = b.pick(12);
            let (what, s, msg) = match op {
                0 => {
                    let mut o = HgmOutputs::default();
                    let args = [
                        b.f64_near(LOADED[0], 100.0),
                        b.f64_near(LOADED[1], 1e-2),
                        b.f64_near(LOADED[2], 20.0),
                        b.f64_near(LOADED[3], 20.0),
                    ];
                    let out = if b.u8() == 0 { null_mut() } else { &mut o as *mut _ };
                    let s = hgm_evaluate(m, args[0], args[1], args[2], args[3], out);
                    if s == HgmStatus::Ok {
                        for (n, v) in [
                            ("m_f_p", o.m_f_p),
                            ("m_f_g", o.m_f_g),
                            ("m_d_p", o.m_d_p),
                            ("m_d_g", o.m_d_g),
                            ("te", o.te),
                            ("f_n", o.f_n),
                            ("contact_length", o.contact_length),
                            ("p_max", o.p_max),
                        ] {
                            finite(&format!("hgm_evaluate{args:?} {n}"), v);
                        }
                    }
                    ("hgm_evaluate", s, hgm_last_error(m))
                }
                1 => {
                    let d = b.f64_near(GearPair::paper_table1().d_mesh_n_s_per_m, 4.0);
                    ("hgm_set_d_mesh", hgm_set_d_mesh(m, d), hgm_last_error(m))
                }
                2 => {
                    let s = hgm_unit_start_static(
                        u,
                        b.f64_near(0.0, 1.0),
                        b.f64_near(300.0, 2.0).clamp(-MAX_SPEED, MAX_SPEED),
                    );
                    ("hgm_unit_start_static", s, hgm_unit_last_error(u))
                }
                3 => {
                    let i = HgmUnitInputs {
                        tau_p: b.f64_near(500.0, 2.0),
                        tau_g: b.f64_near(-783.0, 2.0),
                        phi_1: b.f64_near(0.0, 1.0),
                        w_1: b.f64_near(300.0, 2.0).clamp(-MAX_SPEED, MAX_SPEED),
                        phi_2: b.f64_near(0.0, 1.0),
                        w_2: b.f64_near(-191.0, 2.0).clamp(-MAX_SPEED, MAX_SPEED),
                        torque: b.f64_near(500.0, 2.0),
                    };
                    let p = if b.u8() == 0 { null() } else { &i as *const _ };
                    ("hgm_unit_set_inputs", hgm_unit_set_inputs(u, p), hgm_unit_last_error(u))
                }
                4 => {
                    let r = HgmUnitInputRates {
                        tau_p_rate: b.f64_near(0.0, 1e5),
                        tau_g_rate: b.f64_near(0.0, 1e5),
                        w_1_rate: b.f64_near(0.0, 1e4),
                        w_2_rate: b.f64_near(0.0, 1e4),
                        torque_rate: b.f64_near(0.0, 1e5),
                    };
                    let s = hgm_unit_set_input_rates(u, &r);
                    ("hgm_unit_set_input_rates", s, hgm_unit_last_error(u))
                }
                5 => {
                    let s = hgm_unit_set_hub_coupling(
                        u,
                        b.f64_near(0.0, 1e6),
                        b.f64_near(0.0, 1e2),
                        b.f64_near(0.0, 1e6),
                        b.f64_near(0.0, 1e2),
                    );
                    ("hgm_unit_set_hub_coupling", s, hgm_unit_last_error(u))
                }
                6 | 7 => {
                    let h = match b.u8() {
                        0..=15 => b.special(1e-4).min(MAX_STEP_S),
                        _ => b.f64_in(0.0, MAX_STEP_S),
                    };
                    ("hgm_unit_advance", hgm_unit_advance(u, h), hgm_unit_last_error(u))
                }
                8 => {
                    unit_outputs_finite(u);
                    ("hgm_unit_outputs", HgmStatus::Ok, hgm_unit_last_error(u))
                }
                9 => {
                    let p = hgm_unit_snapshot(u);
                    if !p.is_null() {
                        saved.push(CStr::from_ptr(p).to_owned());
                    }
                    ("hgm_unit_snapshot", HgmStatus::Ok, hgm_unit_last_error(u))
                }
                10 => {
                    // A saved snapshot, with a byte flipped or not, or fuzzed text.
                    let text = match (saved.last(), b.u8()) {
                        (Some(s), x) if x >= 64 => {
                            let mut v = s.as_bytes().to_vec();
                            if x >= 160 && !v.is_empty() {
                                let i = b.u16() as usize % v.len();
                                v[i] ^= 1 << b.pick(7);
                                if v[i] == 0 {
                                    v[i] = b'0';
                                }
                            }
                            CString::new(v).unwrap_or_default()
                        }
                        _ => CString::new(
                            b.chunk(120).iter().map(|&c| c.max(1)).collect::<Vec<u8>>(),
                        )
                        .unwrap_or_default(),
                    };
                    let s = hgm_unit_restore(u, text.as_ptr());
                    if s == HgmStatus::Ok {
                        unit_outputs_finite(u);
                    }
                    ("hgm_unit_restore", s, hgm_unit_last_error(u))
                }
                _ => {
                    unit_outputs_finite(u);
                    let mut o = HgmOutputs::default();
                    let s = hgm_evaluate(m, f64::NAN, 0.0, 0.0, 0.0, &mut o);
                    assert!(m.is_null() || s == HgmStatus::InvalidArgument, "NaN evaluates");
                    ("hgm_evaluate(NaN)", HgmStatus::Ok, hgm_last_error(m))
                }
            };
            trace(|| format!("{what} -> {s:?}"));
            not_internal(what, s, msg);
            if s == HgmStatus::Ok && !u.is_null() && matches!(op, 2 | 6 | 7) {
                unit_outputs_finite(u);
            }
        }
        hgm_unit_free(u);
        hgm_free(m);
    }
}

// ---------------------------------------------------------------------------------------------
// fmi2_calls
// ---------------------------------------------------------------------------------------------

fn ok(s: fmi2Status) -> bool {
    matches!(s, fmi2Status::Ok | fmi2Status::Warning)
}

fn not_fatal(what: &str, s: fmi2Status) {
    assert!(s != fmi2Status::Fatal, "{what}: fmi2Fatal");
}

/// An FMI instance freed on drop.
struct Instance {
    c: fmi2Component,
    info: &'static ModelInfo,
}

impl Drop for Instance {
    fn drop(&mut self) {
        // SAFETY: live instance.
        unsafe { fmi2FreeInstance(self.c) };
    }
}

/// True for a variable whose value a model computes (outputs, calculated parameters, states'
/// derivatives and locals): finite whenever a get succeeds.
fn computed(v: &Variable) -> bool {
    matches!(v.causality, Causality::Output | Causality::CalculatedParameter | Causality::Local)
        && v.var_type() == VarType::Real
}

/// Checks every computed Real of the instance when the get succeeds.
fn check_reals(f: &Instance, what: &str) {
    let vrs: Vec<u32> = f.info.variables.iter().filter(|v| computed(v)).map(|v| v.vr).collect();
    let mut out = vec![0.0; vrs.len()];
    // SAFETY: live instance; arrays of the given length.
    let s = unsafe { fmi2GetReal(f.c, vrs.as_ptr(), vrs.len(), out.as_mut_ptr()) };
    not_fatal("fmi2GetReal", s);
    if ok(s) {
        for (vr, v) in vrs.iter().zip(&out) {
            let name = f.info.by_vr(*vr).map_or("?", |v| v.name);
            finite(&format!("after {what}: fmi2GetReal `{name}`"), *v);
        }
    }
}

/// A value for a Real variable: near its start value, sometimes special; bounded where a known
/// cost would hang (speeds, inertias, stiffnesses).
fn real_value(b: &mut Bytes, f: &Instance, v: &Variable) -> f64 {
    let start = f.info.start(v).and_then(|s| s.parse::<f64>().ok()).unwrap_or(0.0);
    if v.group & (group::GEOMETRY | group::ELASTIC) != 0 && v.causality == Causality::Parameter {
        // Any accepted change would mean an FE run: only values validation must refuse.
        let v = [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, -start][b.pick(4)];
        return b.bound(v, -start);
    }
    let x = b.f64_near(start, 2.0);
    let name = v.name;
    if name.starts_with('w') || name.contains("w_p_start") {
        return if x.is_finite() { x.clamp(-MAX_SPEED, MAX_SPEED) } else { x };
    }
    if v.group & (group::DRIVE | group::DENSITY) != 0
        && v.causality == Causality::Parameter
        && start > 0.0
        && x.is_finite()
        && x > 0.0
    {
        return x.clamp(start * MIN_INERTIA, start / MIN_INERTIA);
    }
    if name == "rtol" && x.is_finite() && x > 0.0 {
        return x.max(MIN_RTOL);
    }
    x
}

/// A value for an Integer variable, bounded where a known cost would hang.
fn int_value(b: &mut Bytes, v: &Variable) -> i32 {
    let x = if b.u8() < 16 { b.u32() as i32 } else { i32::from(b.u8() as i8) };
    match v.name {
        "slices" if x > MAX_SLICES => x % MAX_SLICES + 1,
        "table_phase_points" | "table_te_points" if x > MAX_TABLE_POINTS => {
            x % MAX_TABLE_POINTS + 1
        }
        "rk4_steps_per_mesh_period" if x > MAX_RK4_STEPS => x % MAX_RK4_STEPS + 1,
        _ => x,
    }
}

/// Sequences of `fmi2*` calls on one of the four models (first byte), Co-Simulation or Model
/// Exchange: set-up with coarse options (few slices, small tables, few RK4 sub-steps), then
/// set/get of every type by any value reference, steps with fuzzed sizes and communication
/// points, FMU states got, set, serialised and deserialised from fuzzed or flipped bytes, Model
/// Exchange calls, and calls in illegal orders.
pub fn fmi2_calls(data: &[u8]) {
    let mut b = Bytes::new(data);
    let info: &'static ModelInfo = MODELS[b.pick(MODELS.len())];
    let me = b.u8() < 64;
    let guid = CString::new(info.guid()).expect("no NUL");
    // SAFETY: valid strings; no callbacks.
    let c = unsafe {
        fmi2Instantiate(
            c"fuzz".as_ptr(),
            if me { FMI2_MODEL_EXCHANGE } else { FMI2_CO_SIMULATION },
            guid.as_ptr(),
            null(),
            null(),
            0,
            0,
        )
    };
    assert!(!c.is_null(), "{} instantiates", info.identifier);
    let f = Instance { c, info };
    // Coarse options: few slices, full fidelity or a small table, few RK4 sub-steps.
    let coarse = [
        ("slices", 8 + b.pick(25) as i32),
        ("fidelity", i32::from(b.bool())),
        ("table_phase_points", 8 + b.pick(3) as i32),
        ("table_te_points", 8 + b.pick(3) as i32),
        ("rk4_steps_per_mesh_period", 4 + b.pick(13) as i32),
    ];
    let set_coarse = || {
        for (name, v) in coarse {
            if let Some(var) = info.by_name(name) {
                // SAFETY: live instance; one value.
                let s = unsafe { fmi2SetInteger(c, &var.vr, 1, &v) };
                assert!(ok(s), "{name} = {v} refused");
            }
        }
    };
    set_coarse();
    trace(|| format!("{} {} {coarse:?}", info.identifier, if me { "ME" } else { "CS" }));
    let vars = info.variables;
    let nx = info.state_names().len();
    let mut t = 0.0;
    let mut states: Vec<fmi2FMUstate> = Vec::new();
    let mut serialised: Vec<u8> = Vec::new();
    for _ in 0..MAX_CALLS {
        if b.is_empty() {
            break;
        }
        let op = b.pick(24);
        // SAFETY: live instance; every pointer is to a local of the stated length.
        let (what, s) = unsafe {
            match op {
                0 => {
                    let s = fmi2SetupExperiment(
                        c,
                        b.u8() as i32 % 3,
                        b.f64_near(1e-6, 1.0),
                        0.0,
                        0,
                        0.0,
                    );
                    ("fmi2SetupExperiment", s)
                }
                1 => ("fmi2EnterInitializationMode", fmi2EnterInitializationMode(c)),
                2 | 3 => ("fmi2ExitInitializationMode", fmi2ExitInitializationMode(c)),
                4 | 5 => {
                    let n = 1 + b.pick(3);
                    let mut vrs = Vec::new();
                    let mut vals = Vec::new();
                    for _ in 0..n {
                        let v = &vars[b.pick(vars.len())];
                        if v.var_type() != VarType::Real {
                            continue;
                        }
                        vrs.push(if b.u8() == 0 { b.u32() } else { v.vr });
                        vals.push(real_value(&mut b, &f, v));
                    }
                    ("fmi2SetReal", fmi2SetReal(c, vrs.as_ptr(), vrs.len(), vals.as_ptr()))
                }
                6 => {
                    let v = &vars[b.pick(vars.len())];
                    let vr = if b.u8() == 0 { b.u32() } else { v.vr };
                    let x = int_value(&mut b, v);
                    ("fmi2SetInteger", fmi2SetInteger(c, &vr, 1, &x))
                }
                7 => {
                    let v = &vars[b.pick(vars.len())];
                    let x = if b.u8() < 16 { b.u32() as i32 } else { i32::from(b.bool()) };
                    ("fmi2SetBoolean", fmi2SetBoolean(c, &v.vr, 1, &x))
                }
                8 => {
                    let v = &vars[b.pick(vars.len())];
                    let text =
                        CString::new(b.chunk(80).iter().map(|&c| c.max(1)).collect::<Vec<u8>>())
                            .unwrap_or_default();
                    let p = if b.u8() == 0 { null() } else { text.as_ptr() };
                    ("fmi2SetString", fmi2SetString(c, &v.vr, 1, &p))
                }
                9 => {
                    let vr: Vec<u32> = vars.iter().map(|v| v.vr).collect();
                    let mut i = vec![0; vr.len()];
                    let mut bo = vec![0; vr.len()];
                    let mut st = vec![null(); vr.len()];
                    let k = b.pick(vr.len());
                    not_fatal("fmi2GetInteger", fmi2GetInteger(c, &vr[k], 1, i.as_mut_ptr()));
                    not_fatal("fmi2GetBoolean", fmi2GetBoolean(c, &vr[k], 1, bo.as_mut_ptr()));
                    let s = fmi2GetString(c, &vr[k], 1, st.as_mut_ptr());
                    if ok(s) {
                        assert!(!st[0].is_null(), "fmi2GetString gave NULL with OK");
                    }
                    ("fmi2GetString", s)
                }
                10..=12 => {
                    let h = match b.u8() {
                        0..=15 => b.special(1e-4).min(MAX_STEP_S),
                        _ => b.f64_in(0.0, MAX_STEP_S),
                    };
                    let at = if b.u8() < 16 { b.f64_near(t, 1.0) } else { t };
                    let s = fmi2DoStep(c, at, h, b.u8() as i32 % 2);
                    if ok(s) {
                        t = at + h;
                    }
                    ("fmi2DoStep", s)
                }
                13 => {
                    let mut st: fmi2FMUstate = null_mut();
                    let s = fmi2GetFMUstate(c, &mut st);
                    if ok(s) && !st.is_null() {
                        let mut n = 0usize;
                        if ok(fmi2SerializedFMUstateSize(c, st, &mut n)) && n < 1 << 20 {
                            let mut buf = vec![0 as fmi2Byte; n];
                            if ok(fmi2SerializeFMUstate(c, st, buf.as_mut_ptr(), n)) {
                                serialised = buf.iter().map(|&x| x as u8).collect();
                            }
                        }
                        states.push(st);
                    }
                    ("fmi2GetFMUstate", s)
                }
                14 => match states.last() {
                    Some(&st) if b.bool() => ("fmi2SetFMUstate", fmi2SetFMUstate(c, st)),
                    _ => ("fmi2SetFMUstate(NULL)", fmi2SetFMUstate(c, null_mut())),
                },
                15 => {
                    // Deserialise: the last serialised state (maybe with a flipped bit) or
                    // fuzzed bytes.
                    let bytes: Vec<u8> = if !serialised.is_empty() && b.bool() {
                        let mut v = serialised.clone();
                        if b.bool() {
                            let i = b.u16() as usize % v.len();
                            let bit = b.pick(8);
                            v[i] ^= 1 << bit;
                            trace(|| format!("serialised state, bit {bit} of byte {i} flipped"));
                        }
                        v
                    } else {
                        let v = b.chunk(200).to_vec();
                        trace(|| format!("fuzzed bytes as a state: {v:02x?}"));
                        v
                    };
                    let mut st: fmi2FMUstate = null_mut();
                    let s = fmi2DeSerializeFMUstate(c, bytes.as_ptr().cast(), bytes.len(), &mut st);
                    if ok(s) && !st.is_null() {
                        let s2 = fmi2SetFMUstate(c, st);
                        not_fatal("fmi2SetFMUstate", s2);
                        if ok(s2) {
                            check_reals(&f, "fmi2SetFMUstate of a deserialised state");
                        }
                        states.push(st);
                    }
                    ("fmi2DeSerializeFMUstate", s)
                }
                16 => {
                    let s = fmi2Reset(c);
                    if ok(s) {
                        // Back to the start values: the coarse options again.
                        set_coarse();
                    }
                    ("fmi2Reset", s)
                }
                17 => ("fmi2Terminate", fmi2Terminate(c)),
                18 => {
                    let s = fmi2SetTime(c, b.f64_near(t, 1.0));
                    ("fmi2SetTime", s)
                }
                19 => {
                    let mut x = vec![0.0; nx];
                    let s = fmi2GetContinuousStates(c, x.as_mut_ptr(), nx);
                    if ok(s) {
                        x.iter().for_each(|v| finite("fmi2GetContinuousStates", *v));
                        if b.bool() {
                            let i = b.pick(nx.max(1));
                            if let Some(v) = x.get_mut(i) {
                                *v = b.f64_near(*v, 1e-3);
                            }
                        }
                        let s2 = fmi2SetContinuousStates(c, x.as_ptr(), nx);
                        not_fatal("fmi2SetContinuousStates", s2);
                    }
                    ("fmi2GetContinuousStates", s)
                }
                20 => {
                    let mut dx = vec![0.0; nx];
                    let s = fmi2GetDerivatives(c, dx.as_mut_ptr(), nx);
                    if ok(s) {
                        dx.iter().for_each(|v| finite("fmi2GetDerivatives", *v));
                    }
                    let mut nom = vec![0.0; nx];
                    let s2 = fmi2GetNominalsOfContinuousStates(c, nom.as_mut_ptr(), nx);
                    if ok(s2) {
                        nom.iter().for_each(|v| finite("fmi2GetNominalsOfContinuousStates", *v));
                    }
                    ("fmi2GetDerivatives", s)
                }
                21 => {
                    let (mut enter, mut term) = (0, 0);
                    let s = fmi2CompletedIntegratorStep(c, 1, &mut enter, &mut term);
                    not_fatal("fmi2CompletedIntegratorStep", s);
                    not_fatal("fmi2EnterEventMode", fmi2EnterEventMode(c));
                    let mut ev = fmi2EventInfo {
                        newDiscreteStatesNeeded: 0,
                        terminateSimulation: 0,
                        nominalsOfContinuousStatesChanged: 0,
                        valuesOfContinuousStatesChanged: 0,
                        nextEventTimeDefined: 0,
                        nextEventTime: 0.0,
                    };
                    not_fatal("fmi2NewDiscreteStates", fmi2NewDiscreteStates(c, &mut ev));
                    ("fmi2EnterContinuousTimeMode", fmi2EnterContinuousTimeMode(c))
                }
                22 => {
                    // Directional derivative of up to 2 unknowns by up to 2 knowns, any vrs.
                    let pickvr = |b: &mut Bytes| vars[b.pick(vars.len())].vr;
                    let unknown = [pickvr(&mut b), pickvr(&mut b)];
                    let known = [pickvr(&mut b), pickvr(&mut b)];
                    let nu = 1 + b.pick(2);
                    let nk = 1 + b.pick(2);
                    let dk = [b.f64_near(1.0, 1.0), b.f64_near(1.0, 1.0)];
                    let mut du = [0.0; 2];
                    let s = fmi2GetDirectionalDerivative(
                        c,
                        unknown.as_ptr(),
                        nu,
                        known.as_ptr(),
                        nk,
                        dk.as_ptr(),
                        du.as_mut_ptr(),
                    );
                    if ok(s) && dk.iter().take(nk).all(|x| x.is_finite()) {
                        du.iter().take(nu).for_each(|v| finite("fmi2GetDirectionalDerivative", *v));
                    }
                    ("fmi2GetDirectionalDerivative", s)
                }
                _ => {
                    let v = &vars[b.pick(vars.len())];
                    let order = [b.u8() as i32 % 3];
                    let val = [b.f64_near(0.0, 1e3)];
                    let s = fmi2SetRealInputDerivatives(c, &v.vr, 1, order.as_ptr(), val.as_ptr());
                    not_fatal("fmi2SetRealInputDerivatives", s);
                    let mut out = [0.0];
                    let s2 =
                        fmi2GetRealOutputDerivatives(c, &v.vr, 1, order.as_ptr(), out.as_mut_ptr());
                    if ok(s2) {
                        finite("fmi2GetRealOutputDerivatives", out[0]);
                    }
                    ("fmi2SetRealInputDerivatives", s)
                }
            }
        };
        trace(|| format!("{}: {what} -> {s:?}", info.identifier));
        not_fatal(what, s);
        check_reals(&f, what);
    }
    for mut st in states {
        // SAFETY: states of this instance.
        unsafe { fmi2FreeFMUstate(c, &mut st) };
    }
}
