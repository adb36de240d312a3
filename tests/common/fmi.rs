//! FMI 2.0 instances through the exported `fmi2*` functions, as an importer would hold them:
//! [`Fmu`], a Co-Simulation instance of the HelicalGearMesh model (`tests/fmi2.rs`,
//! `tests/robust_interfaces.rs`, `tests/stress_interfaces.rs`), and [`ModelFmu`], an instance
//! of any model of the family (`tests/fmi2_family.rs`, `tests/fmi2_model_exchange.rs`).

use std::ffi::CString;
use std::ptr::{null, null_mut};

use helical_gear_mesh::fmi2::exports::*;
use helical_gear_mesh::fmi2::model::ModelInfo;
use helical_gear_mesh::fmi2::models::mesh::{by_name, guid};
use helical_gear_mesh::fmi2::types::*;

/// The value reference of the HelicalGearMesh variable `name` (panics on an unknown name).
pub fn vr(name: &str) -> u32 {
    by_name(name).unwrap_or_else(|| panic!("no variable {name}")).vr
}

/// An instance created without callbacks (no logger), with a resource location that does not
/// exist (the model needs no resource; the URI's `%20` is decoded and only logged); freed on
/// drop.
pub struct Fmu(pub fmi2Component);

impl Fmu {
    /// A new instance in the `instantiated` state.
    #[allow(clippy::new_without_default)] // an instance is a resource, not a default value
    pub fn new() -> Self {
        let g = CString::new(guid()).unwrap();
        let c = unsafe {
            fmi2Instantiate(
                c"test".as_ptr(),
                FMI2_CO_SIMULATION,
                g.as_ptr(),
                c"file:///nonexistent/my%20fmu/resources".as_ptr(),
                null(),
                FMI2_FALSE,
                FMI2_FALSE,
            )
        };
        assert!(!c.is_null());
        Fmu(c)
    }

    /// A new instance, initialised with the default parameters ([`Fmu::init`]).
    pub fn initialised() -> Self {
        let f = Self::new();
        f.init();
        f
    }

    /// `fmi2SetupExperiment` (no tolerance, start 0, no stop time) and
    /// `fmi2EnterInitializationMode`, both asserted Ok.
    pub fn setup(&self) {
        unsafe {
            assert_eq!(
                fmi2SetupExperiment(self.0, FMI2_FALSE, 0.0, 0.0, FMI2_FALSE, 0.0),
                fmi2Status::Ok
            );
            assert_eq!(fmi2EnterInitializationMode(self.0), fmi2Status::Ok);
        }
    }

    /// [`Fmu::setup`], then `fmi2ExitInitializationMode`, asserted Ok.
    pub fn init(&self) {
        self.setup();
        assert_eq!(unsafe { fmi2ExitInitializationMode(self.0) }, fmi2Status::Ok);
    }

    /// `fmi2Reset`, asserted Ok.
    pub fn reset(&self) {
        assert_eq!(unsafe { fmi2Reset(self.0) }, fmi2Status::Ok);
    }

    /// [`Fmu::reset`] and [`Fmu::init`]: back to an initialised instance after an error.
    pub fn recover(&self) {
        self.reset();
        self.init();
    }

    /// `fmi2SetReal` of the variables `names` to `values`; its status.
    pub fn set(&self, names: &[&str], values: &[f64]) -> fmi2Status {
        let r: Vec<u32> = names.iter().map(|n| vr(n)).collect();
        unsafe { fmi2SetReal(self.0, r.as_ptr(), r.len(), values.as_ptr()) }
    }

    /// `fmi2GetReal` of the variables `names`: the values, or the status if not Ok.
    pub fn get(&self, names: &[&str]) -> Result<Vec<f64>, fmi2Status> {
        let r: Vec<u32> = names.iter().map(|n| vr(n)).collect();
        let mut out = vec![0.0; r.len()];
        match unsafe { fmi2GetReal(self.0, r.as_ptr(), r.len(), out.as_mut_ptr()) } {
            fmi2Status::Ok => Ok(out),
            s => Err(s),
        }
    }

    /// The serialised FMU state (every call asserted Ok; the state is freed).
    pub fn serialize(&self) -> Vec<fmi2Byte> {
        serialize(self.0)
    }

    /// Deserialises `b` and sets the state; the status of the first call that fails.
    pub fn restore(&self, b: &[fmi2Byte]) -> fmi2Status {
        restore(self.0, b)
    }
}

/// The serialised FMU state of instance `c` (every call asserted Ok; the state is freed).
fn serialize(c: fmi2Component) -> Vec<fmi2Byte> {
    let mut st: fmi2FMUstate = null_mut();
    let mut size = 0usize;
    unsafe {
        assert_eq!(fmi2GetFMUstate(c, &mut st), fmi2Status::Ok);
        assert_eq!(fmi2SerializedFMUstateSize(c, st, &mut size), fmi2Status::Ok);
        let mut b = vec![0 as fmi2Byte; size];
        assert_eq!(fmi2SerializeFMUstate(c, st, b.as_mut_ptr(), size), fmi2Status::Ok);
        assert_eq!(fmi2FreeFMUstate(c, &mut st), fmi2Status::Ok);
        b
    }
}

/// Deserialises `b` into instance `c` and sets the state; the status of the first call that
/// fails.
fn restore(c: fmi2Component, b: &[fmi2Byte]) -> fmi2Status {
    let mut st: fmi2FMUstate = null_mut();
    unsafe {
        let s = fmi2DeSerializeFMUstate(c, b.as_ptr(), b.len(), &mut st);
        if s != fmi2Status::Ok {
            return s;
        }
        let s = fmi2SetFMUstate(c, st);
        assert_eq!(fmi2FreeFMUstate(c, &mut st), fmi2Status::Ok);
        s
    }
}

impl Drop for Fmu {
    fn drop(&mut self) {
        unsafe { fmi2FreeInstance(self.0) };
    }
}

/// An instance of any model of the family (`ModelInfo`: HelicalGearMesh, Pair, Stage, Drive)
/// with its variable table, for value references by name; freed on drop. The binaries add
/// their own constructors and calls in `impl` blocks of their own.
pub struct ModelFmu(pub fmi2Component, pub &'static ModelInfo);

impl ModelFmu {
    /// A new instance of `m` of interface `ty` (Co-Simulation or Model Exchange), without
    /// callbacks or resource location, in the `instantiated` state.
    pub fn instantiate(m: &'static ModelInfo, ty: fmi2Type) -> Self {
        let g = CString::new(m.guid()).unwrap();
        let c = unsafe { fmi2Instantiate(c"test".as_ptr(), ty, g.as_ptr(), null(), null(), 0, 0) };
        assert!(!c.is_null(), "{}", m.identifier);
        ModelFmu(c, m)
    }

    /// `fmi2SetupExperiment` (start 0), `fmi2EnterInitializationMode` and
    /// `fmi2ExitInitializationMode`, each asserted Ok.
    pub fn init(&self) {
        unsafe {
            assert_eq!(fmi2SetupExperiment(self.0, 0, 0.0, 0.0, 0, 0.0), fmi2Status::Ok);
            assert_eq!(fmi2EnterInitializationMode(self.0), fmi2Status::Ok);
            assert_eq!(fmi2ExitInitializationMode(self.0), fmi2Status::Ok);
        }
    }

    /// The value references of the variables `names` (panics on an unknown name).
    pub fn vrs(&self, names: &[&str]) -> Vec<u32> {
        names.iter().map(|n| self.1.by_name(n).unwrap_or_else(|| panic!("{n}")).vr).collect()
    }

    /// `fmi2GetReal` of the variables `names`, asserted Ok.
    pub fn get(&self, names: &[&str]) -> Vec<f64> {
        let r = self.vrs(names);
        let mut out = vec![0.0; r.len()];
        let st = unsafe { fmi2GetReal(self.0, r.as_ptr(), r.len(), out.as_mut_ptr()) };
        assert_eq!(st, fmi2Status::Ok, "get {names:?}");
        out
    }

    /// `fmi2SetReal` of the variables `names` to `v`, asserted Ok.
    pub fn set(&self, names: &[&str], v: &[f64]) {
        let r = self.vrs(names);
        assert_eq!(unsafe { fmi2SetReal(self.0, r.as_ptr(), r.len(), v.as_ptr()) }, fmi2Status::Ok);
    }

    /// The serialised FMU state (every call asserted Ok; the state is freed).
    pub fn serialize(&self) -> Vec<fmi2Byte> {
        serialize(self.0)
    }

    /// Deserialises `b` and sets the state; the status of the first call that fails.
    pub fn restore(&self, b: &[fmi2Byte]) -> fmi2Status {
        restore(self.0, b)
    }
}

impl Drop for ModelFmu {
    fn drop(&mut self) {
        unsafe { fmi2FreeInstance(self.0) };
    }
}
