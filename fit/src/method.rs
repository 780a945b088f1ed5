//! Which searches a fit runs (`--method`), as files and the command line name them.

/// Which searches to run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    /// The genetic algorithm.
    Ga,
    /// The hill climber.
    Hill,
    /// Both, as in the study's comparison.
    Both,
    /// The genetic algorithm, then Levenberg-Marquardt refinement to the noise floor.
    GaLm,
    /// The hill climber, then Levenberg-Marquardt refinement.
    HillLm,
}

impl Method {
    /// Every method, in the order the command line lists them.
    pub const ALL: [Method; 5] = [
        Method::Ga,
        Method::Hill,
        Method::Both,
        Method::GaLm,
        Method::HillLm,
    ];

    /// The method of a name (`ga`, `hill`, `both`, `ga+lm`, `hill+lm`), as files record it.
    pub fn from_name(text: &str) -> Option<Method> {
        Method::ALL.into_iter().find(|m| m.name() == text)
    }

    /// The name used in files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Method::Ga => "ga",
            Method::Hill => "hill",
            Method::Both => "both",
            Method::GaLm => "ga+lm",
            Method::HillLm => "hill+lm",
        }
    }

    /// Whether it runs the genetic algorithm.
    pub fn runs_ga(self) -> bool {
        matches!(self, Method::Ga | Method::Both | Method::GaLm)
    }

    /// Whether it runs the hill climber.
    pub fn runs_hill(self) -> bool {
        matches!(self, Method::Hill | Method::Both | Method::HillLm)
    }

    /// Whether it refines with Levenberg-Marquardt.
    pub fn refines(self) -> bool {
        matches!(self, Method::GaLm | Method::HillLm)
    }
}
