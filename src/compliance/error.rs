//! The error of the compliance computations: the FE runs, the fits, the local contact term,
//! stored data and their files. One type for the whole `compliance` module, so that the data
//! (`data`) and the stiffness measures (`stiffness`) share it without importing each other.

use std::fmt;
use std::path::PathBuf;

use super::fe::FeError;
use super::fitted::FitError;
use super::hertz::HertzError;
use crate::error::ParamError;

/// Failure to compute, read, write or use compliance data.
#[derive(Debug, Clone, PartialEq)]
pub enum ComplianceError {
    /// The gear pair is invalid.
    Param(ParamError),
    /// The FE run of a gear failed.
    Fe {
        /// `"pinion"` or `"gear"`.
        member: &'static str,
        /// The FE error.
        source: FeError,
    },
    /// The fit of a gear failed.
    Fit {
        /// `"pinion"` or `"gear"`.
        member: &'static str,
        /// The fit error.
        source: FitError,
    },
    /// Stored data are unusable; the message names the item and the problem.
    InvalidData(String),
    /// Reading or writing a file failed.
    Io {
        /// The file.
        path: PathBuf,
        /// The operating system's message.
        message: String,
    },
    /// An argument is out of range; the message names it, its value and the limit.
    Input(String),
    /// The local contact term failed.
    Hertz(HertzError),
}

impl fmt::Display for ComplianceError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ComplianceError::Param(e) => write!(f, "{e}"),
            ComplianceError::Fe { member, source } => write!(f, "FE run of the {member}: {source}"),
            ComplianceError::Fit { member, source } => write!(f, "fit of the {member}: {source}"),
            ComplianceError::InvalidData(m) => write!(f, "compliance data: {m}"),
            ComplianceError::Io { path, message } => write!(f, "{}: {message}", path.display()),
            ComplianceError::Input(m) => write!(f, "{m}"),
            ComplianceError::Hertz(e) => write!(f, "local contact term: {e}"),
        }
    }
}

impl std::error::Error for ComplianceError {}

impl From<ParamError> for ComplianceError {
    fn from(e: ParamError) -> Self {
        ComplianceError::Param(e)
    }
}

impl From<HertzError> for ComplianceError {
    fn from(e: HertzError) -> Self {
        ComplianceError::Hertz(e)
    }
}
