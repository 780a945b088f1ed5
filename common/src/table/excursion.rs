//! A run's table scratch (interval cursors, excursion counts: fixed size, no allocation) and
//! the excursions it reports: how often and how far a run left each table (docs/model.md
//! section 3, "Tabulated coefficients": outside a table its value is held at the edge and the
//! excursion recorded).

use super::prepared::MAX_GROUPS;
use super::*;

/// One propagation's table scratch: interval cursors and excursion counts (fixed size).
#[derive(Debug, Default, Clone)]
pub struct TableState {
    pub(super) cursor: [[Cell<u32>; 3]; MAX_GROUPS],
    pub(super) evaluations: Cell<u64>,
    pub(super) count: [Cell<u64>; MAX_TABLES],
    pub(super) worst: [[Cell<f64>; Variable::ALL.len()]; MAX_TABLES],
}

impl TableState {
    /// Counts one force evaluation (of a scenario with tables).
    #[inline(always)]
    pub fn count_evaluation(&self) {
        self.evaluations.set(self.evaluations.get() + 1);
    }

    /// Puts this state back to `saved` (cursors and counts): for a step taken again from where
    /// `saved` was taken, so that the cursors' history, which decides the interval of an input
    /// on a breakpoint, is the one of a single pass.
    pub fn restore(&self, saved: &TableState) {
        for (group, from) in self.cursor.iter().zip(&saved.cursor) {
            for (c, f) in group.iter().zip(from) {
                c.set(f.get());
            }
        }
        self.evaluations.set(saved.evaluations.get());
        for (c, f) in self.count.iter().zip(&saved.count) {
            c.set(f.get());
        }
        for (w, f) in self.worst.iter().zip(&saved.worst) {
            for (c, f) in w.iter().zip(f) {
                c.set(f.get());
            }
        }
    }

    /// The counts so far.
    pub fn excursions(&self) -> TableExcursions {
        TableExcursions {
            evaluations: self.evaluations.get(),
            count: std::array::from_fn(|k| self.count[k].get()),
            worst: std::array::from_fn(|k| std::array::from_fn(|v| self.worst[k][v].get())),
        }
    }
}

/// How often a run's force evaluations left each table, and how far (fixed size, in
/// [`crate::propagator::RunLog`]); [`PreparedTables::report`] names them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TableExcursions {
    /// Force evaluations that looked tables up.
    pub evaluations: u64,
    /// Per table: evaluations outside it (beyond an axis other than Mach).
    pub count: [u64; MAX_TABLES],
    /// Per table and variable ([`Variable::ALL`] order): the largest excursion, in the
    /// variable's unit.
    pub worst: [[f64; Variable::ALL.len()]; MAX_TABLES],
}

impl Default for TableExcursions {
    fn default() -> Self {
        TableExcursions {
            evaluations: 0,
            count: [0; MAX_TABLES],
            worst: [[0.0; Variable::ALL.len()]; MAX_TABLES],
        }
    }
}

/// A table a run left: how often and how far beyond each axis.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TableExcursion {
    /// The scenario field, e.g. `aero.cz`.
    pub table: String,
    /// Force evaluations (RK4 stages) outside the table, its value held at the edge.
    pub evaluations_outside: u64,
    /// Force evaluations of the run.
    pub evaluations: u64,
    /// Each axis left: its range and the largest excursion beyond it.
    pub axes: Vec<AxisExcursion>,
    /// Whether the counts are of the run's samples rather than its force evaluations (the
    /// flowfield's tables over position, docs/model.md section 3b).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub at_samples: bool,
}

/// The excursion beyond one axis of a table.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AxisExcursion {
    /// The variable, with its unit (`alpha_deg`, `distance_m`, `mach`).
    pub variable: String,
    /// The table's first and last breakpoint.
    pub range: [f64; 2],
    /// The largest distance beyond the range, in the variable's unit.
    pub worst_excursion: f64,
}

impl fmt::Display for TableExcursion {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        let counted = if self.at_samples {
            "samples"
        } else {
            "force evaluations"
        };
        write!(
            f,
            "left table `{}` in {} of {} {counted} (value held at the edge)",
            self.table, self.evaluations_outside, self.evaluations
        )?;
        for a in &self.axes {
            let unit = a.unit().map(|u| format!(" {u}")).unwrap_or_default();
            write!(
                f,
                "; {} by up to {}{unit} beyond [{}, {}]{unit}",
                a.variable, a.worst_excursion, a.range[0], a.range[1]
            )?;
        }
        Ok(())
    }
}

impl AxisExcursion {
    /// The unit of the variable, from its name (`x_m`: m, `alpha_deg`: deg; `mach`: none).
    pub fn unit(&self) -> Option<&str> {
        let (_, unit) = self.variable.rsplit_once('_')?;
        ["m", "deg", "rad", "s", "ft"]
            .contains(&unit)
            .then_some(unit)
    }
}
