//! One encoding of every option: the integer code (FMU Integer parameter, C constant) and the
//! name (Python and CLI string, error messages) of each value of [`Fidelity`],
//! [`ComplianceModel`], [`Integrator`] and [`UnitKind`].
//!
//! Every interface reads the table of its enum ([`OptionEnum::VALUES`]) rather than writing its
//! own match: the FMU's `fidelity`, `compliance_model` and `integrator` parameters take the
//! codes, the C API's `HGM_FIDELITY_*` and `HGM_UNIT_KIND_*` constants are the same codes (a
//! test of `capi` holds them equal), Python's and the CLI's strings are the names
//! ([`std::str::FromStr`] and [`std::fmt::Display`] on each enum). The codes are those of the
//! FMUs:
//!
//! | option           | code 0         | code 1    | code 2  |
//! |------------------|----------------|-----------|---------|
//! | fidelity         | `full`         | `table`   |         |
//! | compliance model | `interpolated` | `fitted`  |         |
//! | integrator       | `rk4`          | `dopri5`  |         |
//! | unit kind        | `pair`         | `stage`   | `drive` |

use std::fmt;
use std::str::FromStr;

pub use crate::dynamics::integrators::Integrator;
pub use crate::dynamics::unit::UnitKind;
pub use crate::mesh::{ComplianceModel, Fidelity};

/// An option with a fixed table of values: each value's integer code and name.
pub trait OptionEnum: Copy + PartialEq + 'static {
    /// Name of the option in messages (`fidelity`, `integrator` …).
    const OPTION: &'static str;
    /// Every value with its code and name, in code order.
    const VALUES: &'static [(Self, i32, &'static str)];

    /// The value's integer code (FMU Integer, C constant).
    fn code(self) -> i32 {
        Self::VALUES.iter().find(|v| v.0 == self).map_or(-1, |v| v.1)
    }

    /// The value's name (Python, CLI, messages).
    fn name(self) -> &'static str {
        Self::VALUES.iter().find(|v| v.0 == self).map_or("", |v| v.2)
    }

    /// The value of code `code`; an error names the option, the code and the allowed codes.
    fn from_code(code: i32) -> Result<Self, String> {
        Self::VALUES
            .iter()
            .find(|v| v.1 == code)
            .map(|v| v.0)
            .ok_or_else(|| format!("`{}` = {code}: allowed {}", Self::OPTION, Self::allowed()))
    }

    /// The value named `name`; an error names the option, the text and the allowed names.
    fn from_name(name: &str) -> Result<Self, String> {
        Self::VALUES
            .iter()
            .find(|v| v.2 == name)
            .map(|v| v.0)
            .ok_or_else(|| format!("`{}` = {name:?}: allowed {}", Self::OPTION, Self::allowed()))
    }

    /// The allowed values in words, e.g. `0 (full) or 1 (table)`.
    fn allowed() -> String {
        let items: Vec<String> =
            Self::VALUES.iter().map(|v| format!("{} ({})", v.1, v.2)).collect();
        match items.split_last() {
            Some((last, rest)) if !rest.is_empty() => format!("{} or {last}", rest.join(", ")),
            _ => items.join(""),
        }
    }
}

impl OptionEnum for Fidelity {
    const OPTION: &'static str = "fidelity";
    const VALUES: &'static [(Self, i32, &'static str)] =
        &[(Fidelity::Full, 0, "full"), (Fidelity::Table, 1, "table")];
}

impl OptionEnum for ComplianceModel {
    const OPTION: &'static str = "compliance_model";
    const VALUES: &'static [(Self, i32, &'static str)] = &[
        (ComplianceModel::Interpolated, 0, "interpolated"),
        (ComplianceModel::Fitted, 1, "fitted"),
    ];
}

impl OptionEnum for Integrator {
    const OPTION: &'static str = "integrator";
    const VALUES: &'static [(Self, i32, &'static str)] =
        &[(Integrator::Rk4, 0, "rk4"), (Integrator::Dopri5, 1, "dopri5")];
}

impl OptionEnum for UnitKind {
    const OPTION: &'static str = "kind";
    const VALUES: &'static [(Self, i32, &'static str)] = &[
        (UnitKind::Pair, 0, "pair"),
        (UnitKind::Stage, 1, "stage"),
        (UnitKind::Drive, 2, "drive"),
    ];
}

macro_rules! display_and_from_str {
    ($($t:ty),*) => {$(
        impl fmt::Display for $t {
            /// The value's name ([`OptionEnum::name`]).
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str(self.name())
            }
        }
        impl FromStr for $t {
            type Err = String;
            /// The value of a name ([`OptionEnum::from_name`]).
            fn from_str(s: &str) -> Result<Self, String> {
                Self::from_name(s)
            }
        }
    )*};
}

display_and_from_str!(Fidelity, ComplianceModel, Integrator, UnitKind);

#[cfg(test)]
mod tests {
    use super::*;

    fn round_trips<T: OptionEnum + fmt::Debug>() {
        for (i, &(v, code, name)) in T::VALUES.iter().enumerate() {
            assert_eq!(code, i as i32, "{} codes are 0, 1, … in order", T::OPTION);
            assert_eq!(T::from_code(code).unwrap(), v);
            assert_eq!(T::from_name(name).unwrap(), v);
            assert_eq!(v.code(), code);
            assert_eq!(v.name(), name);
        }
        let n = T::VALUES.len() as i32;
        assert!(T::from_code(n).unwrap_err().contains(&format!("`{}` = {n}", T::OPTION)));
        assert!(T::from_code(-1).is_err());
        assert!(T::from_name("nope").unwrap_err().contains("\"nope\""));
    }

    /// The codes of the tables are the enums' explicit discriminants (which the C API's
    /// constants are checked against at compile time).
    #[test]
    fn codes_are_the_discriminants() {
        for &(v, code, _) in Fidelity::VALUES {
            assert_eq!(v as i32, code);
        }
        for &(v, code, _) in ComplianceModel::VALUES {
            assert_eq!(v as i32, code);
        }
        for &(v, code, _) in Integrator::VALUES {
            assert_eq!(v as i32, code);
        }
        for &(v, code, _) in UnitKind::VALUES {
            assert_eq!(v as i32, code);
        }
    }

    #[test]
    fn every_option_round_trips_through_code_and_name() {
        round_trips::<Fidelity>();
        round_trips::<ComplianceModel>();
        round_trips::<Integrator>();
        round_trips::<UnitKind>();
        assert_eq!(Fidelity::allowed(), "0 (full) or 1 (table)");
        assert_eq!(UnitKind::allowed(), "0 (pair), 1 (stage) or 2 (drive)");
        assert_eq!("table".parse::<Fidelity>().unwrap(), Fidelity::Table);
        assert_eq!(Integrator::Dopri5.to_string(), "dopri5");
    }
}
