//! The parameters of a least-squares problem as the solvers see them: a name, a unit and
//! bounds each (what each one means to the model is the caller's).

/// Names, units and bounds of the parameters of a least-squares problem, in the order of its
/// parameter vectors.
#[derive(Debug, Clone, PartialEq)]
pub struct Params {
    /// Names.
    pub names: Vec<String>,
    /// Units ("-" when dimensionless).
    pub units: Vec<String>,
    /// Lower bounds.
    pub lo: Vec<f64>,
    /// Upper bounds.
    pub hi: Vec<f64>,
}

impl Params {
    /// No parameters.
    pub fn empty() -> Self {
        Params {
            names: Vec::new(),
            units: Vec::new(),
            lo: Vec::new(),
            hi: Vec::new(),
        }
    }

    /// Adds a parameter.
    pub fn push(&mut self, name: impl Into<String>, unit: impl Into<String>, lo: f64, hi: f64) {
        self.names.push(name.into());
        self.units.push(unit.into());
        self.lo.push(lo);
        self.hi.push(hi);
    }

    /// Number of parameters.
    pub fn len(&self) -> usize {
        self.names.len()
    }

    /// Whether there are no parameters.
    pub fn is_empty(&self) -> bool {
        self.names.is_empty()
    }

    /// Width of parameter `i`'s range.
    pub fn range(&self, i: usize) -> f64 {
        self.hi[i] - self.lo[i]
    }

    /// Projects `x` onto the bounds.
    pub fn clamp(&self, x: &[f64]) -> Vec<f64> {
        x.iter()
            .enumerate()
            .map(|(i, v)| v.clamp(self.lo[i], self.hi[i]))
            .collect()
    }
}
