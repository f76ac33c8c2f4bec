//! `[[rust_load]]`: the name and the nodes of a load field whose function
//! the program binds in Rust ([`crate::Model::bind_load`]).

use super::{Ctx, Res};
use crate::raw::{RawRustLoad, S};
use crate::types::{BeamSpec, RustLoad};

impl Ctx<'_> {
    /// The `[[rust_load]]` entries, each with a unique name and at least
    /// one node label; their functions are unbound (`field: None`).
    pub(super) fn rust_loads(
        &self,
        raw: &[S<RawRustLoad>],
        beams: &[BeamSpec],
    ) -> Res<Vec<RustLoad>> {
        let mut out: Vec<RustLoad> = Vec::new();
        for (i, entry) in raw.iter().enumerate() {
            let tk = format!("rust_load[{i}]");
            let hs = entry.span();
            let l = entry.get_ref();
            let name_s = self.entity_name(&l.name, &tk, &hs, "rust_load")?;
            let name = name_s.get_ref().clone();
            if let Some(o) = out.iter().position(|r| r.name == name) {
                return Err(self.at(
                    format!("{tk}.name"),
                    name_s,
                    format!("duplicate rust_load name \"{name}\" (rust_load[{o}] has it too); names must be unique"),
                ));
            }
            let key = format!("{tk}.nodes");
            let nodes_s = self.need(
                &l.nodes,
                &key,
                &hs,
                "the loaded nodes' labels, in the order of the function's rows, e.g. nodes = [\"arm.end\"]",
            )?;
            if nodes_s.get_ref().is_empty() {
                return Err(self.at(key, nodes_s, "the list is empty; give node labels"));
            }
            let nodes = nodes_s
                .get_ref()
                .iter()
                .map(|label| self.node(label, &key, beams))
                .collect::<Res<Vec<_>>>()?;
            out.push(RustLoad {
                name,
                nodes,
                field: None,
            });
        }
        Ok(out)
    }
}
