//! The parameters of an update's output-error refit (docs/update.md section 15.4): the free
//! factors, then the free values of every correction (those not held at 0), and the smoothness
//! penalty on the values as rows appended to the residual vector.

use nalgebra::DMatrix;
use sepval_common::correction::{Correction, CorrectionValues, Derivative, FieldPart, Target};
use sepval_common::evaluation::Candidate;
use sepval_common::model::Model;
use sepval_core::factors::{Factor, FactorTable, Factors};
use sepval_solve::params::Params;

use crate::explored::Proposal;

/// The ridge within a correction's smoothness penalty, relative to its second differences': a
/// whisper that keeps every system definite.
pub const RIDGE: f64 = 1e-4;
/// Bound on a static coefficient's correction (either sign).
pub const STATIC_BOUND: f64 = 2.0;
/// Smallest bound on a derivative's correction \[1/rad\]; larger derivatives get twice their
/// size.
pub const DERIVATIVE_BOUND: f64 = 10.0;
/// Smallest bound on an interference increment's correction; larger increments at carriage get
/// twice their size.
pub const INTERFERENCE_BOUND: f64 = 2.0;

/// Each axis's offset factor (CA ... Cn): a constant added to its coefficient.
pub const OFFSETS: [Factor; 6] = [
    Factor::Caoff,
    Factor::Cyoff,
    Factor::Czoff,
    Factor::Cloff,
    Factor::Cmoff,
    Factor::Cnoff,
];
/// Each axis's interference multiplier (CA ... Cn): it scales the axis's increment.
pub const MULTIPLIERS: [Factor; 6] = [
    Factor::Caintfac,
    Factor::Cyintfac,
    Factor::Czintfac,
    Factor::Clintfac,
    Factor::Cmintfac,
    Factor::Cnintfac,
];

/// The refit's parameters and how they make a candidate.
#[derive(Debug, Clone)]
pub struct UpdateSpace {
    /// Names, units and bounds: the free factors, then every correction's free values.
    pub params: Params,
    /// The factors held (and the start of the free ones).
    base: Factors,
    /// The free factors' indices.
    free: Vec<usize>,
    /// The corrections.
    corrections: Vec<Proposal>,
    /// The penalty's square root: (rows, free values); the residual vector gains L v.
    root: DMatrix<f64>,
    /// Each correction's bounds on its values (lowest, highest).
    bounds: Vec<(f64, f64)>,
}

impl UpdateSpace {
    /// The space of `corrections` over `model`'s scenario (its derivatives and increments set
    /// the bounds), with the factors `free` (indices; less those the corrections take over,
    /// [`taken_over`]) starting at `base` and the others held there. `weights[k]` is correction
    /// k's penalty weight: its lambda times its values' mean information.
    pub fn new(
        model: &Model,
        base: Factors,
        free: &[usize],
        corrections: &[Proposal],
        weights: &[f64],
    ) -> UpdateSpace {
        let table: &FactorTable = &model.scenario().factors;
        let taken = taken_over(corrections);
        let free: Vec<usize> = free
            .iter()
            .copied()
            .filter(|i| !taken.contains(i))
            .collect();
        let free = free.as_slice();
        let mut params = Params::empty();
        let bounds = corrections.iter().map(|p| bound(model, p.target)).collect();
        for &i in free {
            let f = &table.0[i];
            params.push(Factor::NAMES[i], "-", f.min, f.max);
        }
        for p in corrections {
            let (lo, hi) = bound(model, p.target);
            for (k, (&b, &pinned)) in p.breakpoints.iter().zip(&p.pinned).enumerate() {
                if !pinned {
                    let unit = match p.target {
                        Target::Derivative(_) => "1/rad",
                        Target::Field(f) if f.is_shape() => "1/m",
                        Target::Field(_) => "deg/deg",
                        _ => "-",
                    };
                    params.push(format!("{}[{k}]@{b}", p.target.field()), unit, lo, hi);
                }
            }
        }
        let values: usize = corrections.iter().map(Proposal::free_values).sum();
        let rows: usize = corrections
            .iter()
            .map(|p| penalty_root(&p.free_breakpoints()).nrows())
            .sum();
        let mut root = DMatrix::zeros(rows, values);
        let (mut r0, mut c0) = (0, 0);
        for (p, &w) in corrections.iter().zip(weights) {
            let block = penalty_root(&p.free_breakpoints()) * w.max(0.0).sqrt();
            root.view_mut((r0, c0), block.shape()).copy_from(&block);
            r0 += block.nrows();
            c0 += block.ncols();
        }
        UpdateSpace {
            params,
            base,
            free: free.to_vec(),
            corrections: corrections.to_vec(),
            root,
            bounds,
        }
    }

    /// The bounds on correction `k`'s values (lowest, highest).
    pub fn bounds(&self, k: usize) -> (f64, f64) {
        self.bounds[k]
    }

    /// The corrections.
    pub fn corrections(&self) -> &[Proposal] {
        &self.corrections
    }

    /// The corrections as a scenario holds them.
    pub fn checked(&self) -> Vec<Correction> {
        self.corrections
            .iter()
            .map(|p| Correction {
                target: p.target,
                variable: p.variable,
                breakpoints: p.breakpoints.clone(),
            })
            .collect()
    }

    /// The positions among the parameters of the factors that share what an interference
    /// correction (with free values) describes: its axis's multiplier, which scales the
    /// scenario's increment and the correction together, and its axis's offset, which within
    /// the distances the releases reached is the correction's constant part.
    pub fn shared_factors(&self) -> Vec<usize> {
        self.corrections
            .iter()
            .filter(|p| p.free_values() > 0)
            .flat_map(|p| match p.target {
                Target::Interference(a) => vec![MULTIPLIERS[a].index(), OFFSETS[a].index()],
                _ => Vec::new(),
            })
            .filter_map(|i| self.free.iter().position(|&f| f == i))
            .collect()
    }

    /// The free factors' indices.
    pub fn free(&self) -> &[usize] {
        &self.free
    }

    /// Number of free factors.
    pub fn factor_count(&self) -> usize {
        self.free.len()
    }

    /// The start: the free factors at `base`, the values at `values` (free values only, in
    /// order) or 0.
    pub fn start(&self, factors: &Factors, values: Option<&[f64]>) -> Vec<f64> {
        let mut x: Vec<f64> = self.free.iter().map(|&i| factors.0[i]).collect();
        let n = self.params.len() - x.len();
        match values {
            Some(v) if v.len() == n => x.extend_from_slice(v),
            _ => x.extend(std::iter::repeat_n(0.0, n)),
        }
        x
    }

    /// The factors at `x`.
    pub fn factors(&self, x: &[f64]) -> Factors {
        let mut f = self.base;
        for (k, &i) in self.free.iter().enumerate() {
            f.0[i] = x[k];
        }
        f
    }

    /// The free values at `x`.
    pub fn free_values<'a>(&self, x: &'a [f64]) -> &'a [f64] {
        &x[self.free.len()..]
    }

    /// Every breakpoint's value at `x`, per correction (those held: 0).
    pub fn values(&self, x: &[f64]) -> Vec<Vec<f64>> {
        let mut it = self.free_values(x).iter();
        self.corrections
            .iter()
            .map(|p| {
                p.pinned
                    .iter()
                    .map(|&pinned| {
                        if pinned {
                            0.0
                        } else {
                            *it.next().unwrap_or(&0.0)
                        }
                    })
                    .collect()
            })
            .collect()
    }

    /// The candidate of `x`.
    pub fn candidate(&self, x: &[f64]) -> Candidate {
        let all: Vec<f64> = self.values(x).concat();
        Candidate {
            corrections: CorrectionValues::of(&all).unwrap_or(CorrectionValues::NONE),
            ..Candidate::baseline(self.factors(x))
        }
    }

    /// The point of this space nearest `x` of `from` (a space of the same corrections, or of
    /// none): its free factors, and the values of `x` that this space keeps free.
    pub fn project(&self, from: &UpdateSpace, x: &[f64]) -> Vec<f64> {
        let factors = from.factors(x);
        let values = from.values(x);
        let mut out: Vec<f64> = self.free.iter().map(|&i| factors.0[i]).collect();
        for (k, p) in self.corrections.iter().enumerate() {
            for (j, &pinned) in p.pinned.iter().enumerate() {
                if !pinned {
                    out.push(values.get(k).and_then(|v| v.get(j)).copied().unwrap_or(0.0));
                }
            }
        }
        out
    }

    /// The penalty rows L v at `x` (each correction's weighted).
    pub fn penalty_rows(&self, x: &[f64]) -> Vec<f64> {
        let v = nalgebra::DVector::from_column_slice(self.free_values(x));
        (&self.root * v).iter().copied().collect()
    }

    /// Number of penalty rows.
    pub fn penalty_len(&self) -> usize {
        self.root.nrows()
    }
}

/// The factors the corrections take over, which a refit holds where they are: a static
/// coefficient's correction over alpha, beta or Mach holds a constant part, which is its axis's
/// offset (caoff ... cnoff), and the two together would be undetermined. An interference
/// increment's correction keeps its axis's multiplier free: the multiplier scales the
/// increment and the correction together (section 15.1), so holding it where the factors alone
/// put it (near 0 when the scenario's shape is wrong) would leave the correction no effect; the
/// smoothness penalty settles what the two share. A correction whose values are all held takes
/// nothing over.
pub fn taken_over(corrections: &[Proposal]) -> Vec<usize> {
    corrections
        .iter()
        .filter(|p| p.free_values() > 0)
        .filter_map(|p| match p.target {
            Target::Static(k) => Some(OFFSETS[k].index()),
            Target::Interference(_)
            | Target::Derivative(_)
            | Target::Field(_)
            | Target::ShapeTable => None,
        })
        .collect()
}

/// The square root of one correction's smoothness penalty on the values at its free
/// breakpoints `b`: the second divided differences, scaled to (1, -2, 1) where the breakpoints
/// are evenly spaced (row j: h/h_j, -(h/h_j + h/h_{j+1}), h/h_{j+1}, h the mean of the two
/// spacings h_j, h_{j+1}), which vanish on any straight line whatever the spacing; then a
/// ridge of sqrt([`RIDGE`]) on each value, so that its square is D2^T D2 + RIDGE I.
pub fn penalty_root(b: &[f64]) -> DMatrix<f64> {
    let n = b.len();
    let d2 = n.saturating_sub(2);
    let mut root = DMatrix::zeros(d2 + n, n);
    for j in 0..d2 {
        let (h0, h1) = (b[j + 1] - b[j], b[j + 2] - b[j + 1]);
        let h = 0.5 * (h0 + h1);
        root[(j, j)] = h / h0;
        root[(j, j + 1)] = -(h / h0 + h / h1);
        root[(j, j + 2)] = h / h1;
    }
    for j in 0..n {
        root[(d2 + j, j)] = RIDGE.sqrt();
    }
    root
}

/// The bounds of a correction of `target` on `model`'s scenario: for the aerodynamic data,
/// either sign of the larger of a floor and twice the size of what it corrects at the flight
/// condition; for the flowfield's shape ([`field_bounds`]), what keeps it a field that decays.
fn bound(model: &Model, target: Target) -> (f64, f64) {
    let symmetric = |b: f64| (-b, b);
    let a = &model.aero_at_mach;
    match target {
        Target::Field(part) => field_bounds(model, part),
        Target::ShapeTable => symmetric(SHAPE_BOUND),
        Target::Static(_) => symmetric(STATIC_BOUND),
        Target::Derivative(d) => {
            let base = match d {
                Derivative::CzAlpha => a.cz_alpha_per_rad,
                Derivative::CyBeta => a.cy_beta_per_rad,
                Derivative::CmAlpha => a.cm_alpha_per_rad,
                Derivative::CnBeta => a.cn_beta_per_rad,
                Derivative::ClP => a.cl_p_per_rad,
                Derivative::CmQ => a.cm_q_per_rad,
                Derivative::CnR => a.cn_r_per_rad,
            };
            symmetric(DERIVATIVE_BOUND.max(2.0 * base.abs()))
        }
        Target::Interference(k) => {
            symmetric(INTERFERENCE_BOUND.max(2.0 * model.interference_at_carriage[k].abs()))
        }
    }
}

/// The depths \[m\] between which a corrected flowfield's half depth and reversal depth may
/// lie: from a tenth of the store's diameter (a field halving closer to carriage than that is
/// not resolved by stations along the store) to a hundred metres (no decay or reversal within
/// any release: an inverse of 0.01 per m).
pub const FIELD_DEPTH_M: (f64, f64) = (0.05, 100.0);

/// The bound of a correction of the field's shape table over depth (either sign): g changed by
/// at most twice its value at carriage.
pub const SHAPE_BOUND: f64 = 2.0;

/// The least bound of a correction of the field's upwash or sidewash per degree of the
/// aircraft's angle of attack \[deg/deg\] (either sign): a field growing by twice the change
/// of the aircraft's angle is beyond what a wing induces beneath it.
pub const PER_ALPHA_BOUND: f64 = 2.0;

/// The bounds of a correction of the flowfield's `part`: for the shape (it adds to the inverse
/// depth), the corrected half depth within [`FIELD_DEPTH_M`] and the corrected reversal depth
/// beyond its shallowest, or none (an inverse of 0); for the upwash's and sidewash's change
/// with alpha, either sign of the larger of [`PER_ALPHA_BOUND`] and twice the scenario's.
fn field_bounds(model: &Model, part: FieldPart) -> (f64, f64) {
    let Some(field) = model.scenario().flowfield.as_ref() else {
        return (0.0, 0.0);
    };
    let (shallowest, deepest) = FIELD_DEPTH_M;
    match part {
        FieldPart::HalfDepth => {
            // A table's shape is never corrected (no proposal is made for it): no room.
            let Some(l_z) = field.half_depth_m else {
                return (0.0, 0.0);
            };
            let inverse = 1.0 / l_z;
            (1.0 / deepest - inverse, 1.0 / shallowest - inverse)
        }
        FieldPart::Reversal => {
            let inverse = field.reversal_m.map_or(0.0, |z_r| 1.0 / z_r);
            (-inverse, 1.0 / shallowest - inverse)
        }
        FieldPart::UpwashPerAlpha | FieldPart::SidewashPerAlpha => {
            let given = match part {
                FieldPart::UpwashPerAlpha => field.upwash_per_alpha,
                _ => field.sidewash_per_alpha,
            };
            let b = PER_ALPHA_BOUND.max(2.0 * given.abs());
            (-b, b)
        }
    }
}
