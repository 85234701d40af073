//! The report as one self-contained HTML file: the markdown report rendered by
//! `pulldown-cmark` (tables on), every local image inlined as a `data:` URI (base64), and a small
//! style sheet — a file that can be mailed or attached to a ticket and opens in any browser
//! without the folder beside it.

use std::path::Path;

use base64::Engine;
use pulldown_cmark::{html, CowStr, Event, Options, Parser, Tag};

use crate::error::Error;

/// Style of the page: readable width, tables with rules, images scaled to the page.
const STYLE: &str = "body{font-family:DejaVu Sans,Helvetica,Arial,sans-serif;max-width:1100px;\
margin:2em auto;padding:0 1em;line-height:1.45;color:#222}\
table{border-collapse:collapse;margin:1em 0;font-size:0.85em;display:block;overflow-x:auto}\
th,td{border:1px solid #bbb;padding:0.25em 0.6em;text-align:right}\
th{background:#f0f0f0}td:first-child,th:first-child{text-align:left}\
img{max-width:100%;height:auto;display:block;margin:1em 0}\
code{background:#f4f4f4;padding:0 0.2em}h1,h2{border-bottom:1px solid #ddd}";

/// Renders `markdown` (whose image links are relative to `dir`) as a complete HTML page titled
/// `title`. Local PNG, SVG and JPEG images are read (bounded like every input) and inlined; an
/// image that cannot be read is an error naming it; remote links are kept as they are.
pub(crate) fn render(markdown: &str, dir: &Path, title: &str) -> Result<String, Error> {
    let mut events = Vec::new();
    for ev in Parser::new_ext(markdown, Options::ENABLE_TABLES) {
        events.push(match ev {
            Event::Start(Tag::Image {
                link_type,
                dest_url,
                title,
                id,
            }) => Event::Start(Tag::Image {
                link_type,
                dest_url: inline(&dest_url, dir)?,
                title,
                id,
            }),
            other => other,
        });
    }
    let mut body = String::new();
    html::push_html(&mut body, events.into_iter());
    Ok(format!(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>{}</title>\n\
         <style>{STYLE}</style>\n</head>\n<body>\n{body}</body>\n</html>\n",
        escape(title)
    ))
}

/// A `data:` URI for a local image, or the link unchanged (remote, or not an image type).
fn inline<'a>(url: &CowStr<'a>, dir: &Path) -> Result<CowStr<'a>, Error> {
    let u: &str = url;
    if u.contains("://") || u.starts_with("data:") {
        return Ok(url.clone());
    }
    let mime = match Path::new(u).extension().and_then(|e| e.to_str()) {
        Some("png") => "image/png",
        Some("svg") => "image/svg+xml",
        Some("jpg") | Some("jpeg") => "image/jpeg",
        _ => return Ok(url.clone()),
    };
    let bytes = crate::files::read_bytes(&dir.join(u))?;
    let b64 = base64::engine::general_purpose::STANDARD.encode(bytes);
    Ok(CowStr::from(format!("data:{mime};base64,{b64}")))
}

/// `text` safe inside HTML.
fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '&' => out.push_str("&amp;"),
            '"' => out.push_str("&quot;"),
            _ => out.push(c),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn images_are_inlined_and_tables_rendered() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("a.png"), [0x89, b'P', b'N', b'G']).unwrap();
        let md = "# T <x>\n\n| a | b |\n|---|---|\n| 1 | 2 |\n\n![chart](a.png)\n\n![web](https://x/y.png)\n";
        let page = render(md, dir.path(), "r <&>").unwrap();
        assert!(page.contains("<title>r &lt;&amp;&gt;</title>"));
        assert!(page.contains("<table>") && page.contains("<td>2</td>"));
        assert!(
            page.contains("src=\"data:image/png;base64,iVBORw==\""),
            "{page}"
        );
        assert!(page.contains("src=\"https://x/y.png\""));
        // A missing image names the file.
        let err = render("![x](missing.png)", dir.path(), "t")
            .unwrap_err()
            .to_string();
        assert!(err.contains("missing.png"), "{err}");
    }
}
