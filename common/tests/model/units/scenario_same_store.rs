//! The unit tests of `sepval_common::scenario::same_store`.

use sepval_common::scenario::*;

#[test]
fn the_first_field_that_differs_is_named() {
    let fitted = Scenario::embedded_default();
    let mut other = fitted.clone();
    other.flight.mach = 0.6;
    other.name = "elsewhere".into();
    assert_eq!(fitted.store_difference(&other), None);
    other.store.diameter_m = 0.3;
    other.store.mass_kg = 500.0;
    let d = fitted.store_difference(&other).unwrap();
    assert_eq!(d.to_string(), "store.mass_kg is 500, not 907.18474");
    let mut other = fitted.clone();
    other.ejector.curve[0][1] += 1.0;
    assert_eq!(
        fitted.store_difference(&other).unwrap().to_string(),
        "ejector.curve differs"
    );
}
