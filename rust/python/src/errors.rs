//! The errors of the binding and the one way a kernel runs: core errors as their `allanite.errors`
//! classes, [`run_interruptible`] (GIL released, Ctrl-C honoured).

use allanite_core::{run_in_pool_interruptible, Cancel, CoreError};
use pyo3::prelude::*;
use std::time::Duration;

/// How often the calling thread looks for a pending signal while the workers run: often enough
/// for Ctrl-C to land well within a second, rarely enough that taking the GIL costs nothing.
const SIGNAL_POLL: Duration = Duration::from_millis(50);

/// `allanite.errors.<class_name>(msg)`; falls back to ValueError if the package is absent.
fn allanite_error_of(py: Python<'_>, class_name: &str, msg: String) -> PyErr {
    let made = py
        .import("allanite.errors")
        .and_then(|m| m.getattr(class_name))
        .and_then(|cls| cls.call1((msg.clone(),)));
    match made {
        Ok(instance) => PyErr::from_value(instance),
        Err(_) => pyo3::exceptions::PyValueError::new_err(msg),
    }
}

/// Raises `allanite.errors.AllaniteError(msg)`; falls back to ValueError if the package is absent.
pub(crate) fn allanite_error(py: Python<'_>, msg: String) -> PyErr {
    allanite_error_of(py, "AllaniteError", msg)
}

/// `allanite.errors.ParameterError(msg)`: a bad argument.
pub(crate) fn parameter_error(py: Python<'_>, msg: String) -> PyErr {
    allanite_error_of(py, "ParameterError", msg)
}

/// `allanite.errors.InputError(msg)`: bad samples.
pub(crate) fn input_error(py: Python<'_>, msg: String) -> PyErr {
    allanite_error_of(py, "InputError", msg)
}

/// Each core error as its `allanite.errors` class, message unchanged.
pub(crate) fn core_error(py: Python<'_>, e: CoreError) -> PyErr {
    let class_name = match &e {
        CoreError::TooShort { .. } | CoreError::NonFinite { .. } | CoreError::InvalidInput(_) => {
            "InputError"
        }
        CoreError::InvalidParameter(_) => "ParameterError",
        CoreError::Cancelled => {
            return pyo3::exceptions::PyKeyboardInterrupt::new_err(e.to_string());
        }
    };
    allanite_error_of(py, class_name, e.to_string())
}

/// Runs a core kernel on `workers` rayon threads (0: rayon's default) with the GIL released, and
/// makes it interruptible: while the workers run, this thread takes the GIL every `SIGNAL_POLL`
/// to run Python's signal handlers (`check_signals`; a no-op off the main thread). If a handler
/// raises (Ctrl-C: KeyboardInterrupt), the kernel's `Cancel` flag is set, the workers are waited
/// for (they stop at their next check), and the handler's exception is returned. Core errors come
/// back as their `allanite.errors` classes.
///
/// Every kernel of this module goes through here: `job` receives the flag and passes it on.
pub(crate) fn run_interruptible<R: Send>(
    py: Python<'_>,
    workers: usize,
    job: impl FnOnce(&Cancel) -> allanite_core::Result<R> + Send,
) -> PyResult<R> {
    let outcome = py.detach(|| {
        run_in_pool_interruptible(workers, SIGNAL_POLL, job, || {
            Python::attach(|py| py.check_signals())
        })
    })?;
    outcome.map_err(|e| core_error(py, e))
}
