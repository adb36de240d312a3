//! Model Exchange through the exported FMI functions: the state machine, the states in
//! relative coordinates and their derivatives, integration by a master's own RK4 against the
//! Co-Simulation run, and `fmi2GetDirectionalDerivative` against central differences of the
//! model's own derivatives and outputs (the FMU computes its derivatives from the mesh
//! Jacobian, never by differences; this test is the independent check).

mod common;

use helical_gear_mesh::fmi2::exports::*;
use helical_gear_mesh::fmi2::model::ModelInfo;
use helical_gear_mesh::fmi2::models::mesh::INFO as MESH;
use helical_gear_mesh::fmi2::models::unit::{DRIVE, PAIR, STAGE};
use helical_gear_mesh::fmi2::types::*;

use common::fmi::ModelFmu as Fmu;

/// A coarse mesh and table (the properties checked do not depend on the resolution).
const COARSE: [(&str, i32); 3] =
    [("slices", 30), ("table_phase_points", 24), ("table_te_points", 16)];

impl Fmu {
    /// An instance of `m` of type `ty`, integers/booleans/reals set before initialisation.
    fn new(
        m: &'static ModelInfo,
        ty: fmi2Type,
        reals: &[(&str, f64)],
        ints: &[(&str, i32)],
    ) -> Self {
        let f = Fmu::instantiate(m, ty);
        for (n, v) in reals {
            f.set(&[n], &[*v]);
        }
        for (n, v) in ints {
            let vr = m.by_name(n).unwrap().vr;
            assert_eq!(unsafe { fmi2SetInteger(f.0, &vr, 1, v) }, fmi2Status::Ok);
        }
        f.init();
        f
    }

    fn nx(&self) -> usize {
        self.1.state_names().len()
    }

    fn states(&self) -> Vec<f64> {
        let mut x = vec![0.0; self.nx()];
        assert_eq!(
            unsafe { fmi2GetContinuousStates(self.0, x.as_mut_ptr(), x.len()) },
            fmi2Status::Ok
        );
        x
    }

    fn set_states(&self, x: &[f64]) {
        assert_eq!(unsafe { fmi2SetContinuousStates(self.0, x.as_ptr(), x.len()) }, fmi2Status::Ok);
    }

    fn derivatives(&self) -> Vec<f64> {
        let mut dx = vec![0.0; self.nx()];
        assert_eq!(
            unsafe { fmi2GetDerivatives(self.0, dx.as_mut_ptr(), dx.len()) },
            fmi2Status::Ok
        );
        dx
    }

    fn nominals(&self) -> Vec<f64> {
        let mut x = vec![0.0; self.nx()];
        let st = unsafe { fmi2GetNominalsOfContinuousStates(self.0, x.as_mut_ptr(), x.len()) };
        assert_eq!(st, fmi2Status::Ok);
        x
    }

    /// ∂unknowns/∂known by fmi2GetDirectionalDerivative with a unit seed.
    fn dd(&self, unknowns: &[&str], known: &str) -> Result<Vec<f64>, fmi2Status> {
        let u = self.vrs(unknowns);
        let k = self.vrs(&[known]);
        let mut out = vec![0.0; u.len()];
        let st = unsafe {
            fmi2GetDirectionalDerivative(
                self.0,
                u.as_ptr(),
                u.len(),
                k.as_ptr(),
                1,
                &1.0,
                out.as_mut_ptr(),
            )
        };
        if st == fmi2Status::Ok { Ok(out) } else { Err(st) }
    }

    fn to_continuous_time(&self) {
        unsafe {
            let mut info = std::mem::zeroed::<fmi2EventInfo>();
            assert_eq!(fmi2NewDiscreteStates(self.0, &mut info), fmi2Status::Ok);
            assert_eq!(info.newDiscreteStatesNeeded, FMI2_FALSE);
            assert_eq!(info.nextEventTimeDefined, FMI2_FALSE);
            assert_eq!(fmi2EnterContinuousTimeMode(self.0), fmi2Status::Ok);
        }
    }
}

/// Largest |a − b| over the largest |a| (or `floor`).
fn rel(a: &[f64], b: &[f64], floor: f64) -> f64 {
    let s = a.iter().fold(floor, |m, v| m.max(v.abs()));
    a.iter().zip(b).fold(0.0_f64, |m, (x, y)| m.max((x - y).abs())) / s
}

#[test]
fn states_and_derivatives_are_the_co_simulation_model_in_relative_coordinates() {
    for m in [&PAIR, &STAGE, &DRIVE] {
        let me = Fmu::new(m, FMI2_MODEL_EXCHANGE, &[], &COARSE);
        let cs = Fmu::new(m, FMI2_CO_SIMULATION, &[], &COARSE);
        me.to_continuous_time();
        let x = me.states();
        let names = m.state_names();
        // The states are the variables they name, and TE is the mesh's TE.
        for (i, n) in names.iter().enumerate() {
            let v = me.get(&[n])[0];
            assert!(
                (v - x[i]).abs() <= 1e-12 * v.abs().max(1e-9),
                "{} {n}: {v} vs {}",
                m.identifier,
                x[i]
            );
        }
        let dx = me.derivatives();
        let ders: Vec<String> = names.iter().map(|n| format!("der({n})")).collect();
        let der_names: Vec<&str> = ders.iter().map(String::as_str).collect();
        assert_eq!(
            me.get(&der_names),
            dx,
            "{}: der(...) variables = fmi2GetDerivatives",
            m.identifier
        );
        // Kinematic rows: der(phi_p) = w_p, der(TE) = v_TE.
        let ix = |n: &str| names.iter().position(|s| *s == n).unwrap();
        assert_eq!(dx[ix("phi_p")], x[ix("w_p")]);
        assert_eq!(dx[ix("TE")], x[ix("v_TE")]);
        // Same start, same physics as the Co-Simulation instance.
        let a = cs.get(&["a_p", "a_g", "TE", "w_p"]);
        let b = me.get(&["a_p", "a_g", "TE", "w_p"]);
        assert!(rel(&a, &b, 0.0) < 1e-9, "{}: CS {a:?} ME {b:?}", m.identifier);
        assert!((dx[ix("w_p")] - a[0]).abs() <= 1e-9 * a[0].abs().max(1.0));
        // No event indicators (a measured contact-loss run gained nothing from them: docs/fmus.md).
        assert_eq!(m.event_indicators, 0);
        assert_eq!(
            unsafe { fmi2GetEventIndicators(me.0, std::ptr::null_mut(), 0) },
            fmi2Status::Ok
        );
        // Nominals positive; a state set is read back.
        assert!(me.nominals().iter().all(|v| v.is_finite() && *v > 0.0));
        let mut x2 = x.clone();
        x2[ix("TE")] *= 1.01;
        me.set_states(&x2);
        assert!(rel(&me.states(), &x2, 0.0) < 1e-12);
        assert!(me.get(&["TE"])[0] > 1.009 * x[ix("TE")]);
        // Wrong nx and non-finite states are errors.
        unsafe {
            assert_eq!(fmi2SetContinuousStates(me.0, x.as_ptr(), x.len() - 1), fmi2Status::Error);
            assert_eq!(fmi2Reset(me.0), fmi2Status::Ok);
        }
    }
}

/// A master's own classical RK4 through fmi2SetTime/SetContinuousStates/GetDerivatives at
/// the Co-Simulation unit's sub-step reproduces its trajectory (different coordinates, same
/// method and step: agreement to rounding).
#[test]
fn a_masters_rk4_through_model_exchange_follows_the_co_simulation_run() {
    let w = 532.0;
    // Below T_m/128 at every speed the run reaches: one sub-step of the unit per step.
    let h = 0.99 * 2.0 * std::f64::consts::PI / (30.0 * w) / 128.0;
    let n = 400;
    let me = Fmu::new(&DRIVE, FMI2_MODEL_EXCHANGE, &[("w_p_start", w)], &COARSE);
    let cs = Fmu::new(&DRIVE, FMI2_CO_SIMULATION, &[("w_p_start", w)], &COARSE);
    me.to_continuous_time();
    let mut x = me.states();
    let nx = x.len();
    let mut t = 0.0;
    let (mut te_me, mut te_cs) = (Vec::new(), Vec::new());
    let rhs = |t: f64, x: &[f64]| -> Vec<f64> {
        assert_eq!(unsafe { fmi2SetTime(me.0, t) }, fmi2Status::Ok);
        me.set_states(x);
        me.derivatives()
    };
    for _ in 0..n {
        let k1 = rhs(t, &x);
        let xa: Vec<f64> = (0..nx).map(|i| x[i] + 0.5 * h * k1[i]).collect();
        let k2 = rhs(t + 0.5 * h, &xa);
        let xb: Vec<f64> = (0..nx).map(|i| x[i] + 0.5 * h * k2[i]).collect();
        let k3 = rhs(t + 0.5 * h, &xb);
        let xc: Vec<f64> = (0..nx).map(|i| x[i] + h * k3[i]).collect();
        let k4 = rhs(t + h, &xc);
        for i in 0..nx {
            x[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        }
        t += h;
        assert_eq!(unsafe { fmi2SetTime(me.0, t) }, fmi2Status::Ok);
        me.set_states(&x);
        let mut enter = FMI2_TRUE;
        let mut stop = FMI2_TRUE;
        let st = unsafe { fmi2CompletedIntegratorStep(me.0, FMI2_TRUE, &mut enter, &mut stop) };
        assert_eq!((st, enter, stop), (fmi2Status::Ok, FMI2_FALSE, FMI2_FALSE));
        te_me.push(me.get(&["TE"])[0]);
        assert_eq!(unsafe { fmi2DoStep(cs.0, t - h, h, 1) }, fmi2Status::Ok);
        te_cs.push(cs.get(&["TE"])[0]);
    }
    let e = rel(&te_cs, &te_me, 0.0);
    eprintln!(
        "ME (master RK4) vs CS over {n} steps of T_m/128 at {w} rad/s: TE difference {e:.2e}"
    );
    assert!(e < 1e-8, "TE difference {e:e} of max |TE|");
    unsafe {
        assert_eq!(fmi2Terminate(me.0), fmi2Status::Ok);
        assert_eq!(fmi2DoStep(me.0, t, h, 1), fmi2Status::Error, "no doStep in Model Exchange");
    }
}

/// Central differences of `f` (outputs or derivatives) in known `k` with step `d`.
fn central(
    f: &Fmu,
    known: &str,
    is_state: bool,
    d: f64,
    read: &dyn Fn(&Fmu) -> Vec<f64>,
) -> Vec<f64> {
    let at = |s: f64| -> Vec<f64> {
        if is_state {
            let names = f.1.state_names();
            let i = names.iter().position(|n| *n == known).unwrap();
            let mut x = f.states();
            let x0 = x[i];
            x[i] = x0 + s;
            f.set_states(&x);
            let r = read(f);
            x[i] = x0;
            f.set_states(&x);
            r
        } else {
            let v0 = f.get(&[known])[0];
            f.set(&[known], &[v0 + s]);
            let r = read(f);
            f.set(&[known], &[v0]);
            r
        }
    };
    let (p, m) = (at(d), at(-d));
    p.iter().zip(&m).map(|(a, b)| (a - b) / (2.0 * d)).collect()
}

/// Directional derivatives of the state derivatives and the outputs of every stateful model
/// (table fidelity, the default; and the Drive at full fidelity) with respect to every state and input, against central
/// differences of `fmi2GetDerivatives` and `fmi2GetReal` near the static-equilibrium start
/// (loaded, no change of contact state within the steps). Worst relative error per column
/// (over the column's largest entry) asserted below 1e-5.
#[test]
fn directional_derivatives_agree_with_central_differences() {
    let full = [("slices", 30), ("fidelity", 0)];
    let mut worst: f64 = 0.0;
    let mut worst_full: f64 = 0.0;
    for (m, ints) in [(&PAIR, &COARSE[..]), (&STAGE, &COARSE), (&DRIVE, &COARSE), (&DRIVE, &full)] {
        let f = Fmu::new(m, FMI2_MODEL_EXCHANGE, &[], ints);
        let is_full = ints.contains(&("fidelity", 0));
        f.to_continuous_time();
        let states = m.state_names();
        // Off the table's phase nodes (the static start φp = 0 is one; there the interpolant
        // is C¹ but its second derivative jumps, which central differences straddle).
        let mut x = f.states();
        x[0] += 0.0037;
        f.set_states(&x);
        let ders: Vec<String> = states.iter().map(|n| format!("der({n})")).collect();
        let mut unknowns: Vec<&str> = ders.iter().map(String::as_str).collect();
        let outs: Vec<&str> = [
            "M_F_p", "M_F_g", "M_D_p", "M_D_g", "TE", "a_p", "a_g", "phi_g", "w_g", "tau_1",
            "tau_2", "phi_1", "w_2",
        ]
        .into_iter()
        .filter(|n| m.by_name(n).is_some_and(|v| v.causality.as_str() == "output"))
        .collect();
        unknowns.extend(&outs);
        let inputs: Vec<&str> = m
            .variables
            .iter()
            .filter(|v| v.causality.as_str() == "input")
            .map(|v| v.name)
            .collect();
        let nominals = f.nominals();
        let mut knowns: Vec<(&str, bool, f64)> =
            states.iter().zip(&nominals).map(|(n, nom)| (*n, true, 1e-5 * nom)).collect();
        for i in &inputs {
            let v = f.get(&[i])[0];
            knowns.push((i, false, 1e-6 * v.abs().max(1.0)));
        }
        for (k, is_state, d) in knowns {
            let ad =
                f.dd(&unknowns, k).unwrap_or_else(|s| panic!("{} d/d{k}: {s:?}", m.identifier));
            let un = unknowns.clone();
            let fd = central(&f, k, is_state, d, &|f: &Fmu| f.get(&un));
            for (r, name) in unknowns.iter().enumerate() {
                // Each unknown row against its own scale over all knowns would need the whole
                // matrix; per entry: relative to max(|ad|, |fd|) with an absolute floor of
                // 1e-9 of the row's unit scale.
                let scale = ad[r].abs().max(fd[r].abs());
                let err = (ad[r] - fd[r]).abs();
                if scale > 0.0 {
                    let e = err / scale;
                    if err > 1e-9 * scale.max(1e-300) && scale > 1e-6 * largest(&ad).max(1e-12) {
                        if is_full {
                            worst_full = worst_full.max(e);
                        } else {
                            worst = worst.max(e);
                        }
                        assert!(
                            e < 1e-5,
                            "{}: d{name}/d{k}: exact {} vs central {} (rel {e:.2e})",
                            m.identifier,
                            ad[r],
                            fd[r]
                        );
                    }
                } else {
                    assert_eq!(fd[r], 0.0, "{}: d{name}/d{k}", m.identifier);
                }
            }
        }
        // Unknowns the model does not differentiate are named errors, not zeros.
        assert_eq!(f.dd(&["F_n"], "w_p"), Err(fmi2Status::Error));
    }
    eprintln!(
        "directional derivatives vs central differences: worst relative {worst:.2e} (table), \
         {worst_full:.2e} (full, Drive)"
    );
    assert!(worst_full > 0.0, "the full-fidelity Drive was checked");
}

fn largest(v: &[f64]) -> f64 {
    v.iter().fold(0.0_f64, |m, x| m.max(x.abs()))
}

/// The mesh element (no states, direct feedthrough) in Model Exchange at its default full
/// fidelity: ∂(mesh torques, TE)/∂(angles, rates) against central differences of the outputs.
#[test]
fn mesh_element_directional_derivatives_at_full_fidelity() {
    let f = Fmu::new(&MESH, FMI2_MODEL_EXCHANGE, &[], &[("slices", 30)]);
    assert_eq!(f.nx(), 0);
    f.to_continuous_time();
    let gp = f.get(&["base_radius_p"])[0];
    let gg = f.get(&["base_radius_g"])[0];
    // A loaded state: TE = 15 µm at a mesh phase inside a pitch, running at 300 rad/s.
    let phi_p = 0.013;
    let phi_g = (15e-6 - gp * phi_p) / gg;
    f.set(&["phi_p", "phi_g", "w_p", "w_g"], &[phi_p, phi_g, 300.0, -300.0 * gp / gg + 1e-3 / gg]);
    let unknowns = ["M_F_p", "M_F_g", "M_D_p", "M_D_g", "TE"];
    let mut worst: f64 = 0.0;
    for (k, d) in [("phi_p", 2e-9), ("phi_g", 2e-9), ("w_p", 1e-3), ("w_g", 1e-3)] {
        let ad = f.dd(&unknowns, k).unwrap();
        let fd = central(&f, k, false, d, &|f: &Fmu| f.get(&unknowns));
        let e = rel(&ad, &fd, 1e-12);
        worst = worst.max(e);
        assert!(e < 1e-5, "d/d{k}: exact {ad:?} vs central {fd:?} ({e:.2e})");
    }
    eprintln!(
        "mesh element, full fidelity: directional derivatives vs central differences {worst:.2e}"
    );
    // Derivatives with respect to a parameter are not provided: a named error.
    assert_eq!(f.dd(&["M_F_p"], "d_mesh"), Err(fmi2Status::Error));
}

/// The mesh element as a force element of a multibody master: the twenty pose inputs
/// (`u_p_x` … `om_g_y`) displace the gear bodies; the outputs are the library's at that state
/// and the directional derivatives with respect to every pose input agree with central
/// differences of the outputs; a pose beyond its bound is an error status whose message names
/// the input.
#[test]
fn mesh_element_pose_inputs_and_their_directional_derivatives() {
    use helical_gear_mesh::GearPair;
    use helical_gear_mesh::mesh::{BodyPose, Mesh, MeshOptions, MeshState, pose};
    let f = Fmu::new(&MESH, FMI2_MODEL_EXCHANGE, &[], &[("slices", 30)]);
    f.to_continuous_time();
    let gp = f.get(&["base_radius_p"])[0];
    let gg = f.get(&["base_radius_g"])[0];
    let phi_p = 0.013;
    let phi_g = (15e-6 - gp * phi_p) / gg;
    let (w_p, w_g) = (300.0, -300.0 * gp / gg + 1e-3 / gg);
    f.set(&["phi_p", "phi_g", "w_p", "w_g"], &[phi_p, phi_g, w_p, w_g]);
    let values = [
        -2e-6, 1e-6, 3e-6, 1e-4, -5e-5, 3e-6, -2e-6, -4e-6, -1e-4, 2e-4, 1e-3, -2e-3, 5e-4, 0.02,
        -0.01, -1e-3, 1e-3, 0.0, 0.01, 0.03,
    ];
    f.set(&pose::INPUT_NAMES, &values);
    let unknowns = ["M_F_p", "M_F_g", "M_D_p", "M_D_g", "TE"];
    let got = f.get(&unknowns);
    let options = MeshOptions { slices: 30, ..MeshOptions::default() };
    let mut lib = Mesh::new(&GearPair::paper_table1(), options).unwrap();
    let mut s = MeshState { phi_p, phi_g, w_p, w_g, ..Default::default() };
    pose::set_inputs(&mut s, &values);
    assert!(s.pose_g != BodyPose::default());
    let o = lib.evaluate(&s).unwrap();
    let want = [o.m_f_p, o.m_f_g, o.m_d_p, o.m_d_g, o.te];
    assert!(rel(&got, &want, 1e-12) < 1e-9, "{got:?} vs the library's {want:?}");
    let mut worst: f64 = 0.0;
    for (k, name) in pose::INPUT_NAMES.iter().enumerate() {
        // Steps large enough that the warm-started solves' rounding stays below 1e-6 of the
        // quotient, small enough that no slice changes its load state.
        let d = match (k / 10, k % 5 < 3) {
            (0, true) => 1e-9,
            (0, false) => 1e-7,
            _ => 1e-3,
        };
        let ad = f.dd(&unknowns, name).unwrap();
        let fd = central(&f, name, false, d, &|f: &Fmu| f.get(&unknowns));
        let e = rel(&ad, &fd, 1e-6);
        worst = worst.max(e);
        assert!(e < 1e-5, "d/d{name}: exact {ad:?} vs central {fd:?} ({e:.2e})");
    }
    eprintln!(
        "mesh element pose inputs: directional derivatives vs central differences {worst:.2e}"
    );
    // Beyond its bound (0.05·m_n = 150 µm for Table 1): an error, not a number.
    f.set(&["u_g_x"], &[2e-4]);
    let r = f.vrs(&["M_F_p"]);
    let mut x = [0.0];
    let st = unsafe { fmi2GetReal(f.0, r.as_ptr(), 1, x.as_mut_ptr()) };
    assert_eq!(st, fmi2Status::Error);
}

/// Model Exchange at large angles: the states are (φp, TE, …) and the gear angle is formed from
/// them, so TE keeps its digits only up to the stated bound (|φp|·g_p ≤ 4.5·10⁶ m, about 10⁸ rad
/// for Table 1). Up to it the outputs at a state whole pitches away (φp + k·2π/z_p, the same TE)
/// equal those at the small angle (TE to 1 nm, M_F,p to 10⁻⁴); beyond it, at 10¹² rad where TE
/// came out 37.9 µm for a 31.1 µm state with fmi2OK, the state is refused naming φp and the
/// bound.
#[test]
fn large_angle_states_keep_te_or_are_refused() {
    use helical_gear_mesh::mesh::validity::MAX_FORMED_ARC_M;
    for m in [&PAIR, &DRIVE] {
        let me = Fmu::new(m, FMI2_MODEL_EXCHANGE, &[], &COARSE);
        me.to_continuous_time();
        let x0 = me.states();
        let te_at = |x: &[f64]| {
            me.set_states(x);
            me.get(&["TE", "M_F_p"])
        };
        let small = te_at(&x0);
        let gp = me.get(&["base_radius_p"])[0];
        let pitch = 2.0 * std::f64::consts::PI / 30.0;
        let max = MAX_FORMED_ARC_M / gp;
        // Whole pitches up to the bound: at 1e4 rad and just below the bound.
        for target in [1e4, 0.99 * max] {
            let k = (target / pitch).floor();
            let mut x = x0.clone();
            x[0] = x0[0] + k * pitch;
            let big = te_at(&x);
            // The shift itself is rounded to ulp(φp): up to ½ulp(φp)·g_p of TE.
            let shift_err = 0.5 * f64::EPSILON * x[0].abs() * gp;
            assert!(
                (big[0] - small[0]).abs() <= 1e-9 + shift_err,
                "{} at {:.3e} rad: TE {:e} against {:e}",
                m.identifier,
                x[0],
                big[0],
                small[0]
            );
            assert!((big[1] - small[1]).abs() <= 1e-4 * small[1].abs(), "{}", m.identifier);
        }
        let mut x = x0.clone();
        x[0] = 1e12;
        let st = unsafe { fmi2SetContinuousStates(me.0, x.as_ptr(), x.len()) };
        assert_eq!(st, fmi2Status::Error, "{}: a state at 1e12 rad is refused", m.identifier);
    }
}
