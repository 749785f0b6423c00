//! Reading a pipeline file: YAML with `--set` overrides, `${ENV}`
//! substitution (typed only where the key needs it), registered steps taken
//! out and built by their own entries, then serde with the key path of the
//! first error, located in the text.

use super::{locate, ConfigError, PipelineFile, Step, StepsFile};
use crate::methods::SkeletonParams;
use crate::process::step::{Extra, StepRegistry};
use locate::Locations;
use serde_yaml_ng::Value;

/// Parses `text` as a `T` after overrides and substitution, then checks it
/// with `check`; every error located in the text, or in the `--set` that
/// gave the key.
pub(super) fn parse<T: serde::de::DeserializeOwned + HasSteps>(
    text: &str,
    origin: &str,
    overrides: &[String],
    registry: &StepRegistry,
    check: impl Fn(&T) -> Result<(), (String, String)>,
) -> Result<T, ConfigError> {
    // The nesting is checked before anything parses the text (the YAML
    // scanner's time is quadratic in it), the keys located after.
    let mut value = yaml(text, origin)?;
    let r = Reading {
        origin,
        overrides,
        locs: Locations::index(text),
    };
    for o in overrides {
        apply_override(&mut value, o, registry).map_err(|m| ConfigError {
            origin: "--set".into(),
            position: None,
            key: o.clone(),
            message: m,
        })?;
    }
    let mut typed = Typed::new();
    substitute_env(&mut value, "", &mut typed).map_err(|(k, m)| r.at_value(&k, m))?;
    unknown_skeleton_keys(&value).map_err(|(k, m)| r.at_key(&k, m))?;
    collapse_runs_ma(&mut value);
    let extras =
        take_registered(&mut value, registry, &mut typed).map_err(|(k, m)| r.at_key(&k, m))?;
    let mut file: T = r.deserialize(value, typed)?;
    for (i, extra) in extras {
        let steps = file.steps_mut();
        steps.insert(i.min(steps.len()), Step::Extra(extra));
    }
    check(&file).map_err(|(k, m)| r.at_key(&k, m))?;
    Ok(file)
}

/// The text as YAML (not empty, not too deep); `origin` names it in errors.
fn yaml(text: &str, origin: &str) -> Result<Value, ConfigError> {
    let error = |position, message: String| ConfigError {
        origin: origin.to_string(),
        position,
        key: String::new(),
        message,
    };
    if let Some(at) = too_deep(text) {
        return Err(error(
            Some(at),
            format!("invalid YAML: brackets nested deeper than {MAX_NESTING} levels; a pipeline file needs a handful"),
        ));
    }
    let value: Value = serde_yaml_ng::from_str(text).map_err(|e| {
        let pos = e.location().map(|l| (l.line(), l.column()));
        error(pos, format!("invalid YAML: {e}"))
    })?;
    if value.is_null() {
        return Err(error(
            None,
            "the pipeline file is empty; see `skeletonise schema` or pipelines/demo.yaml".into(),
        ));
    }
    Ok(value)
}

/// A file being read: where it came from, the overrides, where its keys are.
struct Reading<'a> {
    origin: &'a str,
    overrides: &'a [String],
    locs: Locations,
}

impl Reading<'_> {
    /// The error at `position` in key `key`: the override's when a `--set`
    /// gave the key, else the file's.
    fn error(&self, position: Option<(usize, usize)>, key: &str, message: String) -> ConfigError {
        let plain = locate::strip_indices(key);
        let overridden = self.overrides.iter().find(|o| {
            let k = o.split_once('=').map_or(o.as_str(), |(k, _)| k);
            plain == k || plain.starts_with(&format!("{k}.")) || k.starts_with(&format!("{plain}."))
        });
        match overridden {
            Some(o) if !key.is_empty() => ConfigError {
                origin: format!("--set {o}"),
                position: None,
                key: key.to_string(),
                message,
            },
            _ => ConfigError {
                origin: self.origin.to_string(),
                position,
                key: key.to_string(),
                message,
            },
        }
    }

    /// The error of key `key`, pointing at the key.
    fn at_key(&self, key: &str, message: String) -> ConfigError {
        self.error(self.locs.key(key), key, message)
    }

    /// The error of key `key`, pointing at its value.
    fn at_value(&self, key: &str, message: String) -> ConfigError {
        self.error(self.locs.value(key), key, message)
    }

    /// The value as a `T`; a substituted number or boolean that was kept a
    /// string is put in as such where the string does not do.
    fn deserialize<T: serde::de::DeserializeOwned>(
        &self,
        mut value: Value,
        mut typed: Typed,
    ) -> Result<T, ConfigError> {
        loop {
            // Enums are written as single-key maps (`prune: {...}`, `densify: {factor: 4}`).
            let mut track = serde_path_to_error::Track::new();
            let de = serde_path_to_error::Deserializer::new(value.clone(), &mut track);
            let e = match serde_yaml_ng::with::singleton_map_recursive::deserialize(de) {
                Ok(file) => return Ok(file),
                Err(e) => e,
            };
            let key = path_string(&track.path());
            if let Some(t) = typed.remove(&key) {
                if let Some(slot) = value_at(&mut value, &key) {
                    *slot = t;
                    continue;
                }
            }
            let inner = e.to_string();
            // Point unknown keys at the key itself.
            let pos = match unknown_field(&inner) {
                Some(f) if key.ends_with(&f) => self.locs.key(&key),
                Some(f) => self.locs.key(&locate::join(&key, &f)),
                None => self.locs.value(&key),
            };
            return Err(self.error(pos, &key, hint(&inner)));
        }
    }
}

/// A file whose `steps` registered steps are put back into after parsing.
pub(super) trait HasSteps {
    /// Its steps.
    fn steps_mut(&mut self) -> &mut Vec<Step>;
}

impl HasSteps for PipelineFile {
    fn steps_mut(&mut self) -> &mut Vec<Step> {
        &mut self.steps
    }
}

impl HasSteps for StepsFile {
    fn steps_mut(&mut self) -> &mut Vec<Step> {
        &mut self.steps
    }
}

/// Takes the registered steps out of `steps` (serde knows only the
/// built-in ones) and builds each from its options: `(index, step)`, in
/// order. A substituted `${…}` that makes a number or a boolean is put in
/// as such where the step does not take the string (as for the built-in
/// steps); a YAML `.nan` or `.inf` is refused at its key.
fn take_registered(
    root: &mut Value,
    registry: &StepRegistry,
    typed: &mut Typed,
) -> Result<Vec<(usize, Extra)>, (String, String)> {
    let Some(steps) = root.get_mut("steps").and_then(Value::as_sequence_mut) else {
        return Ok(Vec::new());
    };
    let mut out = Vec::new();
    let mut i = 0;
    let mut index = 0;
    while i < steps.len() {
        let entry = steps[i]
            .as_mapping()
            .filter(|m| m.len() == 1)
            .and_then(|m| m.keys().next())
            .and_then(Value::as_str)
            .and_then(|k| registry.get(k))
            .copied();
        let Some(entry) = entry else {
            i += 1;
            index += 1;
            continue;
        };
        let body = steps.remove(i);
        let mut yaml = body.get(entry.name).cloned().unwrap_or(Value::Null);
        let at = format!("steps[{index}].{}", entry.name);
        let (options, step) = loop {
            if let Some(k) = not_finite(&yaml, "") {
                return Err((
                    locate::join(&at, &k),
                    "not a finite number: give a number such as 0.5".into(),
                ));
            }
            let options = match &yaml {
                Value::Null => serde_json::Value::Object(Default::default()),
                v => serde_json::to_value(v).map_err(|e| (at.clone(), e.to_string()))?,
            };
            match (entry.build)(&options) {
                Ok(step) => break (options, step),
                Err((k, m)) => {
                    if let Some(t) = typed.remove(&locate::join(&at, &k)) {
                        if let Some(slot) = value_at(&mut yaml, &k).filter(|_| !k.is_empty()) {
                            *slot = t;
                            continue;
                        }
                    }
                    // serde's "unknown field `x`" names the key to point at.
                    let k = match unknown_field(&m) {
                        Some(f) if k.is_empty() => f,
                        _ => k,
                    };
                    let key = if k.is_empty() {
                        at.clone()
                    } else {
                        locate::join(&at, &k)
                    };
                    return Err((key, hint(&m)));
                }
            }
        };
        out.push((
            index,
            Extra {
                entry,
                options,
                step,
                side: None,
            },
        ));
        index += 1;
    }
    Ok(out)
}

/// The key path (below `path`) of the first number in `v` that is NaN or
/// infinite (JSON has none: they would be read as null).
fn not_finite(v: &Value, path: &str) -> Option<String> {
    match v {
        Value::Number(n) => n
            .as_f64()
            .filter(|x| !x.is_finite())
            .map(|_| path.to_string()),
        Value::Mapping(m) => m.iter().find_map(|(k, val)| {
            not_finite(val, &locate::join(path, k.as_str().unwrap_or_default()))
        }),
        Value::Sequence(s) => s
            .iter()
            .enumerate()
            .find_map(|(i, val)| not_finite(val, &format!("{path}[{i}]"))),
        _ => None,
    }
}

/// Deepest nesting of flow collections (`[`, `{`) a pipeline file may have
/// (the YAML deserialiser's own recursion limit).
pub(super) const MAX_NESTING: usize = 128;

/// Where the flow brackets of `text` first nest deeper than
/// [`MAX_NESTING`] (line and column, from 1), if they do. Checked before
/// the YAML parser sees the text: its scanner takes time quadratic in the
/// depth (200 KB of `[` took 18 s) before it reports its recursion limit.
/// Brackets inside quotes and comments do not count; one in a plain scalar
/// does, which only matters past a hundred of them.
fn too_deep(text: &str) -> Option<(usize, usize)> {
    let (mut depth, mut line, mut column) = (0usize, 1usize, 0usize);
    let mut quote: Option<char> = None;
    let (mut comment, mut escaped, mut prev) = (false, false, '\n');
    for c in text.chars() {
        column += 1;
        if c == '\n' {
            (line, column, comment) = (line + 1, 0, false);
            prev = c;
            continue;
        }
        match quote {
            Some('"') if escaped => escaped = false,
            Some('"') if c == '\\' => escaped = true,
            Some(q) if c == q => quote = None,
            Some(_) => {}
            None if comment => {}
            None => match c {
                '#' if prev.is_whitespace() => comment = true,
                '"' | '\'' => quote = Some(c),
                '[' | '{' => {
                    depth += 1;
                    if depth > MAX_NESTING {
                        return Some((line, column));
                    }
                }
                ']' | '}' => depth = depth.saturating_sub(1),
                _ => {}
            },
        }
        prev = c;
    }
    None
}

/// The `skeleton` step takes its own keys and every registered method's
/// options flat (so that serde cannot reject unknown ones itself): a key
/// that none of them owns is an error.
fn unknown_skeleton_keys(root: &Value) -> Result<(), (String, String)> {
    let Some(steps) = root.get("steps").and_then(Value::as_sequence) else {
        return Ok(());
    };
    // The step's keys as its type declares them (methods' options flattened in).
    let schema = serde_json::to_value(schemars::schema_for!(SkeletonParams)).unwrap_or_default();
    let mut allowed: Vec<&str> = schema["properties"]
        .as_object()
        .map(|p| p.keys().map(String::as_str).collect())
        .unwrap_or_default();
    for e in crate::methods::BUILTIN {
        allowed.extend(e.options.iter().copied());
    }
    allowed.sort_unstable();
    allowed.dedup();
    for (i, step) in steps.iter().enumerate() {
        let Some(opts) = step.get("skeleton").and_then(Value::as_mapping) else {
            continue;
        };
        for k in opts.keys() {
            let k = k.as_str().unwrap_or_default();
            if !allowed.contains(&k) {
                let list: Vec<String> = allowed.iter().map(|a| format!("`{a}`")).collect();
                return Err((
                    format!("steps[{i}].skeleton.{k}"),
                    format!(
                        "unknown field `{k}`, expected one of {}; `skeletonise schema` lists every key",
                        list.join(", ")
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// With a `collapse` step, a skeleton step that lists no `methods` runs MA
/// alone: collapse cuts by the medial axis's discs and draws its lines, so
/// the other methods would only be scored and dropped. An explicit list is
/// kept (and must hold MA, `validate::collapse_on_ma`).
fn collapse_runs_ma(root: &mut Value) {
    let Some(steps) = root.get_mut("steps").and_then(Value::as_sequence_mut) else {
        return;
    };
    if !steps.iter().any(|s| s.get("collapse").is_some()) {
        return;
    }
    for step in steps.iter_mut() {
        let Some(m) = step.as_mapping_mut() else {
            continue;
        };
        let Some(body) = m.get_mut("skeleton") else {
            continue;
        };
        if body.is_null() {
            *body = Value::Mapping(Default::default());
        }
        if let Value::Mapping(opts) = body {
            let key = Value::String("methods".into());
            if !opts.contains_key(&key) {
                opts.insert(key, Value::Sequence(vec![Value::String("MA".into())]));
            }
        }
    }
}

fn path_string(p: &serde_path_to_error::Path) -> String {
    use serde_path_to_error::Segment;
    let mut s = String::new();
    for seg in p.iter() {
        match seg {
            Segment::Seq { index } => s.push_str(&format!("[{index}]")),
            Segment::Map { key } | Segment::Enum { variant: key } => {
                if !s.is_empty() {
                    s.push('.');
                }
                s.push_str(key);
            }
            Segment::Unknown => {}
        }
    }
    s
}

fn unknown_field(msg: &str) -> Option<String> {
    let rest = msg
        .strip_prefix("unknown field `")
        .or_else(|| msg.strip_prefix("unknown variant `"))?;
    Some(rest[..rest.find('`')?].to_string())
}

fn hint(msg: &str) -> String {
    if msg.starts_with("unknown variant") && msg.contains("prepare") {
        format!("{msg}; steps are {}", Step::ORDER.join(", "))
    } else if msg.starts_with("unknown field") {
        format!("{msg}; `skeletonise schema` lists every key")
    } else {
        msg.to_string()
    }
}

/// Applies `KEY=VALUE` (dotted path; `steps.NAME.key` addresses a step by name
/// and adds the step when absent; the value is parsed as YAML).
fn apply_override(root: &mut Value, o: &str, registry: &StepRegistry) -> Result<(), String> {
    let (key, val) = o
        .split_once('=')
        .ok_or_else(|| "expected KEY=VALUE, e.g. --set steps.prune.ratio=2".to_string())?;
    let new: Value =
        serde_yaml_ng::from_str(val).map_err(|e| format!("value is not valid YAML: {e}"))?;
    let parts: Vec<&str> = key.split('.').collect();
    if parts.iter().any(|p| p.is_empty()) {
        return Err("empty key segment".into());
    }
    let mut cur = root;
    let mut i = 0;
    while i < parts.len() {
        let seg = parts[i];
        let last = i + 1 == parts.len();
        cur = match cur {
            Value::Mapping(m) => {
                let k = Value::String(seg.to_string());
                if last {
                    m.insert(k, new);
                    return Ok(());
                }
                if !m.contains_key(&k) {
                    m.insert(k.clone(), Value::Mapping(Default::default()));
                }
                m.get_mut(&k).expect("inserted")
            }
            Value::Sequence(seq) => {
                if let Ok(idx) = seg.parse::<usize>() {
                    let len = seq.len();
                    let slot = seq.get_mut(idx).ok_or_else(|| {
                        format!("index {idx} is out of range (the list has {len} entries)")
                    })?;
                    if last {
                        *slot = new;
                        return Ok(());
                    }
                    slot
                } else {
                    // A step addressed by name.
                    let k = Value::String(seg.to_string());
                    let idx = step_index(seq, seg, registry)?;
                    let m = seq[idx].as_mapping_mut().expect("a step is a mapping");
                    if last {
                        m.insert(k, new);
                        return Ok(());
                    }
                    let v = m.get_mut(&k).expect("present");
                    if v.is_null() {
                        *v = Value::Mapping(Default::default());
                    }
                    v
                }
            }
            _ => {
                return Err(format!(
                    "`{}` is not a mapping or list",
                    parts[..i].join(".")
                ))
            }
        };
        i += 1;
    }
    Ok(())
}

/// The index of step `name` in the `steps` list, inserting an empty step in
/// its place in the step order when it is absent.
fn step_index(seq: &mut Vec<Value>, name: &str, registry: &StepRegistry) -> Result<usize, String> {
    let k = Value::String(name.to_string());
    if let Some(idx) = seq
        .iter()
        .position(|v| v.as_mapping().is_some_and(|m| m.contains_key(&k)))
    {
        return Ok(idx);
    }
    let rank = super::validate::rank(name, registry).ok_or_else(|| {
        format!(
            "no step `{name}`; steps are {}",
            super::validate::step_names(registry).join(", ")
        )
    })?;
    let at = seq
        .iter()
        .position(|v| {
            v.as_mapping()
                .and_then(|m| m.keys().next())
                .and_then(Value::as_str)
                .and_then(|n| super::validate::rank(n, registry))
                .is_some_and(|r| r > rank)
        })
        .unwrap_or(seq.len());
    let mut m = serde_yaml_ng::Mapping::new();
    m.insert(k, Value::Mapping(Default::default()));
    seq.insert(at, Value::Mapping(m));
    Ok(at)
}

/// A value that was one `${…}` as a whole, by key path, with the value its
/// text has in YAML: it stays a string unless the key needs a number or a
/// boolean ([`parse`] retries with the typed value where the string fails).
type Typed = std::collections::HashMap<String, Value>;

/// Replaces `${NAME}` and `${NAME:-default}` in every string; records the
/// values that were one `${…}` as a whole in `typed`.
fn substitute_env(v: &mut Value, path: &str, typed: &mut Typed) -> Result<(), (String, String)> {
    match v {
        Value::String(s) if s.contains("${") => {
            let whole = s.starts_with("${") && s.ends_with('}') && s.matches("${").count() == 1;
            let text = expand(s).map_err(|m| (path.to_string(), m))?;
            if whole {
                let t = serde_yaml_ng::from_str::<Value>(&text)
                    .ok()
                    .filter(|t| matches!(t, Value::Number(_) | Value::Bool(_)));
                if let Some(t) = t {
                    typed.insert(path.to_string(), t);
                }
            }
            *v = Value::String(text);
        }
        Value::Mapping(m) => {
            for (k, val) in m.iter_mut() {
                let key = k.as_str().map(str::to_string).unwrap_or_default();
                substitute_env(val, &locate::join(path, &key), typed)?;
            }
        }
        Value::Sequence(s) => {
            for (i, val) in s.iter_mut().enumerate() {
                substitute_env(val, &format!("{path}[{i}]"), typed)?;
            }
        }
        _ => {}
    }
    Ok(())
}

/// The value at key path `path` (`a.b[2].c`, as [`substitute_env`] names
/// them).
fn value_at<'v>(v: &'v mut Value, path: &str) -> Option<&'v mut Value> {
    let mut cur = v;
    for seg in path.split('.') {
        let (key, indices) = match seg.find('[') {
            Some(i) => (&seg[..i], &seg[i..]),
            None => (seg, ""),
        };
        if !key.is_empty() {
            cur = cur.as_mapping_mut()?.get_mut(key)?;
        }
        for idx in indices.split('[').filter(|x| !x.is_empty()) {
            let i: usize = idx.trim_end_matches(']').parse().ok()?;
            cur = cur.as_sequence_mut()?.get_mut(i)?;
        }
    }
    Some(cur)
}

/// `${NAME}` and `${NAME:-default}` in `s` replaced by the environment. A
/// variable that is not set, or set but empty, is an error naming it,
/// unless the expression gives a default (`:-`, as in the shell: used when
/// the variable is unset or empty).
fn expand(s: &str) -> Result<String, String> {
    let mut out = String::new();
    let mut rest = s;
    while let Some(start) = rest.find("${") {
        out.push_str(&rest[..start]);
        let after = &rest[start + 2..];
        let end = after
            .find('}')
            .ok_or_else(|| format!("unclosed `${{` in \"{s}\""))?;
        let expr = &after[..end];
        let (name, default) = match expr.split_once(":-") {
            Some((n, d)) => (n, Some(d)),
            None => (expr, None),
        };
        match (std::env::var(name), default) {
            (Ok(v), _) if !v.is_empty() => out.push_str(&v),
            (_, Some(d)) => out.push_str(d),
            (Ok(_), None) => {
                return Err(format!(
                    "environment variable `{name}` is set but empty; give it a value, or write `${{{name}:-default}}` for a default"
                ))
            }
            (Err(_), None) => {
                return Err(format!(
                    "environment variable `{name}` is not set; export it or write `${{{name}:-default}}`"
                ))
            }
        }
        rest = &after[end + 1..];
    }
    out.push_str(rest);
    Ok(out)
}
