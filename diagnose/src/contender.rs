//! A contender of the rival search (`crate::rivals`): a fitted model that may explain the data
//! as well as the answer, kept light (where it is, not how it got there) by the stages that
//! fit it: the catalogue's first round, discovery's first step, the answer's decision.

use crate::Fitted;

/// A fitted model that may explain the data as well as the answer.
#[derive(Clone)]
pub(crate) struct Contender {
    /// Its fit (light: no Jacobian, residuals or history).
    pub fitted: Fitted,
    /// How many models its pool tried (its significance threshold is 1 % over this).
    pub pool_size: usize,
    /// How it came to be tried.
    pub origin: String,
    /// The rival class (`crate::classes`) of discovery's first step it represents.
    pub class: Option<usize>,
}

impl Contender {
    /// A contender of `fitted`, kept light.
    pub fn new(fitted: &Fitted, pool_size: usize, origin: String) -> Contender {
        let mut fitted = fitted.clone();
        fitted.lm.jacobian = nalgebra::DMatrix::zeros(0, 0);
        fitted.lm.residuals = Vec::new();
        fitted.lm.history = Vec::new();
        Contender {
            fitted,
            pool_size,
            origin,
            class: None,
        }
    }

    /// The contender as the representative of rival class `class`.
    pub fn in_class(self, class: Option<usize>) -> Contender {
        Contender { class, ..self }
    }
}
