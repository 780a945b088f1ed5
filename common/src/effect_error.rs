//! What the model and the effect catalogue share without depending on each other: the errors
//! of an effect's specification and parameters, and the most parameters one effect has. The
//! model's runs hold coefficient terms with that many parameters; the catalogue's plug-ins
//! (`effects/`) fill them in (docs/model.md section 7).

/// Most parameters one effect has.
pub const MAX_EFFECT_PARAMS: usize = 3;

/// Errors in effect specifications and parameters.
#[derive(Debug, Clone, thiserror::Error, PartialEq)]
#[non_exhaustive]
pub enum EffectError {
    /// An id not in the catalogue.
    #[error("unknown effect `{id}` (run `sepval effects` for the catalogue)")]
    Unknown {
        /// The id given.
        id: String,
    },
    /// An effect index not in the catalogue.
    #[error("effect index {index} is not in the catalogue of {len} effects")]
    BadIndex {
        /// The index given.
        index: usize,
        /// Catalogue length.
        len: usize,
    },
    /// Wrong number of parameters.
    #[error("effect `{id}` takes {expected} parameter(s) ({names}), {given} given")]
    ParamCount {
        /// The effect.
        id: &'static str,
        /// How many it takes.
        expected: usize,
        /// Their names and units.
        names: String,
        /// How many were given.
        given: usize,
    },
    /// A parameter that is not a finite number.
    #[error("effect `{id}`: parameter {name} = {value} is not a finite number")]
    NotFinite {
        /// The effect.
        id: &'static str,
        /// The parameter.
        name: &'static str,
        /// The value.
        value: f64,
    },
    /// A parameter outside its physical domain.
    #[error("effect `{id}`: parameter {name} = {value} {reason}")]
    OutOfDomain {
        /// The effect.
        id: &'static str,
        /// The parameter.
        name: &'static str,
        /// The value.
        value: f64,
        /// What is required.
        reason: &'static str,
    },
    /// The same effect given twice.
    #[error("effect `{id}` is given twice")]
    Duplicate {
        /// The effect.
        id: &'static str,
    },
    /// More effects than one run can carry.
    #[error("at most {max} effects can be active at once")]
    TooMany {
        /// The limit.
        max: usize,
    },
    /// More coefficient terms than one run can carry.
    #[error("at most {max} coefficient terms can be active at once")]
    TooManyCoefficientTerms {
        /// The limit.
        max: usize,
    },
    /// A malformed `ID=V1,V2` specification.
    #[error("effect specification `{spec}`: {reason}")]
    Syntax {
        /// The text given.
        spec: String,
        /// What is wrong.
        reason: String,
    },
}
