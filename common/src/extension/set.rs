//! The terms of one run (docs/discovery.md section 11.2): a fixed-capacity `Copy` set, the
//! scenario's and the candidate's together, and what the force evaluation reads from it (the
//! coefficient increments and the ejector factor; the wind is in [`super::wind`]).

use super::{Axis, MAX_TERMS, Regressor, Term, TermError, TermInput};

/// The terms of one run (fixed capacity, `Copy`: no allocation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TermSet {
    len: usize,
    items: [Option<Term>; MAX_TERMS],
}

impl Default for TermSet {
    fn default() -> Self {
        TermSet::NONE
    }
}

impl TermSet {
    /// No terms.
    pub const NONE: TermSet = TermSet {
        len: 0,
        items: [None; MAX_TERMS],
    };

    /// Adds a (checked) term.
    pub fn push(&mut self, term: Term) -> Result<(), TermError> {
        term.check()?;
        if self.len == MAX_TERMS {
            return Err(TermError::TooMany);
        }
        self.items[self.len] = Some(term);
        self.len += 1;
        Ok(())
    }

    /// The terms of `terms` (checked).
    pub fn of(terms: &[Term]) -> Result<TermSet, TermError> {
        let mut s = TermSet::NONE;
        for t in terms {
            s.push(*t)?;
        }
        Ok(s)
    }

    /// Number of terms.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The terms.
    pub fn iter(&self) -> impl Iterator<Item = &Term> {
        self.items[..self.len].iter().flatten()
    }

    /// These terms followed by `other`'s.
    pub fn merged(&self, other: &TermSet) -> Result<TermSet, TermError> {
        let mut s = *self;
        for t in other.iter() {
            s.push(*t)?;
        }
        Ok(s)
    }

    /// Whether any term acts on the ejector.
    pub fn has_ejector(&self) -> bool {
        self.iter().any(|t| t.axis == Axis::Ejector)
    }

    /// Whether any term acts on an aerodynamic coefficient.
    pub fn has_aero(&self) -> bool {
        self.iter().any(|t| t.axis.is_coefficient())
    }

    /// The increments of (CA, CY, CZ, Cl, Cm, Cn) at one force evaluation (inlined always, as
    /// [`Term::regressor_value`]).
    ///
    /// An oscillation entry is a sine and a cosine of one argument: the pair is computed once
    /// (`sin_cos`, of which `sin` and `cos` are each one half) and the second term of the pair
    /// reads it, the same bits as computing it again.
    #[inline(always)]
    pub fn aero_increments(&self, x: &TermInput) -> [f64; 6] {
        let mut d = [0.0; 6];
        // The last sine-cosine pair computed, with its argument's bits.
        let mut pair: Option<(u64, (f64, f64))> = None;
        for t in self.iter().filter(|t| t.axis.is_coefficient()) {
            let v = match t.regressor {
                Regressor::Sin | Regressor::Cos => {
                    let arg = t.oscillation_argument(x.t_s);
                    let (sin, cos) = match pair {
                        Some((bits, sc)) if bits == arg.to_bits() => sc,
                        _ => {
                            let sc = crate::elementary::sin_cos(arg);
                            pair = Some((arg.to_bits(), sc));
                            sc
                        }
                    };
                    if t.regressor == Regressor::Sin {
                        sin
                    } else {
                        cos
                    }
                }
                _ => t.regressor_value(x),
            };
            d[t.axis.index()] += t.coefficient * v;
        }
        d
    }

    /// The ejector force factor max(0, 1 + dE) of a foot at stroke fraction `sigma` at time
    /// `t_s`: an ejector pushes, it never pulls, however large a negative term.
    #[inline(always)]
    pub fn ejector_factor(&self, t_s: f64, sigma: f64) -> f64 {
        let mut d = 0.0;
        for t in self.iter().filter(|t| t.axis == Axis::Ejector) {
            d += t.coefficient * t.ejector_value(t_s, sigma);
        }
        (1.0 + d).max(0.0)
    }
}
