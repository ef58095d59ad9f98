//! Errors of the core. Every public entry point returns `Result<_, CoreError>`; nothing panics on user
//! input. The binding maps each variant to its `allanite.errors` class: `TooShort`, `NonFinite` and
//! `InvalidInput` to `InputError`, `InvalidParameter` to `ParameterError` (both `ValueError`s), and
//! `Cancelled` to `KeyboardInterrupt`.

use std::fmt;

#[derive(Debug, Clone, PartialEq)]
pub enum CoreError {
    /// A record or window is shorter than the computation needs.
    TooShort {
        what: &'static str,
        needed: usize,
        got: usize,
    },
    /// A parameter outside its allowed range; the message names the value and the range.
    InvalidParameter(String),
    /// The records themselves are unusable (no axis, axes of different lengths); the message says why.
    InvalidInput(String),
    /// NaN or ±inf in the input, at `index` of axis `axis`.
    NonFinite {
        axis: usize,
        index: usize,
        value: f64,
    },
    /// The caller asked the computation to stop (Ctrl-C); no partial result is returned.
    Cancelled,
}

impl fmt::Display for CoreError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CoreError::TooShort { what, needed, got } => {
                write!(
                    f,
                    "{what} is too short: {got} samples, at least {needed} needed"
                )
            }
            CoreError::InvalidParameter(msg) | CoreError::InvalidInput(msg) => write!(f, "{msg}"),
            CoreError::NonFinite { axis, index, value } => write!(
                f,
                "input contains a non-finite value ({value}) at sample {index} of axis {axis}; \
                 only finite numbers are allowed"
            ),
            CoreError::Cancelled => write!(f, "the computation was interrupted"),
        }
    }
}

impl std::error::Error for CoreError {}

pub type Result<T> = std::result::Result<T, CoreError>;
