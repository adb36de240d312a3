//! Error types shared by the whole crate.
//!
//! Every error names what went wrong in words a user can act on: for parameters, the
//! parameter's JSON name, its value and the allowed range.

use std::fmt;

/// A number for a message: its shortest round-trip text when that has at most 16 characters
/// (`12`, `0.0205`, `-1e-5`, `NaN`, `inf`), otherwise scientific with five significant digits
/// (`1.0000e300`), so that no message carries a 300-digit number.
pub fn short_num(v: f64) -> String {
    let s = format!("{v}");
    if s.len() <= 16 { s } else { format!("{v:.4e}") }
}

/// A gear-pair parameter outside its allowed range.
///
/// `name` is the parameter's JSON key (e.g. `"z_p"`), `value` the offending value in the unit of
/// that key, and `allowed` a human-readable statement of the limit (e.g. `"> 0"`,
/// `">= 17.1 (undercut limit)"`).
#[derive(Debug, Clone, PartialEq)]
pub struct ParamError {
    /// JSON key of the parameter (for a derived quantity, the key of the parameter to change).
    pub name: String,
    /// The offending value, in the unit of the key.
    pub value: f64,
    /// The allowed range or rule, in words.
    pub allowed: String,
}

impl ParamError {
    /// Builds an error for parameter `name` with `value` violating `allowed`.
    pub fn new(name: &str, value: f64, allowed: impl Into<String>) -> Self {
        Self { name: name.to_string(), value, allowed: allowed.into() }
    }
}

impl fmt::Display for ParamError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "invalid parameter `{}` = {}: allowed {}",
            self.name,
            short_num(self.value),
            self.allowed
        )
    }
}

impl std::error::Error for ParamError {}
