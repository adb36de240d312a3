//! TEMPORARY stand-in for `mesh::MeshModel` with the same signatures, so that the FMI and C
//! layers can be written before the real façade is merged. It is a linear spring along the line
//! of action and is NOT the Andersson–Vedmar model. This file is deleted, and the two `use`
//! lines that name it switch to `crate::mesh::MeshModel`, as soon as the real model is merged.

use crate::mesh::{MeshError, MeshOptions, MeshOutputs, MeshState, MeshTorques};
use crate::{GearPair, PairGeometry, ParamError};

/// Stand-in mesh model (linear spring, see the module doc).
#[derive(Debug, Clone)]
pub struct MeshModel {
    rb: (f64, f64),
    backlash: f64,
    d_mesh: f64,
    options: MeshOptions,
}

impl MeshModel {
    /// Validates the pair and the options.
    pub fn new(pair: &GearPair, options: MeshOptions) -> Result<Self, MeshError> {
        let g = PairGeometry::new(pair)?;
        if options.slices == 0 {
            return Err(ParamError::new("slices", 0.0, ">= 1").into());
        }
        Ok(Self {
            rb: (g.pinion.rb, g.gear.rb),
            backlash: g.backlash_te,
            d_mesh: pair.d_mesh_n_s_per_m,
            options,
        })
    }

    /// Sets the mesh damping, N·s/m.
    pub fn set_d_mesh(&mut self, d: f64) -> Result<(), MeshError> {
        if !d.is_finite() || d < 0.0 {
            return Err(ParamError::new("d_mesh_n_s_per_m", d, ">= 0").into());
        }
        self.d_mesh = d;
        Ok(())
    }

    /// Linear-spring outputs.
    pub fn evaluate(&mut self, s: &MeshState) -> Result<MeshOutputs, MeshError> {
        for (name, v) in [("phi_p", s.phi_p), ("phi_g", s.phi_g), ("w_p", s.w_p), ("w_g", s.w_g)] {
            if !v.is_finite() {
                return Err(MeshError::NonFinite { name, value: v });
            }
        }
        let (gp, gg) = self.rb;
        let te = s.phi_p * gp + s.phi_g * gg;
        let k = 3e8 * (1.0 + 0.1 * (s.phi_p * 30.0).sin());
        let f = if te > 0.0 {
            k * te
        } else if te < -self.backlash {
            k * (te + self.backlash)
        } else {
            0.0
        };
        let loaded = f != 0.0;
        let fd = if loaded { self.d_mesh * (s.w_p * gp + s.w_g * gg) } else { 0.0 };
        Ok(MeshOutputs {
            m_f_p: f * gp,
            m_f_g: f * gg,
            m_d_p: fd * gp,
            m_d_g: fd * gg,
            te,
            f_n: f.abs(),
            contact_length: if loaded { 0.03 } else { 0.0 },
            p_max: if self.options.pressure && loaded { 1e9 * (f.abs() / 3e3).sqrt() } else { 0.0 },
            n_pairs: if loaded { 2 } else { 0 },
            tip_contact: false,
            separated: !loaded,
            back_contact: f < 0.0,
        })
    }
}

impl MeshTorques for MeshModel {
    fn mesh(&mut self, state: &MeshState) -> Result<MeshOutputs, MeshError> {
        self.evaluate(state)
    }
    fn base_radii(&self) -> (f64, f64) {
        self.rb
    }
}
