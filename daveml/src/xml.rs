//! A small XML writer: elements with attributes and text, escaped (XML 1.0, section 2.4 and
//! 3.3.3: `&`, `<`, `>`, `"` and `'` as character references), indented two spaces per level.
//! Numbers are written with Rust's `{:?}` for f64, the shortest text that reads back as the
//! same double.

/// The text of a document being written.
#[derive(Debug, Default)]
pub struct Xml {
    text: String,
    depth: usize,
}

/// `s` escaped for an attribute value or element text.
pub fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            c => out.push(c),
        }
    }
    out
}

/// A number as text that reads back as the same double.
pub fn number(x: f64) -> String {
    format!("{x:?}")
}

impl Xml {
    /// A document with its XML declaration.
    pub fn new() -> Xml {
        Xml {
            text: "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n".to_string(),
            depth: 0,
        }
    }

    fn start(&mut self, name: &str, attrs: &[(&str, &str)]) {
        for _ in 0..self.depth {
            self.text.push_str("  ");
        }
        self.text.push('<');
        self.text.push_str(name);
        for (k, v) in attrs {
            self.text.push_str(&format!(" {k}=\"{}\"", escape(v)));
        }
    }

    /// Opens an element.
    pub fn open(&mut self, name: &str, attrs: &[(&str, &str)]) {
        self.start(name, attrs);
        self.text.push_str(">\n");
        self.depth += 1;
    }

    /// Closes an element.
    pub fn close(&mut self, name: &str) {
        self.depth -= 1;
        for _ in 0..self.depth {
            self.text.push_str("  ");
        }
        self.text.push_str(&format!("</{name}>\n"));
    }

    /// An empty element.
    pub fn empty(&mut self, name: &str, attrs: &[(&str, &str)]) {
        self.start(name, attrs);
        self.text.push_str("/>\n");
    }

    /// An element holding text.
    pub fn leaf(&mut self, name: &str, attrs: &[(&str, &str)], text: &str) {
        self.start(name, attrs);
        self.text.push_str(&format!(">{}</{name}>\n", escape(text)));
    }

    /// An element holding numbers, comma-separated, `per_line` to a line.
    pub fn numbers(&mut self, name: &str, values: &[f64], per_line: usize) {
        let lines: Vec<String> = values
            .chunks(per_line.max(1))
            .map(|c| c.iter().map(|&x| number(x)).collect::<Vec<_>>().join(", "))
            .collect();
        self.start(name, &[]);
        self.text.push('>');
        self.text.push_str(&lines.join(",\n"));
        self.text.push_str(&format!("</{name}>\n"));
    }

    /// The document's text.
    pub fn finish(self) -> String {
        self.text
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escapes_markup_and_numbers_round_trip() {
        assert_eq!(
            escape("a<b & \"c\" 'd'>"),
            "a&lt;b &amp; &quot;c&quot; &apos;d&apos;&gt;"
        );
        for x in [0.1, -0.0, 1e-300, 5e-324, f64::MAX, 1.0 / 3.0] {
            let back: f64 = number(x).parse().unwrap();
            assert_eq!(back.to_bits(), x.to_bits());
        }
    }
}
