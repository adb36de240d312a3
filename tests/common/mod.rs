//! Helpers shared by the integration-test binaries under `tests/` (each binary declares
//! `mod common;` and uses what it needs; a helper one binary leaves unused is no warning there).
//!
//! * this module: the Table 1 pair's geometry, drivetrain and pitch, mesh options and states,
//!   a relative difference, the deterministic random numbers of the randomised tests, the
//!   drive line's right-hand side with a dissipation quadrature, and a mesh that fails on
//!   purpose;
//! * [`cosim`]: the co-simulation masters of the Table 1 drive line;
//! * [`fe`]: checks of a whole-gear FE mesh (volume, Jacobians);
//! * [`fmi`]: FMI 2.0 instances freed on drop, of the HelicalGearMesh model (Co-Simulation)
//!   and of any model of the family, with value references by name.
//!
//! `cosim` and `fe` are also compiled into the measurement program `app/examples/measure.rs`,
//! so the figures of `docs/bench/` come from the code the tests assert.
//! `tests/fuzz_harness/` is the other shared module: the fuzz targets' harness, replayed over
//! the corpus by `tests/fuzz_corpus.rs`.
#![allow(dead_code)]

pub mod cosim;
pub mod fe;
pub mod fmi;

use helical_gear_mesh::dynamics::model::{W_1, W_2, W_G, W_P};
use helical_gear_mesh::dynamics::{
    ConstantStiffnessMesh, Drivetrain, GearDynamics, OdeError, OdeSystem,
};
use helical_gear_mesh::mesh::{
    Fidelity, Mesh, MeshError, MeshOptions, MeshOutputs, MeshState, MeshTorques,
};
use helical_gear_mesh::{GearPair, PairGeometry};

/// The geometry of the Table 1 pair.
pub fn table1_geometry() -> PairGeometry {
    PairGeometry::new(&GearPair::paper_table1()).expect("Table 1 is valid")
}

/// The Table 1 drivetrain and the base radii (g_p, g_g), m.
pub fn table1_drive_radii() -> (Drivetrain, f64, f64) {
    let pair = GearPair::paper_table1();
    let g = PairGeometry::new(&pair).unwrap();
    (
        Drivetrain::from_pair(&pair, &helical_gear_mesh::DriveLine::paper_table1()).unwrap(),
        g.pinion.rb,
        g.gear.rb,
    )
}

/// The angular pitch of the Table 1 pinion, 2π/z_p, rad.
pub fn table1_pitch() -> f64 {
    2.0 * std::f64::consts::PI / GearPair::paper_table1().z_p as f64
}

/// The benchmark's layout of Table 1 states (`bench`, "Mesh evaluation", which takes 64
/// phases): `phases` pinion angles over one pitch, each at 0.37 of its phase cell, at TE = 16,
/// 32 and 48 µm (0.53, 1.07 and 1.61 × 30 µm), with a TE rate for the damping torque
/// (φ̇p = 200, φ̇g = −120 rad/s).
pub fn benchmark_states(geo: &PairGeometry, phases: usize) -> Vec<MeshState> {
    let pitch = table1_pitch();
    let mut states = Vec::new();
    for f in [0.53, 1.07, 1.61] {
        for k in 0..phases {
            let phi_p = (k as f64 + 0.37) / phases as f64 * pitch;
            let phi_g = geo.phi_g_for_te(phi_p, f * 30e-6);
            states.push(MeshState { phi_p, phi_g, w_p: 200.0, w_g: -120.0, ..Default::default() });
        }
    }
    states
}

/// Small, fast mesh options at `fidelity`: 40 slices and a 16 × 12 table.
pub fn coarse_options(fidelity: Fidelity) -> MeshOptions {
    MeshOptions {
        fidelity,
        slices: 40,
        table_phase_points: 16,
        table_te_points: 12,
        ..MeshOptions::default()
    }
}

/// Table fidelity on a small table for dynamics (60 slices, 24 × 16 nodes, no pressure
/// output): quick to build.
pub fn small_table_options() -> MeshOptions {
    MeshOptions {
        fidelity: Fidelity::Table,
        slices: 60,
        table_phase_points: 24,
        table_te_points: 16,
        pressure: false,
        ..MeshOptions::default()
    }
}

/// A state of `m` at rest (zero speeds) with pinion angle `phi_p` (rad) and transmission error
/// `te` (m, positive loading the driving flanks).
pub fn state_at_rest(m: &Mesh, phi_p: f64, te: f64) -> MeshState {
    MeshState {
        phi_p,
        phi_g: m.geometry().phi_g_for_te(phi_p, te),
        w_p: 0.0,
        w_g: 0.0,
        ..Default::default()
    }
}

/// |a − b| / |b|: the relative difference of `a` from the reference `b`.
pub fn rel_diff(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// Deterministic pseudo-random numbers from a 64-bit linear congruential generator (Knuth's
/// MMIX constants), the upper 53 bits as the fraction.
pub struct Lcg(pub u64);

impl Lcg {
    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> f64 {
        self.0 =
            self.0.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in [−1, 1).
    pub fn signed(&mut self) -> f64 {
        self.uniform() * 2.0 - 1.0
    }

    /// Standard normal deviate (Box–Muller).
    pub fn normal(&mut self) -> f64 {
        let u1 = self.uniform().max(1e-300);
        let u2 = self.uniform();
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    }
}

/// Deterministic pseudo-random numbers from SplitMix64.
pub struct SplitMix64(pub u64);

impl SplitMix64 {
    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Deterministic pseudo-random numbers from xorshift64* (Vigna): small, seeded, no dependency.
pub struct XorShift64Star(pub u64);

impl XorShift64Star {
    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        let mut x = self.0;
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        self.0 = x;
        x.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }

    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }

    /// An integer in lo..=hi (modulo bias negligible for small ranges).
    pub fn int(&mut self, lo: u32, hi: u32) -> u32 {
        lo + (self.next_u64() % u64::from(hi - lo + 1)) as u32
    }
}

/// Eqs. 1–4 of `model` into `d[..8]` and, in `d[8]`, the power (W) dissipated in the shaft
/// dampers d₁, d₂ and the mesh damper: the right-hand side of the drive line with one
/// quadrature state `y[8]`, the energy dissipated, for energy-balance checks.
pub fn rhs_with_dissipation<M: MeshTorques>(
    model: &mut GearDynamics<M>,
    t: f64,
    y: &[f64],
    d: &mut [f64],
) -> Result<(), OdeError> {
    model.rhs(t, &y[..8], &mut d[..8])?;
    // The same mesh evaluation (remembered) gives the mesh damping torques.
    let o = model.outputs(&y[..8]).map_err(|e| OdeError::rhs(t, e))?;
    let dr = model.drive();
    d[8] = dr.d1 * (y[W_1] - y[W_P]).powi(2)
        + dr.d2 * (y[W_G] - y[W_2]).powi(2)
        + o.m_d_p * y[W_P]
        + o.m_d_g * y[W_G];
    Ok(())
}

/// A mesh that fails beyond a pinion angle, like a load solver that does not converge.
#[derive(Clone)]
pub struct FailingMesh {
    /// The mesh below `phi_fail`.
    pub inner: ConstantStiffnessMesh,
    /// The pinion angle (rad) beyond which every evaluation fails.
    pub phi_fail: f64,
}

impl MeshTorques for FailingMesh {
    fn mesh(&mut self, s: &MeshState) -> Result<MeshOutputs, MeshError> {
        if s.phi_p > self.phi_fail {
            return Err(MeshError::Equilibrium(format!("synthetic failure at φp = {}", s.phi_p)));
        }
        self.inner.mesh(s)
    }

    fn base_radii(&self) -> (f64, f64) {
        self.inner.base_radii()
    }
}
