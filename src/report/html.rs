//! A small HTML writer for the report: one self-contained page (inline CSS,
//! no scripts, no network), images and downloads by relative links.

/// Escapes text for HTML content and attribute values.
pub fn esc(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
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

/// A relative link target: each path segment percent-encoded where needed.
pub fn href(path: &str) -> String {
    let mut out = String::new();
    for b in path.bytes() {
        match b {
            b'A'..=b'Z' | b'a'..=b'z' | b'0'..=b'9' | b'-' | b'_' | b'.' | b'/' | b'~' => {
                out.push(b as char)
            }
            _ => out.push_str(&format!("%{b:02X}")),
        }
    }
    out
}

/// A table cell holding a run-directory image at the grid's thumbnail
/// width (pixels drawn square, not smoothed).
fn thumb_cell(file: &str) -> String {
    format!(
        "<td><img class=\"px\" style=\"width:192px\" src=\"{}\" alt=\"\"></td>",
        href(file)
    )
}

/// A row of a photographs' grid: the photograph's label, its figures
/// (three decimals) and its run-directory images as thumbnails.
pub fn shot_row(label: &str, figures: &[f64], images: &[String]) -> String {
    let mut row = format!("<tr><td class=\"l\">{}</td>", esc(label));
    for f in figures {
        row.push_str(&format!("<td>{f:.3}</td>"));
    }
    for i in images {
        row.push_str(&thumb_cell(i));
    }
    row.push_str("</tr>\n");
    row
}

const STYLE: &str = r#"
body { font-family: system-ui, -apple-system, "DejaVu Sans", sans-serif; margin: 2em auto; max-width: 1720px; padding: 0 1em; color: #222; }
h1 { font-size: 1.6em; } h2 { font-size: 1.25em; margin-top: 2em; border-bottom: 1px solid #ccc; }
table { border-collapse: collapse; margin: 0.8em 0; }
th, td { border: 1px solid #ccc; padding: 0.25em 0.6em; text-align: right; font-variant-numeric: tabular-nums; }
th { background: #f2f2f2; } td.l, th.l { text-align: left; }
figure { display: inline-block; margin: 0.5em 1em 0.5em 0; vertical-align: top; }
figcaption { font-size: 0.9em; color: #444; max-width: 640px; }
img.px { image-rendering: pixelated; image-rendering: crisp-edges; }
p.note { color: #666; font-size: 0.9em; }
code { background: #f4f4f4; padding: 0 0.2em; }
"#;

/// The page being built.
pub struct Page {
    title: String,
    body: String,
}

impl Page {
    pub fn new(title: &str) -> Page {
        Page {
            title: title.into(),
            body: format!("<h1>{}</h1>\n", esc(title)),
        }
    }

    pub fn h2(&mut self, text: &str, id: &str) {
        self.body
            .push_str(&format!("<h2 id=\"{}\">{}</h2>\n", esc(id), esc(text)));
    }

    pub fn p(&mut self, text: &str) {
        self.body.push_str(&format!("<p>{}</p>\n", esc(text)));
    }

    /// A paragraph of trusted markup (built by this module's callers from
    /// escaped parts).
    pub fn raw(&mut self, html: &str) {
        self.body.push_str(html);
        self.body.push('\n');
    }

    pub fn note(&mut self, text: &str) {
        self.body
            .push_str(&format!("<p class=\"note\">{}</p>\n", esc(text)));
    }

    /// A table; the first column is left-aligned (labels).
    pub fn table(&mut self, headers: &[&str], rows: &[Vec<String>]) {
        let mut t = String::from("<table>\n<tr>");
        for (i, h) in headers.iter().enumerate() {
            let class = if i == 0 { " class=\"l\"" } else { "" };
            t.push_str(&format!("<th{class}>{}</th>", esc(h)));
        }
        t.push_str("</tr>\n");
        for row in rows {
            t.push_str("<tr>");
            for (i, cell) in row.iter().enumerate() {
                // Labels left, numbers right.
                let text = i == 0 || cell.starts_with(|c: char| c.is_alphabetic());
                let class = if text { " class=\"l\"" } else { "" };
                t.push_str(&format!("<td{class}>{}</td>", esc(cell)));
            }
            t.push_str("</tr>\n");
        }
        t.push_str("</table>\n");
        self.body.push_str(&t);
    }

    /// An image with a caption; `pixelated` keeps upscaled renders crisp;
    /// `svg` adds a link to the vector version.
    pub fn figure(&mut self, src: &str, caption: &str, pixelated: bool, svg: Option<&str>) {
        let class = if pixelated { " class=\"px\"" } else { "" };
        let mut cap = esc(caption);
        if let Some(s) = svg {
            cap.push_str(&format!(" (<a href=\"{}\">SVG</a>)", href(s)));
        }
        self.body.push_str(&format!(
            "<figure><img{class} src=\"{}\" alt=\"{}\"><figcaption>{cap}</figcaption></figure>\n",
            href(src),
            esc(caption)
        ));
    }

    /// A small render shown enlarged to `width` CSS pixels, kept crisp.
    pub fn figure_enlarged(&mut self, src: &str, caption: &str, width: u32) {
        self.body.push_str(&format!(
            "<figure><img class=\"px\" style=\"width:{width}px\" src=\"{}\" alt=\"{}\"><figcaption>{}</figcaption></figure>\n",
            href(src),
            esc(caption),
            esc(caption)
        ));
    }

    /// A paragraph with one emphasised part: `before` **`bold`** `after`.
    pub fn p_bold(&mut self, before: &str, bold: &str, after: &str) {
        self.body.push_str(&format!(
            "<p>{}<b>{}</b>{}</p>\n",
            esc(before),
            esc(bold),
            esc(after)
        ));
    }

    /// A list of links to files beside the page.
    pub fn links(&mut self, files: &[(String, String)]) {
        let mut s = String::from("<ul>\n");
        for (path, what) in files {
            s.push_str(&format!(
                "<li><a href=\"{}\">{}</a> — {}</li>\n",
                href(path),
                esc(path),
                esc(what)
            ));
        }
        s.push_str("</ul>\n");
        self.body.push_str(&s);
    }

    pub fn finish(self) -> String {
        format!(
            "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>{}</title>\n<style>{STYLE}</style>\n</head>\n<body>\n{}</body>\n</html>\n",
            esc(&self.title),
            self.body
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escapes_and_links() {
        assert_eq!(esc("a<b & \"c\""), "a&lt;b &amp; &quot;c&quot;");
        assert_eq!(href("stage 1/best.png"), "stage%201/best.png");
        let mut p = Page::new("T<1>");
        p.figure("fig.png", "x & y", true, Some("fig.svg"));
        let html = p.finish();
        assert!(html.contains("<title>T&lt;1&gt;</title>"));
        assert!(html.contains("src=\"fig.png\" alt=\"x &amp; y\""));
        assert!(html.contains("href=\"fig.svg\""));
    }

    #[test]
    fn enlarged_figures_and_bold_parts_are_escaped() {
        let mut p = Page::new("t");
        p.figure_enlarged("a b.png", "<x>", 384);
        p.p_bold("A: ", "x & y", ".");
        let html = p.finish();
        assert!(html.contains("style=\"width:384px\" src=\"a%20b.png\" alt=\"&lt;x&gt;\""));
        assert!(html.contains("<p>A: <b>x &amp; y</b>.</p>"));
    }
}
