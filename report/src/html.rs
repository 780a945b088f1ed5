//! HTML pages for people: one layout (`templates/base.html`) and one stylesheet
//! (`templates/style.css`) shared by every page, and each page's own template, rendered by
//! minijinja (<https://docs.rs/minijinja>, a maintained Jinja2 engine) from a serializable
//! context. A page template extends the layout (`{% extends "base.html" %}`) and fills its
//! `title` and `body` blocks; the crate that owns the page owns its template and its context,
//! this module knows nothing of what the page says.
//!
//! Text is escaped for HTML in every template whose name ends in `.html` (the engine's
//! autoescaping): `&`, `<` and `"`, enough for text and double-quoted attribute values (HTML
//! 5.2, section 8.1.2.3, and the W3C's "Escaping in HTML"); `>` is left as it is, so that
//! "0.004 m -> 0.003 m" stays readable in the page's source. A value the template marks
//! `|safe` is written as it is. Undefined variables are errors, not empty text.

use minijinja::{AutoEscape, Environment, Error, UndefinedBehavior};
use serde::Serialize;

/// The layout of every page.
const BASE: &str = include_str!("../templates/base.html");
/// The stylesheet of every page.
const STYLE: &str = include_str!("../templates/style.css");

/// Errors of rendering a page.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum HtmlError {
    /// A template that does not parse, or does not render with its context.
    #[error("the page template {name} does not render: {source:#}")]
    Template {
        /// The template's name.
        name: String,
        /// What the engine said.
        #[source]
        source: Error,
    },
}

/// A page's own template.
#[derive(Debug, Clone, Copy)]
pub struct PageTemplate {
    /// Its name, ending in `.html` (which turns autoescaping on).
    pub name: &'static str,
    /// Its source, which extends `base.html`.
    pub source: &'static str,
}

/// `s` escaped for HTML text and double-quoted attribute values.
pub fn escape_html(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('"', "&quot;")
}

/// Renders `page` with `context`.
pub fn render_page(page: &PageTemplate, context: &impl Serialize) -> Result<String, HtmlError> {
    let failed = |source| HtmlError::Template {
        name: page.name.to_string(),
        source,
    };
    let mut env = Environment::new();
    env.set_undefined_behavior(UndefinedBehavior::Strict);
    // A line that holds only a block tag leaves no blank line behind.
    env.set_trim_blocks(true);
    env.set_lstrip_blocks(true);
    env.set_formatter(|out, state, value| {
        if state.auto_escape() == AutoEscape::Html && !value.is_safe() {
            out.write_str(&escape_html(&value.to_string()))
                .map_err(Error::from)
        } else {
            minijinja::escape_formatter(out, state, value)
        }
    });
    env.add_template("base.html", BASE).map_err(failed)?;
    env.add_template("style.css", STYLE).map_err(failed)?;
    env.add_template(page.name, page.source).map_err(failed)?;
    let template = env.get_template(page.name).map_err(failed)?;
    template.render(context).map_err(failed)
}

#[cfg(test)]
mod tests {
    use super::*;

    const PAGE: PageTemplate = PageTemplate {
        name: "test.html",
        source: r#"{% extends "base.html" %}{% block title %}t{% endblock %}{% block body %}<p title="{{ name }}">{{ name }} {{ mark|safe }} {{ x }}</p>{% endblock %}"#,
    };

    #[derive(Serialize)]
    struct Context<'a> {
        name: &'a str,
        mark: &'a str,
        x: f64,
    }

    #[test]
    fn text_is_escaped_and_the_layout_carries_the_stylesheet_once() {
        let html = render_page(
            &PAGE,
            &Context {
                name: r#"<script>"a" & b -> c</script>"#,
                mark: "<b>kept</b>",
                x: 1.5,
            },
        )
        .unwrap();
        assert!(html.starts_with("<!DOCTYPE html>"), "{html}");
        assert!(html.contains("<title>t</title>"), "{html}");
        assert!(
            html.contains(
                r#"<p title="&lt;script>&quot;a&quot; &amp; b -> c&lt;/script>">&lt;script>&quot;a&quot; &amp; b -> c&lt;/script> <b>kept</b> 1.5</p>"#
            ),
            "{html}"
        );
        assert_eq!(html.matches("border-collapse").count(), 1, "{html}");
        assert!(!html.contains("<script>"), "{html}");
    }

    #[test]
    fn an_undefined_variable_is_an_error() {
        let page = PageTemplate {
            name: "missing.html",
            source: r#"{% extends "base.html" %}{% block body %}{{ nowhere }}{% endblock %}"#,
        };
        let e = render_page(&page, &()).unwrap_err();
        assert!(
            e.to_string()
                .starts_with("the page template missing.html does not render"),
            "{e}"
        );
    }

    #[test]
    fn escape_html_leaves_plain_text_alone() {
        assert_eq!(escape_html("0.004 m -> 0.003 m"), "0.004 m -> 0.003 m");
        assert_eq!(escape_html("a<b & \"c\""), "a&lt;b &amp; &quot;c&quot;");
    }
}
