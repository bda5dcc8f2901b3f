//! Errors of the solver crate: bad input named by field, and numerical failures.

use thiserror::Error;

/// Everything the solver can refuse or fail at.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum SolverError {
    /// An input value is impossible; `field` names it.
    #[error("invalid {field}: {reason}")]
    Invalid {
        /// The offending input (config key or parameter name).
        field: String,
        /// What is wrong with it.
        reason: String,
    },
    /// The contact reaches the edge of the computational domain.
    #[error("the contact reaches the edge of the domain ({detail}); enlarge grid.points or grid.spacing_um")]
    DomainTooSmall {
        /// Which zone touches the boundary.
        detail: String,
    },
    /// The grid does not resolve the contact: it spans too few cells for a
    /// contact radius (or anything derived from it) to mean something.
    #[error("the contact is not resolved ({detail}); refine grid.spacing_um, or check the indenter radius and the load")]
    ContactUnresolved {
        /// What was found.
        detail: String,
    },
    /// The grid does not resolve the slip zone: no part of the contact's
    /// outline slips, so a = c and μa (Eq. 19) is undefined.
    #[error("the slip zone is not resolved ({detail}); refine grid.spacing_um (more cells across the contact)")]
    SlipUnresolved {
        /// What was found.
        detail: String,
    },
    /// The whole contact slides: no stick cell is left.
    #[error("gross sliding: {detail}")]
    GrossSliding {
        /// Context.
        detail: String,
    },
    /// The solve was stopped by [`crate::cancel`] (e.g. Ctrl-C in Python).
    #[error("cancelled")]
    Cancelled,
}

impl SolverError {
    /// Shorthand for [`SolverError::Invalid`].
    pub fn invalid(field: &str, reason: impl Into<String>) -> Self {
        SolverError::Invalid {
            field: field.to_string(),
            reason: reason.into(),
        }
    }
}

/// `Ok` when `v` is positive and finite; otherwise an `Invalid` error naming
/// `param`: "{what} must be positive and finite, got {v}{unit}".
pub(crate) fn positive(param: &str, v: f64, what: &str, unit: &str) -> Result<(), SolverError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(SolverError::invalid(
            param,
            format!("{what} must be positive and finite, got {v}{unit}"),
        ))
    }
}
