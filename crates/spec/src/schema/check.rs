//! The validator: the schema compiled once into a table of checks, then walked per spec value,
//! collecting every problem with its dotted path.
//!
//! Why compiled: walking the JSON schema itself looked up every keyword of every node by
//! SipHash in its map and rebuilt the tag list of each tagged enum per visit: ≈ 0.75 M
//! instructions per spec, an eighth of a whole §3.3 trial called from Python (callgrind). The
//! compiled walk reads plain fields, and a path string is built only for a problem.

use std::collections::HashMap;
use std::sync::OnceLock;

use paritysim_error::Problem;
use serde_json::{Map, Value};

use super::{
    Branch, Enter, classify, describe, enter, is_null_schema, join_values, node, num, schema,
    short, suggestion, tag_of, types,
};

/// Index of a compiled node in [`Compiled::nodes`].
type Id = usize;

/// What a schema node checks (the cases of the former walk over the schema, in its order).
enum Node {
    /// `Option<T>`: null, or the inner node.
    Optional(Id),
    /// A tagged enum: the `kind` names and each branch's plain check.
    Tagged {
        schema: &'static Value,
        tags: Vec<(&'static str, Id)>,
    },
    /// Untagged alternatives: fits when one branch has no problem.
    Untagged {
        schema: &'static Value,
        branches: Vec<Id>,
        null_ok: bool,
    },
    /// A node without alternatives.
    Plain(Plain),
}

/// Bits of [`Plain::types`].
const NULL: u8 = 1;
const BOOLEAN: u8 = 2;
const NUMBER: u8 = 4;
const INTEGER: u8 = 8;
const STRING: u8 = 16;
const ARRAY: u8 = 32;
const OBJECT: u8 = 64;

struct Plain {
    /// The schema node, for messages.
    map: &'static Map<String, Value>,
    allowed: Option<&'static Vec<Value>>,
    constant: Option<&'static Value>,
    /// The `type` keyword's bits (0: no type, anything goes).
    types: u8,
    minimum: Option<f64>,
    exclusive_minimum: Option<f64>,
    maximum: Option<f64>,
    exclusive_maximum: Option<f64>,
    min_items: Option<f64>,
    max_items: Option<f64>,
    items: Option<Id>,
    properties: Vec<(&'static str, Id)>,
    closed: bool,
    /// A tagged-enum branch: its `kind` was checked by the enum.
    tagged: bool,
    /// Required names, with what a missing one accepts (its description).
    required: Vec<(&'static str, Option<&'static Value>)>,
}

#[derive(Default)]
struct Compiled {
    nodes: Vec<Node>,
    /// Nodes by the address of the schema value (or plain map) they came from.
    values: HashMap<usize, Id>,
    plains: HashMap<usize, Id>,
}

/// A schema node with `$ref` resolved, as a `'static` map: merged nodes (a `$ref` with
/// sibling keywords) are leaked once; the compiled table lives for the process.
fn resolved(s: &'static Value) -> &'static Map<String, Value> {
    leaked(node(s))
}

/// A borrowed node as is, a merged one leaked (compiled once per process).
fn leaked(map: std::borrow::Cow<'static, Map<String, Value>>) -> &'static Map<String, Value> {
    match map {
        std::borrow::Cow::Borrowed(map) => map,
        std::borrow::Cow::Owned(map) => Box::leak(Box::new(map)),
    }
}

impl Compiled {
    fn push(&mut self, n: Node) -> Id {
        self.nodes.push(n);
        self.nodes.len() - 1
    }

    /// The check of `schema` as the former `check` read it.
    fn value(&mut self, schema: &'static Value) -> Id {
        let key = schema as *const Value as usize;
        if let Some(&id) = self.values.get(&key) {
            return id;
        }
        // Reserved first: a recursive definition refers to itself.
        let id = self.push(Node::Optional(usize::MAX));
        self.values.insert(key, id);
        let s = resolved(schema);
        let compiled = match classify(s) {
            Branch::Plain => Node::Plain(self.plain_fields(s)),
            Branch::Optional(inner) => {
                // `inner` borrows the 'static schema through `s`.
                let inner: &'static Value = inner;
                Node::Optional(self.value(inner))
            }
            Branch::Tagged(variants) => {
                let tags = variants
                    .into_iter()
                    .map(|(tag, branch)| {
                        let map = leaked(branch);
                        let tag: &'static str = Box::leak(tag.into_boxed_str());
                        (tag, self.plain(map))
                    })
                    .collect();
                Node::Tagged { schema, tags }
            }
            Branch::Untagged(list) => {
                let list: &'static Vec<Value> = list;
                Node::Untagged {
                    schema,
                    branches: list.iter().map(|b| self.value(b)).collect(),
                    null_ok: list.iter().any(is_null_schema),
                }
            }
        };
        self.nodes[id] = compiled;
        id
    }

    /// The check of a plain map (a tagged branch: no alternatives looked for).
    fn plain(&mut self, map: &'static Map<String, Value>) -> Id {
        let key = map as *const Map<String, Value> as usize;
        if let Some(&id) = self.plains.get(&key) {
            return id;
        }
        let id = self.push(Node::Optional(usize::MAX));
        self.plains.insert(key, id);
        let fields = self.plain_fields(map);
        self.nodes[id] = Node::Plain(fields);
        id
    }

    fn plain_fields(&mut self, s: &'static Map<String, Value>) -> Plain {
        let bits = types(s).iter().fold(0, |b, t| {
            b | match *t {
                "null" => NULL,
                "boolean" => BOOLEAN,
                "number" => NUMBER,
                "integer" => INTEGER,
                "string" => STRING,
                "array" => ARRAY,
                "object" => OBJECT,
                _ => 0,
            }
        });
        let props = s.get("properties").and_then(Value::as_object);
        let properties = props
            .into_iter()
            .flatten()
            .map(|(k, v)| (k.as_str(), self.value(v)))
            .collect();
        let required = s
            .get("required")
            .and_then(Value::as_array)
            .into_iter()
            .flatten()
            .filter_map(Value::as_str)
            .map(|r| (r, props.and_then(|p| p.get(r))))
            .collect();
        Plain {
            map: s,
            allowed: s.get("enum").and_then(Value::as_array),
            constant: s.get("const"),
            types: bits,
            minimum: num(s, "minimum"),
            exclusive_minimum: num(s, "exclusiveMinimum"),
            maximum: num(s, "maximum"),
            exclusive_maximum: num(s, "exclusiveMaximum"),
            min_items: num(s, "minItems"),
            max_items: num(s, "maxItems"),
            items: s.get("items").map(|item| self.value(item)),
            properties,
            closed: s.get("additionalProperties") == Some(&Value::Bool(false))
                || s.get("unevaluatedProperties") == Some(&Value::Bool(false)),
            tagged: tag_of(s).is_some(),
            required,
        }
    }
}

/// The compiled schema and the ids of its root and `$defs` entries.
struct Validator {
    compiled: Compiled,
    root: Id,
    definitions: HashMap<&'static str, Id>,
}

fn validator() -> &'static Validator {
    static VALIDATOR: OnceLock<Validator> = OnceLock::new();
    VALIDATOR.get_or_init(|| {
        let mut compiled = Compiled::default();
        let root = compiled.value(schema());
        let definitions = schema()
            .get("$defs")
            .and_then(Value::as_object)
            .into_iter()
            .flatten()
            .map(|(name, def)| (name.as_str(), compiled.value(def)))
            .collect();
        Validator {
            compiled,
            root,
            definitions,
        }
    })
}

/// A dotted path, built as text only when a problem is reported.
#[derive(Clone, Copy)]
enum Path<'a> {
    Root(&'a str),
    Key(&'a Path<'a>, &'a str),
    Index(&'a Path<'a>, usize),
}

impl Path<'_> {
    /// The field a problem here names: the path, or `spec` for the document itself.
    fn field(&self) -> String {
        let text = self.text();
        if text.is_empty() {
            "spec".to_string()
        } else {
            text
        }
    }

    fn text(&self) -> String {
        match self {
            Path::Root(p) => (*p).to_string(),
            Path::Key(parent, key) => super::join(&parent.text(), key),
            Path::Index(parent, i) => format!("{}[{i}]", parent.text()),
        }
    }
}

/// Walks `value` against the whole spec schema, pushing every problem.
pub(crate) fn check(value: &Value, problems: &mut Vec<Problem>) {
    let v = validator();
    walk(
        &v.compiled.nodes,
        v.root,
        value,
        (&Path::Root(""), None),
        problems,
    );
}

/// [`check`] of a value that was a valid spec before the fields at the canonical `paths` were
/// set: only those fields (and the objects on their way) are walked. The whole check was
/// most of reading a sensitivity's perturbed spec (docs/findings.md §30, session 21).
pub(crate) fn check_along(value: &Value, paths: &[&str], problems: &mut Vec<Problem>) {
    let v = validator();
    let only = (&Path::Root(""), Some(paths));
    walk(&v.compiled.nodes, v.root, value, only, problems);
}

/// Walks `value` against the schema's definition `name` (e.g. `Drivetrain`), with paths under
/// `path`. A name the schema does not define checks nothing.
pub(crate) fn check_definition(value: &Value, name: &str, path: &str, problems: &mut Vec<Problem>) {
    let v = validator();
    if let Some(&id) = v.definitions.get(name) {
        walk(
            &v.compiled.nodes,
            id,
            value,
            (&Path::Root(path), None),
            problems,
        );
    }
}

/// The fields a walk enters below its node: all (`None`), or only those on the way to the
/// `only` paths, written relative to the node (`.a.b[2]`, `[0].c`; an empty one: all below).
type Only<'a> = Option<&'a [&'a str]>;

fn walk(
    nodes: &[Node],
    id: Id,
    value: &Value,
    (path, only): (&Path<'_>, Only<'_>),
    problems: &mut Vec<Problem>,
) {
    match &nodes[id] {
        Node::Plain(plain) => walk_plain(nodes, plain, value, (path, only), problems),
        Node::Optional(inner) => {
            if !value.is_null() {
                walk(nodes, *inner, value, (path, only), problems);
            }
        }
        Node::Tagged { schema, tags } => {
            let Some(obj) = value.as_object() else {
                problems.push(Problem::new(path.field(), short(value), describe(schema)));
                return;
            };
            let names = || tags.iter().map(|(t, _)| *t);
            let one_of = || format!("one of {}", names().collect::<Vec<_>>().join(", "));
            match obj.get("kind") {
                None => problems.push(Problem::new(
                    Path::Key(path, "kind").text(),
                    "missing",
                    one_of(),
                )),
                Some(Value::String(kind)) => match tags.iter().find(|(t, _)| t == kind) {
                    Some((_, branch)) => walk(nodes, *branch, value, (path, only), problems),
                    None => problems.push(Problem::new(
                        Path::Key(path, "kind").text(),
                        format!("{kind:?}"),
                        suggestion(kind, names()),
                    )),
                },
                Some(other) => problems.push(Problem::new(
                    Path::Key(path, "kind").text(),
                    short(other),
                    one_of(),
                )),
            }
        }
        Node::Untagged {
            schema,
            branches,
            null_ok,
        } => {
            if value.is_null() && *null_ok {
                return;
            }
            let fits = branches.iter().any(|&b| {
                let mut sub = Vec::new();
                walk(nodes, b, value, (path, only), &mut sub);
                sub.is_empty()
            });
            if !fits {
                problems.push(Problem::new(path.field(), short(value), describe(schema)));
            }
        }
    }
}

fn walk_plain(
    nodes: &[Node],
    s: &Plain,
    value: &Value,
    (path, only): (&Path<'_>, Only<'_>),
    problems: &mut Vec<Problem>,
) {
    let described = || describe(&Value::Object(s.map.clone()));
    if let Some(allowed) = s.allowed {
        if !allowed.contains(value) {
            let names: Vec<&str> = allowed.iter().filter_map(Value::as_str).collect();
            let text = match value.as_str() {
                Some(word) => suggestion(word, names.iter().copied()),
                None => format!("one of {}", join_values(allowed)),
            };
            problems.push(Problem::new(path.field(), short(value), text));
        }
        return;
    }
    if let Some(c) = s.constant {
        if c != value {
            problems.push(Problem::new(path.field(), short(value), format!("{c}")));
        }
        return;
    }
    let t = s.types;
    if t == 0 {
        return;
    }
    let fits = match value {
        Value::Null => t & NULL != 0,
        Value::Bool(_) => t & BOOLEAN != 0,
        Value::Number(n) => t & NUMBER != 0 || (t & INTEGER != 0 && (n.is_u64() || n.is_i64())),
        Value::String(_) => t & STRING != 0,
        Value::Array(_) => t & ARRAY != 0,
        Value::Object(_) => t & OBJECT != 0,
    };
    if !fits {
        let allowed = described();
        let allowed = if value.is_string() && t & (NUMBER | INTEGER) != 0 {
            format!("{allowed} (finite)")
        } else {
            allowed
        };
        problems.push(Problem::new(path.field(), short(value), allowed));
        return;
    }
    match value {
        Value::Number(n) => {
            let x = n.as_f64().unwrap_or(f64::NAN);
            let below =
                s.minimum.is_some_and(|m| x < m) || s.exclusive_minimum.is_some_and(|m| x <= m);
            let above =
                s.maximum.is_some_and(|m| x > m) || s.exclusive_maximum.is_some_and(|m| x >= m);
            if below || above || !x.is_finite() {
                problems.push(Problem::new(path.field(), n.to_string(), described()));
            }
        }
        Value::Array(items) => {
            let len = items.len() as f64;
            let (lo, hi) = (s.min_items, s.max_items);
            if lo.is_some_and(|m| len < m) || hi.is_some_and(|m| len > m) {
                let want = match (lo, hi) {
                    (Some(a), Some(b)) if a == b => format!("exactly {a} items"),
                    (Some(a), Some(b)) => format!("{a} to {b} items"),
                    (Some(a), None) => format!("at least {a} items"),
                    (None, Some(b)) => format!("at most {b} items"),
                    (None, None) => String::new(),
                };
                problems.push(Problem::new(
                    path.field(),
                    format!("{} items", items.len()),
                    want,
                ));
            }
            if let Some(item) = s.items {
                for (i, v) in items.iter().enumerate() {
                    let below;
                    let only = match only.map(|o| enter(o, &format!("[{i}]"))) {
                        None | Some(Enter::All) => None,
                        Some(Enter::Only(paths)) => {
                            below = paths;
                            Some(&below[..])
                        }
                        Some(Enter::Skip) => continue,
                    };
                    walk(nodes, item, v, (&Path::Index(path, i), only), problems);
                }
            }
        }
        Value::Object(obj) => {
            for (k, v) in obj {
                let below;
                let only = match only.map(|o| enter(o, k)) {
                    None | Some(Enter::All) => None,
                    Some(Enter::Only(paths)) => {
                        below = paths;
                        Some(&below[..])
                    }
                    Some(Enter::Skip) => continue,
                };
                match s.properties.iter().find(|(name, _)| *name == k.as_str()) {
                    // The tag of a tagged enum was checked by the caller.
                    Some(_) if k == "kind" && s.tagged => {}
                    Some(&(_, sub)) => walk(nodes, sub, v, (&Path::Key(path, k), only), problems),
                    None if s.closed => problems.push(Problem::new(
                        Path::Key(path, k).text(),
                        "<unknown field>",
                        suggestion(k, s.properties.iter().map(|(name, _)| *name)),
                    )),
                    None => {}
                }
            }
            for &(r, property) in &s.required {
                if !obj.contains_key(r) {
                    let allowed = property.map_or_else(|| "required".to_string(), describe);
                    problems.push(Problem::new(Path::Key(path, r).text(), "missing", allowed));
                }
            }
        }
        _ => {}
    }
}
