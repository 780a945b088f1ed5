//! Stage 0 of **parse**: entity declarations refused before the XML parser sees the text.
//!
//! DAVE-ML needs no entities (the standard's files carry `<!DOCTYPE DAVEfunc PUBLIC ...>` with
//! no internal subset), and an internal entity expanded thousands of times makes the parser
//! build gigabytes of text (a 1 MB file, one 1 MB entity used 4 000 times, aborts the process;
//! roxmltree's loop limit bounds nesting, not the size of one entity's uses). So the prolog is
//! scanned (XML 1.0 sections 2.8, 2.7 and 4.2: the XML declaration, comments, processing
//! instructions, the DOCTYPE and its internal subset, literals quoted with `"` or `'`) and any
//! `<!ENTITY` in the internal subset, general or parameter, internal or external, is refused
//! naming its line. A DOCTYPE without one (an external ID, `<!ELEMENT>`, `<!ATTLIST>`,
//! comments) is left to the parser, which reads no external DTD. Text the scanner cannot follow
//! (an unterminated comment or literal) is left to the parser too, which refuses it.

use crate::error::DavemlError;

/// Refuses `text` (from `file`) when its DOCTYPE declares an entity.
pub fn refuse_entities(text: &str, file: &str) -> Result<(), DavemlError> {
    let b = text.as_bytes();
    let mut i = if text.starts_with('\u{feff}') { 3 } else { 0 };
    loop {
        while i < b.len() && b[i].is_ascii_whitespace() {
            i += 1;
        }
        let rest = &b[i..];
        i = if rest.starts_with(b"<?") {
            skip_past(b, i + 2, b"?>")
        } else if rest.starts_with(b"<!--") {
            skip_past(b, i + 4, b"-->")
        } else if rest.starts_with(b"<!DOCTYPE") {
            return doctype(text, i + 9, file);
        } else {
            // The root element (or text the parser refuses): no DOCTYPE comes after it.
            return Ok(());
        };
    }
}

/// The index just past the first `end` at or after `from` (the text's length if none).
fn skip_past(b: &[u8], from: usize, end: &[u8]) -> usize {
    b.get(from..)
        .and_then(|r| r.windows(end.len()).position(|w| w == end))
        .map_or(b.len(), |k| from + k + end.len())
}

/// Scans a DOCTYPE from just after `<!DOCTYPE` to its closing `>`.
fn doctype(text: &str, from: usize, file: &str) -> Result<(), DavemlError> {
    let b = text.as_bytes();
    let mut i = from;
    let mut subset = false;
    while i < b.len() {
        let rest = &b[i..];
        i = match b[i] {
            q @ (b'"' | b'\'') => skip_past(b, i + 1, &[q]),
            b'[' if !subset => {
                subset = true;
                i + 1
            }
            b']' if subset => {
                subset = false;
                i + 1
            }
            b'>' if !subset => return Ok(()),
            b'<' if subset && rest.starts_with(b"<!--") => skip_past(b, i + 4, b"-->"),
            b'<' if subset && rest.starts_with(b"<?") => skip_past(b, i + 2, b"?>"),
            b'<' if subset && rest.starts_with(b"<!ENTITY") => {
                return Err(entity(text, i, file));
            }
            _ => i + 1,
        };
    }
    Ok(())
}

/// The refusal of the `<!ENTITY` at `at`.
fn entity(text: &str, at: usize, file: &str) -> DavemlError {
    let line = text[..at].bytes().filter(|&c| c == b'\n').count() + 1;
    let mut words = text[at + 8..].split_ascii_whitespace();
    let mut name = words.next().unwrap_or("");
    let kind = if name == "%" {
        name = words.next().unwrap_or("");
        "parameter entity"
    } else {
        "entity"
    };
    let name: String = name
        .chars()
        .take_while(|c| !matches!(c, '"' | '\'' | '>'))
        .take(64)
        .collect();
    DavemlError::Entity {
        file: file.to_string(),
        line: u32::try_from(line).unwrap_or(u32::MAX),
        kind,
        name,
    }
}

#[cfg(test)]
mod tests {
    use super::refuse_entities;

    fn line(text: &str) -> Option<u32> {
        match refuse_entities(text, "f") {
            Ok(()) => None,
            Err(crate::DavemlError::Entity { line, .. }) => Some(line),
            Err(e) => panic!("{e}"),
        }
    }

    #[test]
    fn entities_are_found_past_comments_literals_and_instructions() {
        assert_eq!(
            line("<?xml version='1.0'?><!DOCTYPE a [<!ENTITY e 'x'>]><a/>"),
            Some(1)
        );
        assert_eq!(
            line("\u{feff}<!-- <!DOCTYPE -->\n<!DOCTYPE a [\n<?pi '?>\n<!ENTITY e 'x'>]><a/>"),
            Some(4)
        );
        assert_eq!(
            line("<!DOCTYPE a SYSTEM '[' [<!ATTLIST a b CDATA ']>'><!ENTITY e 'x'>]><a/>"),
            Some(1)
        );
        // Not declarations: in a comment, a literal, after the DOCTYPE, or without a DOCTYPE.
        assert_eq!(
            line("<!DOCTYPE a [<!-- <!ENTITY e 'x'> --><!ATTLIST a b CDATA '<!ENTITY'>]><a/>"),
            None
        );
        assert_eq!(
            line("<!DOCTYPE a PUBLIC 'p' 'u'><a><![CDATA[<!ENTITY e 'x'>]]></a>"),
            None
        );
        assert_eq!(line("<a>&lt;!ENTITY</a>"), None);
        assert_eq!(line("<!DOCTYPE a [<!-- unterminated"), None);
    }
}
