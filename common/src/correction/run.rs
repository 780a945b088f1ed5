//! A candidate's correction values ([`CorrectionValues`]) and one run's corrections
//! ([`CorrectionRun`]): fixed capacity and `Copy`, so that a candidate travels to the workers and
//! a run is set up without allocation.

use super::{
    Correction, CorrectionError, Derivative, FieldPart, MAX_CORRECTION_VALUES, MAX_CORRECTIONS,
    MAX_SHAPE_POINTS, Target, interpolate,
};
use crate::table::Variable;

/// The values of a scenario's corrections carried by one candidate: every correction's
/// breakpoints' values, in the scenario's order (none: no correction).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CorrectionValues {
    len: usize,
    values: [f64; MAX_CORRECTION_VALUES],
}

impl Default for CorrectionValues {
    fn default() -> Self {
        CorrectionValues::NONE
    }
}

impl CorrectionValues {
    /// No values: every correction is zero.
    pub const NONE: CorrectionValues = CorrectionValues {
        len: 0,
        values: [0.0; MAX_CORRECTION_VALUES],
    };

    /// The values `v` (at most [`MAX_CORRECTION_VALUES`]; whether they are finite and fit the
    /// scenario is checked when a run is set up, as the factors are).
    pub fn of(v: &[f64]) -> Result<CorrectionValues, CorrectionError> {
        if v.len() > MAX_CORRECTION_VALUES {
            return Err(CorrectionError::TooManyValues { count: v.len() });
        }
        let mut c = CorrectionValues::NONE;
        c.values[..v.len()].copy_from_slice(v);
        c.len = v.len();
        Ok(c)
    }

    /// The values.
    pub fn as_slice(&self) -> &[f64] {
        &self.values[..self.len]
    }

    /// Number of values.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
}

/// What a force evaluation reads a run-time correction at.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Input {
    Alpha,
    Beta,
    Distance,
}

/// One correction evaluated at every force evaluation.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Runtime {
    /// 0..6: a static coefficient (CA, CY, ..., Cn); 6..12: an interference increment.
    slot: usize,
    input: Input,
    /// Its breakpoints and values in `knots` and `values`: `start..start + len`.
    start: usize,
    len: usize,
}

const NO_RUNTIME: Runtime = Runtime {
    slot: 0,
    input: Input::Distance,
    start: 0,
    len: 0,
};

/// What the corrections over Mach give a run, folded into its constants: each static
/// coefficient's offset (CA positive aft, as the field), each derivative's change, and the
/// change of the flowfield's parts.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Folded {
    /// Added to CA, CY, CZ, Cl, Cm, Cn.
    pub statics: [f64; 6],
    /// Added to each derivative, in [`Derivative::ALL`] order.
    pub derivatives: [f64; 7],
    /// Added to the flowfield's 1 / L_z and 1 / z_r \[1/m\], a_alpha and b_alpha
    /// \[deg/deg\], in [`FieldPart::ALL`] order.
    pub field: [f64; 4],
    /// Added to the flowfield's shape table over depth.
    pub shape: ShapeChange,
}

/// A correction of the flowfield's shape table: c(z) at `len` depths (section 1's
/// interpolation, held at the ends).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ShapeChange {
    /// Number of depths (0: none).
    pub len: usize,
    /// The depths \[m\], increasing.
    pub depth_m: [f64; MAX_SHAPE_POINTS],
    /// The change of g at each.
    pub value: [f64; MAX_SHAPE_POINTS],
}

/// One run's corrections evaluated at each force evaluation (those over alpha, beta and
/// distance), breakpoints in the force evaluation's units (angles in rad).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CorrectionRun {
    count: usize,
    items: [Runtime; MAX_CORRECTIONS],
    knots: [f64; MAX_CORRECTION_VALUES],
    values: [f64; MAX_CORRECTION_VALUES],
}

impl Default for CorrectionRun {
    fn default() -> Self {
        CorrectionRun::NONE
    }
}

impl CorrectionRun {
    /// No run-time correction.
    pub const NONE: CorrectionRun = CorrectionRun {
        count: 0,
        items: [NO_RUNTIME; MAX_CORRECTIONS],
        knots: [0.0; MAX_CORRECTION_VALUES],
        values: [0.0; MAX_CORRECTION_VALUES],
    };

    /// The run of `corrections` with `values` (none: every correction zero) at the flight
    /// condition's `mach`: the run-time corrections, and what those over Mach fold into the
    /// run's constants.
    pub fn new(
        corrections: &[Correction],
        values: &CorrectionValues,
        mach: f64,
    ) -> Result<(CorrectionRun, Folded), CorrectionError> {
        let mut run = CorrectionRun::NONE;
        let mut folded = Folded::default();
        if values.is_empty() {
            return Ok((run, folded));
        }
        let needed: usize = corrections.iter().map(|c| c.breakpoints.len()).sum();
        if values.len() != needed {
            return Err(CorrectionError::ValueCount {
                carried: values.len(),
                needed,
            });
        }
        let v = values.as_slice();
        if let Some(k) = v.iter().position(|x| !x.is_finite()) {
            return Err(CorrectionError::ValueNotFinite {
                index: k,
                value: v[k],
            });
        }
        let mut at = 0;
        for c in corrections {
            let n = c.breakpoints.len();
            let own = &v[at..at + n];
            at += n;
            if c.target == Target::ShapeTable {
                // Checked with the scenario: at most MAX_SHAPE_POINTS depths.
                let k = n.min(MAX_SHAPE_POINTS);
                folded.shape.len = k;
                folded.shape.depth_m[..k].copy_from_slice(&c.breakpoints[..k]);
                folded.shape.value[..k].copy_from_slice(&own[..k]);
                continue;
            }
            let input = match c.variable {
                Variable::Mach => {
                    let x = interpolate(&c.breakpoints, own, mach);
                    match c.target {
                        Target::Static(k) => folded.statics[k] += x,
                        Target::Derivative(d) => {
                            let i = Derivative::ALL.iter().position(|&e| e == d).unwrap_or(0);
                            folded.derivatives[i] += x;
                        }
                        Target::Field(f) => {
                            let i = FieldPart::ALL.iter().position(|&e| e == f).unwrap_or(0);
                            folded.field[i] += x;
                        }
                        Target::Interference(_) | Target::ShapeTable => {}
                    }
                    continue;
                }
                Variable::Alpha => Input::Alpha,
                Variable::Beta => Input::Beta,
                _ => Input::Distance,
            };
            let slot = match c.target {
                Target::Static(k) => k,
                Target::Interference(k) => 6 + k,
                Target::Derivative(_) | Target::Field(_) | Target::ShapeTable => continue,
            };
            let start = run.count_values();
            for (j, (&b, &x)) in c.breakpoints.iter().zip(own).enumerate() {
                run.knots[start + j] = match input {
                    Input::Distance => b,
                    _ => b.to_radians(),
                };
                run.values[start + j] = x;
            }
            run.items[run.count] = Runtime {
                slot,
                input,
                start,
                len: n,
            };
            run.count += 1;
        }
        Ok((run, folded))
    }

    fn count_values(&self) -> usize {
        self.items[..self.count].iter().map(|r| r.len).sum()
    }

    /// Whether any correction is evaluated at each force evaluation.
    #[inline(always)]
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// The run-time corrections at the local `alpha_rad`, `beta_rad` and `distance_m`: (the
    /// static coefficients' increments CA, ..., Cn (CA positive aft), the interference
    /// increments' before their multipliers).
    #[inline(always)]
    pub fn evaluate(&self, alpha_rad: f64, beta_rad: f64, distance_m: f64) -> [f64; 12] {
        let mut d = [0.0; 12];
        for r in &self.items[..self.count] {
            let x = match r.input {
                Input::Alpha => alpha_rad,
                Input::Beta => beta_rad,
                Input::Distance => distance_m,
            };
            let range = r.start..r.start + r.len;
            add_at(
                &mut d,
                r.slot,
                interpolate(&self.knots[range.clone()], &self.values[range], x),
            );
        }
        d
    }
}

/// `d[slot] += v`, each slot by a constant index, so that `d` stays in registers: written at a
/// computed index, it went through memory and was read back as vectors by the caller, a load
/// the stores cannot forward to (a third of an update's correction time, `perf annotate`,
/// 2026-11-28). The same sums in the same order; a slot outside `d` is a defect, as the
/// computed index's bounds check made it.
#[inline(always)]
fn add_at(d: &mut [f64; 12], slot: usize, v: f64) {
    match slot {
        0 => d[0] += v,
        1 => d[1] += v,
        2 => d[2] += v,
        3 => d[3] += v,
        4 => d[4] += v,
        5 => d[5] += v,
        6 => d[6] += v,
        7 => d[7] += v,
        8 => d[8] += v,
        9 => d[9] += v,
        10 => d[10] += v,
        11 => d[11] += v,
        _ => unreachable!("correction slot {slot}: a run has 12"),
    }
}
