//! One description of every mesh output: the table [`MESH_OUTPUT_FIELDS`] names each field of
//! [`MeshOutputs`] once — its interface name (the FMI variable and the Python key), its
//! result-column name (the CLI's JSON and CSV records), its C field (`HgmOutputs`), its SI
//! unit, its meaning with the sign convention, and how to read and write it. Every boundary
//! loops over this table instead of listing the outputs again:
//!
//! * the FMI layer takes each mesh output variable's name, unit and description from it, and
//!   writes the output slots in its order (`fmi2::models::write_mesh_outputs`);
//! * the C API refuses a result with any non-finite Real field, naming the field;
//! * the Python package's result keys and the CLI's trajectory columns are its names;
//! * a caller that reads only some outputs names them by this table (the C API's
//!   `hgm_evaluate_outputs`, Python's `evaluate(..., outputs=...)`): when every one it names is
//!   a [`OutputField::torques`] output, the evaluation takes the torques path
//!   ([`super::MeshTorques::torques`]), which on the periodic table interpolates 3 of the 13
//!   node values instead of all of them.
//!
//! A new output is a field of [`MeshOutputs`] and one entry here; the FMI variable table adds
//! only what is FMI's own (value reference, dependencies, display unit), and a test holds the
//! two in the same order.
//!
//! Units are SI, spelled as the FMI unit definitions spell them (`N.m`); counts, flags and
//! the efficiency have the empty unit. Order: the FMI output order (value references 10–21, then 400–417), which is
//! also the order of the FMU's output slots and of the outputs cached in an FMU state.

use super::MeshOutputs;

/// The value type of an output.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OutputKind {
    /// A real number (f64), in the field's unit.
    Real,
    /// A count (u32).
    Integer,
    /// A flag.
    Boolean,
}

/// How to read and write one field of [`MeshOutputs`].
#[derive(Clone, Copy)]
pub enum FieldAccess {
    /// A real field.
    Real {
        /// Reads the field.
        get: fn(&MeshOutputs) -> f64,
        /// The field, writable.
        get_mut: fn(&mut MeshOutputs) -> &mut f64,
    },
    /// A count.
    Integer {
        /// Reads the field.
        get: fn(&MeshOutputs) -> u32,
    },
    /// A flag.
    Boolean {
        /// Reads the field.
        get: fn(&MeshOutputs) -> bool,
    },
}

/// One output of the mesh: names, unit, meaning and access.
#[derive(Clone, Copy)]
pub struct OutputField {
    /// Interface name: the FMI output variable and the key of Python's results (`M_F_p`).
    pub name: &'static str,
    /// Result-column name with its unit suffix (`m_f_p_nm`): the CLI's JSON and CSV columns.
    pub column: &'static str,
    /// The field of [`MeshOutputs`] and of the C struct `HgmOutputs` (`force_p[0]`).
    pub c_field: &'static str,
    /// SI unit (FMI spelling: `N.m`, `m`, `Pa`, `N`); empty for counts and flags.
    pub unit: &'static str,
    /// Meaning, with the sign convention.
    pub description: &'static str,
    /// Read and write access.
    pub access: FieldAccess,
    /// Given by the torques path ([`super::MeshTorques::torques`]) bit for bit as by
    /// [`super::MeshTorques::mesh`], whether or not that path's outputs are complete: the
    /// mesh torques, TE, the loaded contact length behind the damping, and the friction
    /// torques and loss.
    pub torques: bool,
}

impl OutputField {
    /// The value type.
    pub const fn kind(&self) -> OutputKind {
        match self.access {
            FieldAccess::Real { .. } => OutputKind::Real,
            FieldAccess::Integer { .. } => OutputKind::Integer,
            FieldAccess::Boolean { .. } => OutputKind::Boolean,
        }
    }

    /// The value of a Real field of `o`; `None` for counts and flags.
    pub fn real(&self, o: &MeshOutputs) -> Option<f64> {
        match self.access {
            FieldAccess::Real { get, .. } => Some(get(o)),
            _ => None,
        }
    }

    /// The position of this field among the fields of its kind (the FMU's output slot).
    pub const fn slot(index: usize) -> usize {
        let kind = MESH_OUTPUT_FIELDS[index].kind() as u8;
        let mut slot = 0;
        let mut i = 0;
        while i < index {
            if MESH_OUTPUT_FIELDS[i].kind() as u8 == kind {
                slot += 1;
            }
            i += 1;
        }
        slot
    }
}

/// The first Real field of `o` that is not finite, as (C field name, value).
pub fn first_non_finite(o: &MeshOutputs) -> Option<(&'static str, f64)> {
    MESH_OUTPUT_FIELDS
        .iter()
        .find_map(|f| f.real(o).filter(|v| !v.is_finite()).map(|v| (f.c_field, v)))
}

/// The position of the output named `name` ([`OutputField::name`]) in [`MESH_OUTPUT_FIELDS`].
pub fn field_index(name: &str) -> Option<usize> {
    MESH_OUTPUT_FIELDS.iter().position(|f| f.name == name)
}

/// True when every index of `fields` is a [`OutputField::torques`] output, so that the torques
/// path gives them all (an index beyond the table is not: the caller checks indices first).
pub fn torques_cover(fields: impl IntoIterator<Item = usize>) -> bool {
    fields.into_iter().all(|k| MESH_OUTPUT_FIELDS.get(k).is_some_and(|f| f.torques))
}

/// The value of field `index` of `o` as a double: Reals as they are, counts as whole numbers,
/// flags as 0 or 1. Panics on an index beyond [`MESH_OUTPUT_FIELDS`].
pub fn value_f64(o: &MeshOutputs, index: usize) -> f64 {
    match MESH_OUTPUT_FIELDS[index].access {
        FieldAccess::Real { get, .. } => get(o),
        FieldAccess::Integer { get } => f64::from(get(o)),
        FieldAccess::Boolean { get } => f64::from(u8::from(get(o))),
    }
}

/// The Real fields in table order.
pub fn real_fields() -> impl Iterator<Item = &'static OutputField> {
    MESH_OUTPUT_FIELDS.iter().filter(|f| f.kind() == OutputKind::Real)
}

/// `torques` after an entry's description marks it [`OutputField::torques`].
macro_rules! torques {
    () => {
        false
    };
    (torques) => {
        true
    };
}

macro_rules! real {
    ($name:literal, $col:literal, $unit:literal, $f:ident $([$i:literal])?, $desc:literal
     $(, $t:ident)?) => {
        OutputField {
            name: $name,
            column: $col,
            c_field: concat!(stringify!($f) $(, "[", stringify!($i), "]")?),
            unit: $unit,
            description: $desc,
            access: FieldAccess::Real {
                get: |o: &MeshOutputs| o.$f $([$i])?,
                get_mut: |o: &mut MeshOutputs| &mut o.$f $([$i])?,
            },
            torques: torques!($($t)?),
        }
    };
}

macro_rules! integer {
    ($name:literal, $col:literal, $unit:literal, $f:ident, $desc:literal) => {
        OutputField {
            name: $name,
            column: $col,
            c_field: stringify!($f),
            unit: $unit,
            description: $desc,
            access: FieldAccess::Integer { get: |o: &MeshOutputs| o.$f },
            torques: false,
        }
    };
}

macro_rules! boolean {
    ($name:literal, $col:literal, $unit:literal, $f:ident, $desc:literal) => {
        OutputField {
            name: $name,
            column: $col,
            c_field: stringify!($f),
            unit: $unit,
            description: $desc,
            access: FieldAccess::Boolean { get: |o: &MeshOutputs| o.$f },
            torques: false,
        }
    };
}

/// Every output of [`MeshOutputs`], in the FMI output order.
#[rustfmt::skip]
pub const MESH_OUTPUT_FIELDS: [OutputField; 30] = [
    real!("M_F_p", "m_f_p_nm", "N.m", m_f_p,
        "Elastic mesh torque on the pinion (Eq. 13), N.m; enters the pinion equation with a \
         minus sign: J_p*phi_p'' = c1*(phi_1 - phi_p) + ... - M_F_p - M_D_p; positive in \
         normal drive", torques
    ),
    real!("M_F_g", "m_f_g_nm", "N.m", m_f_g,
        "Elastic mesh torque on the gear (Eq. 13), N.m; enters the gear equation with a minus \
         sign; M_F_g/M_F_p = g_g/g_p in the plane of action", torques
    ),
    real!("M_D_p", "m_d_p_nm", "N.m", m_d_p,
        "Damping mesh torque on the pinion (Eq. 14, d_mesh), N.m; enters the pinion equation \
         with a minus sign", torques
    ),
    real!("M_D_g", "m_d_g_nm", "N.m", m_d_g,
        "Damping mesh torque on the gear (Eq. 14, d_mesh), N.m; enters the gear equation with \
         a minus sign", torques
    ),
    real!("TE", "te_m", "m", te,
        "Transmission error TE = phi_p*g_p + phi_g*g_g (Eq. 16), m; 0 when ideal unloaded \
         driving flanks just touch, > 0 when the teeth must deform", torques
    ),
    real!("F_n", "f_n_n", "N", f_n,
        "Total normal contact force of all loaded flanks, N (elastic part, >= 0)"
    ),
    real!("contact_length", "contact_length_m", "m", contact_length,
        "Total length of the loaded contact lines, m", torques
    ),
    real!("p_max", "p_max_pa", "Pa", p_max,
        "Largest Hertz contact pressure (Eq. 15), Pa; 0 without load or when compute_pressure \
         is false"
    ),
    integer!("n_pairs", "n_pairs", "", n_pairs,
        "Number of tooth pairs carrying load"
    ),
    boolean!("tip_contact", "tip_contact", "", tip_contact,
        "True when a loaded contact lies on the tip rounding (or tip edge) of either gear"
    ),
    boolean!("separated", "separated", "", separated,
        "True when no flank carries load (loss of contact)"
    ),
    boolean!("back_contact", "back_contact", "", back_contact,
        "True when the back flanks carry load (TE below minus the backlash); the mesh torques \
         are then negative"
    ),
    real!("F_p_x", "force_p_x_n", "N", force_p[0],
        "Force of the mesh on the pinion, x component (from the pinion axis to the gear axis; \
         < 0 in normal drive: the gears are pushed apart), N (housing frame of docs/loads.md: \
         elastic and damping parts)"
    ),
    real!("F_p_y", "force_p_y_n", "N", force_p[1],
        "Force of the mesh on the pinion, y component (y = z x x; < 0 in normal drive), N \
         (housing frame of docs/loads.md: elastic and damping parts)"
    ),
    real!("F_p_z", "force_p_z_n", "N", force_p[2],
        "Force of the mesh on the pinion, z component (axial, along the pinion axis towards \
         the face end zeta = b; > 0 in normal drive, right-hand pinion), N (housing frame of \
         docs/loads.md: elastic and damping parts)"
    ),
    real!("M_p_x", "moment_p_x_nm", "N.m", moment_p[0],
        "Tilting moment of the mesh force on the pinion about its centre at mid-face, x \
         component, N.m (housing frame of docs/loads.md: elastic and damping parts)"
    ),
    real!("M_p_y", "moment_p_y_nm", "N.m", moment_p[1],
        "Tilting moment of the mesh force on the pinion about its centre at mid-face, y \
         component, N.m (housing frame of docs/loads.md: elastic and damping parts)"
    ),
    real!("F_g_x", "force_g_x_n", "N", force_g[0],
        "Force of the mesh on the gear, x component (F_g = -F_p), N (housing frame of \
         docs/loads.md: elastic and damping parts)"
    ),
    real!("F_g_y", "force_g_y_n", "N", force_g[1],
        "Force of the mesh on the gear, y component (F_g = -F_p), N (housing frame of \
         docs/loads.md: elastic and damping parts)"
    ),
    real!("F_g_z", "force_g_z_n", "N", force_g[2],
        "Force of the mesh on the gear, z component (axial; F_g = -F_p), N (housing frame of \
         docs/loads.md: elastic and damping parts)"
    ),
    real!("M_g_x", "moment_g_x_nm", "N.m", moment_g[0],
        "Tilting moment of the mesh force on the gear about its centre at mid-face, x \
         component, N.m (housing frame of docs/loads.md: elastic and damping parts)"
    ),
    real!("M_g_y", "moment_g_y_nm", "N.m", moment_g[1],
        "Tilting moment of the mesh force on the gear about its centre at mid-face, y \
         component, N.m (housing frame of docs/loads.md: elastic and damping parts)"
    ),
    real!("sigma_F_p", "root_stress_p_pa", "Pa", root_stress_p,
        "Tooth-root stress of the pinion, Pa: largest maximum principal stress at the \
         tension-side root fillet over the loaded teeth and the face width (FE stress \
         influence superposed over the loaded slices); 0 without load"
    ),
    real!("sigma_F_g", "root_stress_g_pa", "Pa", root_stress_g,
        "Tooth-root stress of the gear, Pa (as sigma_F_p)"
    ),
    real!("M_R_p", "m_r_p_nm", "N.m", m_r_p,
        "Friction torque on the pinion, N.m: the part of M_F_p due to the friction at the \
         flanks (option friction), signed as M_F_p; M_R_p*w_p + M_R_g*w_g = P_loss; 0 without \
         friction", torques
    ),
    real!("M_R_g", "m_r_g_nm", "N.m", m_r_g,
        "Friction torque on the gear, N.m: the part of M_F_g due to the friction at the \
         flanks, signed as M_F_g; 0 without friction", torques
    ),
    real!("P_loss", "p_loss_w", "W", p_loss,
        "Mesh friction power loss, W (>= 0): the work of the friction forces on the sliding \
         of the flanks; 0 without friction and at standstill", torques
    ),
    real!("eta_mesh", "eta_mesh", "", eta_mesh,
        "Instantaneous mesh efficiency 1 - P_loss/P_in (P_in: the power the driving gear puts \
         into the mesh, (M_F + M_D)*w of that gear), 0...1; 1 where P_in <= 0 and without \
         friction"
    ),
    real!("Q_p", "q_p_w", "W", q_p,
        "Heat of the mesh friction into the pinion's flanks, W (Blok's partition for equal \
         thermal effusivity; Q_p + Q_g = P_loss)"
    ),
    real!("Q_g", "q_g_w", "W", q_g,
        "Heat of the mesh friction into the gear's flanks, W (Q_p + Q_g = P_loss)"
    ),
];

#[cfg(test)]
mod tests {
    use super::*;

    /// Every field of `MeshOutputs` is in the table once: a value planted in each Real field
    /// through the table is read back by that entry alone.
    #[test]
    fn every_real_field_is_described_once() {
        for (k, f) in MESH_OUTPUT_FIELDS.iter().enumerate() {
            let FieldAccess::Real { get_mut, .. } = f.access else { continue };
            // All zero (the efficiency's default is 1), then one field planted.
            let mut o = MeshOutputs { eta_mesh: 0.0, ..MeshOutputs::default() };
            *get_mut(&mut o) = 1.0 + k as f64;
            let hits: Vec<_> = real_fields().filter(|g| g.real(&o) != Some(0.0)).collect();
            assert_eq!(hits.len(), 1, "{}", f.name);
            assert_eq!(hits[0].name, f.name);
            assert_eq!(first_non_finite(&o), None);
            *get_mut(&mut o) = f64::NAN;
            assert_eq!(first_non_finite(&o).map(|x| x.0), Some(f.c_field));
        }
        let names: std::collections::BTreeSet<_> =
            MESH_OUTPUT_FIELDS.iter().map(|f| f.name).collect();
        assert_eq!(names.len(), MESH_OUTPUT_FIELDS.len(), "names are unique");
        let reals = real_fields().count();
        // 26 f64 values in MeshOutputs: 8 scalars, 3 + 2 + 3 + 2 force and moment
        // components, 2 stresses, 6 of the friction.
        assert_eq!(reals, 8 + 10 + 2 + 6);
    }

    #[test]
    fn slots_count_within_each_kind() {
        assert_eq!(OutputField::slot(0), 0);
        assert_eq!(OutputField::slot(8), 0, "n_pairs is the first Integer");
        assert_eq!(OutputField::slot(11), 2, "back_contact is the third Boolean");
        assert_eq!(OutputField::slot(12), 8, "F_p_x follows the eight first Reals");
        assert_eq!(OutputField::slot(23), 19);
        assert_eq!(OutputField::slot(29), 25, "Q_g is the last Real");
    }
}
