//! What the display and the tests read from a hierarchy: the leaf under a
//! point, the leaves, and the share of the hemisphere each gathers from.

use super::{Hierarchy, NONE};
use crate::math::Rgb;
use crate::radiosity::mesh::child_at;
use crate::radiosity::{Element, VertexField};

impl Hierarchy {
    /// The leaf of scene triangle `triangle`, or of its back, at the
    /// triangle's barycentrics (b1, b2): its node, radiance, element and
    /// depth in the patch's tree.
    pub fn leaf_at(
        &self,
        triangle: usize,
        back: bool,
        b1: f32,
        b2: f32,
    ) -> Option<(usize, Rgb, &Element, u8)> {
        let roots = if back { &self.back_roots } else { &self.roots };
        let mut k = *roots.get(triangle)?;
        if k == NONE {
            return None;
        }
        // A back's root lists the triangle's corners 0, 2, 1.
        let mut b = if back {
            [1.0 - b1 - b2, b2, b1]
        } else {
            [1.0 - b1 - b2, b1, b2]
        };
        while self.nodes[k as usize].children != NONE {
            let child = child_at(&mut b);
            k = self.nodes[k as usize].children + child as u32;
        }
        let n = &self.nodes[k as usize];
        Some((k as usize, n.radiance, &n.element, n.depth))
    }

    /// The smooth display's radiance over the leaves, once
    /// [`Hierarchy::smooth`] ran (by node).
    pub fn vertex_field(&self) -> &VertexField {
        &self.vertex_radiance
    }

    /// Per leaf, the sum of the form factors over its links and its
    /// ancestors': the share of its hemisphere it gathers from (1 in a
    /// closed scene, if no light is counted twice or missed).
    pub fn gathered_share(&self) -> Vec<f32> {
        let mut out = Vec::new();
        let mut stack: Vec<(u32, f32)> = self
            .roots
            .iter()
            .chain(&self.back_roots)
            .filter(|&&r| r != NONE)
            .map(|&r| {
                let e = &self.nodes[r as usize].element;
                let centroid = (e.vertices[0] + e.vertices[1] + e.vertices[2]) / 3.0;
                (r, self.cluster_form_factor(r, centroid, e.normal))
            })
            .collect();
        while let Some((k, above)) = stack.pop() {
            let n = &self.nodes[k as usize];
            let share = above + n.links.iter().map(|l| l.f).sum::<f32>();
            if n.children == NONE {
                out.push(share);
            } else {
                for c in n.children..n.children + 4 {
                    stack.push((c, share));
                }
            }
        }
        out
    }

    /// The leaves with their node numbers (as [`Hierarchy::leaf_at`] gives
    /// them), elements and radiance, and how many node numbers there are.
    pub fn numbered_leaves(&self) -> (usize, impl Iterator<Item = (usize, &Element, Rgb)>) {
        let leaves = self
            .nodes
            .iter()
            .enumerate()
            .filter(|(_, n)| n.children == NONE)
            .map(|(k, n)| (k, &n.element, n.radiance));
        (self.nodes.len(), leaves)
    }

    /// The leaves' elements and radiance (for tests and displays).
    pub fn leaves(&self) -> impl Iterator<Item = (&Element, Rgb)> {
        self.nodes
            .iter()
            .filter(|n| n.children == NONE)
            .map(|n| (&n.element, n.radiance))
    }
}
