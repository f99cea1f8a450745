//! Recipes (issue 35, docs/file-formats.md "recipes/"): named sets of tag
//! values in `recipes/<name>.csv` (`tag,value`).
//!
//! `GET /api/recipes` lists them; `GET /api/recipes/{name}` answers the
//! entries as a JSON object in file order (`Accept: text/csv`: the file);
//! `PUT /api/recipes/{name}` (engineer) saves one from CSV (`text/csv`) or
//! a JSON object `{tag: value}` atomically under its audit row
//! (`save_recipe`); `POST /api/recipes/{name}/capture` (engineer) saves the
//! current values of the listed tags (or of the recipe's own) as the recipe;
//! `POST /api/recipes/{name}/apply` (operator) writes every
//! entry at one scan boundary through the control layer
//! (`Control::write_rows`): every entry is checked first, and the first
//! refused one is named in a 422 with nothing written.
//!
//! A recipe is saved as written, whether its tags exist or not (the
//! program may change after it was saved): its entries are checked when it
//! is applied. Only its form is checked on saving: tag names, scalar values,
//! no tag twice.

use super::audit::{Actor, audited, json_text};
use crate::error::{ApiError, ApiResult};
use crate::state::AppState;
use alba_control::audit::Action;
use axum::Json;
use axum::body::Bytes;
use axum::extract::{Path, State};
use axum::http::{HeaderMap, header};
use axum::response::{IntoResponse, Response};
use serde_json::{Value as JsonValue, json};
use std::path::PathBuf;
use std::sync::Arc;

/// The most entries a recipe holds.
pub const MAX_ENTRIES: usize = 10_000;

/// A recipe's entries, in order.
type Entries = Vec<(String, JsonValue)>;

/// The file of recipe `name`: letters, digits, `_` and `-` (it is a file name).
fn file_of(dir: &std::path::Path, name: &str) -> ApiResult<PathBuf> {
    let ok =
        !name.is_empty() && name.len() <= 64 && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-');
    if !ok {
        return Err(ApiError::Malformed(format!(
            "`{name}` is not a recipe name (letters, digits, `_` and `-`, at most 64)"
        )));
    }
    Ok(dir.join("recipes").join(format!("{name}.csv")))
}

/// A tag name as a recipe holds it: a tag, a member (`T1.PRE`), no spaces or commas.
fn check_tag(row: usize, tag: &str) -> ApiResult<()> {
    let ok =
        !tag.is_empty() && tag.len() <= 128 && tag.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '.');
    if ok {
        Ok(())
    } else {
        Err(ApiError::Malformed(format!(
            "row {row}: `{tag}` is not a tag name (letters, digits, `_` and `.`)"
        )))
    }
}

/// A CSV field, unquoted (`"a ""b"""` → `a "b"`), or why not.
fn unquote(field: &str) -> Option<String> {
    let f = field.trim();
    match f.strip_prefix('"') {
        None => (!f.contains('"')).then(|| f.to_string()),
        Some(rest) => {
            let inner = rest.strip_suffix('"')?;
            let text = inner.replace("\"\"", "\"");
            (text.matches('"').count() * 2 == inner.matches('"').count()).then_some(text)
        }
    }
}

/// A CSV value as JSON: `true`/`false`, a number, else (quoted or not) text.
fn csv_value(field: &str) -> Option<JsonValue> {
    let f = field.trim();
    if f.starts_with('"') {
        return unquote(f).map(JsonValue::String);
    }
    match f.to_ascii_lowercase().as_str() {
        "true" => return Some(JsonValue::Bool(true)),
        "false" => return Some(JsonValue::Bool(false)),
        _ => {}
    }
    if let Ok(i) = f.parse::<i64>() {
        return Some(json!(i));
    }
    if let Ok(x) = f.parse::<f64>()
        && x.is_finite()
    {
        return Some(json!(x));
    }
    unquote(f).map(JsonValue::String)
}

/// Parses a recipe's CSV: an optional `tag,value` header, then one
/// `tag,value` per line (blank lines and `#` comments skipped).
pub fn parse_csv(text: &str) -> ApiResult<Entries> {
    let mut out: Entries = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line = line.trim_end_matches('\r');
        let t = line.trim();
        if t.is_empty() || t.starts_with('#') {
            continue;
        }
        let Some((tag, value)) = t.split_once(',') else {
            return Err(ApiError::Malformed(format!("line {}: expected `tag,value`", i + 1)));
        };
        let tag = unquote(tag).unwrap_or_default();
        if out.is_empty() && tag.eq_ignore_ascii_case("tag") && value.trim().eq_ignore_ascii_case("value") {
            continue;
        }
        let row = out.len() + 1;
        check_tag(row, &tag).map_err(|e| ApiError::Malformed(format!("line {}: {e}", i + 1)))?;
        let Some(v) = csv_value(value) else {
            return Err(ApiError::Malformed(format!(
                "line {}: `{}` is not a value",
                i + 1,
                value.trim()
            )));
        };
        out.push((tag, v));
    }
    finish(out)
}

/// Parses a recipe's JSON object `{tag: value}`, keeping the order written.
pub fn parse_json(text: &str) -> ApiResult<Entries> {
    struct Ordered(Entries);
    impl<'de> serde::Deserialize<'de> for Ordered {
        fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Ordered, D::Error> {
            struct V;
            impl<'de> serde::de::Visitor<'de> for V {
                type Value = Ordered;
                fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                    f.write_str("an object {tag: value}")
                }
                fn visit_map<A: serde::de::MapAccess<'de>>(self, mut m: A) -> Result<Ordered, A::Error> {
                    let mut out = Vec::new();
                    while let Some((k, v)) = m.next_entry::<String, JsonValue>()? {
                        if out.len() >= MAX_ENTRIES {
                            return Err(serde::de::Error::custom(format!("more than {MAX_ENTRIES} entries")));
                        }
                        out.push((k, v));
                    }
                    Ok(Ordered(out))
                }
            }
            d.deserialize_map(V)
        }
    }
    let Ordered(entries) = serde_json::from_str(text)
        .map_err(|e| ApiError::Malformed(format!("a recipe is a JSON object {{tag: value}}: {e}")))?;
    for (i, (tag, v)) in entries.iter().enumerate() {
        check_tag(i + 1, tag)?;
        if v.is_array() || v.is_object() || v.is_null() {
            return Err(ApiError::Malformed(format!(
                "row {} (`{tag}`): a value is a number, true/false or text",
                i + 1
            )));
        }
    }
    finish(entries)
}

/// Refuses a tag given twice (which value would win?) and too many entries.
fn finish(entries: Entries) -> ApiResult<Entries> {
    if entries.len() > MAX_ENTRIES {
        return Err(ApiError::Malformed(format!(
            "a recipe holds at most {MAX_ENTRIES} entries"
        )));
    }
    let mut seen = std::collections::HashSet::new();
    for (i, (tag, _)) in entries.iter().enumerate() {
        if !seen.insert(tag.to_ascii_lowercase()) {
            return Err(ApiError::Malformed(format!("row {}: `{tag}` is given twice", i + 1)));
        }
    }
    Ok(entries)
}

/// The entries as the file holds them (`tag,value` header, text quoted).
pub fn to_csv(entries: &Entries) -> String {
    let mut out = String::from("tag,value\n");
    for (tag, v) in entries {
        let value = match v {
            JsonValue::String(s) => format!("\"{}\"", s.replace('"', "\"\"")),
            other => other.to_string(),
        };
        out.push_str(&format!("{tag},{value}\n"));
    }
    out
}

fn as_object(entries: &Entries) -> JsonValue {
    JsonValue::Object(entries.iter().cloned().collect())
}

/// Reads recipe `name` from the project.
async fn load(st: &AppState, name: &str) -> ApiResult<Entries> {
    let path = file_of(&st.project.lock().await.project.dir, name)?;
    let text = std::fs::read_to_string(&path).map_err(|e| match e.kind() {
        std::io::ErrorKind::NotFound => ApiError::NotFound(format!("no recipe `{name}`")),
        _ => ApiError::Internal(format!("cannot read {}: {e}", path.display())),
    })?;
    // A file edited by hand that does not read: the recipe is refused, with its line.
    parse_csv(&text).map_err(|e| ApiError::Invalid(format!("recipes/{name}.csv does not read: {e}")))
}

/// The recipes of the project, by name.
pub async fn list(State(st): State<Arc<AppState>>) -> ApiResult<Json<JsonValue>> {
    let dir = st.project.lock().await.project.dir.join("recipes");
    let mut names: Vec<String> = match std::fs::read_dir(&dir) {
        Ok(entries) => entries
            .flatten()
            .filter(|e| e.path().is_file())
            .filter_map(|e| e.file_name().to_str()?.strip_suffix(".csv").map(str::to_string))
            .collect(),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Vec::new(),
        Err(e) => return Err(ApiError::Internal(format!("cannot list {}: {e}", dir.display()))),
    };
    names.sort();
    Ok(Json(json!(names)))
}

/// One recipe: a JSON object in file order, or the CSV file when the client asks for `text/csv`.
pub async fn get(State(st): State<Arc<AppState>>, Path(name): Path<String>, headers: HeaderMap) -> ApiResult<Response> {
    let entries = load(&st, &name).await?;
    let wants_csv = headers
        .get(header::ACCEPT)
        .and_then(|v| v.to_str().ok())
        .is_some_and(|v| v.contains("text/csv"));
    if wants_csv {
        return Ok(([(header::CONTENT_TYPE, "text/csv; charset=utf-8")], to_csv(&entries)).into_response());
    }
    // serde_json's map is sorted: keep the file's order by writing the object by hand.
    let mut text = String::from("{");
    for (i, (tag, v)) in entries.iter().enumerate() {
        if i > 0 {
            text.push(',');
        }
        text.push_str(&JsonValue::String(tag.clone()).to_string());
        text.push(':');
        text.push_str(&v.to_string());
    }
    text.push('}');
    Ok(([(header::CONTENT_TYPE, "application/json")], text).into_response())
}

/// Audited (`save_recipe`): parsed from CSV (`Content-Type: text/csv`) or
/// JSON, then written atomically (`recipes/` made if needed).
pub async fn put(
    State(st): State<Arc<AppState>>,
    actor: Actor,
    Path(name): Path<String>,
    headers: HeaderMap,
    bytes: Result<Bytes, axum::extract::rejection::BytesRejection>,
) -> ApiResult<Json<JsonValue>> {
    let text = super::text_body(bytes, "the recipe")?;
    let ctype = headers
        .get(header::CONTENT_TYPE)
        .and_then(|v| v.to_str().ok())
        .unwrap_or("");
    let entries = if ctype.starts_with("text/csv") {
        parse_csv(&text)?
    } else {
        parse_json(&text)?
    };
    save(&st, &actor, &name, &entries, None).await?;
    Ok(Json(json!({"name": name, "entries": entries.len()})))
}

/// Saves `entries` as recipe `name` atomically under its audit row (`save_recipe`).
async fn save(st: &AppState, actor: &Actor, name: &str, entries: &Entries, detail: Option<&str>) -> ApiResult<()> {
    let path = file_of(&st.project.lock().await.project.dir, name)?;
    let csv = to_csv(entries);
    let entry = alba_control::audit::Entry {
        target: Some(format!("recipes/{name}.csv")),
        new: Some(json_text(&as_object(entries))),
        detail: detail.map(str::to_string),
        ..actor.entry(Action::SaveRecipe)
    };
    audited(st, entry, async {
        if let Some(dir) = path.parent() {
            std::fs::create_dir_all(dir)
                .map_err(|e| ApiError::Internal(format!("cannot create {}: {e}", dir.display())))?;
        }
        alba_ir::model::fsutil::write_atomic(&path, |w| w.write_all(csv.as_bytes()))
            .map_err(|e| ApiError::Internal(format!("cannot save {}: {e}", path.display())))
    })
    .await
}

/// Captures the current values (engineer): of the tags of the body's
/// `{"tags": [...]}`, else of the recipe's own tags, saved as recipe
/// `name` (`save_recipe`, detail `captured`) → `{"name", "entries", "values"}`.
/// A tag that cannot be read is `422` naming its row, nothing saved.
pub async fn capture(
    State(st): State<Arc<AppState>>,
    actor: Actor,
    Path(name): Path<String>,
    bytes: Result<Bytes, axum::extract::rejection::BytesRejection>,
) -> ApiResult<Json<JsonValue>> {
    let text = super::text_body(bytes, "the body")?;
    let j: JsonValue = if text.trim().is_empty() {
        JsonValue::Null
    } else {
        serde_json::from_str(&text).map_err(|e| ApiError::Malformed(format!("malformed JSON body: {e}")))?
    };
    let tags: Vec<String> = match j.get("tags") {
        Some(JsonValue::Array(list)) => list
            .iter()
            .enumerate()
            .map(|(i, t)| {
                let t = t
                    .as_str()
                    .ok_or_else(|| ApiError::Malformed(format!("`tags` row {}: a tag name is a string", i + 1)))?;
                check_tag(i + 1, t)?;
                Ok(t.to_string())
            })
            .collect::<ApiResult<_>>()?,
        Some(_) => return Err(ApiError::Malformed("`tags` is a list of tag names".into())),
        None => load(&st, &name).await?.into_iter().map(|(t, _)| t).collect(),
    };
    let mut entries: Entries = Vec::with_capacity(tags.len());
    for (i, tag) in tags.into_iter().enumerate() {
        let v = st
            .control
            .read(&tag)
            .map_err(|r| ApiError::Invalid(format!("recipe `{name}` not captured: row {} (`{tag}`): {r}", i + 1)))?;
        entries.push((tag, v));
    }
    let entries = finish(entries)?;
    save(&st, &actor, &name, &entries, Some("captured")).await?;
    Ok(Json(
        json!({"name": name, "entries": entries.len(), "values": as_object(&entries)}),
    ))
}

/// Writes every entry at one scan boundary (operator): `{"name",
/// "written"}`, or 422 naming the first refused row with nothing written.
pub async fn apply(
    State(st): State<Arc<AppState>>,
    actor: Actor,
    Path(name): Path<String>,
) -> ApiResult<Json<JsonValue>> {
    let entries = load(&st, &name).await?;
    let detail = format!("recipe {name}");
    st.control
        .write_rows(&actor.control(), &entries, Some(&detail))
        .await
        .map_err(|e| {
            let Some(row) = e.row else {
                return ApiError::from(e.refused);
            };
            let tag = entries.get(row).map(|(t, _)| t.as_str()).unwrap_or_default();
            match e.refused {
                // The role is the route's concern: still a 403.
                r @ alba_control::Refused::Role { .. } => ApiError::from(r),
                r => ApiError::Invalid(format!(
                    "recipe `{name}` not applied, nothing written: row {} (`{tag}`): {r}",
                    row + 1
                )),
            }
        })?;
    Ok(Json(json!({"name": name, "written": entries.len()})))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_reads_header_values_and_quotes() {
        let e =
            parse_csv("tag,value\nSpeed,12\nOn,TRUE\nRatio,0.5\nName,\"a, \"\"b\"\"\"\n# note\n\n").expect("parses");
        assert_eq!(
            e,
            vec![
                ("Speed".into(), json!(12)),
                ("On".into(), json!(true)),
                ("Ratio".into(), json!(0.5)),
                ("Name".into(), json!("a, \"b\"")),
            ]
        );
        assert_eq!(parse_csv(&to_csv(&e)).expect("round trip"), e);
    }

    #[test]
    fn bad_recipes_are_refused_with_their_line() {
        for (text, says) in [
            ("tag,value\nSpeed\n", "line 2"),
            ("Sp eed,1\n", "not a tag name"),
            ("A,1\na,2\n", "row 2: `a` is given twice"),
            ("A,\"open\n", "line 1"),
        ] {
            let e = parse_csv(text).expect_err(text).to_string();
            assert!(e.contains(says), "{text:?}: {e}");
        }
    }

    #[test]
    fn json_keeps_the_order_written_and_refuses_structures() {
        let e = parse_json(r#"{"Zeta": 1, "Alpha": false}"#).expect("parses");
        assert_eq!(e[0].0, "Zeta");
        assert_eq!(e[1], ("Alpha".into(), json!(false)));
        for bad in [r#"[1]"#, r#"{"A": [1]}"#, r#"{"A": null}"#, r#"{"A": 1, "A": 2}"#, "{"] {
            assert!(parse_json(bad).is_err(), "{bad}");
        }
    }
}
