//! The output plan: made once from the pipeline file, it says which layers
//! a run writes and which of their columns, for every part of the tool that
//! needs to know — the per-feature path (what rows to keep), the writer,
//! the Python table and the reader of an output.

use super::rows::{Layer, BUILTIN};
use crate::layer::{ColumnType, StepLayer, When};
use std::collections::BTreeSet;

/// The layers and columns of a run's output (see the module documentation).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Plan {
    skeleton_layer: String,
    holds: BTreeSet<When>,
    steps: Vec<&'static StepLayer>,
}

impl Plan {
    /// The plan of an output whose skeleton layer is called
    /// `skeleton_layer`, where the conditions `holds` hold (besides
    /// [`When::Always`]) and registered steps add the layers `steps`.
    pub fn new(
        skeleton_layer: impl Into<String>,
        holds: impl IntoIterator<Item = When>,
        steps: &[&'static StepLayer],
    ) -> Self {
        let mut holds: BTreeSet<When> = holds.into_iter().collect();
        holds.insert(When::Always);
        Self {
            skeleton_layer: skeleton_layer.into(),
            holds,
            steps: steps.to_vec(),
        }
    }

    /// Whether `when` holds.
    pub fn holds(&self, when: When) -> bool {
        self.holds.contains(&when)
    }

    /// The name of the skeleton layer (`output.layer`).
    pub fn skeleton_layer(&self) -> &str {
        &self.skeleton_layer
    }

    /// The layers written, in order: the built-in ones whose condition
    /// holds (the run record last), then the registered steps'.
    pub fn layers(&self) -> Vec<&dyn Layer> {
        BUILTIN
            .iter()
            .copied()
            .filter(|l| self.holds(l.when()))
            .chain(self.steps.iter().map(|l| *l as &dyn Layer))
            .collect()
    }

    /// The names for which a source field is written as `src_<name>`: the
    /// columns of the skeleton layer (every one, whether written or not)
    /// and of every other layer of the plan that carries the source's
    /// fields (the kept `areas`, a registered step's, e.g. `labels`) — in
    /// every layer alike, so that a field keeps one name in the output.
    pub fn reserved_names(&self) -> Vec<&'static str> {
        super::SKELETONS
            .column_names()
            .chain(self.columns_carrying(crate::layer::Fields::Input))
            .collect()
    }

    /// The names for which a field of `input.neighbours` is renamed: the
    /// columns of the layers that carry the units' fields (the grown
    /// coverage's `received`, `src_fid`, …).
    pub fn reserved_neighbour_names(&self) -> Vec<&'static str> {
        self.columns_carrying(crate::layer::Fields::Neighbours)
            .collect()
    }

    fn columns_carrying(
        &self,
        fields: crate::layer::Fields,
    ) -> impl Iterator<Item = &'static str> + '_ {
        self.layers()
            .into_iter()
            .filter(move |l| l.fields() == Some(fields))
            .flat_map(|l| l.columns().into_iter().map(|c| c.name))
    }

    /// The name `layer` is written under (the skeleton layer's is
    /// configurable).
    pub fn name_of<'a>(&'a self, layer: &dyn Layer) -> &'a str {
        if layer.name() == super::SKELETONS.name {
            &self.skeleton_layer
        } else {
            layer.name()
        }
    }

    /// Whether `layer` is the skeleton layer and its lines carry M values.
    pub fn measured(&self, layer: &dyn Layer) -> bool {
        layer.name() == super::SKELETONS.name && self.holds(When::Measures)
    }

    /// The columns of `layer` this output has, with their index among the
    /// layer's columns.
    pub fn columns(&self, layer: &dyn Layer) -> Vec<(usize, &'static str, ColumnType)> {
        layer
            .columns()
            .into_iter()
            .enumerate()
            .filter(|(_, c)| self.holds(c.when))
            .map(|(i, c)| (i, c.name, c.ty))
            .collect()
    }

    /// The names of every layer the tool may write besides the skeleton
    /// layer (which must be none of them), the run record's included.
    pub fn tool_layer_names(&self) -> Vec<&'static str> {
        BUILTIN
            .iter()
            .map(|l| l.name())
            .filter(|n| *n != super::SKELETONS.name)
            .chain(self.steps.iter().map(|l| l.name))
            .collect()
    }
}

/// The names a source's fields are written under beside the tool's columns
/// `reserved` (see [`Plan::reserved_names`]): a field named as one of them
/// gets a `src_` prefix, repeated until the name is neither reserved, nor
/// another field's, nor given already (`src_fid` beside a source field
/// `src_src_fid`, as in a previous run's output, becomes `src_src_src_fid`);
/// the others keep their names. Names compare without case, as SQLite's
/// columns do. The command line's writer, the Python package and QGIS all
/// name the fields by this rule.
pub fn source_names<S: AsRef<str>>(names: &[S], reserved: &[&str]) -> Vec<String> {
    let mut taken: Vec<String> = reserved
        .iter()
        .map(|n| n.to_ascii_lowercase())
        .chain(names.iter().map(|n| n.as_ref().to_ascii_lowercase()))
        .collect();
    names
        .iter()
        .map(|n| {
            let mut name = n.as_ref().to_string();
            if reserved.iter().any(|r| r.eq_ignore_ascii_case(&name)) {
                name = format!("src_{name}");
                while taken.contains(&name.to_ascii_lowercase()) {
                    name = format!("src_{name}");
                }
                taken.push(name.to_ascii_lowercase());
            }
            name
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::source_names;

    #[test]
    fn fields_named_as_a_column_are_prefixed_until_free() {
        let names = ["kind", "SRC_KIND", "name", "src_fid", "src_src_fid"];
        assert_eq!(
            source_names(&names, &["src_fid", "kind"]),
            [
                "src_src_kind",
                "SRC_KIND",
                "name",
                "src_src_src_fid",
                "src_src_fid"
            ]
        );
    }
}
