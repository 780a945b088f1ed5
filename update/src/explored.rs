//! What the releases explored, and the corrections that may be proposed over it
//! (docs/update.md section 15.2): a correction spans only the range of its variable that the
//! releases went through along their fitted trajectories, so that nothing beyond it is
//! presented as measured.
//!
//! Choices, written down in docs/update.md section 15.2:
//! - **distance from carriage**: [`DISTANCE_KNOTS`] breakpoints from 0 to the largest distance
//!   reached, spaced quadratically (s_max (j / (n - 1))^2: dense near carriage, where the
//!   interference changes fastest), then the scenario's `s_end_m` with its value held at 0 (the
//!   scenario says the interference ends there; the correction falls linearly to it beyond the
//!   last distance reached);
//! - **local alpha and beta**: [`ANGLE_KNOTS`] breakpoints evenly over the range reached, when
//!   it is at least [`MIN_ANGLE_RANGE_DEG`] wide (a narrower range gives a constant, which the
//!   factor offsets already are);
//! - **Mach**: the flight Mach numbers of the releases (those within [`MACH_MERGE`] of each
//!   other counted once). A static coefficient over Mach needs two of them (one would be a
//!   constant); a derivative may be corrected at one (a constant change of its slope).

use sepval_common::correction::{Derivative, FieldPart, Target};
use sepval_common::evaluation::Job;
use sepval_common::table::Variable;
use sepval_diagnose::Sample;

/// Breakpoints of a correction over distance, before the one at `s_end_m`.
pub const DISTANCE_KNOTS: usize = 7;
/// Breakpoints of a correction over local alpha or beta.
pub const ANGLE_KNOTS: usize = 5;
/// The narrowest range of local alpha or beta over which a correction is proposed \[deg\].
pub const MIN_ANGLE_RANGE_DEG: f64 = 1.0;
/// Flight Mach numbers closer than this are one.
pub const MACH_MERGE: f64 = 0.005;
/// Aircraft angles of attack closer than this are one \[deg\].
pub const ALPHA_MERGE_DEG: f64 = 0.05;

/// The ranges the releases explored along their fitted trajectories.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Explored {
    /// Largest distance of the CG from carriage \[m\] (the smallest is 0, at release).
    pub distance_m: f64,
    /// Smallest and largest local angle of attack \[deg\].
    pub alpha_deg: (f64, f64),
    /// Smallest and largest local sideslip \[deg\].
    pub beta_deg: (f64, f64),
    /// The flight Mach numbers, increasing, near ones merged.
    pub machs: Vec<f64>,
    /// The scenario's interference cut-off \[m\].
    pub s_end_m: f64,
    /// Whether the scenario's interference is the aircraft's flowfield (docs/model.md section
    /// 3b), whose increments over distance are 0 by definition: no correction over distance
    /// is proposed then (it would bring back the model the field replaces).
    pub flowfield: bool,
    /// Whether that field's shape is a table over depth, or the field tables over position (its
    /// shape is then not corrected).
    pub field_shape_table: bool,
    /// Whether that field is tables over position (they scale with alpha by their zero-lift
    /// angle: no change with alpha is corrected).
    #[serde(default)]
    pub field_grid: bool,
    /// The number of depths of that field's shape table (0: none).
    #[serde(default)]
    pub field_shape_points: usize,
    /// The releases' aircraft angles of attack \[deg\], increasing, those within
    /// [`ALPHA_MERGE_DEG`] of each other counted once.
    #[serde(default)]
    pub aircraft_alphas_deg: Vec<f64>,
}

impl Explored {
    /// What the releases of `job` explored, from what their fitted trajectories saw
    /// (`history[event][sample]`).
    pub fn of(job: &Job, history: &[Vec<Sample>]) -> Explored {
        let samples = || history.iter().flatten();
        let range = |f: &dyn Fn(&Sample) -> f64| {
            samples()
                .map(f)
                .filter(|x| x.is_finite())
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
                    (lo.min(x), hi.max(x))
                })
        };
        let distance = range(&|s| s.input.distance_m).1.max(0.0);
        let alpha = range(&|s| s.input.alpha_rad.to_degrees());
        let beta = range(&|s| s.input.beta_rad.to_degrees());
        let distinct = |of: &dyn Fn(&sepval_common::scenario::Flight) -> f64, merge: f64| {
            let mut v: Vec<f64> = job
                .events()
                .iter()
                .map(|e| of(&e.simulator.scenario().flight))
                .collect();
            v.sort_by(f64::total_cmp);
            v.dedup_by(|a, b| (*a - *b).abs() < merge);
            v
        };
        let machs = distinct(&|f| f.mach, MACH_MERGE);
        let alphas = distinct(&|f| f.alpha_deg, ALPHA_MERGE_DEG);
        let field = job.events()[0].simulator.scenario().flowfield.as_ref();
        Explored {
            distance_m: distance,
            alpha_deg: alpha,
            beta_deg: beta,
            machs,
            s_end_m: job.events()[0].simulator.scenario().interference.s_end_m,
            flowfield: field.is_some(),
            field_shape_table: field.is_some_and(|f| f.shape_is_tabulated()),
            field_grid: field.is_some_and(|f| f.is_grid()),
            field_shape_points: field
                .and_then(|f| f.shape.as_ref())
                .map_or(0, |t| t.depth_m.len()),
            aircraft_alphas_deg: alphas,
        }
    }

    /// The explored range of `variable` (Mach: the first and last flight Mach; depth: that of
    /// distance).
    pub fn range(&self, variable: Variable) -> (f64, f64) {
        match variable {
            // A depth below carriage is at most the distance from it.
            Variable::Distance | Variable::Z => (0.0, self.distance_m),
            Variable::Alpha => self.alpha_deg,
            Variable::Beta => self.beta_deg,
            _ => (
                self.machs.first().copied().unwrap_or(0.0),
                self.machs.last().copied().unwrap_or(0.0),
            ),
        }
    }
}

/// A correction that may be proposed: its field and variable, its breakpoints, and which of
/// their values are held at 0 (the last breakpoint of one over distance, at `s_end_m`).
#[derive(Debug, Clone, PartialEq)]
pub struct Proposal {
    /// The field.
    pub target: Target,
    /// The variable.
    pub variable: Variable,
    /// Breakpoints in the variable's unit.
    pub breakpoints: Vec<f64>,
    /// Per breakpoint, whether its value is held at 0.
    pub pinned: Vec<bool>,
}

impl Proposal {
    /// Number of values a fit estimates.
    pub fn free_values(&self) -> usize {
        self.pinned.iter().filter(|p| !**p).count()
    }

    /// The breakpoints whose values a fit estimates.
    pub fn free_breakpoints(&self) -> Vec<f64> {
        self.breakpoints
            .iter()
            .zip(&self.pinned)
            .filter(|(_, p)| !**p)
            .map(|(b, _)| *b)
            .collect()
    }

    /// A short name, e.g. `Cm over alpha` or `interference dCZ over distance`.
    pub fn name(&self) -> String {
        const AXES: [&str; 6] = ["CA", "CY", "CZ", "Cl", "Cm", "Cn"];
        const INCREMENTS: [&str; 6] = ["dCX", "dCY", "dCZ", "dCl", "dCm", "dCn"];
        let what = match self.target {
            Target::Static(k) => AXES[k].to_string(),
            Target::Interference(k) => format!("interference {}", INCREMENTS[k]),
            Target::Derivative(d) => derivative_name(d).to_string(),
            Target::Field(FieldPart::HalfDepth) => {
                return "the flowfield's half depth (1 / L_z)".to_string();
            }
            Target::Field(FieldPart::Reversal) => {
                return "the flowfield's reversal depth (1 / z_r)".to_string();
            }
            Target::Field(FieldPart::UpwashPerAlpha) => {
                return "the flowfield's upwash per alpha".to_string();
            }
            Target::Field(FieldPart::SidewashPerAlpha) => {
                return "the flowfield's sidewash per alpha".to_string();
            }
            Target::ShapeTable => return "the flowfield's shape table over depth".to_string(),
        };
        let over = match self.variable {
            Variable::Distance => "distance",
            Variable::Alpha => "alpha",
            Variable::Beta => "beta",
            _ => "Mach",
        };
        format!("{what} over {over}")
    }
}

/// A derivative's usual name.
pub fn derivative_name(d: Derivative) -> &'static str {
    match d {
        Derivative::CzAlpha => "CZ_alpha",
        Derivative::CyBeta => "CY_beta",
        Derivative::CmAlpha => "Cm_alpha",
        Derivative::CnBeta => "Cn_beta",
        Derivative::ClP => "Cl_p",
        Derivative::CmQ => "Cm_q",
        Derivative::CnR => "Cn_r",
    }
}

/// The derivatives whose coefficient is on axis `axis` (0 CA, ..., 5 Cn).
fn derivatives_of(axis: usize) -> Vec<Derivative> {
    Derivative::ALL
        .into_iter()
        .filter(|&d| Target::Derivative(d).axis() == axis)
        .collect()
}

/// `n` breakpoints from 0 to `max`, spaced quadratically (max (j / (n - 1))^2: dense near 0).
fn quadratic(max: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|j| max * (j as f64 / (n - 1) as f64).powi(2))
        .collect()
}

/// `n` breakpoints evenly from `lo` to `hi`.
fn even(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|j| lo + (hi - lo) * j as f64 / (n - 1) as f64)
        .collect()
}

/// The corrections of the flowfield (docs/update.md section 15.3a), when the scenario has a
/// field, each one constant (a field is the aircraft's, one for every release) at the first
/// release's Mach: its inverse half depth and inverse reversal depth, unless its shape is a
/// table; its upwash's and sidewash's change per degree of the aircraft's angle of attack, when
/// the releases were flown at two angles or more (at one, a change with alpha is a change of the
/// field's strength, which its factors fit) and the field is not tables over position; and a
/// shape given as a table, over depth ([`shape_table_proposal`]).
pub fn field_proposals(explored: &Explored) -> Vec<Proposal> {
    if !explored.flowfield {
        return Vec::new();
    }
    let mach = explored.machs.first().copied().unwrap_or(0.0);
    let shape: &[FieldPart] = if explored.field_shape_table {
        &[]
    } else {
        &FieldPart::SHAPE
    };
    let per_alpha: &[FieldPart] = if explored.field_grid || explored.aircraft_alphas_deg.len() < 2 {
        &[]
    } else {
        &FieldPart::PER_ALPHA
    };
    shape
        .iter()
        .chain(per_alpha)
        .map(|&part| Proposal {
            target: Target::Field(part),
            variable: Variable::Mach,
            breakpoints: vec![mach],
            pinned: vec![false],
        })
        .chain(shape_table_proposal(explored))
        .collect()
}

/// The correction of a shape table over depth, when the field has one: [`DISTANCE_KNOTS`]
/// depths from 0 to the largest distance from carriage reached (the CG's depth is at most that),
/// spaced quadratically as a correction over distance is (dense near carriage, where the field
/// changes fastest), fewer where the table and the correction would have more than
/// `MAX_SHAPE_POINTS` depths together; its value at 0 held there (g stays 1 at carriage), the
/// last held below the last depth as the table holds its own.
pub fn shape_table_proposal(explored: &Explored) -> Option<Proposal> {
    use sepval_common::scenario::MAX_SHAPE_POINTS;
    if !explored.flowfield || explored.field_shape_points == 0 || explored.distance_m <= 0.0 {
        return None;
    }
    // The union shares depth 0 at least.
    let n = DISTANCE_KNOTS.min(MAX_SHAPE_POINTS + 1 - explored.field_shape_points);
    if n < 3 {
        return None;
    }
    let breakpoints = quadratic(explored.distance_m, n);
    let mut pinned = vec![false; n];
    pinned[0] = true;
    Some(Proposal {
        target: Target::ShapeTable,
        variable: Variable::Z,
        breakpoints,
        pinned,
    })
}

/// Every correction of axis `axis` (0 CA, ..., 5 Cn) that the explored ranges allow.
pub fn proposals(axis: usize, explored: &Explored) -> Vec<Proposal> {
    let mut out = Vec::new();
    let free = |b: Vec<f64>| {
        let n = b.len();
        (b, vec![false; n])
    };
    let s_max = explored.distance_m;
    if s_max > 0.0 && !explored.flowfield {
        let mut b = quadratic(s_max, DISTANCE_KNOTS);
        let mut pinned = vec![false; b.len()];
        if explored.s_end_m > s_max * 1.05 {
            b.push(explored.s_end_m);
            pinned.push(true);
        }
        out.push(Proposal {
            target: Target::Interference(axis),
            variable: Variable::Distance,
            breakpoints: b,
            pinned,
        });
    }
    for (variable, (lo, hi)) in [
        (Variable::Alpha, explored.alpha_deg),
        (Variable::Beta, explored.beta_deg),
    ] {
        if hi - lo >= MIN_ANGLE_RANGE_DEG {
            let (breakpoints, pinned) = free(even(lo, hi, ANGLE_KNOTS));
            out.push(Proposal {
                target: Target::Static(axis),
                variable,
                breakpoints,
                pinned,
            });
        }
    }
    if explored.machs.len() >= 2 {
        let (breakpoints, pinned) = free(explored.machs.clone());
        out.push(Proposal {
            target: Target::Static(axis),
            variable: Variable::Mach,
            breakpoints,
            pinned,
        });
    }
    for d in derivatives_of(axis) {
        let (breakpoints, pinned) = free(explored.machs.clone());
        out.push(Proposal {
            target: Target::Derivative(d),
            variable: Variable::Mach,
            breakpoints,
            pinned,
        });
    }
    out
}
