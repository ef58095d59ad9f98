//! The property tests' configuration: fixed inputs by default, exploration on request.
//!
//! Every property test of the workspace takes its config here: `#![proptest_config(proptest_config::config(n))]`.
//!
//! A default `cargo test` draws the same cases on every run (seed [`FIXED_SEED`], or `PROPTEST_RNG_SEED`
//! when set), replays the failures kept in the committed `*.proptest-regressions` files and never writes
//! to them — a red run is a change, never a draw. `ALLANITE_EXPLORE=1 cargo test` draws at random and
//! records new failures there, as plain proptest does (the same switch as the Python suite's hypothesis
//! profile, tests/conftest.py).

use std::any::Any;

use proptest::test_runner::{
    Config, FailurePersistence, FileFailurePersistence, PersistedSeed, RngSeed,
};

/// The seed of a default run (the date this rule was made).
pub const FIXED_SEED: u64 = 20_261_125;

/// True when `ALLANITE_EXPLORE` asks for random draws.
pub fn exploring() -> bool {
    std::env::var("ALLANITE_EXPLORE").is_ok_and(|v| !matches!(v.trim(), "" | "0"))
}

/// `cases` cases; fixed and read-only unless exploring.
pub fn config(cases: u32) -> Config {
    let mut c = Config::with_cases(cases);
    if exploring() {
        return c;
    }
    if std::env::var_os("PROPTEST_RNG_SEED").is_none() {
        c.rng_seed = RngSeed::Fixed(FIXED_SEED);
    }
    c.failure_persistence = Some(Box::new(ReadOnly(FileFailurePersistence::default())));
    c
}

/// Replays the persisted failures of `inner`, records none.
#[derive(Debug, Clone, PartialEq)]
struct ReadOnly(FileFailurePersistence);

impl FailurePersistence for ReadOnly {
    fn load_persisted_failures2(&self, source_file: Option<&'static str>) -> Vec<PersistedSeed> {
        self.0.load_persisted_failures2(source_file)
    }

    fn save_persisted_failure2(
        &mut self,
        _source_file: Option<&'static str>,
        _seed: PersistedSeed,
        _shrunken_value: &dyn std::fmt::Debug,
    ) {
    }

    fn box_clone(&self) -> Box<dyn FailurePersistence> {
        Box::new(self.clone())
    }

    fn eq(&self, other: &dyn FailurePersistence) -> bool {
        other.as_any().downcast_ref::<Self>() == Some(self)
    }

    fn as_any(&self) -> &dyn Any {
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// A default run replays the committed failures but records none ([`config`]); exploring records.
    #[test]
    fn a_default_run_records_no_failure() {
        let dir = std::env::temp_dir().join(format!("allanite-proptest-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let src = dir.join("probe.rs").to_string_lossy().into_owned();
        let mut cfg = config(8);
        cfg.source_file = Some(Box::leak(src.into_boxed_str()));
        let mut runner = proptest::test_runner::TestRunner::new(cfg);
        let failed = runner.run(&(0u32..100), |v| {
            prop_assert!(v > 1000);
            Ok(())
        });
        assert!(failed.is_err(), "the probe property must fail");
        let written = dir.join("probe.proptest-regressions").exists();
        std::fs::remove_dir_all(&dir).ok();
        assert_eq!(written, exploring());
    }
}
