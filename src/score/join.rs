//! Joining another tool's skeleton lines to their polygons, for scoring
//! them (`skeletonise score`, and the QGIS provider's `score` through the
//! Python binding): by key — a skeleton row's key equals a polygon's — or by
//! location — the polygon whose area holds the midpoint of a line's first
//! segment. Rows that join no polygon are counted by why ([`Unjoined`]);
//! a join that joins nothing at all is an error with the reasons
//! ([`Unjoined::nothing_joined`]).

use crate::geometry::parts::polygon_parts;
use crate::geometry::PreparedPolygon;
use geo::{BoundingRect, Geometry, LineString};
use rstar::AABB;
use std::collections::HashMap;

/// Skeleton rows that were joined to no polygon, by why.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Unjoined {
    /// Rows whose key is NULL.
    pub null_key: usize,
    /// Rows whose key no polygon has, with the first such key.
    pub unknown_key: (usize, Option<String>),
    /// Rows without a geometry, or whose geometry has no line (points,
    /// polygons).
    pub not_lines: usize,
    /// Lines (joined by location) that lie in no polygon.
    pub outside: usize,
}

impl Unjoined {
    /// What was left out, in words (empty: nothing).
    pub fn reasons(&self) -> Vec<String> {
        let mut why = Vec::new();
        if self.null_key > 0 {
            why.push(format!("{} with a NULL key", self.null_key));
        }
        if let (n, Some(k)) = &self.unknown_key {
            why.push(format!("{n} with a key no polygon has (e.g. `{k}`)"));
        }
        if self.not_lines > 0 {
            why.push(format!(
                "{} without a line geometry (points, polygons or NULL)",
                self.not_lines
            ));
        }
        if self.outside > 0 {
            why.push(format!("{} lines inside no polygon", self.outside));
        }
        why
    }

    /// The reason of a join that joined no line at all; `keys` names the
    /// options that set the join (`--skeleton-key`/`--polygon-key`).
    pub fn nothing_joined(&self, keys: &str) -> String {
        let why = self.reasons();
        format!(
            "no skeleton line could be joined to a polygon ({}); check {keys} (or, joining by location, that the lines lie in the polygons) and that both layers are the ones meant",
            if why.is_empty() {
                "the layer has no rows".to_string()
            } else {
                why.join(", ")
            }
        )
    }
}

/// The lines of a skeleton row's geometry (none when it has none).
pub fn lines_of(g: Option<&Geometry<f64>>) -> Vec<LineString<f64>> {
    let mut ls = Vec::new();
    if let Some(g) = g {
        crate::geometry::parts::lines_of(g, &mut ls);
    }
    ls
}

/// The lines of every polygon: row `s` of `skeletons` (its key, its lines)
/// goes to the polygon whose key is the same.
pub fn by_key(
    polygon_keys: &[Option<String>],
    skeletons: impl IntoIterator<Item = (Option<String>, Vec<LineString<f64>>)>,
    unjoined: &mut Unjoined,
) -> Vec<Vec<LineString<f64>>> {
    let mut assigned = vec![Vec::new(); polygon_keys.len()];
    let index: HashMap<&str, usize> = polygon_keys
        .iter()
        .enumerate()
        .filter_map(|(i, k)| k.as_deref().map(|k| (k, i)))
        .collect();
    for (key, ls) in skeletons {
        if ls.is_empty() {
            unjoined.not_lines += 1;
            continue;
        }
        let Some(k) = key else {
            unjoined.null_key += 1;
            continue;
        };
        match index.get(k.as_str()) {
            Some(&i) => assigned[i].extend(ls),
            None => {
                unjoined.unknown_key.0 += 1;
                unjoined.unknown_key.1.get_or_insert(k);
            }
        }
    }
    assigned
}

/// The lines of every polygon: each line goes to the polygon (the first
/// in order) whose area holds the midpoint of its first segment.
pub fn by_location(
    polygons: &[Option<&Geometry<f64>>],
    skeletons: impl IntoIterator<Item = Vec<LineString<f64>>>,
    unjoined: &mut Unjoined,
) -> Vec<Vec<LineString<f64>>> {
    let mut assigned = vec![Vec::new(); polygons.len()];
    let prepared: Vec<Vec<PreparedPolygon>> = polygons
        .iter()
        .map(|g| {
            polygon_parts(*g)
                .map(|ps| {
                    ps.iter()
                        .filter_map(|p| PreparedPolygon::new(p).ok())
                        .collect()
                })
                .unwrap_or_default()
        })
        .collect();
    let tree = crate::geometry::box_index(
        polygons
            .iter()
            .map(|g| g.as_ref().and_then(|g| g.bounding_rect())),
    );
    for ls in skeletons {
        if ls.is_empty() {
            unjoined.not_lines += 1;
        }
        for l in ls {
            let Some(w) = l.0.windows(2).find(|w| w[0] != w[1]) else {
                continue;
            };
            let m = (w[0] + w[1]) * 0.5;
            let hit = tree
                .locate_in_envelope_intersecting(&AABB::from_point([m.x, m.y]))
                .map(|c| c.data)
                .filter(|&i| {
                    prepared[i]
                        .iter()
                        .any(|p| p.boundary().contains_with_tolerance(m, 1e-9 * p.extent()))
                })
                .min();
            match hit {
                Some(i) => assigned[i].push(l),
                None => unjoined.outside += 1,
            }
        }
    }
    assigned
}
