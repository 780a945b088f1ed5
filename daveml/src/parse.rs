//! Stage 1, **parse**: the DAVE-ML text read into plain data ([`Parsed`]), each item with the
//! line of its element, so that every later refusal names line and element.
//!
//! Source: DAVE-ML 2.0 (the reference manual of the DAVE-ML 2.0 release, and ANSI/AIAA
//! S-119-2011, sections 5.1 to 5.6 and 5.8): `DAVEfunc` holds `fileHeader`, `variableDef`s
//! (`varID`, `name`, `units`, optional `initialValue`, `calculation` and `uncertainty`,
//! `minValue`, `maxValue`), `breakpointDef`s (`bpID`, `units`, `bpVals`: comma or white-space separated),
//! `griddedTableDef`s (`gtID`, `breakpointRefs`/`bpRef`, optional `uncertainty`, `dataTable`
//! with the last breakpoint set changing fastest), `function`s (`independentVarRef`s with
//! `varID`, `min`, `max`, `extrapolate` and `interpolate`, a `dependentVarRef`, a
//! `functionDefn` holding a `griddedTableRef` or a `griddedTableDef`) and `checkData`
//! (`staticShot`s of `checkInputs` and `checkOutputs` `signal`s: `signalName` or `varID`,
//! `signalUnits`, `signalValue`, `tol`). Elements sepval does not use (`provenance`,
//! `description`, `reference`, ...) are skipped; elements it cannot represent are kept as
//! [`TableDefn::Simple`] or [`TableDefn::Unsupported`] so the map stage can refuse them where
//! they matter.

use roxmltree::{Document, Node, ParsingOptions};

use crate::error::{DavemlError, Place};

/// An item with the line of its element.
#[derive(Debug, Clone, PartialEq)]
pub struct Located<T> {
    /// Where it is.
    pub place: Place,
    /// The item.
    pub item: T,
}

/// What a PDF in an `uncertainty` is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PdfKind {
    /// `normalPDF`.
    Normal,
    /// `uniformPDF`.
    Uniform,
}

/// An `uncertainty` (DAVE-ML 2.0 section 5.7): its PDF, its `numSigmas` and the numbers of its
/// `bounds`, kept so that a reader of the store's uncertainty (`sepval campaign init
/// --prior-daveml`) has them; before 2026-12-02 only the PDF's kind was kept.
#[derive(Debug, Clone, PartialEq)]
pub struct Pdf {
    /// `normalPDF` or `uniformPDF`.
    pub kind: PdfKind,
    /// A `normalPDF`'s `numSigmas`: its bounds are that many standard deviations.
    pub num_sigmas: Option<f64>,
    /// The numbers of its `bounds` (their `dataTable`'s, or their text): one, or one per value
    /// of its table; empty when given otherwise (a `variableRef`).
    pub bounds: Vec<f64>,
    /// Where the PDF is.
    pub place: Place,
}

/// A `variableDef`.
#[derive(Debug, Clone, PartialEq)]
pub struct VariableDef {
    /// `varID`.
    pub var_id: String,
    /// `name`.
    pub name: String,
    /// `units`.
    pub units: String,
    /// `initialValue`.
    pub initial_value: Option<f64>,
    /// `minValue` and `maxValue`: limits (saturations) on the variable's value.
    pub limits: (Option<f64>, Option<f64>),
    /// The line of its `calculation`, if it has one.
    pub calculation: Option<Place>,
    /// Its `uncertainty`'s PDF, if it has one.
    pub uncertainty: Option<Pdf>,
}

/// A `breakpointDef`.
#[derive(Debug, Clone, PartialEq)]
pub struct BreakpointDef {
    /// `bpID`.
    pub bp_id: String,
    /// `units`, if given.
    pub units: Option<String>,
    /// `bpVals`.
    pub values: Vec<f64>,
}

/// A `griddedTableDef`.
#[derive(Debug, Clone, PartialEq)]
pub struct GriddedTable {
    /// `gtID` (absent for one defined inside a `functionDefn`).
    pub gt_id: Option<String>,
    /// The `bpRef`s' `bpID`s, first slowest.
    pub breakpoints: Vec<String>,
    /// `dataTable`, last breakpoint set fastest.
    pub data: Vec<f64>,
    /// Its `uncertainty`'s PDF, if it has one.
    pub uncertainty: Option<Pdf>,
}

/// An `independentVarRef`.
#[derive(Debug, Clone, PartialEq)]
pub struct InputRef {
    /// `varID`.
    pub var_id: String,
    /// `min`, if given.
    pub min: Option<f64>,
    /// `max`, if given.
    pub max: Option<f64>,
    /// `extrapolate` (`neither` when absent, the standard's default).
    pub extrapolate: String,
    /// `interpolate` (`linear` when absent, the standard's default).
    pub interpolate: String,
}

/// How a function's table is given.
#[derive(Debug, Clone, PartialEq)]
pub enum TableDefn {
    /// A `griddedTableRef` to a `griddedTableDef` by `gtID`.
    Ref {
        /// The `gtID`.
        gt_id: String,
    },
    /// A `griddedTableDef` inside the `functionDefn`.
    Inline(GriddedTable),
    /// A simple function (`independentVarPts`/`dependentVarPts`): refused when used.
    Simple,
    /// Another element (an ungridded table): refused when used.
    Unsupported {
        /// The element's tag name.
        tag: String,
    },
}

/// A `function`.
#[derive(Debug, Clone, PartialEq)]
pub struct Function {
    /// `name`.
    pub name: String,
    /// Its `independentVarRef`s, in the table's order (first slowest).
    pub inputs: Vec<Located<InputRef>>,
    /// Its `dependentVarRef`'s `varID`.
    pub output: Located<String>,
    /// Its table.
    pub table: Located<TableDefn>,
}

/// A `signal` of a check case.
#[derive(Debug, Clone, PartialEq)]
pub struct Signal {
    /// `signalName` or `varID`.
    pub name: String,
    /// `signalUnits`, if given.
    pub units: Option<String>,
    /// `signalValue`.
    pub value: f64,
    /// `tol`, if given.
    pub tol: Option<f64>,
}

/// A `staticShot`.
#[derive(Debug, Clone, PartialEq)]
pub struct CheckCase {
    /// `name`.
    pub name: String,
    /// Its `checkInputs`.
    pub inputs: Vec<Located<Signal>>,
    /// Its `checkOutputs`.
    pub outputs: Vec<Located<Signal>>,
}

/// A DAVE-ML file as plain data.
#[derive(Debug, Clone, PartialEq)]
pub struct Parsed {
    /// The file's name, for messages.
    pub file: String,
    /// Every `variableDef`.
    pub variables: Vec<Located<VariableDef>>,
    /// Every `breakpointDef`.
    pub breakpoints: Vec<Located<BreakpointDef>>,
    /// Every top-level `griddedTableDef`.
    pub tables: Vec<Located<GriddedTable>>,
    /// Every `function`.
    pub functions: Vec<Located<Function>>,
    /// Every `staticShot` of `checkData`.
    pub checks: Vec<Located<CheckCase>>,
}

/// Most XML nodes a file may have (elements, attributes' texts, ...): a table of the most
/// grid points sepval takes is one text node, so this bounds only a file of many small
/// elements.
const NODES_LIMIT: u32 = 4_000_000;

/// Parses DAVE-ML `text` (from `file`, for messages), after refusing any entity declaration
/// ([`crate::doctype`]).
pub fn parse(text: &str, file: &str) -> Result<Parsed, DavemlError> {
    crate::doctype::refuse_entities(text, file)?;
    let options = ParsingOptions {
        allow_dtd: true,
        nodes_limit: NODES_LIMIT,
        ..ParsingOptions::default()
    };
    let doc = Document::parse_with_options(text, options).map_err(|e| DavemlError::NotXml {
        file: file.to_string(),
        message: e.to_string(),
    })?;
    let r = Reader { doc: &doc, file };
    let root = doc.root_element();
    if root.tag_name().name() != "DAVEfunc" {
        return Err(DavemlError::at(
            &r.place(root),
            "the root element is not <DAVEfunc>: not a DAVE-ML model",
        ));
    }
    let mut p = Parsed {
        file: file.to_string(),
        variables: Vec::new(),
        breakpoints: Vec::new(),
        tables: Vec::new(),
        functions: Vec::new(),
        checks: Vec::new(),
    };
    for n in root.children().filter(Node::is_element) {
        match n.tag_name().name() {
            "variableDef" => p.variables.push(r.located(n, r.variable(n)?)),
            "breakpointDef" => p.breakpoints.push(r.located(n, r.breakpoint(n)?)),
            "griddedTableDef" => p.tables.push(r.located(n, r.table(n)?)),
            "function" => p.functions.push(r.located(n, r.function(n)?)),
            "checkData" => {
                for s in r.elements(n, "staticShot") {
                    p.checks.push(r.located(s, r.case(s)?));
                }
            }
            _ => {}
        }
    }
    Ok(p)
}

/// Reads elements of one document.
struct Reader<'a, 'input> {
    doc: &'a Document<'input>,
    file: &'a str,
}

impl<'a, 'input> Reader<'a, 'input> {
    fn place(&self, n: Node) -> Place {
        Place {
            file: self.file.to_string(),
            line: self.doc.text_pos_at(n.range().start).row,
            element: n.tag_name().name().to_string(),
        }
    }

    fn located<T>(&self, n: Node, item: T) -> Located<T> {
        Located {
            place: self.place(n),
            item,
        }
    }

    fn elements<'b>(
        &self,
        n: Node<'b, 'input>,
        name: &'static str,
    ) -> impl Iterator<Item = Node<'b, 'input>> + use<'b, 'input> {
        n.children()
            .filter(move |c| c.is_element() && c.tag_name().name() == name)
    }

    fn child<'b>(&self, n: Node<'b, 'input>, name: &'static str) -> Option<Node<'b, 'input>> {
        self.elements(n, name).next()
    }

    fn required<'b>(
        &self,
        n: Node<'b, 'input>,
        name: &'static str,
    ) -> Result<Node<'b, 'input>, DavemlError> {
        self.child(n, name)
            .ok_or_else(|| DavemlError::at(&self.place(n), format!("has no <{name}>")))
    }

    fn attr(&self, n: Node, name: &str) -> Result<String, DavemlError> {
        n.attribute(name)
            .map(str::to_string)
            .ok_or_else(|| DavemlError::at(&self.place(n), format!("has no `{name}` attribute")))
    }

    fn number(&self, n: Node, what: &str, text: &str) -> Result<f64, DavemlError> {
        let t = text.trim();
        match t.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err(DavemlError::at(
                &self.place(n),
                format!("{what} `{}` is not a finite number", short(t)),
            )),
        }
    }

    fn optional_number(&self, n: Node, name: &str) -> Result<Option<f64>, DavemlError> {
        n.attribute(name)
            .map(|t| self.number(n, &format!("`{name}`"), t))
            .transpose()
    }

    /// The numbers of an element's text, separated by commas and white space.
    fn numbers(&self, n: Node) -> Result<Vec<f64>, DavemlError> {
        let text = n.text().unwrap_or("");
        text.split(|c: char| c == ',' || c.is_whitespace())
            .filter(|t| !t.is_empty())
            .map(|t| self.number(n, "value", t))
            .collect()
    }

    fn pdf(&self, n: Node) -> Result<Option<Pdf>, DavemlError> {
        let Some(u) = self.child(n, "uncertainty") else {
            return Ok(None);
        };
        let (kind, at) = match (self.child(u, "uniformPDF"), self.child(u, "normalPDF")) {
            (Some(p), _) => (PdfKind::Uniform, p),
            (None, Some(p)) => (PdfKind::Normal, p),
            (None, None) => (PdfKind::Normal, u),
        };
        let num_sigmas = self.optional_number(at, "numSigmas")?;
        let mut bounds = Vec::new();
        for b in self.elements(at, "bounds") {
            match self.child(b, "dataTable") {
                Some(t) => bounds.extend(self.numbers(t)?),
                None if self.child(b, "variableRef").is_none() => bounds.extend(self.numbers(b)?),
                None => {}
            }
        }
        Ok(Some(Pdf {
            kind,
            num_sigmas,
            bounds,
            place: self.place(at),
        }))
    }

    fn variable(&self, n: Node) -> Result<VariableDef, DavemlError> {
        Ok(VariableDef {
            var_id: self.attr(n, "varID")?,
            name: n.attribute("name").unwrap_or("").to_string(),
            units: self.attr(n, "units")?,
            initial_value: self.optional_number(n, "initialValue")?,
            limits: (
                self.optional_number(n, "minValue")?,
                self.optional_number(n, "maxValue")?,
            ),
            calculation: self.child(n, "calculation").map(|c| self.place(c)),
            uncertainty: self.pdf(n)?,
        })
    }

    fn breakpoint(&self, n: Node) -> Result<BreakpointDef, DavemlError> {
        Ok(BreakpointDef {
            bp_id: self.attr(n, "bpID")?,
            units: n.attribute("units").map(str::to_string),
            values: self.numbers(self.required(n, "bpVals")?)?,
        })
    }

    fn table(&self, n: Node) -> Result<GriddedTable, DavemlError> {
        let refs = self.required(n, "breakpointRefs")?;
        let breakpoints = self
            .elements(refs, "bpRef")
            .map(|b| self.attr(b, "bpID"))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(GriddedTable {
            gt_id: n.attribute("gtID").map(str::to_string),
            breakpoints,
            data: self.numbers(self.required(n, "dataTable")?)?,
            uncertainty: self.pdf(n)?,
        })
    }

    fn function(&self, n: Node) -> Result<Function, DavemlError> {
        let name = n.attribute("name").unwrap_or("").to_string();
        if let Some(pts) = self.child(n, "independentVarPts") {
            let table = self.located(pts, TableDefn::Simple);
            let out = self.required(n, "dependentVarPts")?;
            let output = self.located(out, self.attr(out, "varID")?);
            return Ok(Function {
                name,
                inputs: Vec::new(),
                output,
                table,
            });
        }
        let inputs = self
            .elements(n, "independentVarRef")
            .map(|i| Ok(self.located(i, self.input(i)?)))
            .collect::<Result<Vec<_>, DavemlError>>()?;
        let out = self.required(n, "dependentVarRef")?;
        let output = self.located(out, self.attr(out, "varID")?);
        let defn = self.required(n, "functionDefn")?;
        let table = match defn.children().find(Node::is_element) {
            Some(t) if t.tag_name().name() == "griddedTableRef" => self.located(
                t,
                TableDefn::Ref {
                    gt_id: self.attr(t, "gtID")?,
                },
            ),
            Some(t) if t.tag_name().name() == "griddedTableDef" => {
                self.located(t, TableDefn::Inline(self.table(t)?))
            }
            Some(t) => self.located(
                t,
                TableDefn::Unsupported {
                    tag: t.tag_name().name().to_string(),
                },
            ),
            None => return Err(DavemlError::at(&self.place(defn), "is empty")),
        };
        Ok(Function {
            name,
            inputs,
            output,
            table,
        })
    }

    fn input(&self, n: Node) -> Result<InputRef, DavemlError> {
        Ok(InputRef {
            var_id: self.attr(n, "varID")?,
            min: self.optional_number(n, "min")?,
            max: self.optional_number(n, "max")?,
            extrapolate: n.attribute("extrapolate").unwrap_or("neither").to_string(),
            interpolate: n.attribute("interpolate").unwrap_or("linear").to_string(),
        })
    }

    fn case(&self, n: Node) -> Result<CheckCase, DavemlError> {
        let signals = |list: &'static str| -> Result<Vec<Located<Signal>>, DavemlError> {
            let l = self.required(n, list)?;
            self.elements(l, "signal")
                .map(|s| Ok(self.located(s, self.signal(s)?)))
                .collect()
        };
        Ok(CheckCase {
            name: n.attribute("name").unwrap_or("").to_string(),
            inputs: signals("checkInputs")?,
            outputs: signals("checkOutputs")?,
        })
    }

    fn signal(&self, n: Node) -> Result<Signal, DavemlError> {
        let text = |name: &'static str| {
            self.child(n, name)
                .map(|c| c.text().unwrap_or("").trim().to_string())
        };
        let name = text("signalName")
            .or_else(|| text("varID"))
            .ok_or_else(|| {
                DavemlError::at(&self.place(n), "has neither <signalName> nor <varID>")
            })?;
        let value = self.required(n, "signalValue")?;
        let tol = self
            .child(n, "tol")
            .map(|t| {
                let v = self.number(t, "tolerance", t.text().unwrap_or(""))?;
                if v < 0.0 {
                    return Err(DavemlError::at(
                        &self.place(t),
                        format!("tolerance {v} is negative: a check's tolerance is 0 or more"),
                    ));
                }
                Ok(v)
            })
            .transpose()?;
        Ok(Signal {
            name,
            units: text("signalUnits"),
            value: self.number(value, "value", value.text().unwrap_or(""))?,
            tol,
        })
    }
}

/// A text shortened for a message (at most 32 characters).
fn short(t: &str) -> String {
    if t.chars().count() <= 32 {
        t.to_string()
    } else {
        format!("{}...", t.chars().take(32).collect::<String>())
    }
}
