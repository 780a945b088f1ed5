//! Table CSV files (docs/model.md section 1, "Tables"): a header naming each column and its
//! unit, one row per grid point; the reader refuses a bad file with its line and column.

use super::error::could_be_header;
use super::*;

/// Splits a CSV line into trimmed fields (double quotes around a whole field are removed).
fn fields(line: &str) -> Vec<String> {
    line.split(',')
        .map(|f| {
            let f = f.trim();
            f.strip_prefix('"')
                .and_then(|g| g.strip_suffix('"'))
                .unwrap_or(f)
                .trim()
                .to_string()
        })
        .collect()
}

/// One column of a table file.
enum Column {
    Axis(Variable, Conversion),
    Value(String, Conversion),
}

/// The header row of a table file: its line, its field names, and what each column is.
struct Header {
    file: String,
    line: usize,
    names: Vec<String>,
    columns: Vec<Column>,
}

/// The rows of a table file: (line, the fields converted to the scenario's units).
type Rows = Vec<(usize, Vec<f64>)>;

/// Reads the table of `kind` in a CSV file: a header row `name [unit]` per column, the axis
/// columns first (in nesting order), then one or more value columns, then one row per grid
/// point in row-major order (first axis slowest). `column` picks the value column (needed when
/// there are several). Lines starting with `#` and blank lines are skipped. Only a regular file
/// of at most [`MAX_TABLE_CSV_BYTES`](sepval_core::limits::MAX_TABLE_CSV_BYTES) is read.
pub fn read_csv(path: &Path, column: Option<&str>, kind: Kind) -> Result<Table, TableError> {
    let file = path.display().to_string();
    let text = sepval_core::input_file::read_string(
        path,
        "table",
        sepval_core::limits::MAX_TABLE_CSV_BYTES,
    )
    .map_err(|e| match e.into_io() {
        Ok(io) => TableError::Io {
            file: file.clone(),
            message: io.to_string(),
        },
        Err(refused) => TableError::Input(Box::new(refused)),
    })?;
    let mut lines = text
        .trim_start_matches('\u{feff}')
        .lines()
        .enumerate()
        .map(|(k, l)| (k + 1, l))
        .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'));
    let Some((header_line, header)) = lines.next() else {
        return Err(TableError::Empty { file });
    };
    let header = Header::parse(file, header_line, header, kind)?;
    let chosen = header.chosen(column, kind)?;
    let rows = header.rows(lines)?;
    header.table(&rows, chosen, kind)
}

impl Header {
    /// Reads the header row: every field a column `name [unit]` the kind allows, axes first in
    /// nesting order.
    fn parse(file: String, line: usize, text: &str, kind: Kind) -> Result<Header, TableError> {
        let names = fields(text);
        if let Some(k) = names.iter().position(|h| !could_be_header(h)) {
            return Err(TableError::NotAHeader {
                file,
                line,
                column: k + 1,
            });
        }
        let mut header = Header {
            file,
            line,
            names,
            columns: Vec::new(),
        };
        for k in 0..header.names.len() {
            let c = header.column(k, kind)?;
            header.columns.push(c);
        }
        header.check_axes(kind)?;
        Ok(header)
    }

    /// Column `k` (0-based), given the columns before it.
    fn column(&self, k: usize, kind: Kind) -> Result<Column, TableError> {
        let (file, line, h) = (&self.file, self.line, &self.names[k]);
        let at = |reason: String| TableError::Header {
            file: file.clone(),
            line,
            column: k + 1,
            header: h.clone(),
            reason,
        };
        let (name, unit) = match h.find('[') {
            Some(open) if h.ends_with(']') => (h[..open].trim(), h[open + 1..h.len() - 1].trim()),
            _ => {
                let variable = Variable::ALL.iter().find(|v| v.csv_name() == h);
                return Err(TableError::MissingUnit {
                    file: file.clone(),
                    line,
                    column: k + 1,
                    header: h.clone(),
                    example: variable
                        .map(|v| v.csv_units()[0].0)
                        .unwrap_or(kind.value_units()[0].0)
                        .to_string(),
                });
            }
        };
        let conversion = |accepted: &[(&str, Conversion)]| {
            accepted
                .iter()
                .find(|(u, _)| *u == unit)
                .map(|(_, c)| *c)
                .ok_or_else(|| self.unknown_unit(k, name, accepted))
        };
        let columns = &self.columns;
        if let Some(v) = Variable::ALL.iter().find(|v| v.csv_name() == name) {
            if !kind.allowed().contains(v) {
                return Err(at(format!(
                    "{} may be tabulated over {} only, not over {name}",
                    kind.what(),
                    kind.allowed_list(", ")
                )));
            }
            let conv = conversion(v.csv_units())?;
            if columns.iter().any(|c| matches!(c, Column::Value(..))) {
                return Err(at("axis columns come before the value columns".into()));
            }
            let rank = |v: &Variable| kind.allowed().iter().position(|w| w == v);
            if let Some(Column::Axis(p, _)) = columns.last()
                && rank(p) >= rank(v)
            {
                return Err(at(format!(
                    "axis columns must come in the order {} (first axis slowest)",
                    kind.allowed_list(", ")
                )));
            }
            return Ok(Column::Axis(*v, conv));
        }
        if name.is_empty() {
            return Err(at("a column needs a name".into()));
        }
        let conv = match conversion(kind.value_units()) {
            Ok(c) => c,
            Err(_) if kind.sibling_units().contains(&unit) => Conversion::Foreign,
            Err(e) => return Err(e),
        };
        if columns
            .iter()
            .any(|c| matches!(c, Column::Value(n, _) if n == name))
        {
            return Err(at(format!("repeats the column `{name}`")));
        }
        Ok(Column::Value(name.to_string(), conv))
    }

    /// An error about the header at `column` (1-based).
    fn error(&self, column: usize, reason: String) -> TableError {
        TableError::Header {
            file: self.file.clone(),
            line: self.line,
            column,
            header: self
                .names
                .get(column.saturating_sub(1))
                .cloned()
                .unwrap_or_default(),
            reason,
        }
    }

    fn n_axes(&self) -> usize {
        self.columns
            .iter()
            .filter(|c| matches!(c, Column::Axis(..)))
            .count()
    }

    fn value_names(&self) -> Vec<&str> {
        self.columns
            .iter()
            .filter_map(|c| match c {
                Column::Value(n, _) => Some(n.as_str()),
                _ => None,
            })
            .collect()
    }

    /// At least one axis, and the one every table of the kind needs.
    fn check_axes(&self, kind: Kind) -> Result<(), TableError> {
        if self.n_axes() == 0 {
            return Err(self.error(
                1,
                format!(
                    "no axis column: {} is tabulated over {}",
                    kind.what(),
                    kind.allowed_list(", ")
                ),
            ));
        }
        if let Some(r) = kind.required()
            && !self
                .columns
                .iter()
                .any(|c| matches!(c, Column::Axis(v, _) if *v == r))
        {
            return Err(self.error(
                1,
                format!("no {} column: {} needs one", r.csv_name(), kind.what()),
            ));
        }
        Ok(())
    }

    /// The index of the value column used: `want`, or the only one; in a unit of the kind.
    fn chosen(&self, want: Option<&str>, kind: Kind) -> Result<usize, TableError> {
        let k = self.chosen_column(want)?;
        if let Column::Value(name, Conversion::Foreign) = &self.columns[k] {
            return Err(self.unknown_unit(k, name, kind.value_units()));
        }
        Ok(k)
    }

    /// Column `k` (0-based), named `name`, is in none of the units `accepted`.
    fn unknown_unit(&self, k: usize, name: &str, accepted: &[(&str, Conversion)]) -> TableError {
        TableError::UnknownUnit {
            file: self.file.clone(),
            line: self.line,
            column: k + 1,
            header: self.names[k].clone(),
            expected: accepted
                .iter()
                .map(|(u, _)| format!("`{name} [{u}]`"))
                .collect::<Vec<_>>()
                .join(" or "),
        }
    }

    fn chosen_column(&self, want: Option<&str>) -> Result<usize, TableError> {
        let (n_axes, value_names) = (self.n_axes(), self.value_names());
        match want {
            Some(want) => self
                .columns
                .iter()
                .position(|c| matches!(c, Column::Value(n, _) if n == want))
                .ok_or_else(|| {
                    self.error(
                        n_axes + 1,
                        format!(
                            "no value column `{want}` (the file has: {})",
                            value_names.join(", ")
                        ),
                    )
                }),
            None if value_names.len() == 1 => Ok(n_axes),
            None => Err(self.error(
                n_axes + 1,
                format!(
                    "{} value columns ({}): name one with `column = \"...\"` in the scenario",
                    value_names.len(),
                    value_names.join(", ")
                ),
            )),
        }
    }

    /// The rows: every field a finite number, converted to the scenario's units.
    fn rows<'t>(&self, lines: impl Iterator<Item = (usize, &'t str)>) -> Result<Rows, TableError> {
        let file = || self.file.clone();
        let mut rows: Rows = Vec::new();
        for (line, text) in lines {
            let f = fields(text);
            if f.len() != self.columns.len() {
                return Err(TableError::Ragged {
                    file: file(),
                    line,
                    expected: self.columns.len(),
                    found: f.len(),
                });
            }
            let mut row = Vec::with_capacity(f.len());
            for (k, (s, c)) in f.iter().zip(&self.columns).enumerate() {
                let v: f64 = match s.parse::<f64>() {
                    Ok(v) if v.is_finite() => v,
                    _ => {
                        return Err(TableError::NotFinite {
                            file: file(),
                            line,
                            column: k + 1,
                            header: self.names[k].clone(),
                            value: s.clone(),
                        });
                    }
                };
                let conv = match c {
                    Column::Axis(_, conv) | Column::Value(_, conv) => *conv,
                };
                row.push(conv.apply(v));
            }
            if rows.len() >= MAX_TABLE_VALUES {
                return Err(TableError::Grid {
                    file: file(),
                    line,
                    column: 1,
                    header: self.names[0].clone(),
                    reason: format!("more rows than the limit of {MAX_TABLE_VALUES} grid points"),
                });
            }
            rows.push((line, row));
        }
        if rows.is_empty() {
            return Err(self.error(1, "no rows after the header".into()));
        }
        Ok(rows)
    }

    /// An error about row `r`, column `j` (0-based) of the grid.
    fn grid_error(&self, rows: &Rows, r: usize, j: usize, reason: String) -> TableError {
        TableError::Grid {
            file: self.file.clone(),
            line: rows[r].0,
            column: j + 1,
            header: self.names[j].clone(),
            reason,
        }
    }

    /// The breakpoints of each axis: axis j's are its values at rows 0, stride_j, 2 stride_j,
    /// ... while the slower axes keep row 0's values (stride_j: the product of the faster axes'
    /// sizes, found from the last axis backwards).
    fn breakpoints(&self, rows: &Rows) -> Result<Vec<Vec<f64>>, TableError> {
        let n_axes = self.n_axes();
        let mut breakpoints: Vec<Vec<f64>> = vec![Vec::new(); n_axes];
        let mut stride = 1usize;
        for j in (0..n_axes).rev() {
            let mut r = 0;
            while r < rows.len() && (0..j).all(|i| rows[r].1[i].to_bits() == rows[0].1[i].to_bits())
            {
                let x = rows[r].1[j];
                if let Some(&prev) = breakpoints[j].last()
                    && x <= prev
                {
                    return Err(self.grid_error(
                        rows,
                        r,
                        j,
                        format!(
                            "breakpoints are not strictly increasing: {x} after {prev} (rows are in row-major order, the first axis slowest)"
                        ),
                    ));
                }
                breakpoints[j].push(x);
                r += stride;
            }
            if breakpoints[j].len() < 2 {
                if let Some(e) = self.out_of_order(rows, j, r) {
                    return Err(e);
                }
                return Err(self.grid_error(
                    rows,
                    0,
                    j,
                    format!(
                        "axis {} has 1 breakpoint: expected at least 2 (give a constant instead of a table)",
                        self.names[j]
                    ),
                ));
            }
            stride *= breakpoints[j].len();
        }
        Ok(breakpoints)
    }

    /// Rows out of row-major order, when axis `j` seemed to have one breakpoint but takes
    /// another value in a later row: the row `r` where a slower axis changed too early (or the
    /// first row with another value of axis `j`) named, rather than "1 breakpoint".
    fn out_of_order(&self, rows: &Rows, j: usize, r: usize) -> Option<TableError> {
        let first = rows[0].1[j].to_bits();
        let other = rows.iter().position(|(_, v)| v[j].to_bits() != first)?;
        let (at, i) = match (0..j)
            .find(|&i| r < rows.len() && rows[r].1[i].to_bits() != rows[0].1[i].to_bits())
        {
            Some(i) => (r, i),
            None => (other, j),
        };
        Some(self.grid_error(
            rows,
            at,
            i,
            format!(
                "the rows are out of order: {} changes here before {} has gone through its breakpoints (rows list every grid point in row-major order, the first axis slowest, the last fastest): sort them so",
                self.names[i], self.names[j]
            ),
        ))
    }

    /// The table: the grid complete and in row-major order, the chosen column's values.
    fn table(&self, rows: &Rows, chosen: usize, kind: Kind) -> Result<Table, TableError> {
        let n_axes = self.n_axes();
        let breakpoints = self.breakpoints(rows)?;
        let sizes: Vec<usize> = breakpoints.iter().map(Vec::len).collect();
        let points: usize = sizes.iter().product();
        if rows.len() != points {
            let last = rows.len().min(points) - 1;
            return Err(self.grid_error(
                rows,
                last,
                0,
                format!(
                    "the rows do not form a complete grid: {} rows for {} breakpoints ({points} rows expected)",
                    rows.len(),
                    sizes
                        .iter()
                        .map(|s| s.to_string())
                        .collect::<Vec<_>>()
                        .join(" x ")
                ),
            ));
        }
        let mut values = Vec::with_capacity(rows.len());
        for (r, (_, row)) in rows.iter().enumerate() {
            let mut rem = r;
            for j in (0..n_axes).rev() {
                let expected = breakpoints[j][rem % sizes[j]];
                rem /= sizes[j];
                if row[j].to_bits() != expected.to_bits() {
                    return Err(self.grid_error(
                        rows,
                        r,
                        j,
                        format!(
                            "expected {expected} here: rows list every grid point in row-major order (the first axis slowest)"
                        ),
                    ));
                }
            }
            values.push(row[chosen]);
        }
        let axes = self
            .columns
            .iter()
            .zip(breakpoints)
            .filter_map(|(c, breakpoints)| match c {
                Column::Axis(variable, _) => Some(Axis {
                    variable: *variable,
                    breakpoints,
                }),
                Column::Value(..) => None,
            })
            .collect();
        Table::new(axes, values, kind).map_err(|reason| self.error(1, reason.to_string()))
    }
}

/// Writes a table as CSV (header `name [unit]`, one row per grid point, numbers in the shortest
/// form that reads back as the same double): one or more value columns on one grid.
pub fn write_csv(axes: &[Axis], columns: &[(&str, &str, &[f64])]) -> String {
    use std::fmt::Write as _;
    let mut s = String::new();
    let head: Vec<String> = axes
        .iter()
        .map(|a| format!("{} [{}]", a.variable.csv_name(), a.variable.unit()))
        .chain(columns.iter().map(|(n, u, _)| format!("{n} [{u}]")))
        .collect();
    s.push_str(&head.join(","));
    s.push('\n');
    let sizes: Vec<usize> = axes.iter().map(|a| a.breakpoints.len()).collect();
    let n: usize = sizes.iter().product();
    for r in 0..n {
        let mut rem = r;
        let mut idx = vec![0; axes.len()];
        for j in (0..axes.len()).rev() {
            idx[j] = rem % sizes[j];
            rem /= sizes[j];
        }
        let fields: Vec<String> = axes
            .iter()
            .zip(&idx)
            .map(|(a, &i)| format!("{:?}", a.breakpoints[i]))
            .chain(columns.iter().map(|(_, _, v)| format!("{:?}", v[r])))
            .collect();
        let _ = writeln!(s, "{}", fields.join(","));
    }
    s
}
