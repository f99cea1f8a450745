//! Images of the project's screens (issue 35, docs/api.md "Assets"):
//! `hmi/assets/<name>`.
//!
//! `PUT /api/assets/{name}` (engineer) saves an image atomically under its
//! audit row (`save_asset`); `GET /api/assets/{name}` serves it with its
//! type, `X-Content-Type-Options: nosniff` and a Content-Security-Policy
//! that allows nothing to run or load; `GET /api/assets` lists them.
//!
//! PNG, JPEG and GIF are recognised by their magic bytes, which must agree
//! with the name's extension. An SVG is checked with quick-xml and
//! **refused** (422 naming the reason), never cleaned: a cleaned file is
//! not the file the engineer drew, and a refusal tells them what to remove
//! (docs/adr/0016-uploaded-svg-is-refused-not-cleaned.md). Refused: a
//! `<script>`, `<foreignObject>` and other embedding elements, event
//! handler attributes (`on…`), an `href`/`xlink:href`/`src` that is not a
//! fragment (`#id`) or a `data:image/(png|jpeg|gif)` URL, `url(…)` to
//! anything else, `javascript:`, CSS `@import` and escapes, a document type
//! declaration, processing instructions, a root that is not `<svg>`.

use super::audit::{Actor, audited};
use crate::error::{ApiError, ApiResult};
use crate::state::AppState;
use alba_control::audit::Action;
use axum::Json;
use axum::body::Bytes;
use axum::extract::{Path, State};
use axum::http::{StatusCode, header};
use axum::response::{IntoResponse, Response};
use quick_xml::events::Event;
use serde_json::{Value as JsonValue, json};
use std::path::PathBuf;
use std::sync::Arc;

/// The largest image accepted (bigger: 413).
pub const ASSET_BODY: usize = 2 * 1024 * 1024;

/// What an image is served with: nothing in it may run, load or be framed.
pub const ASSET_CSP: &str = "default-src 'none'; img-src data:; style-src 'unsafe-inline'; sandbox";

/// The deepest element nesting an SVG may have.
const MAX_DEPTH: usize = 256;

/// The kinds of image, by extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    Png,
    Jpeg,
    Gif,
    Svg,
}

impl Kind {
    pub fn mime(self) -> &'static str {
        match self {
            Kind::Png => "image/png",
            Kind::Jpeg => "image/jpeg",
            Kind::Gif => "image/gif",
            Kind::Svg => "image/svg+xml",
        }
    }
}

/// The kind an asset's name says, or why it is not an asset name: a safe
/// file name (letters, digits, `_`, `-`, `.`; not starting with `.`; at
/// most 64) ending in `.png`, `.jpg`, `.jpeg`, `.gif` or `.svg`.
pub fn kind_of(name: &str) -> Result<Kind, String> {
    let safe = !name.is_empty()
        && name.len() <= 64
        && !name.starts_with('.')
        && !name.contains("..")
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.'));
    let ext = name.rsplit_once('.').map(|(_, e)| e.to_ascii_lowercase());
    let kind = match ext.as_deref() {
        Some("png") => Some(Kind::Png),
        Some("jpg" | "jpeg") => Some(Kind::Jpeg),
        Some("gif") => Some(Kind::Gif),
        Some("svg") => Some(Kind::Svg),
        _ => None,
    };
    match kind {
        Some(k) if safe => Ok(k),
        _ => Err(format!(
            "`{name}` is not an image name (letters, digits, `_`, `-` and `.`, at most 64, ending in .png, .jpg, .jpeg, .gif or .svg)"
        )),
    }
}

/// Checks `bytes` as an image of `kind`: the magic bytes of a raster image,
/// the SVG rules of this module's doc. The reason of a refusal.
pub fn check(kind: Kind, bytes: &[u8]) -> Result<(), String> {
    let magic: &[&[u8]] = match kind {
        Kind::Png => &[b"\x89PNG\r\n\x1a\n"],
        Kind::Jpeg => &[b"\xff\xd8\xff"],
        Kind::Gif => &[b"GIF87a", b"GIF89a"],
        Kind::Svg => return check_svg(bytes),
    };
    if magic.iter().any(|m| bytes.starts_with(m)) {
        Ok(())
    } else {
        Err(format!(
            "the body is not a {} image (its first bytes are not a {} signature)",
            kind.mime(),
            kind.mime()
        ))
    }
}

/// A URL an SVG may refer to: a fragment of itself or an embedded raster image.
fn local_url(url: &str) -> bool {
    let u = url.trim().trim_matches(|c| c == '\'' || c == '"').trim();
    let lower = u.to_ascii_lowercase();
    u.starts_with('#')
        || ["data:image/png", "data:image/jpeg", "data:image/gif"]
            .iter()
            .any(|p| lower.starts_with(p))
}

/// Checks CSS (a `style` attribute or element, a presentation attribute's
/// value): `url(…)` only to local URLs, no `@import`, no escapes (which
/// could spell either), no `javascript:`.
fn check_css(css: &str, at: &str) -> Result<(), String> {
    let lower = css.to_ascii_lowercase();
    if lower.contains('\\') {
        return Err(format!("{at}: CSS escapes (`\\`) are not accepted"));
    }
    if lower.contains("@import") {
        return Err(format!("{at}: `@import` loads an external style sheet"));
    }
    if lower.contains("javascript:") {
        return Err(format!("{at}: a `javascript:` URL"));
    }
    let mut rest = lower.as_str();
    while let Some(i) = rest.find("url(") {
        let after = &rest[i + 4..];
        let end = after.find(')').unwrap_or(after.len());
        if !local_url(&after[..end]) {
            return Err(format!(
                "{at}: `url({})` refers outside the image (only `#id` or a data: PNG/JPEG/GIF)",
                after[..end].trim()
            ));
        }
        rest = &after[end..];
    }
    Ok(())
}

/// The SVG rules (this module's doc).
fn check_svg(bytes: &[u8]) -> Result<(), String> {
    let text = std::str::from_utf8(bytes).map_err(|e| format!("the SVG is not UTF-8 text: {e}"))?;
    let mut reader = quick_xml::Reader::from_str(text);
    reader.config_mut().check_end_names = true;
    let mut depth = 0usize;
    let mut root_seen = false;
    // Depth of the `<style>` element the reader is in, if any.
    let mut style: Option<usize> = None;
    let mut style_text = String::new();
    loop {
        let at = reader.buffer_position();
        let ev = reader.read_event().map_err(|e| {
            format!(
                "the SVG is not well-formed XML at byte {}: {e}",
                reader.error_position()
            )
        })?;
        match ev {
            Event::Start(ref e) | Event::Empty(ref e) => {
                let name = String::from_utf8_lossy(e.local_name().as_ref()).to_ascii_lowercase();
                let place = format!("`<{name}>` at byte {at}");
                if !root_seen {
                    if name != "svg" {
                        return Err(format!("the root element is {place}, not `<svg>`"));
                    }
                    root_seen = true;
                } else if depth == 0 {
                    return Err(format!("{place}: a second root element"));
                }
                match name.as_str() {
                    "script" | "handler" | "listener" => {
                        return Err(format!("{place}: scripts are not accepted"));
                    }
                    "foreignobject" | "iframe" | "embed" | "object" | "audio" | "video" | "canvas" => {
                        return Err(format!("{place}: embedded documents and media are not accepted"));
                    }
                    _ => {}
                }
                for a in e.attributes() {
                    let a = a.map_err(|err| format!("{place}: a bad attribute: {err}"))?;
                    let key = String::from_utf8_lossy(a.key.local_name().as_ref()).to_ascii_lowercase();
                    let value = a
                        .unescape_value()
                        .map_err(|err| format!("{place}: a bad attribute value: {err}"))?;
                    let where_ = format!("{place}, attribute `{}`", String::from_utf8_lossy(a.key.as_ref()));
                    if key.starts_with("on") {
                        return Err(format!("{where_}: event handler attributes are not accepted"));
                    }
                    if matches!(key.as_str(), "href" | "src") && !local_url(&value) {
                        return Err(format!(
                            "{where_}: `{value}` is an external reference (only `#id` or a data: PNG/JPEG/GIF)"
                        ));
                    }
                    if key == "attributename" && value.to_ascii_lowercase().ends_with("href") {
                        return Err(format!("{where_}: an animation may not change a link"));
                    }
                    check_css(&value, &where_)?;
                }
                if matches!(ev, Event::Start(_)) {
                    depth += 1;
                    if depth > MAX_DEPTH {
                        return Err(format!("{place}: elements nested deeper than {MAX_DEPTH}"));
                    }
                    if name == "style" && style.is_none() {
                        style = Some(depth);
                        style_text.clear();
                    }
                }
            }
            Event::End(_) => {
                if style == Some(depth) {
                    check_css(&style_text, &format!("the `<style>` element ending at byte {at}"))?;
                    style = None;
                }
                depth = depth.saturating_sub(1);
            }
            Event::Text(t) if style.is_some() => {
                style_text.push_str(&t.decode().map_err(|e| format!("byte {at}: {e}"))?);
            }
            Event::CData(t) if style.is_some() => {
                style_text.push_str(&t.decode().map_err(|e| format!("byte {at}: {e}"))?);
            }
            Event::GeneralRef(r) if style.is_some() => match r.resolve_char_ref() {
                Ok(Some(c)) => style_text.push(c),
                _ => {
                    let name = r.decode().map_err(|e| format!("byte {at}: {e}"))?;
                    match quick_xml::escape::resolve_predefined_entity(&name) {
                        Some(s) => style_text.push_str(s),
                        None => return Err(format!("byte {at}: the entity `&{name};` is not defined")),
                    }
                }
            },
            Event::DocType(_) => {
                return Err(format!(
                    "byte {at}: a document type declaration (`<!DOCTYPE>`) is not accepted"
                ));
            }
            Event::PI(_) => {
                return Err(format!(
                    "byte {at}: processing instructions (`<?xml-stylesheet …?>`) are not accepted"
                ));
            }
            Event::Eof => break,
            _ => {}
        }
    }
    if !root_seen {
        return Err("the SVG has no `<svg>` element".into());
    }
    Ok(())
}

/// The file of asset `name` and its kind.
async fn file_of(st: &AppState, name: &str) -> ApiResult<(PathBuf, Kind)> {
    let kind = kind_of(name).map_err(ApiError::Malformed)?;
    let dir = st.project.lock().await.project.dir.join("hmi").join("assets");
    Ok((dir.join(name), kind))
}

/// The images of the project, by name.
pub async fn list(State(st): State<Arc<AppState>>) -> ApiResult<Json<JsonValue>> {
    let dir = st.project.lock().await.project.dir.join("hmi").join("assets");
    let mut names: Vec<String> = match std::fs::read_dir(&dir) {
        Ok(entries) => entries
            .flatten()
            .filter(|e| e.path().is_file())
            .filter_map(|e| e.file_name().to_str().map(str::to_string))
            .filter(|n| kind_of(n).is_ok())
            .collect(),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Vec::new(),
        Err(e) => return Err(ApiError::Internal(format!("cannot list {}: {e}", dir.display()))),
    };
    names.sort();
    Ok(Json(json!(names)))
}

/// One image with its type, `nosniff` and [`ASSET_CSP`].
pub async fn get(State(st): State<Arc<AppState>>, Path(name): Path<String>) -> ApiResult<Response> {
    let (path, kind) = file_of(&st, &name).await?;
    let bytes = std::fs::read(&path).map_err(|e| match e.kind() {
        std::io::ErrorKind::NotFound => ApiError::NotFound(format!("no image `{name}`")),
        _ => ApiError::Internal(format!("cannot read {}: {e}", path.display())),
    })?;
    Ok((
        [
            (header::CONTENT_TYPE, kind.mime()),
            (header::X_CONTENT_TYPE_OPTIONS, "nosniff"),
            (header::CONTENT_SECURITY_POLICY, ASSET_CSP),
            (header::CACHE_CONTROL, "no-cache"),
        ],
        bytes,
    )
        .into_response())
}

/// Audited (`save_asset`): checked ([`check`]), then written atomically
/// (`hmi/assets/` made if needed) → `{"name", "type", "bytes"}`.
pub async fn put(
    State(st): State<Arc<AppState>>,
    actor: Actor,
    Path(name): Path<String>,
    body: Result<Bytes, axum::extract::rejection::BytesRejection>,
) -> ApiResult<(StatusCode, Json<JsonValue>)> {
    let bytes = body.map_err(|e| {
        if e.status() == StatusCode::PAYLOAD_TOO_LARGE {
            ApiError::TooLarge
        } else {
            ApiError::Malformed(e.body_text())
        }
    })?;
    let (path, kind) = file_of(&st, &name).await?;
    check(kind, &bytes).map_err(|why| ApiError::Invalid(format!("image `{name}` refused: {why}")))?;
    let entry = alba_control::audit::Entry {
        target: Some(format!("hmi/assets/{name}")),
        detail: Some(format!("{}, {} bytes", kind.mime(), bytes.len())),
        ..actor.entry(Action::SaveAsset)
    };
    audited(&st, entry, async {
        if let Some(dir) = path.parent() {
            std::fs::create_dir_all(dir)
                .map_err(|e| ApiError::Internal(format!("cannot create {}: {e}", dir.display())))?;
        }
        alba_ir::model::fsutil::write_atomic(&path, |w| w.write_all(&bytes))
            .map_err(|e| ApiError::Internal(format!("cannot save {}: {e}", path.display())))
    })
    .await?;
    Ok((
        StatusCode::OK,
        Json(json!({"name": name, "type": kind.mime(), "bytes": bytes.len()})),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    const CLEAN: &str = r##"<?xml version="1.0"?>
<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink" viewBox="0 0 10 10">
  <defs><linearGradient id="g"><stop offset="0" stop-color="red"/></linearGradient></defs>
  <style>.a { fill: url(#g); }</style>
  <rect class="a" width="10" height="10" style="stroke: url('#g')"/>
  <use xlink:href="#g"/>
  <image href="data:image/png;base64,iVBORw0KGgo="/>
  <text>5 &lt; 6</text>
</svg>"##;

    #[test]
    fn a_clean_svg_and_raster_images_pass() {
        check(Kind::Svg, CLEAN.as_bytes()).expect("clean");
        check(Kind::Png, b"\x89PNG\r\n\x1a\n....").expect("png");
        check(Kind::Jpeg, b"\xff\xd8\xff\xe0....").expect("jpeg");
        check(Kind::Gif, b"GIF89a....").expect("gif");
    }

    #[test]
    fn each_refusal_says_why() {
        let svg = |inner: &str| format!(r#"<svg xmlns="http://www.w3.org/2000/svg">{inner}</svg>"#);
        for (body, says) in [
            (svg("<script>alert(1)</script>"), "scripts"),
            (svg("<SCRIPT>alert(1)</SCRIPT>"), "scripts"),
            (svg(r#"<rect onload="alert(1)"/>"#), "event handler"),
            (svg(r#"<rect OnClick="alert(1)"/>"#), "event handler"),
            (
                svg(r#"<image href="http://evil.example/x.png"/>"#),
                "external reference",
            ),
            (
                svg(r#"<use xmlns:xlink="http://www.w3.org/1999/xlink" xlink:href="other.svg#a"/>"#),
                "external reference",
            ),
            (
                svg(r#"<a href="javascript:alert(1)"><rect/></a>"#),
                "external reference",
            ),
            (
                svg(r#"<image href="data:image/svg+xml;base64,PHN2Zz4="/>"#),
                "external reference",
            ),
            (svg(r#"<rect fill="url(http://evil.example/#g)"/>"#), "refers outside"),
            (svg("<style>@import 'http://evil.example/a.css';</style>"), "@import"),
            (
                svg("<style>rect { fill: url(https://evil.example/) }</style>"),
                "refers outside",
            ),
            (
                svg("<style>rect { fill: u&#114;l(https://evil.example/) }</style>"),
                "refers outside",
            ),
            (svg(r#"<rect style="fill: u\72l(http://x)"/>"#), "CSS escapes"),
            (svg(r#"<foreignObject><div/></foreignObject>"#), "embedded"),
            (
                svg(r#"<set attributeName="href" to="javascript:alert(1)"/>"#),
                "change a link",
            ),
            ("<!DOCTYPE svg [<!ENTITY a 'b'>]><svg/>".to_string(), "DOCTYPE"),
            (
                r#"<?xml-stylesheet href="http://evil.example/a.css"?><svg/>"#.to_string(),
                "processing instructions",
            ),
            ("<html><script/></html>".to_string(), "not `<svg>`"),
            ("<svg><rect></svg>".to_string(), "not well-formed"),
            ("".to_string(), "no `<svg>`"),
        ] {
            let e = check(Kind::Svg, body.as_bytes()).expect_err(&body);
            assert!(e.contains(says), "{body}: {e}");
        }
        assert!(check(Kind::Png, b"GIF89a").unwrap_err().contains("image/png"));
        assert!(check(Kind::Gif, b"<svg/>").is_err());
        assert!(check(Kind::Jpeg, b"").is_err());
    }

    #[test]
    fn names_are_safe_file_names_of_an_image_kind() {
        assert_eq!(kind_of("pump-1.PNG"), Ok(Kind::Png));
        assert_eq!(kind_of("logo.jpeg"), Ok(Kind::Jpeg));
        for bad in [
            "../x.png", ".x.png", "a/b.png", "x.exe", "x", "x..svg", "x.html", "a b.gif",
        ] {
            assert!(kind_of(bad).is_err(), "{bad}");
        }
    }
}
