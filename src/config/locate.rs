//! Source positions of every key and value of a YAML document, by key path
//! (`steps[2].prune.ratio`), so that errors found after parsing still name
//! `line:column`.

use std::collections::HashMap;
use yaml_rust2::parser::{Event, Parser};

/// `line:column` (both 1-based) of keys and values by key path.
#[derive(Debug, Default, Clone)]
pub struct Locations {
    values: HashMap<String, (usize, usize)>,
    keys: HashMap<String, (usize, usize)>,
}

enum Frame {
    Map { path: String, key: Option<String> },
    Seq { path: String, index: usize },
}

impl Locations {
    /// Indexes `text`; a document that does not parse yields an empty index
    /// (the YAML error itself carries its position).
    pub fn index(text: &str) -> Self {
        let mut loc = Locations::default();
        let mut parser = Parser::new_from_str(text);
        let mut stack: Vec<Frame> = Vec::new();
        while let Ok((ev, mark)) = parser.next_token() {
            let pos = (mark.line(), mark.col() + 1);
            let starts_node = matches!(
                ev,
                Event::Scalar(..)
                    | Event::MappingStart(..)
                    | Event::SequenceStart(..)
                    | Event::Alias(_)
            );
            let mut node_path = None;
            if starts_node {
                match stack.last_mut() {
                    Some(Frame::Map { path, key }) => match key.take() {
                        None => {
                            // This node is a key.
                            let k = match &ev {
                                Event::Scalar(s, ..) => s.clone(),
                                _ => "?".into(),
                            };
                            let p = join(path, &k);
                            loc.keys.entry(p).or_insert(pos);
                            *key = Some(k);
                            continue;
                        }
                        Some(k) => node_path = Some(join(path, &k)),
                    },
                    Some(Frame::Seq { path, index }) => {
                        node_path = Some(format!("{path}[{index}]"));
                        *index += 1;
                    }
                    None => node_path = Some(String::new()),
                }
            }
            if let Some(p) = &node_path {
                loc.values.entry(p.clone()).or_insert(pos);
            }
            match ev {
                Event::MappingStart(..) => stack.push(Frame::Map {
                    path: node_path.unwrap_or_default(),
                    key: None,
                }),
                Event::SequenceStart(..) => stack.push(Frame::Seq {
                    path: node_path.unwrap_or_default(),
                    index: 0,
                }),
                Event::MappingEnd | Event::SequenceEnd => {
                    stack.pop();
                }
                Event::StreamEnd => break,
                _ => {}
            }
        }
        loc
    }

    /// Position of the value at `path`, or of the nearest enclosing value.
    pub fn value(&self, path: &str) -> Option<(usize, usize)> {
        let mut p = path.to_string();
        loop {
            if let Some(v) = self.values.get(&p).or_else(|| self.keys.get(&p)) {
                return Some(*v);
            }
            p = parent(&p)?;
        }
    }

    /// Position of the key at `path` (falls back to [`Locations::value`]).
    pub fn key(&self, path: &str) -> Option<(usize, usize)> {
        self.keys.get(path).copied().or_else(|| self.value(path))
    }
}

/// A key path without list indices: `steps[2].prune.ratio` → `steps.prune.ratio`
/// (the form of an override's key).
pub fn strip_indices(key: &str) -> String {
    let mut out = String::with_capacity(key.len());
    let mut depth = 0;
    for c in key.chars() {
        match c {
            '[' => depth += 1,
            ']' => depth -= 1,
            _ if depth == 0 => out.push(c),
            _ => {}
        }
    }
    out
}

/// `path.key`, or `key` at the root.
pub fn join(path: &str, key: &str) -> String {
    if path.is_empty() {
        key.to_string()
    } else {
        format!("{path}.{key}")
    }
}

fn parent(p: &str) -> Option<String> {
    if p.is_empty() {
        return None;
    }
    let cut = p.rfind(['.', '[']).unwrap_or(0);
    Some(p[..cut].to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_keys_and_values_in_block_and_flow_style() {
        let t = "input:\n  source: a.gpkg\nsteps:\n  - skeleton: { methods: [CDT] }\n  - prune:\n      ratio: 2\n";
        let l = Locations::index(t);
        assert_eq!(l.value("input.source"), Some((2, 11)));
        assert_eq!(l.key("input.source"), Some((2, 3)));
        assert_eq!(l.value("steps[1].prune.ratio"), Some((6, 14)));
        assert_eq!(l.value("steps[0].skeleton.methods[0]"), Some((4, 27)));
        assert_eq!(l.value("steps[1].prune.nothing").map(|p| p.0), Some(6));
    }
}
