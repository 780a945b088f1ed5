//! An STL reader, ASCII and binary (the format of 3D Systems' StereoLithography Interface
//! Specification, 1989; see also <https://en.wikipedia.org/wiki/STL_(file_format)>).
//!
//! Our own rather than `stl_io`'s, for three reasons: an ASCII file may hold several
//! `solid NAME ... endsolid` blocks, which become parts; every refusal names the line; and the
//! triangle count is checked against the limit before anything is allocated. A file is binary
//! when its length is exactly 84 + 50 n bytes for the n its header declares (some binary files
//! start with the word `solid` too), otherwise ASCII when it starts with `solid`. Normals are
//! read and ignored (the vertices' order is what counts).

use crate::Stop;
use crate::domain::{MAX_COORDINATE_M, number};

/// One solid: a name and its triangles (vertices in metres).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Solid {
    /// The `solid NAME` of an ASCII file; empty for a binary file or an unnamed solid.
    pub name: String,
    /// The triangles, each three vertices.
    pub triangles: Vec<[[f64; 3]; 3]>,
}

/// Why an STL could not be read: the line (0 for binary) and what.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum StlProblem {
    /// Malformed at `line` (0 in a binary file).
    Malformed { line: usize, what: String },
    /// More than the limit of triangles.
    TooMany { count: u64 },
    /// `stop` asked to stop before the file was read.
    Stopped,
}

fn bad(line: usize, what: impl Into<String>) -> StlProblem {
    StlProblem::Malformed {
        line,
        what: what.into(),
    }
}

/// Lines or triangles read between two calls of `stop`: a few milliseconds' work.
const STOP_EVERY: usize = 1 << 14;

/// The solids of an STL file's bytes, at most `max_triangles` triangles in all; `stop` is
/// asked every [`STOP_EVERY`] lines or triangles.
pub(crate) fn parse(
    bytes: &[u8],
    max_triangles: u64,
    stop: Stop,
) -> Result<Vec<Solid>, StlProblem> {
    if bytes.len() >= 84 {
        let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as u64;
        if 84 + 50 * n == bytes.len() as u64 {
            return parse_binary(bytes, n, max_triangles, stop);
        }
    }
    let start = bytes
        .iter()
        .position(|b| !b.is_ascii_whitespace())
        .unwrap_or(bytes.len());
    if bytes[start..].starts_with(b"solid") {
        return parse_ascii(bytes, max_triangles, stop);
    }
    if bytes.len() >= 84 {
        let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as u64;
        return Err(bad(
            0,
            format!(
                "not an STL file: not ASCII (does not start with `solid`) and not binary (the \
                 header declares {n} triangles, i.e. {} bytes, but the file has {})",
                84 + 50 * n,
                bytes.len()
            ),
        ));
    }
    Err(bad(
        0,
        format!(
            "not an STL file: {} bytes, not ASCII (no `solid`) and shorter than a binary header (84 bytes)",
            bytes.len()
        ),
    ))
}

fn parse_binary(
    bytes: &[u8],
    n: u64,
    max_triangles: u64,
    stop: Stop,
) -> Result<Vec<Solid>, StlProblem> {
    if n > max_triangles {
        return Err(StlProblem::TooMany { count: n });
    }
    let mut triangles = Vec::with_capacity(n as usize);
    for (k, record) in bytes[84..].chunks_exact(50).enumerate() {
        if k % STOP_EVERY == 0 && stop() {
            return Err(StlProblem::Stopped);
        }
        let f = |i: usize| {
            let o = 12 + 4 * i;
            f32::from_le_bytes([record[o], record[o + 1], record[o + 2], record[o + 3]]) as f64
        };
        let t = [[f(0), f(1), f(2)], [f(3), f(4), f(5)], [f(6), f(7), f(8)]];
        if t.iter().flatten().any(|v| !v.is_finite()) {
            return Err(bad(
                0,
                format!("triangle {}: a vertex coordinate is not finite", k + 1),
            ));
        }
        if let Some(v) = t.iter().flatten().find(|v| v.abs() > MAX_COORDINATE_M) {
            return Err(bad(
                0,
                format!(
                    "triangle {}: vertex coordinate {} is beyond +-{MAX_COORDINATE_M} m (the domain of a coordinate)",
                    k + 1,
                    number(*v)
                ),
            ));
        }
        triangles.push(t);
    }
    Ok(vec![Solid {
        name: String::new(),
        triangles,
    }])
}

/// Where the ASCII parser is within a solid.
#[derive(Clone, Copy, PartialEq, Debug)]
enum Expect {
    Solid,
    FacetOrEnd,
    OuterLoop,
    Vertex(usize),
    EndLoop,
    EndFacet,
}

fn parse_ascii(bytes: &[u8], max_triangles: u64, stop: Stop) -> Result<Vec<Solid>, StlProblem> {
    let text = std::str::from_utf8(bytes).map_err(|e| {
        let line = 1 + bytes[..e.valid_up_to()]
            .iter()
            .filter(|&&b| b == b'\n')
            .count();
        bad(line, "not text (invalid UTF-8) in an ASCII STL file")
    })?;
    let mut solids: Vec<Solid> = Vec::new();
    let mut expect = Expect::Solid;
    let mut corners = [[0.0; 3]; 3];
    let mut count = 0u64;
    let mut last_line = 0;
    for (i, raw) in text.lines().enumerate() {
        if i % STOP_EVERY == 0 && stop() {
            return Err(StlProblem::Stopped);
        }
        let line = i + 1;
        let mut words = raw.split_whitespace();
        let Some(word) = words.next() else { continue };
        last_line = line;
        let word = word.to_ascii_lowercase();
        match (expect, word.as_str()) {
            (Expect::Solid, "solid") => {
                let name = raw.trim_start()[5..].trim().to_string();
                solids.push(Solid {
                    name,
                    triangles: Vec::new(),
                });
                expect = Expect::FacetOrEnd;
            }
            (Expect::FacetOrEnd, "facet") => expect = Expect::OuterLoop,
            (Expect::FacetOrEnd, "endsolid") => expect = Expect::Solid,
            (Expect::OuterLoop, "outer") => expect = Expect::Vertex(0),
            (Expect::Vertex(k), "vertex") => {
                corners[k] = vertex(words, line)?;
                expect = if k == 2 {
                    Expect::EndLoop
                } else {
                    Expect::Vertex(k + 1)
                };
            }
            (Expect::EndLoop, "endloop") => expect = Expect::EndFacet,
            (Expect::EndFacet, "endfacet") => {
                count += 1;
                if count > max_triangles {
                    return Err(StlProblem::TooMany { count });
                }
                if let Some(solid) = solids.last_mut() {
                    solid.triangles.push(corners);
                }
                expect = Expect::FacetOrEnd;
            }
            (_, other) => {
                return Err(bad(
                    line,
                    format!("expected {}, found `{other}`", expected(expect)),
                ));
            }
        }
    }
    if expect != Expect::Solid {
        return Err(bad(
            last_line,
            format!("the file ends where {} was expected", expected(expect)),
        ));
    }
    Ok(solids)
}

fn expected(e: Expect) -> &'static str {
    match e {
        Expect::Solid => "`solid`",
        Expect::FacetOrEnd => "`facet` or `endsolid`",
        Expect::OuterLoop => "`outer loop`",
        Expect::Vertex(_) => "`vertex` (three per facet)",
        Expect::EndLoop => "`endloop`",
        Expect::EndFacet => "`endfacet`",
    }
}

fn vertex<'a>(
    mut words: impl Iterator<Item = &'a str>,
    line: usize,
) -> Result<[f64; 3], StlProblem> {
    let mut v = [0.0; 3];
    for (axis, slot) in ["x", "y", "z"].iter().zip(v.iter_mut()) {
        let word = words
            .next()
            .ok_or_else(|| bad(line, format!("vertex: missing the {axis} coordinate")))?;
        let value: f64 = word.parse().map_err(|_| {
            bad(
                line,
                format!("vertex: {axis} coordinate `{word}` is not a number"),
            )
        })?;
        if !value.is_finite() {
            return Err(bad(
                line,
                format!("vertex: {axis} coordinate `{word}` is not finite"),
            ));
        }
        if value.abs() > MAX_COORDINATE_M {
            return Err(bad(
                line,
                format!(
                    "vertex: {axis} coordinate `{word}` is beyond +-{MAX_COORDINATE_M} m (the domain of a coordinate)"
                ),
            ));
        }
        *slot = value;
    }
    if let Some(extra) = words.next() {
        return Err(bad(
            line,
            format!("vertex: unexpected `{extra}` after three coordinates"),
        ));
    }
    Ok(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    const TWO_SOLIDS: &str = "solid a\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   \
        vertex 1 0 0\n   vertex 0 1 0\n  endloop\n endfacet\nendsolid a\nsolid b c\n facet normal 0 0 1\n  \
        outer loop\n   vertex 0 0 1\n   vertex 1 0 1\n   vertex 0 1 1e0\n  endloop\n endfacet\nendsolid\n";

    #[test]
    fn ascii_solids_become_named_solids() {
        let solids = parse(TWO_SOLIDS.as_bytes(), 10, &|| false).unwrap();
        assert_eq!(solids.len(), 2);
        assert_eq!(solids[0].name, "a");
        assert_eq!(solids[1].name, "b c");
        assert_eq!(
            solids[1].triangles,
            vec![[[0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [0.0, 1.0, 1.0]]]
        );
    }

    #[test]
    fn ascii_refusals_name_the_line() {
        let text = TWO_SOLIDS.replace("vertex 1 0 1", "vertex 1 nan 1");
        assert_eq!(
            parse(text.as_bytes(), 10, &|| false).unwrap_err(),
            bad(14, "vertex: y coordinate `nan` is not finite")
        );
        let text = TWO_SOLIDS.replace("endloop\n endfacet\nendsolid\n", "");
        assert!(matches!(
            parse(text.as_bytes(), 10, &|| false),
            Err(StlProblem::Malformed { line: 15, .. })
        ));
        assert_eq!(
            parse(TWO_SOLIDS.as_bytes(), 1, &|| false).unwrap_err(),
            StlProblem::TooMany { count: 2 }
        );
    }

    #[test]
    fn a_binary_file_is_known_by_its_length() {
        let mut bytes = b"solid but binary".to_vec();
        bytes.resize(80, 0);
        bytes.extend(1u32.to_le_bytes());
        bytes.extend([0u8; 12]);
        for v in [0f32, 0., 0., 1., 0., 0., 0., 1., 0.] {
            bytes.extend(v.to_le_bytes());
        }
        bytes.extend([0u8; 2]);
        let solids = parse(&bytes, 10, &|| false).unwrap();
        // Exactly the f32 values written (0 and 1 are exact).
        assert_eq!(
            solids[0].triangles[0][2].map(f64::to_bits),
            [0.0f64, 1.0, 0.0].map(f64::to_bits)
        );
        assert_eq!(
            parse(&bytes, 0, &|| false).unwrap_err(),
            StlProblem::TooMany { count: 1 }
        );
        // One byte more: not binary, and not text either.
        bytes.push(0);
        assert!(matches!(
            parse(&bytes, 10, &|| false),
            Err(StlProblem::Malformed { line: 1, .. })
        ));
        bytes[0] = b'x';
        assert!(matches!(
            parse(&bytes, 10, &|| false),
            Err(StlProblem::Malformed { line: 0, .. })
        ));
    }
}
