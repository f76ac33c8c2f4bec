//! Node labels: `<beam>.start`, `<beam>.end`, `<beam>.<k>`.

use super::types::{BeamSpec, Model, NodeRef};

/// The forms a node label can take, for error messages.
pub(crate) const LABEL_FORMS: &str =
    "node labels are `<beam>.start`, `<beam>.end` or `<beam>.<k>` (k = 0-based node index along the beam)";

fn beam_list(beams: &[BeamSpec]) -> String {
    if beams.is_empty() {
        "the file defines no [[beam]]".to_string()
    } else {
        let names: Vec<String> = beams.iter().map(|b| format!("\"{}\"", b.name)).collect();
        format!("beams are {}", names.join(", "))
    }
}

/// Resolves `label` against `beams`; the error says what is wrong with it and
/// which labels would be valid.
pub(crate) fn resolve_label(beams: &[BeamSpec], label: &str) -> Result<NodeRef, String> {
    let Some((beam_name, node)) = label.split_once('.') else {
        let hint = if beams.iter().any(|b| b.name == label) {
            format!(" (e.g. \"{label}.start\")")
        } else {
            String::new()
        };
        return Err(format!(
            "\"{label}\" is not a node label; {LABEL_FORMS}{hint}"
        ));
    };
    let Some(beam) = beams.iter().position(|b| b.name == beam_name) else {
        return Err(format!(
            "unknown node label \"{label}\": no beam named \"{beam_name}\"; {}; {LABEL_FORMS}",
            beam_list(beams)
        ));
    };
    let spec = &beams[beam];
    let last = spec.node_count() - 1;
    let index = match node {
        "start" => 0,
        "end" => last,
        k => match k
            .bytes()
            .all(|b| b.is_ascii_digit())
            .then(|| k.parse::<usize>().ok())
            .flatten()
        {
            Some(k) if k <= last => k,
            Some(k) => {
                return Err(format!(
                    "node index {k} of \"{label}\" is out of range: beam \"{beam_name}\" has {} \
                     nodes ({} elements with {} nodes each), so k must be in 0..={last} \
                     (\"{beam_name}.end\" is node {last})",
                    last + 1,
                    spec.elements,
                    spec.nodes_per_element
                ))
            }
            None => {
                return Err(format!(
                    "unknown node label \"{label}\": after \"{beam_name}.\" expected `start`, \
                     `end` or a node index in 0..={last}; {LABEL_FORMS}"
                ))
            }
        },
    };
    Ok(NodeRef { beam, node: index })
}

impl Model {
    /// The node named by `label` (`<beam>.start`, `<beam>.end`, `<beam>.<k>`);
    /// the error says why the label is invalid.
    pub fn find_node(&self, label: &str) -> Result<NodeRef, String> {
        resolve_label(&self.beams, label)
    }

    /// The label of `node` as a user would write it: `<beam>.start`,
    /// `<beam>.end`, or `<beam>.<k>` for an inner node.
    ///
    /// # Panics
    /// If `node.beam` is not a beam of the model.
    pub fn node_label(&self, node: NodeRef) -> String {
        let beam = &self.beams[node.beam];
        match node.node {
            0 => format!("{}.start", beam.name),
            k if k + 1 == beam.node_count() => format!("{}.end", beam.name),
            k => format!("{}.{k}", beam.name),
        }
    }
}
