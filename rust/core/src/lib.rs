//! allanite-core: the pure-Rust estimators behind the `allanite` Python package.
//!
//! Nothing here knows about Python. Inputs are rate samples (`&[f64]`), outputs plain vectors; every
//! entry point validates its arguments and returns [`CoreError`] instead of panicking.

pub mod allan;
pub mod angle;
pub mod block_acf;
pub mod cancel;
mod chunked;
pub mod deviations;
pub mod error;
pub mod fit;
mod gather;
mod oavar;
pub mod phase_grid;
pub mod phase_terms;
pub mod range;
pub mod streaming;
pub mod taper;
pub mod text;
pub mod theo;
mod window_sums;

pub use allan::{
    compensated_mean, compensated_sum_from, dynamic_avar, dynamic_avar_cancellable,
    dynamic_avar_part_cancellable, dynamic_avar_ranged_cancellable, max_m, n_terms, n_windows,
    part_grid, run_in_pool, static_avar, Estimator, Method, Request,
};
pub use angle::{angle_term_sums_cancellable, AngleChunk};
pub use cancel::{run_in_pool_interruptible, Cancel};
pub use error::{CoreError, Result};
pub use taper::{dynamic_hann, dynamic_hann_cancellable, static_hann};
pub use theo::{
    detrended_phase, dynamic_theo1, dynamic_theo1_cancellable, static_theo1,
    static_theo1_cancellable, theo1_direct,
};
