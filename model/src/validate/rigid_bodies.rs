//! The `[[rigid_body]]` tables: rigid bodies and point masses on nodes.

use super::{Ctx, Res};
use crate::raw::{v3, NumOrRow, RawRigidBody, S};
use crate::types::*;

impl Ctx<'_> {
    pub(super) fn rigid_bodies(
        &self,
        raw: &[S<RawRigidBody>],
        beams: &[BeamSpec],
    ) -> Res<Vec<RigidBodySpec>> {
        let mut out: Vec<RigidBodySpec> = Vec::new();
        for (i, entry) in raw.iter().enumerate() {
            let tk = format!("rigid_body[{i}]");
            let k = |f: &str| format!("{tk}.{f}");
            let hs = entry.span();
            let b = entry.get_ref();
            let name = match &b.name {
                Some(n) => {
                    let name = n.get_ref().trim().to_string();
                    if name.is_empty() {
                        return Err(self.at(k("name"), n, "must not be empty"));
                    }
                    if out.iter().any(|o| o.name == name) {
                        return Err(self.at(
                            k("name"),
                            n,
                            format!("a rigid body named \"{name}\" comes earlier in the file"),
                        ));
                    }
                    name
                }
                None => i.to_string(),
            };
            let node_s = self.need(
                &b.node,
                &k("node"),
                &hs,
                "the carrying node's label, e.g. node = \"crank.end\"",
            )?;
            let node = self.node(node_s, &k("node"), beams)?;
            let mass_s = self.need(
                &b.mass,
                &k("mass"),
                &hs,
                "the body's mass, e.g. mass = 2.0 (a point mass: give no inertia and offset)",
            )?;
            let mass = self.non_negative(mass_s, &k("mass"))?;
            let inertia = match &b.inertia {
                None => [[0.0; 3]; 3],
                Some(j) => self.inertia(j, &k("inertia"))?,
            };
            let offset = b.offset.as_ref().map_or([0.0; 3], |o| v3(o.get_ref()));
            out.push(RigidBodySpec {
                name,
                node,
                mass,
                inertia,
                offset,
            });
        }
        Ok(out)
    }

    /// Three principal values (a diagonal tensor) or a 3×3 matrix, each
    /// entry checked here for form; physics (symmetry, positive principal
    /// values, the triangle inequality) is the builder's check.
    fn inertia(&self, j: &S<Vec<NumOrRow>>, key: &str) -> Res<[[f64; 3]; 3]> {
        let entries = j.get_ref();
        let nums: Vec<f64> = entries
            .iter()
            .filter_map(|e| match e {
                NumOrRow::Num(n) => Some(n.0),
                NumOrRow::Row(_) => None,
            })
            .collect();
        let rows: Vec<[f64; 3]> = entries
            .iter()
            .filter_map(|e| match e {
                NumOrRow::Row(r) => Some(r.map(|n| n.0)),
                NumOrRow::Num(_) => None,
            })
            .collect();
        match (nums.len(), rows.len()) {
            (3, 0) => {
                if let Some(v) = nums.iter().find(|v| **v < 0.0) {
                    return Err(self.at(
                        key,
                        j,
                        format!("principal moments of inertia must be >= 0, found {v:?}"),
                    ));
                }
                Ok([
                    [nums[0], 0.0, 0.0],
                    [0.0, nums[1], 0.0],
                    [0.0, 0.0, nums[2]],
                ])
            }
            (0, 3) => Ok([rows[0], rows[1], rows[2]]),
            _ => Err(self.at(
                key,
                j,
                "expected 3 principal values, inertia = [J1, J2, J3], or a 3×3 matrix in the \
                 node's initial frame, inertia = [[Jxx, Jxy, Jxz], [Jxy, Jyy, Jyz], [Jxz, Jyz, \
                 Jzz]]",
            )),
        }
    }
}
