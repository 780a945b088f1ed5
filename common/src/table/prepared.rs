//! Interpolation at run time: tables prepared once per scenario and event (Mach axes
//! interpolated at the flight condition, tables over the same axes grouped), looked up at
//! every force evaluation without allocation, and the excursions outside them counted (in a
//! run's [`TableState`], `excursion.rs`). Setting a scenario's tables up is the model's
//! (`crate::model::tables`): this module knows tables, not scenarios.

use super::*;

/// Most tables one scenario can hold (13 aerodynamic fields and 6 interference increments).
pub const MAX_TABLES: usize = 19;
/// Most run-time groups (tables sharing their axes): one per static coefficient and per
/// interference increment at most.
pub(super) const MAX_GROUPS: usize = 12;

/// Where a run-time table's value goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Target {
    /// A static coefficient: 0 CA, 1 CY, 2 CZ, 3 Cl, 4 Cm, 5 Cn.
    Static(usize),
    /// An interference increment: 0 dCX, ..., 5 dCn (times its multiplier).
    Interference(usize),
}

impl Target {
    /// Its place in the output of [`PreparedTables::evaluate`].
    fn slot(self) -> usize {
        match self {
            Target::Static(k) => k,
            Target::Interference(k) => 6 + k,
        }
    }
}

/// What a scenario's table spans, for reports.
#[derive(Debug, Clone, PartialEq)]
pub struct TableInfo {
    /// The scenario field, e.g. `aero.cz`.
    pub name: String,
    /// Each axis and its breakpoint range (first, last), in the variable's unit.
    pub axes: Vec<(Variable, f64, f64)>,
}

/// One axis of a run-time group: breakpoints in the force evaluation's units (angles in rad).
#[derive(Debug, Clone)]
struct RuntimeAxis {
    variable: Variable,
    /// Index of its input in [`PreparedTables::evaluate`]'s `inputs`.
    input: usize,
    breakpoints: Vec<f64>,
    /// Excursions are reported in the variable's unit: degrees per radian for angles.
    report_scale: f64,
}

/// Run-time tables of one block (static coefficients or interference increments) sharing their
/// axes: each grid point holds the block's six lanes (CA, CY, CZ, Cl, Cm, Cn or dCX, ..., dCn;
/// 0 in a lane no table of the group fills), so that one interval search and one set of
/// weights serve them all and the six lanes are interpolated together.
#[derive(Debug, Clone)]
struct Group {
    axes: Vec<RuntimeAxis>,
    /// Values of one grid point (6) times the sizes of the faster axes.
    strides: [usize; 3],
    /// 0 for the static coefficients, 6 for the interference increments.
    block: usize,
    /// The tables (indices into `info`) of the group.
    ids: Vec<usize>,
    values: Vec<f64>,
    /// Per grid cell, the multilinear interpolant as a polynomial in the inputs, 2^k
    /// coefficient lanes (bit j of a coefficient's index: times x_j) of six values each.
    cells: Vec<f64>,
    /// Doubles of one cell times the cell counts of the faster axes.
    cell_strides: [usize; 3],
}

impl Group {
    /// The group's six lanes at `inputs` (held at the edges; `outside` set when held).
    #[inline(always)]
    fn interpolate(
        &self,
        cursors: &[Cell<u32>; 3],
        inputs: &Inputs,
        outside: &mut bool,
    ) -> [f64; 6] {
        let c = &self.cells;
        // The cell's polynomial, nested: (c0 + c1 x) + y (c2 + c3 x), and so on, one arm per
        // axis count (unrolled). Helper functions, not closures, do the arithmetic: a closure
        // is not always inlined into the FMA-compiled propagator.
        match self.axes.len() {
            0 => *lanes(c, 0),
            1 => {
                let (at, x) = self.axis(0, cursors, inputs, outside);
                lin(x, lanes(c, at), lanes(c, at + 6))
            }
            2 => {
                let (a0, x) = self.axis(0, cursors, inputs, outside);
                let (a1, y) = self.axis(1, cursors, inputs, outside);
                bilinear(c, a0 + a1, x, y)
            }
            _ => {
                let (a0, x) = self.axis(0, cursors, inputs, outside);
                let (a1, y) = self.axis(1, cursors, inputs, outside);
                let (a2, z) = self.axis(2, cursors, inputs, outside);
                let at = a0 + a1 + a2;
                lin(z, &bilinear(c, at, x, y), &bilinear(c, at + 24, x, y))
            }
        }
    }

    /// Axis `k` at `inputs`: the offset of its interval's cells and its input held at the
    /// edges (`outside` set when held).
    #[inline(always)]
    fn axis(
        &self,
        k: usize,
        cursors: &[Cell<u32>; 3],
        inputs: &Inputs,
        outside: &mut bool,
    ) -> (usize, f64) {
        let a = &self.axes[k];
        let (i, x, out) = locate(a, pick(a.input, inputs), &cursors[k]);
        *outside |= out;
        (i * self.cell_strides[k], x)
    }

    /// Expands the grid values into each cell's polynomial (docs/model.md section 3): on
    /// [x0, x1] the linear interpolant is v0 (x1 - x)/dx + v1 (x - x0)/dx, and the
    /// multilinear one the product of such factors summed over the cell's 2^k corners; its
    /// monomial coefficients make an evaluation two fused multiply-adds deep per axis less than
    /// weights and differences would (the value is the same to rounding).
    fn build_cells(&mut self) {
        let k = self.axes.len();
        let intervals: Vec<usize> = self.axes.iter().map(|a| a.breakpoints.len() - 1).collect();
        let per_cell = 6 << k;
        let mut stride = per_cell;
        for j in (0..k).rev() {
            self.cell_strides[j] = stride;
            stride *= intervals[j];
        }
        let cells: usize = intervals.iter().product();
        self.cells = vec![0.0; cells * per_cell];
        for cell in 0..cells {
            let mut idx = [0usize; 3];
            let mut rem = cell;
            for j in (0..k).rev() {
                idx[j] = rem % intervals[j];
                rem /= intervals[j];
            }
            for corner in 0..(1usize << k) {
                let point: usize = (0..k)
                    .map(|j| (idx[j] + ((corner >> j) & 1)) * self.strides[j])
                    .sum();
                for mask in 0..(1usize << k) {
                    let mut factor = 1.0;
                    for (j, a) in self.axes.iter().enumerate() {
                        let (x0, x1) = (a.breakpoints[idx[j]], a.breakpoints[idx[j] + 1]);
                        let dx = x1 - x0;
                        let upper = (corner >> j) & 1 == 1;
                        factor *= match ((mask >> j) & 1 == 1, upper) {
                            (true, false) => -1.0 / dx,
                            (true, true) => 1.0 / dx,
                            (false, false) => x1 / dx,
                            (false, true) => -x0 / dx,
                        };
                    }
                    let at = cell * per_cell + mask * 6;
                    for c in 0..6 {
                        self.cells[at + c] += factor * self.values[point + c];
                    }
                }
            }
        }
    }
}

/// The tables of one scenario at its flight Mach, ready for the force evaluation.
#[derive(Debug, Clone, Default)]
pub struct PreparedTables {
    /// Every table of the scenario, in report order.
    pub info: Vec<TableInfo>,
    /// Each table's excursion beyond its Mach axis (0 inside, or without one).
    mach_excursion: Vec<f64>,
    /// The static coefficients' groups first, then the interference increments'.
    groups: Vec<Group>,
    /// How many groups are of static coefficients.
    static_groups: usize,
    /// Constant static coefficients (CY, CZ, Cl, Cm, Cn given as numbers; CA is never here).
    constants: [f64; 6],
    /// Whether the force evaluation has anything to add (groups, or a constant not 0).
    runtime: bool,
}

impl PreparedTables {
    /// No tables.
    pub const NONE: PreparedTables = PreparedTables {
        info: Vec::new(),
        mach_excursion: Vec::new(),
        groups: Vec::new(),
        static_groups: 0,
        constants: [0.0; 6],
        runtime: false,
    };

    /// Whether the scenario has any table.
    #[inline(always)]
    pub fn any(&self) -> bool {
        !self.info.is_empty()
    }

    /// Whether force evaluations must see the tables: to interpolate them, or to count the
    /// evaluations of a run whose Mach lies outside a Mach axis. A scenario whose only tables
    /// are Mach tables containing its Mach (folded into constants) runs the contract's path.
    #[inline(always)]
    pub fn in_evaluation(&self) -> bool {
        self.runtime || self.mach_excursion.iter().any(|&e| e > 0.0)
    }

    /// Whether the force evaluation has tables to interpolate.
    #[inline(always)]
    pub fn runtime(&self) -> bool {
        self.runtime
    }

    /// Registers a table (name for reports) and interpolates its Mach axis at `mach`: the
    /// table over its other axes (or a 0-axis table: one value).
    pub fn slice_mach(
        &mut self,
        name: &str,
        table: &Table,
        mach: f64,
    ) -> (usize, Vec<Axis>, Vec<f64>) {
        let id = self.info.len();
        self.info.push(TableInfo {
            name: name.to_string(),
            axes: table
                .axes
                .iter()
                .map(|a| {
                    (
                        a.variable,
                        a.breakpoints[0],
                        a.breakpoints[a.breakpoints.len() - 1],
                    )
                })
                .collect(),
        });
        let first = &table.axes[0];
        if first.variable != Variable::Mach {
            self.mach_excursion.push(0.0);
            return (id, table.axes.clone(), table.values.clone());
        }
        let b = &first.breakpoints;
        let (i, t, excursion) = locate_cold(b, mach);
        self.mach_excursion.push(excursion.abs());
        let inner: usize = table.values.len() / b.len();
        let lo = &table.values[i * inner..(i + 1) * inner];
        let hi = &table.values[(i + 1) * inner..(i + 2) * inner];
        let values = lo
            .iter()
            .zip(hi)
            .map(|(&v0, &v1)| t.mul_add(v1 - v0, v0))
            .collect();
        (id, table.axes[1..].to_vec(), values)
    }

    /// Sets static coefficient `k` (CY, CZ, Cl, Cm, Cn as 1..=5) to the constant `v`, added at
    /// every force evaluation (only when it is not 0).
    pub fn add_constant(&mut self, k: usize, v: f64) {
        self.constants[k] = v;
        self.runtime |= v != 0.0;
    }

    /// Adds a table (already sliced at the Mach, registered as `id`) for the force evaluation:
    /// a channel of the group with the same axes, or a new group.
    pub fn add_runtime(&mut self, id: usize, target: Target, axes: Vec<Axis>, values: Vec<f64>) {
        let runtime: Vec<RuntimeAxis> = axes
            .iter()
            .map(|a| {
                let (breakpoints, report_scale): (Vec<f64>, f64) = match a.variable {
                    Variable::Alpha | Variable::Beta => (
                        a.breakpoints.iter().map(|d| d.to_radians()).collect(),
                        1.0f64.to_degrees(),
                    ),
                    _ => (a.breakpoints.clone(), 1.0),
                };
                RuntimeAxis {
                    variable: a.variable,
                    input: match a.variable {
                        Variable::Alpha => 0,
                        Variable::Beta => 1,
                        Variable::Distance => 2,
                        // Mach never reaches the run time (sliced above), nor a flowfield's
                        // position (its tables are not the coefficients'; model::flowfield).
                        Variable::Lateral
                        | Variable::Mach
                        | Variable::X
                        | Variable::Y
                        | Variable::Z => 3,
                    },
                    breakpoints,
                    report_scale,
                }
            })
            .collect();
        let sizes: Vec<usize> = axes.iter().map(|a| a.breakpoints.len()).collect();
        let slot = target.slot();
        let (block, lane) = (slot / 6 * 6, slot % 6);
        let same = |g: &Group| {
            g.block == block
                && g.axes.len() == runtime.len()
                && g.axes
                    .iter()
                    .zip(&runtime)
                    .all(|(a, b)| a.variable == b.variable && a.breakpoints == b.breakpoints)
        };
        let g = match self.groups.iter().position(same) {
            Some(k) => &mut self.groups[k],
            None => {
                assert!(
                    self.groups.len() < MAX_GROUPS,
                    "at most {MAX_GROUPS} run-time groups"
                );
                // Static groups before interference groups.
                let at = if block == 0 {
                    self.static_groups += 1;
                    self.static_groups - 1
                } else {
                    self.groups.len()
                };
                self.groups.insert(
                    at,
                    Group {
                        axes: runtime,
                        strides: strides(&sizes, 6),
                        block,
                        ids: Vec::new(),
                        values: vec![0.0; 6 * values.len()],
                        cells: Vec::new(),
                        cell_strides: [0; 3],
                    },
                );
                &mut self.groups[at]
            }
        };
        self.runtime = true;
        g.ids.push(id);
        for (p, v) in values.iter().enumerate() {
            // Two tables of one coefficient in one group add (a static table and a constant
            // never meet here; the scenario has one field per coefficient).
            g.values[6 * p + lane] += v;
        }
        g.build_cells();
    }

    /// The tables' contributions at the inputs of one force evaluation: static coefficients
    /// (CA, CY, CZ, Cl, Cm, Cn) and interference increments (before their multipliers), without
    /// the constant static coefficients ([`PreparedTables::constants`]).
    #[inline(always)]
    pub fn evaluate(&self, state: &TableState, inputs: &Inputs) -> ([f64; 6], [f64; 6]) {
        let mut statics = [0.0; 6];
        let mut increments = [0.0; 6];
        let mut outside = false;
        for (g, cursors) in self.groups.iter().zip(&state.cursor) {
            let r = g.interpolate(cursors, inputs, &mut outside);
            let sum = if g.block == 0 {
                &mut statics
            } else {
                &mut increments
            };
            for c in 0..6 {
                sum[c] += r[c];
            }
        }
        if outside {
            self.record_outside(state, inputs);
        }
        (statics, increments)
    }

    /// The constant static coefficients (CY, CZ, Cl, Cm, Cn given as numbers next to tables).
    #[inline(always)]
    pub fn constants(&self) -> &[f64; 6] {
        &self.constants
    }

    /// Counts, per table, an evaluation outside it and its worst excursion per variable.
    #[cold]
    #[inline(never)]
    fn record_outside(&self, state: &TableState, inputs: &Inputs) {
        for g in &self.groups {
            let mut out = false;
            for a in &g.axes {
                let x = pick(a.input, inputs);
                let b = &a.breakpoints;
                let e = (b[0] - x).max(x - b[b.len() - 1]);
                if e > 0.0 {
                    out = true;
                    let e = e * a.report_scale;
                    for &id in &g.ids {
                        let w = &state.worst[id][a.variable.index()];
                        w.set(w.get().max(e));
                    }
                }
            }
            if out {
                for &id in &g.ids {
                    state.count[id].set(state.count[id].get() + 1);
                }
            }
        }
    }

    /// The excursions of a run, per table (tables never left are omitted).
    pub fn report(&self, ex: &TableExcursions) -> Vec<TableExcursion> {
        let mut out = Vec::new();
        for (id, info) in self.info.iter().enumerate() {
            let mach = self.mach_excursion[id];
            let count = if mach > 0.0 {
                ex.evaluations
            } else {
                ex.count[id]
            };
            if count == 0 {
                continue;
            }
            let axes = info
                .axes
                .iter()
                .filter_map(|&(v, lo, hi)| {
                    let worst = if v == Variable::Mach {
                        mach
                    } else {
                        ex.worst[id][v.index()]
                    };
                    (worst > 0.0).then_some(AxisExcursion {
                        variable: v.key().to_string(),
                        range: [lo, hi],
                        worst_excursion: worst,
                    })
                })
                .collect();
            out.push(TableExcursion {
                table: info.name.clone(),
                evaluations_outside: count,
                evaluations: ex.evaluations,
                axes,
                at_samples: false,
            });
        }
        out
    }
}

fn strides(sizes: &[usize], channels: usize) -> [usize; 3] {
    let mut s = [0usize; 3];
    let mut acc = channels;
    for k in (0..sizes.len()).rev() {
        s[k] = acc;
        acc *= sizes[k];
    }
    s
}

/// The interval of `x` among breakpoints `b` (index i of [b_i, b_{i+1}]), the weight t in [0, 1]
/// and the signed excursion beyond the table (0 inside), for a one-off lookup.
fn locate_cold(b: &[f64], x: f64) -> (usize, f64, f64) {
    let n = b.len();
    if x <= b[0] {
        return (0, 0.0, x - b[0]);
    }
    if x >= b[n - 1] {
        return (n - 2, 1.0, x - b[n - 1]);
    }
    let i = b.partition_point(|&bp| bp <= x) - 1;
    (i, (x - b[i]) / (b[i + 1] - b[i]), 0.0)
}

/// [`locate_cold`] hunting from the previous interval (`cursor`): the interval, `x` held at
/// the table's edges, and whether it was outside. A NaN input stays NaN (the run then
/// diverges).
#[inline(always)]
fn locate(a: &RuntimeAxis, x: f64, cursor: &Cell<u32>) -> (usize, f64, bool) {
    let b = &a.breakpoints;
    let n = b.len();
    if x < b[0] {
        return (0, b[0], true);
    }
    if x > b[n - 1] {
        return (n - 2, b[n - 1], true);
    }
    let mut i = cursor.get() as usize;
    while i > 0 && x < b[i] {
        i -= 1;
    }
    while i + 2 < n && x > b[i + 1] {
        i += 1;
    }
    cursor.set(i as u32);
    (i, x, false)
}

/// Six lanes of `c` from `at`.
#[inline(always)]
fn lanes(c: &[f64], at: usize) -> &[f64; 6] {
    c[at..at + 6].try_into().expect("six lanes")
}

/// a + x b, lane by lane.
#[inline(always)]
fn lin(x: f64, a: &[f64; 6], b: &[f64; 6]) -> [f64; 6] {
    [
        x.mul_add(b[0], a[0]),
        x.mul_add(b[1], a[1]),
        x.mul_add(b[2], a[2]),
        x.mul_add(b[3], a[3]),
        x.mul_add(b[4], a[4]),
        x.mul_add(b[5], a[5]),
    ]
}

/// The input of an axis (`input` as [`RuntimeAxis::input`]), chosen among scalars: an array
/// indexed at run time would go through memory, and its assembly from four scalar stores into
/// one vector load stalls store forwarding at every force evaluation.
#[inline(always)]
fn pick(input: usize, inputs: &Inputs) -> f64 {
    match input {
        0 => inputs.alpha_rad,
        1 => inputs.beta_rad,
        2 => inputs.distance_m,
        _ => inputs.lateral_m,
    }
}

/// What the run-time tables are looked up at.
#[derive(Debug, Clone, Copy)]
pub struct Inputs {
    /// Local angle of attack \[rad\].
    pub alpha_rad: f64,
    /// Local sideslip \[rad\].
    pub beta_rad: f64,
    /// Distance of the CG from carriage \[m\].
    pub distance_m: f64,
    /// Lateral offset of the CG from carriage (launch-frame y) \[m\].
    pub lateral_m: f64,
}

/// (c0 + c1 x) + y (c2 + c3 x) with the four coefficient lanes from `at`.
#[inline(always)]
fn bilinear(c: &[f64], at: usize, x: f64, y: f64) -> [f64; 6] {
    let p = lin(x, lanes(c, at), lanes(c, at + 6));
    let q = lin(x, lanes(c, at + 12), lanes(c, at + 18));
    lin(y, &p, &q)
}
