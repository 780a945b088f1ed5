//! The edges of the locators' domains (docs/discovery.md section 11.2,
//! `sepval_common::extension::locator`; issue 21, item 13): the largest (and smallest) accepted
//! value of each locator simulates the default scenario to a finite trajectory, and the next
//! double beyond is refused when read, naming the field and the domain.

use sepval_common::effects::EffectSet;
use sepval_common::extension::locator::{F_HZ, LAMBDA_M, LocatorDomain, MACH0, T_ON_S};
use sepval_common::extension::{
    Axis, Regressor, Term, TermRecord, extension_toml, parse_extension,
};
use sepval_common::scenario::Scenario;
use sepval_common::simulation::Simulator;
use sepval_core::factors::Factors;

/// A term of `regressor` on Cm at `locator`, with a coefficient that keeps its increment of
/// Cm small at the edge (the point is the regressor's value, not the store's response).
fn term(regressor: Regressor, locator: f64, coefficient: f64) -> Term {
    Term {
        axis: Axis::Cm,
        regressor,
        locator: [locator, 0.0],
        coefficient,
    }
}

/// The edges: (domain, regressor, coefficient).
fn edges() -> [(LocatorDomain, Regressor, f64); 4] {
    [
        (LAMBDA_M, Regressor::F, 0.01),
        (MACH0, Regressor::Dm2, 1e-9),
        (T_ON_S, Regressor::Step, 0.01),
        (F_HZ, Regressor::Sin, 0.01),
    ]
}

fn simulates_finite(t: Term) {
    let mut s = Scenario::embedded_default();
    s.extension = vec![TermRecord::of(&t)];
    let sim = Simulator::new(&s);
    let traj = sim
        .simulate(&Factors::TRUTH, &EffectSet::NONE, &sim.default_times())
        .unwrap_or_else(|e| panic!("{t:?} does not simulate: {e}"));
    let finite = traj
        .pos_m
        .iter()
        .chain(&traj.att_deg)
        .all(|v| v.iter().all(|x| x.is_finite()));
    assert!(finite, "{t:?}: a trajectory that is not finite");
}

#[test]
fn every_edge_of_a_domain_simulates_and_the_next_value_is_refused() {
    for (d, regressor, coefficient) in edges() {
        let mut accepted = vec![d.max];
        if !d.min_open {
            accepted.push(d.min);
        }
        for v in accepted {
            let t = term(regressor, v, coefficient);
            t.check().unwrap();
            simulates_finite(t);
        }
        let beyond = term(regressor, d.above_max(), coefficient);
        let text = extension_toml(&[TermRecord::of(&beyond)]);
        let e = parse_extension(&text, "e.toml").unwrap_err().to_string();
        assert!(
            e.contains(&format!("`{}` {} = ", d.name, d.name)) && e.ends_with(d.expected),
            "{e}"
        );
    }
}

#[test]
fn the_values_of_the_issue_are_refused_with_their_domain() {
    for (regressor, v, expected) in [
        (
            Regressor::F,
            1e300,
            "`lambda_m` lambda_m = 1e300: expected a decay length in (0, 1000] m",
        ),
        (
            Regressor::Sin,
            1e308,
            "`f_hz` f_hz = 1e308: expected a frequency in [0, 1000000] Hz",
        ),
        (
            Regressor::Dm,
            1e300,
            "`mach0` mach0 = 1e300: expected a Mach number in (0, 1000]",
        ),
        (
            Regressor::Step,
            -1e300,
            "`t_on_s` t_on_s = -1e300: expected a time in [-7200, 7200] s",
        ),
    ] {
        let text = extension_toml(&[TermRecord::of(&term(regressor, v, 0.01))]);
        let e = parse_extension(&text, "e.toml").unwrap_err().to_string();
        assert!(
            e.starts_with("extension e.toml: line ") && e.ends_with(expected),
            "{e}"
        );
    }
}
