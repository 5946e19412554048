//! A self-contained HTML report: headings, paragraphs, tables and inline SVG figures in one
//! file with its own style sheet, viewable offline (no scripts, fonts or images from
//! elsewhere). A short inline script counts the figures the browser actually laid out
//! (`data-plots` and `data-plots-rendered` on `<body>`), so a headless browser can check
//! that the report renders.
//!
//! ```
//! use hbal::report::HtmlReport;
//! let mut r = HtmlReport::new("hbal report: a <scene>");
//! r.heading("Summary");
//! r.facts(&[("status", "converged".into()), ("H", "32".into())]);
//! r.table(&["DOF", "max |q| (rad)"], &[vec!["gear".into(), "5.96e-5".into()]]);
//! r.figure(r#"<svg width="10" height="10" xmlns="http://www.w3.org/2000/svg"></svg>"#, "A plot")
//!     .unwrap();
//! let html = r.finish();
//! assert!(html.starts_with("<!DOCTYPE html>"));
//! assert!(html.contains("hbal report: a &lt;scene&gt;"));
//! assert!(html.contains("<td>5.96e-5</td>"));
//! assert!(html.contains("<figure><svg"));
//! ```

use std::fmt::Write as _;

/// An HTML document being built.
#[derive(Debug, Clone)]
pub struct HtmlReport {
    title: String,
    body: String,
}

/// `text` with `&`, `<`, `>`, `"` and `'` escaped for HTML.
///
/// ```
/// assert_eq!(hbal::report::escape("a<b & \"c\""), "a&lt;b &amp; &quot;c&quot;");
/// ```
pub fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

const STYLE: &str = "body{font-family:sans-serif;max-width:1150px;margin:2em auto;padding:0 1em;\
color:#222;line-height:1.4}h1{font-size:1.6em}h2{border-bottom:1px solid #ccc;margin-top:1.8em}\
table{border-collapse:collapse;margin:0.8em 0}td,th{border:1px solid #ccc;padding:0.25em 0.6em;\
text-align:right}th{background:#f3f3f3}td:first-child,th:first-child{text-align:left}\
table.facts td{text-align:left}figure{margin:1em 0}figure svg{max-width:100%;height:auto;\
display:block}figcaption{color:#555;font-size:0.9em}pre{background:#f6f6f6;padding:0.8em;\
overflow-x:auto;font-size:0.85em}.ok{color:#1a7f37;font-weight:bold}\
.fail{color:#c62828;font-weight:bold}.note{color:#555}";

/// Counts the inline figures with a non-empty layout box once the page has loaded.
const RENDER_CHECK: &str = "window.addEventListener('load',function(){\
var s=document.querySelectorAll('figure svg'),n=0;\
s.forEach(function(e){var b=e.getBoundingClientRect();if(b.width>0&&b.height>0)n++;});\
document.body.setAttribute('data-plots',s.length);\
document.body.setAttribute('data-plots-rendered',n);});";

impl HtmlReport {
    /// An empty report with `title` (the page title and its first heading).
    pub fn new(title: &str) -> Self {
        let mut body = String::new();
        let _ = writeln!(body, "<h1>{}</h1>", escape(title));
        Self {
            title: title.to_string(),
            body,
        }
    }

    /// A section heading.
    pub fn heading(&mut self, text: &str) {
        let _ = writeln!(self.body, "<h2>{}</h2>", escape(text));
    }

    /// A paragraph of plain text.
    pub fn paragraph(&mut self, text: &str) {
        let _ = writeln!(self.body, "<p>{}</p>", escape(text));
    }

    /// A status line: `text` in green when `ok`, else in red.
    pub fn status(&mut self, ok: bool, text: &str) {
        let class = if ok { "ok" } else { "fail" };
        let _ = writeln!(self.body, "<p class=\"{class}\">{}</p>", escape(text));
    }

    /// A two-column table of names and values.
    pub fn facts(&mut self, pairs: &[(&str, String)]) {
        self.body.push_str("<table class=\"facts\">\n");
        for (name, value) in pairs {
            let _ = writeln!(
                self.body,
                "<tr><th>{}</th><td>{}</td></tr>",
                escape(name),
                escape(value)
            );
        }
        self.body.push_str("</table>\n");
    }

    /// A table with a header row.
    pub fn table(&mut self, header: &[&str], rows: &[Vec<String>]) {
        self.body.push_str("<table>\n<tr>");
        for h in header {
            let _ = write!(self.body, "<th>{}</th>", escape(h));
        }
        self.body.push_str("</tr>\n");
        for row in rows {
            self.body.push_str("<tr>");
            for cell in row {
                let _ = write!(self.body, "<td>{}</td>", escape(cell));
            }
            self.body.push_str("</tr>\n");
        }
        self.body.push_str("</table>\n");
    }

    /// An SVG figure, inlined, with a caption. `svg` must be one SVG document (an XML
    /// declaration before it is dropped).
    pub fn figure(&mut self, svg: &str, caption: &str) -> Result<(), String> {
        let start = svg
            .find("<svg")
            .ok_or_else(|| format!("figure `{caption}`: not an SVG document"))?;
        let _ = writeln!(
            self.body,
            "<figure>{}<figcaption>{}</figcaption></figure>",
            svg[start..].trim_end(),
            escape(caption)
        );
        Ok(())
    }

    /// Collapsed preformatted text (a scene file) under `summary`.
    pub fn details(&mut self, summary: &str, text: &str) {
        let _ = writeln!(
            self.body,
            "<details><summary>{}</summary><pre>{}</pre></details>",
            escape(summary),
            escape(text)
        );
    }

    /// The complete document.
    pub fn finish(self) -> String {
        format!(
            "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
             <title>{}</title>\n<style>{STYLE}</style>\n</head>\n<body>\n{}\
             <script>{RENDER_CHECK}</script>\n</body>\n</html>\n",
            escape(&self.title),
            self.body
        )
    }
}
