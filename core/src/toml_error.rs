//! TOML parse errors on one line, as every other refusal: `line L, column C: message` (the
//! parser's own rendering spans several lines, with the source line and a caret).

/// `e` (from parsing `text`) as `line L, column C: message`; the message alone when the parser
/// gives no position.
pub fn one_line(text: &str, e: &toml::de::Error) -> String {
    let message = e.message().trim().replace('\n', "; ");
    match e.span() {
        Some(span) => {
            let at = span.start.min(text.len());
            // A span may start inside a multi-byte character: count on the bytes.
            let before = &text.as_bytes()[..at];
            let line = before.iter().filter(|&&b| b == b'\n').count() + 1;
            let line_start = before
                .iter()
                .rposition(|&b| b == b'\n')
                .map_or(0, |p| p + 1);
            let column = String::from_utf8_lossy(&before[line_start..])
                .chars()
                .count()
                + 1;
            format!("line {line}, column {column}: {message}")
        }
        None => message,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_parse_error_is_one_line_with_its_position() {
        let text = "a = 1\nb = \"unterminated\n";
        let e = toml::from_str::<toml::Table>(text).unwrap_err();
        let s = one_line(text, &e);
        assert!(s.starts_with("line 2, column "), "{s}");
        assert!(!s.contains('\n'), "{s}");
        let text = "é = 1\n";
        let e = toml::from_str::<toml::Table>(text).unwrap_err();
        assert!(one_line(text, &e).starts_with("line 1, column 1:"));
    }
}
