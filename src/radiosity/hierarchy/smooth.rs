//! The smooth display of a hierarchy: radiance gathered at the leaves'
//! vertices over their links and their ancestors'.

use super::{Hierarchy, NONE, VERTEX_RAYS, is_cluster};
use crate::accel::Geometry;
use crate::math::Rgb;
use crate::radiosity::VertexField;
use crate::radiosity::form_factor::{open_at, point_to_polygon, point_visibility};
use crate::radiosity::reconstruct::{VertexKey, vertex_key};
use glam::{Vec2, Vec3A};
use rayon::prelude::*;
use std::collections::HashMap;

impl Hierarchy {
    /// Computes the leaves' vertex radiance for the smooth display: at each
    /// vertex, E + ρ Σ B_q F(x → q) V over the links of the leaf and of its
    /// ancestors, F the point-to-polygon form factor at the vertex and V the
    /// link's share of visible shadow rays. A link's transfer is constant
    /// over its gatherer (the constant basis) but its kernel is not, so a
    /// coarse link that lights a whole wall still shades it smoothly where
    /// pushing its constant down would leave steps the size of the link;
    /// Cornell box, ε 1e-5: masked RMSE 0.00450 with per-leaf gradients.
    pub fn smooth(&mut self, geometry: &Geometry) {
        let mut parent = vec![NONE; self.nodes.len()];
        for (k, n) in self.nodes.iter().enumerate() {
            if n.children != NONE {
                parent[n.children as usize..n.children as usize + 4].fill(k as u32);
            }
        }
        let leaves: Vec<u32> = (0..self.nodes.len() as u32)
            .filter(|&k| self.nodes[k as usize].children == NONE)
            .collect();
        // One gather per vertex, through the most exposed, then smallest,
        // leaf that has it (its links are the finest there); the leaves
        // sharing it read it. A vertex gathered from inside a hidden leaf
        // (the ceiling above the light) darkened its open neighbours.
        self.measure_exposure(geometry);
        let preference = |k: u32| {
            let n = &self.nodes[k as usize];
            (n.exposure, -n.element.area)
        };
        let mut index: HashMap<VertexKey, usize> = HashMap::new();
        let mut vertices: Vec<(u32, Vec3A)> = Vec::new();
        for &k in &leaves {
            let e = &self.nodes[k as usize].element;
            for v in e.vertices {
                let slot = *index.entry(vertex_key(v, e)).or_insert_with(|| {
                    vertices.push((k, v));
                    vertices.len() - 1
                });
                if preference(k) > preference(vertices[slot].0) {
                    vertices[slot].0 = k;
                }
            }
        }
        let values: Vec<(Rgb, bool)> = vertices
            .par_iter()
            .map(|&(k, v)| {
                let e = &self.nodes[k as usize].element;
                let centroid = (e.vertices[0] + e.vertices[1] + e.vertices[2]) / 3.0;
                // Just inside: on a neighbour's edge the integral is singular.
                let x = v + 0.05 * (centroid - v);
                let mut irradiance = Rgb::ZERO;
                let (mut a, mut root) = (k, k);
                while a != NONE {
                    for link in &self.nodes[a as usize].links {
                        if is_cluster(link.source) {
                            let f = self.point_to_cluster(x, e.normal, link.source);
                            irradiance += (link.visibility * f) * self.sent_by(link.source);
                            continue;
                        }
                        let q = &self.nodes[link.source as usize];
                        // One-sided sources send nothing behind their plane.
                        if q.element.normal.dot(x - q.element.vertices[0]) <= 0.0 {
                            continue;
                        }
                        let f = point_to_polygon(x, e.normal, &q.element.vertices);
                        // Through a shadow boundary the link's mean is not
                        // the vertex's: a leaf half behind the light gave
                        // the ceiling a dark ring around it.
                        let visibility = if self.uncertain(a, link) {
                            point_visibility(geometry, x, e.normal, &q.element, VERTEX_RAYS)
                        } else {
                            link.visibility
                        };
                        irradiance += (visibility * f) * self.sent_by(link.source);
                    }
                    root = a;
                    a = parent[a as usize];
                }
                irradiance += self.cluster_irradiance(root, x, e.normal);
                let x_error = crate::math::gamma(7) * x.abs();
                let (open, _) = open_at(
                    geometry,
                    &self.two_sided,
                    x,
                    x_error,
                    e.normal,
                    Vec2::splat(0.5),
                );
                (
                    (e.emission + e.reflectance * irradiance).max(Rgb::ZERO),
                    open,
                )
            })
            .collect();
        let mut per_node = vec![[Rgb::ZERO; 3]; self.nodes.len()];
        for &k in &leaves {
            let e = &self.nodes[k as usize].element;
            let corners = e.vertices.map(|v| values[index[&vertex_key(v, e)]]);
            // A leaf partly hidden (the ceiling's edge around the light, the
            // floor's around a block) shows its open part: hidden corners,
            // dark, take the open corners' mean instead of shading it
            // towards black. Cornell box, masked RMSE without -> with: ε 1e-4
            // 0.00236 -> 0.00233, 7e-5 0.00222 -> 0.00217 (large leaves);
            // 1e-5 0.00130 -> 0.00131 (small ones, where it hardly matters).
            let (sum, count) = corners
                .iter()
                .filter(|c| c.1)
                .fold((Rgb::ZERO, 0.0), |(s, n), c| (s + c.0, n + 1.0));
            per_node[k as usize] = corners.map(|(value, is_open)| {
                if is_open || count == 0.0 {
                    value
                } else {
                    sum / count
                }
            });
        }
        let elements = leaves
            .iter()
            .map(|&k| (k as usize, &self.nodes[k as usize].element));
        self.vertex_radiance = VertexField::new(elements, per_node);
    }
}
