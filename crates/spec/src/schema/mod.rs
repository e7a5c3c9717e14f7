//! The JSON Schema of the spec (generated from the types by `schemars`) and the validator
//! that walks a spec value against it, collecting every problem with its dotted path.
//!
//! The schema is the one source of each field's unit (`x-unit`), range
//! (`minimum`/`maximum`/`exclusiveMinimum`/`exclusiveMaximum`), default and documentation:
//! validation, [`crate::paths`] and the Python dataclasses all read it.

use std::borrow::Cow;
use std::sync::OnceLock;

use serde_json::{Map, Value};

use crate::spec::Simulation;

mod check;
pub(crate) use check::{check, check_along, check_definition};

/// The JSON Schema (draft 2020-12) of [`Simulation`].
pub fn schema() -> &'static Value {
    static SCHEMA: OnceLock<Value> = OnceLock::new();
    SCHEMA.get_or_init(|| {
        let schema = schemars::schema_for!(Simulation);
        serde_json::to_value(schema).expect("a generated schema serialises")
    })
}

/// The schema as pretty JSON (what `python/paritysim/spec.schema.json` holds).
pub fn schema_json() -> String {
    serde_json::to_string_pretty(schema()).expect("a generated schema serialises") + "\n"
}

/// A schema node with its `$ref` resolved and merged with its sibling keywords.
pub(crate) fn node(s: &Value) -> Cow<'_, Map<String, Value>> {
    let empty = || Cow::Owned(Map::new());
    let Some(map) = s.as_object() else {
        return empty();
    };
    let Some(reference) = map.get("$ref").and_then(Value::as_str) else {
        return Cow::Borrowed(map);
    };
    let name = reference.trim_start_matches("#/$defs/");
    let Some(target) = schema().get("$defs").and_then(|d| d.get(name)) else {
        return empty();
    };
    // Annotations beside a `$ref` (description, default) change nothing the walker reads: no
    // merge, no copy.
    if map
        .keys()
        .all(|k| matches!(k.as_str(), "$ref" | "description" | "default"))
    {
        return node(target);
    }
    let mut merged = node(target).into_owned();
    for (k, v) in map {
        match (k.as_str(), merged.get_mut(k)) {
            ("$ref", _) => {}
            ("properties", Some(Value::Object(props))) => {
                for (pk, pv) in v.as_object().into_iter().flatten() {
                    props.insert(pk.clone(), pv.clone());
                }
            }
            ("required", Some(Value::Array(req))) => {
                req.extend(v.as_array().into_iter().flatten().cloned());
            }
            _ => {
                merged.insert(k.clone(), v.clone());
            }
        }
    }
    Cow::Owned(merged)
}

fn branches(s: &Map<String, Value>) -> Option<&Vec<Value>> {
    s.get("oneOf")
        .or_else(|| s.get("anyOf"))
        .and_then(Value::as_array)
}

fn is_null_schema(s: &Value) -> bool {
    node(s).get("type").and_then(Value::as_str) == Some("null")
}

/// The `kind` of a tagged-enum branch.
pub(crate) fn tag_of(s: &Map<String, Value>) -> Option<String> {
    let kind = s.get("properties")?.get("kind")?;
    let kind = node(kind);
    kind.get("const")
        .or_else(|| kind.get("enum").and_then(|e| e.get(0)))
        .and_then(Value::as_str)
        .map(str::to_string)
}

/// The branch of a tagged enum (`kind = ...`), an `Option` (`T | null`) or `None`.
pub(crate) enum Branch<'s> {
    /// A plain node.
    Plain,
    /// `Option<T>`: the `T` branch.
    Optional(&'s Value),
    /// Tagged enum: `(tag, branch)` pairs.
    Tagged(Vec<(String, Cow<'s, Map<String, Value>>)>),
    /// Untagged alternatives.
    Untagged(&'s Vec<Value>),
}

pub(crate) fn classify(s: &Map<String, Value>) -> Branch<'_> {
    let Some(list) = branches(s) else {
        return Branch::Plain;
    };
    let non_null: Vec<&Value> = list.iter().filter(|b| !is_null_schema(b)).collect();
    let tagged: Vec<_> = non_null
        .iter()
        .filter_map(|b| {
            let n = node(b);
            tag_of(&n).map(|t| (t, n))
        })
        .collect();
    if !tagged.is_empty() && tagged.len() == non_null.len() {
        return Branch::Tagged(tagged);
    }
    if non_null.len() == 1 {
        return Branch::Optional(non_null[0]);
    }
    Branch::Untagged(list)
}

fn types(s: &Map<String, Value>) -> Vec<&str> {
    match s.get("type") {
        Some(Value::String(t)) => vec![t.as_str()],
        Some(Value::Array(ts)) => ts.iter().filter_map(Value::as_str).collect(),
        _ => Vec::new(),
    }
}

fn num(s: &Map<String, Value>, key: &str) -> Option<f64> {
    s.get(key).and_then(Value::as_f64)
}

/// A bound as a person writes it: `1e-30`, not thirty digits (`{}` of an f64 never uses an
/// exponent); `0.1`, `86400000` as they are.
fn bound(v: f64) -> String {
    if v != 0.0 && (v.abs() < 1e-4 || v.abs() >= 1e16) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

/// The unit of a field (`x-unit`), if any.
pub(crate) fn unit(s: &Map<String, Value>) -> Option<String> {
    s.get("x-unit").and_then(Value::as_str).map(str::to_string)
}

/// Human-readable range of a numeric node, e.g. `in (0, 10] mm`.
pub(crate) fn range_text(s: &Map<String, Value>) -> String {
    let lo = num(s, "exclusiveMinimum")
        .map(|v| format!("({}", bound(v)))
        .or_else(|| num(s, "minimum").map(|v| format!("[{}", bound(v))));
    let hi = num(s, "exclusiveMaximum")
        .map(|v| format!("{})", bound(v)))
        .or_else(|| num(s, "maximum").map(|v| format!("{}]", bound(v))));
    let range = match (lo, hi) {
        (Some(lo), Some(hi)) => format!("in {lo}, {hi}"),
        (Some(lo), None) => format!("in {lo}, inf)"),
        (None, Some(hi)) => format!("in (-inf, {hi}"),
        (None, None) => String::new(),
    };
    match unit(s) {
        Some(u) if u != "1" => format!("{range} {u}"),
        _ => range,
    }
}

/// What a node accepts, for messages and [`crate::paths`].
pub(crate) fn describe(s: &Value) -> String {
    let s = node(s);
    if let Some(values) = s.get("enum").and_then(Value::as_array) {
        return format!("one of {}", join_values(values));
    }
    if let Some(c) = s.get("const") {
        return format!("{c}");
    }
    match classify(&s) {
        Branch::Tagged(t) => {
            let tags: Vec<_> = t.iter().map(|(k, _)| k.as_str()).collect();
            return format!("a table with kind = one of {}", tags.join(", "));
        }
        Branch::Optional(inner) => return describe(inner),
        Branch::Untagged(list) => {
            let parts: Vec<_> = list.iter().map(describe).collect();
            return parts.join(" or ");
        }
        Branch::Plain => {}
    }
    let t = types(&s);
    if t.contains(&"integer") {
        format!("an integer {}", range_text(&s))
            .trim_end()
            .to_string()
    } else if t.contains(&"number") {
        format!("a number {}", range_text(&s))
            .trim_end()
            .to_string()
    } else if t.contains(&"string") {
        "a string".into()
    } else if t.contains(&"boolean") {
        "true or false".into()
    } else if t.contains(&"array") {
        "a list".into()
    } else if t.contains(&"object") {
        "a table".into()
    } else {
        "a value".into()
    }
}

fn join_values(values: &[Value]) -> String {
    values
        .iter()
        .map(|v| v.as_str().map_or_else(|| v.to_string(), str::to_string))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Joins a parent path and a key.
pub(crate) fn join(path: &str, key: &str) -> String {
    if path.is_empty() {
        key.to_string()
    } else {
        format!("{path}.{key}")
    }
}

/// Where a walk limited to a few canonical paths goes at a child `step` (an object's key, an
/// array's `[i]`): the one rule of the path listing's and the schema check's limited walks.
pub(crate) enum Enter<'a> {
    /// Every field below the child (it is one of the paths).
    All,
    /// Only these paths, relative to the child (`a.b`, `[0].c`).
    Only(Vec<&'a str>),
    /// Not the child.
    Skip,
}

/// [`Enter`] at the child `step` of a node for the paths `only`, relative to that node.
pub(crate) fn enter<'a>(only: &[&'a str], step: &str) -> Enter<'a> {
    let mut below = Vec::new();
    for w in only {
        let Some(rest) = w.strip_prefix(step) else {
            continue;
        };
        if rest.is_empty() {
            return Enter::All;
        }
        if let Some(r) = rest.strip_prefix('.') {
            below.push(r);
        } else if rest.starts_with('[') {
            below.push(rest);
        }
    }
    if below.is_empty() {
        Enter::Skip
    } else {
        Enter::Only(below)
    }
}

/// The nearest candidate ([`close`]), when one is close enough.
pub fn nearest<'a>(word: &str, candidates: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    close(word, candidates, 1).into_iter().next()
}

/// The last segment of a dotted name (`balance_spring` of `drivetrain.balance_spring`).
fn last_segment(name: &str) -> &str {
    name.rsplit_once('.').map_or(name, |(_, last)| last)
}

/// The words of a name's segment (`balance`, `spring`; `of` and `per` carry no meaning).
fn words(segment: &str) -> impl Iterator<Item = &str> {
    segment
        .split(['.', '_', '[', ']'])
        .filter(|w| !w.is_empty() && !matches!(*w, "of" | "per"))
}

/// The edit distance of `a` and `b` when it is a plausible typo: at most 2, or a third of the
/// longer (in characters), and less than the shorter (`k3` is no typo of `c0`: nothing of it
/// is left).
fn typo(a: &str, b: &str) -> Option<usize> {
    if a.is_empty() || b.is_empty() {
        return None;
    }
    let d = strsim::levenshtein(a, b);
    let (a, b) = (a.chars().count(), b.chars().count());
    (d <= 2.max(a.max(b) / 3) && d < a.min(b)).then_some(d)
}

/// At most `limit` candidates close to `word`, nearest first (case-insensitive): a typo of the
/// whole name or of its last path segment (ranked by edit distance; on a tie the siblings of
/// `word`'s parent path, then the candidates' order), then candidates that contain `word`'s
/// last segment, then those sharing a word with it (`balance_spring` for the deprecated
/// `balance_stiffness`).
///
/// The one "did you mean" ranking of paritysim: the spec's checks, [`crate::paths`] and the
/// Python facade (`paritysim._errors.close_names`, through the bindings) all use it.
pub fn close<'a>(
    word: &str,
    candidates: impl IntoIterator<Item = &'a str>,
    limit: usize,
) -> Vec<&'a str> {
    let word = word.to_lowercase();
    let tail = last_segment(&word);
    let parent = word.rsplit_once('.').map(|(p, _)| p);
    let tail_words: Vec<&str> = words(tail).collect();
    let mut seen = std::collections::HashSet::new();
    let mut ranked: Vec<(usize, bool, usize, &str)> = Vec::new();
    for (order, candidate) in candidates.into_iter().enumerate() {
        if !seen.insert(candidate) {
            continue;
        }
        let text = candidate.to_lowercase();
        let last = last_segment(&text);
        let score = match (typo(&word, &text), typo(tail, last)) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        }
        .or_else(|| (tail.chars().count() >= 3 && text.contains(tail)).then_some(50))
        .or_else(|| {
            let mut shared: Vec<&str> = words(last).filter(|w| tail_words.contains(w)).collect();
            shared.sort_unstable();
            shared.dedup();
            (!shared.is_empty()).then(|| 60 - shared.len().min(9))
        });
        if let Some(score) = score {
            let sibling = parent.is_some() && text.rsplit_once('.').map(|(p, _)| p) == parent;
            ranked.push((score, !sibling, order, candidate));
        }
    }
    ranked.sort_unstable();
    ranked.into_iter().take(limit).map(|r| r.3).collect()
}

/// Names a message shows at most: a handful of close ones, never a list of a hundred.
pub const SHOWN_NAMES: usize = 5;

/// "a known name: did you mean `x`? (also close: ...; 57 names)": the allowed text of an
/// unknown name, with the whole list only when it is short ([`suggestion_for`]).
pub fn suggestion<'a>(word: &str, valid: impl IntoIterator<Item = &'a str>) -> String {
    suggestion_for(word, valid, "a known name", None)
}

/// The allowed text of an unknown `word` among `valid`: `what` it must be (e.g. "a known
/// name"), the nearest name and at most [`SHOWN_NAMES`] close ones ([`close`]), never the whole
/// list unless it is that short. `listed_by` says where the full list is (e.g.
/// "ps.spec_paths(spec) lists all 120"); without it the count, and a few names when none is
/// close. The one "did you mean" text of paritysim (the Python facade's
/// `paritysim._errors.suggest` calls it through the bindings).
pub fn suggestion_for<'a>(
    word: &str,
    valid: impl IntoIterator<Item = &'a str>,
    what: &str,
    listed_by: Option<&str>,
) -> String {
    let mut list: Vec<&str> = Vec::new();
    for name in valid {
        if !list.contains(&name) {
            list.push(name);
        }
    }
    let near = close(word, list.iter().copied(), SHOWN_NAMES);
    let quoted = |names: &[&str]| {
        names
            .iter()
            .map(|n| format!("`{n}`"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    if list.len() <= SHOWN_NAMES {
        return match near.first() {
            // Read after "must be": "one of: `a`, `b`: did you mean `a`?".
            Some(best) => format!("one of: {}: did you mean `{best}`?", quoted(&list)),
            None => format!("one of: {}", quoted(&list)),
        };
    }
    let count = format!("{} names", list.len());
    let listed = listed_by.unwrap_or(&count);
    match near.split_first() {
        Some((best, [])) => format!("{what}: did you mean `{best}`? ({listed})"),
        Some((best, others)) => format!(
            "{what}: did you mean `{best}`? (also close: {}; {listed})",
            quoted(others)
        ),
        None => match listed_by {
            Some(listed) => format!("{what} (none close to `{word}`; {listed})"),
            None => format!(
                "{what} (none close to `{word}`; {count}, e.g. {})",
                quoted(&list[..3])
            ),
        },
    }
}

/// `requested` names (`None`: all of `valid`) checked against `valid`: an unknown one is an
/// [`Error::InvalidParameter`](paritysim_error::Error::InvalidParameter) naming `field`, the
/// name and a handful of close valid names ([`suggestion`]), not the whole list.
///
/// # Errors
/// The first unknown name.
pub fn select(
    field: &str,
    requested: Option<&[String]>,
    valid: &[String],
) -> paritysim_error::Result<Vec<String>> {
    let Some(requested) = requested else {
        return Ok(valid.to_vec());
    };
    if let Some(name) = requested.iter().find(|n| !valid.contains(n)) {
        // A force or weight metric the device does not have: say why first.
        let why = match field {
            "metrics" => paritysim_dynamics::metrics::unavailable_reason(name, valid),
            _ => None,
        };
        return Err(paritysim_error::Error::invalid(
            field.to_string(),
            format!("{name:?}"),
            format!(
                "{}{}",
                why.unwrap_or(""),
                suggestion(name, valid.iter().map(String::as_str))
            ),
        ));
    }
    Ok(requested.to_vec())
}

fn short(v: &Value) -> String {
    let s = v.to_string();
    if s.len() > 60 {
        format!("{}...", &s[..57])
    } else {
        s
    }
}

/// Defaults of the tagged-enum specs (`Drivetrain`, `Aero`, `Waveform`) as JSON text: the
/// variant a table without `kind` takes, for the generated Python dataclasses.
pub fn tagged_defaults_json() -> String {
    serde_json::json!({
        "Drivetrain": crate::Drivetrain::default(),
        "Aero": crate::Aero::default(),
        "Waveform": crate::Waveform::default(),
    })
    .to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    const PATHS: [&str; 8] = [
        "drivetrain.crank_mm",
        "drivetrain.rod_mm",
        "drivetrain.balance_spring",
        "actuator.force_per_volt",
        "options.max_wall_ms",
        "options.max_cycles",
        "wings[0].aero.omega1",
        "wings[1].aero.omega1",
    ];

    #[test]
    fn close_ranks_typos_then_containment_then_shared_words() {
        // A typo of the whole name, of its last segment, case-insensitive.
        assert_eq!(close("drivetrain.crank", PATHS, 1), ["drivetrain.crank_mm"]);
        assert_eq!(
            close("ACTUATOR.Force_Per_Vol", PATHS, 1),
            ["actuator.force_per_volt"]
        );
        // On a tie, the sibling of the word's parent path first.
        assert_eq!(
            close("wings[1].aero.omega2", PATHS, 1),
            ["wings[1].aero.omega1"]
        );
        // Containment: `max_wall` is in `options.max_wall_ms`.
        assert_eq!(close("max_wall", PATHS, 1), ["options.max_wall_ms"]);
        // A shared word: the deprecated `balance_stiffness` finds `balance_spring`.
        assert_eq!(
            close("balance_stiffness", PATHS, 5),
            ["drivetrain.balance_spring"]
        );
        assert!(close("zzz", PATHS, 5).is_empty());
        // A segment with nothing left of it is no typo (`k3` of `omega1`, of a `c0`), but the
        // whole name still is one of a sibling.
        assert_eq!(
            close("drivetrain.k3", ["configuration.c0", "drivetrain.kind"], 5),
            ["drivetrain.kind"]
        );
        assert_eq!(close("options.max", PATHS, 5).len(), 2);
    }

    #[test]
    fn a_range_reads_as_written() {
        let range = |v: Value| range_text(v.as_object().unwrap());
        let atol = serde_json::json!({"minimum": 1e-30, "maximum": 0.1});
        assert_eq!(range(atol), "in [1e-30, 0.1]");
        let wall =
            serde_json::json!({"exclusiveMinimum": 0.0, "maximum": 86_400_000.0, "x-unit": "ms"});
        assert_eq!(range(wall), "in (0, 86400000] ms");
    }

    #[test]
    fn suggestion_shows_a_handful_never_the_list() {
        let many: Vec<String> = (0..100).map(|i| format!("name_{i:03}")).collect();
        let text = suggestion_for(
            "name_0",
            many.iter().map(String::as_str),
            "a name",
            Some("x lists all 100"),
        );
        assert!(
            text.starts_with("a name: did you mean `name_000`?"),
            "{text}"
        );
        assert_eq!(text.matches('`').count(), 2 * SHOWN_NAMES, "{text}");
        assert!(text.ends_with("x lists all 100)"), "{text}");
        let none = suggestion("qqqq", many.iter().map(String::as_str));
        assert_eq!(
            none,
            "a known name (none close to `qqqq`; 100 names, e.g. `name_000`, `name_001`, `name_002`)"
        );
        assert_eq!(
            suggestion("lfit", ["lift", "drag"]),
            "one of: `lift`, `drag`: did you mean `lift`?"
        );
        assert_eq!(
            suggestion("qqq", ["lift", "drag"]),
            "one of: `lift`, `drag`"
        );
    }

    #[test]
    fn select_names_the_field_and_the_nearest_name() {
        let valid: Vec<String> = PATHS.iter().map(|s| s.to_string()).collect();
        assert_eq!(select("metrics", None, &valid).unwrap(), valid);
        let asked = vec!["options.max_cycles".to_string()];
        assert_eq!(select("metrics", Some(&asked), &valid).unwrap(), asked);
        let err = select("metrics", Some(&["options.max_cycle".to_string()]), &valid).unwrap_err();
        assert_eq!(err.field(), Some("metrics"));
        assert!(
            err.to_string()
                .contains("did you mean `options.max_cycles`?"),
            "{err}"
        );
        assert!(!err.to_string().contains("crank_mm"), "{err}");
    }
}
