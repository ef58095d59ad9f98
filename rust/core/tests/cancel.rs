//! The cancel flag: a set flag makes every kernel return `Cancelled` (never a partial result), a
//! flag set mid-run stops it early, and an unset flag changes no bit.
use allanite_core::{
    dynamic_avar, dynamic_avar_cancellable, dynamic_theo1, dynamic_theo1_cancellable,
    run_in_pool_interruptible, static_theo1, static_theo1_cancellable, Cancel, CoreError,
    Estimator, Method, Request,
};
use allanite_testutil::xorshift_uniform as noise;
use std::time::{Duration, Instant};

#[test]
fn a_set_flag_returns_cancelled_from_every_kernel() {
    let y = noise(3000, 1);
    let cols = [&y[..]];
    let set = Cancel::new();
    set.cancel();
    for estimator in [Estimator::Overlapping, Estimator::Classic] {
        for method in [Method::Fast, Method::Naive] {
            let req = Request {
                columns: &cols,
                window: 1000,
                hop: 7,
                ms: &[1, 2, 9, 100, 400],
                estimator,
                method,
            };
            assert_eq!(
                dynamic_avar_cancellable(&req, &set),
                Err(CoreError::Cancelled)
            );
        }
    }
    assert_eq!(
        static_theo1_cancellable(&cols, &[2, 10, 2998], &set),
        Err(CoreError::Cancelled)
    );
    assert_eq!(
        dynamic_theo1_cancellable(&cols, 500, 3, &[2, 10, 400], &set),
        Err(CoreError::Cancelled)
    );
    // Validation comes first: a bad request is still reported as such.
    assert!(matches!(
        static_theo1_cancellable(&cols, &[3], &set),
        Err(CoreError::InvalidParameter(_))
    ));
}

#[test]
fn an_unset_flag_changes_no_bit() {
    let y = noise(5000, 2);
    let cols = [&y[..]];
    let quiet = Cancel::new();
    let req = Request {
        columns: &cols,
        window: 2000,
        hop: 13,
        ms: &[1, 3, 8, 9, 64, 999],
        estimator: Estimator::Overlapping,
        method: Method::Fast,
    };
    assert_eq!(dynamic_avar_cancellable(&req, &quiet), dynamic_avar(&req));
    let ms = [2, 12, 400, 4998];
    assert_eq!(
        static_theo1_cancellable(&cols, &ms, &quiet),
        static_theo1(&cols, &ms)
    );
    assert_eq!(
        dynamic_theo1_cancellable(&cols, 1000, 11, &ms[..3], &quiet),
        dynamic_theo1(&cols, 1000, 11, &ms[..3])
    );
}

#[test]
fn an_interrupt_stops_a_long_theo1_promptly() {
    // O(N²) static Theo1 on 2e5 samples takes seconds even optimised; stopped after 50 ms.
    let y = noise(200_000, 3);
    let cols = [&y[..]];
    let start = Instant::now();
    let mut stopped_at = None;
    let r = run_in_pool_interruptible(
        2,
        Duration::from_millis(10),
        |c: &Cancel| static_theo1_cancellable(&cols, &[2, 199_998], c),
        || {
            if start.elapsed() > Duration::from_millis(50) {
                stopped_at = Some(Instant::now());
                Err("interrupt")
            } else {
                Ok(())
            }
        },
    );
    assert_eq!(r, Err("interrupt"));
    let after = stopped_at.unwrap().elapsed();
    assert!(
        after < Duration::from_secs(1),
        "{after:?} after the interrupt"
    );
}
