//! The unit tests of `sepval_common::extension::locator`.

use sepval_common::extension::locator::*;

/// Each message states the domain it checks.
#[test]
fn messages_state_the_bounds() {
    for d in [LAMBDA_M, MACH0, T_ON_S, RISE_S, F_HZ] {
        let (open, close) = (if d.min_open { '(' } else { '[' }, ']');
        let stated = format!("{open}{}, {}{close}", d.min, d.max);
        assert!(d.expected.contains(&stated), "{}: {stated}", d.expected);
        assert!(d.contains(d.max) && !d.contains(d.above_max()));
        assert_eq!(d.contains(d.min), !d.min_open);
        assert!(!d.contains(f64::NAN));
    }
}
