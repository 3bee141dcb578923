//! Refinement: a wave of (gatherer, source) pairs split level by level
//! until the oracle accepts each link, the subdivisions in order and the
//! oracle's verdicts and facing tests in parallel.

use super::{Hierarchy, SOURCE_SPLIT_RATIO};
use crate::radiosity::form_factor::faces;
use rayon::prelude::*;

impl Hierarchy {
    /// Refines the pairs (gatherer, source, forced) down to the links the
    /// oracle accepts, which go to `pending` with their bound; level by
    /// level, so that the oracle's contour integrals of a level run in
    /// parallel (serial, they were 20% of the solve at ε 7e-5).
    pub(super) fn refine(
        &mut self,
        mut wave: Vec<(u32, u32, bool)>,
        pending: &mut Vec<(u32, u32, f32)>,
    ) {
        while !wave.is_empty() {
            // The oracle's verdicts (a forced pair is split whatever it
            // says) and the children's facing tests in parallel; only the
            // subdivisions, which grow the tree, in order.
            let verdicts: Vec<(f32, Option<bool>)> = wave
                .par_iter()
                .map(|&(p, q, forced)| {
                    let f_max = if forced { f32::NAN } else { self.f_max(p, q) };
                    (f_max, self.split_end(p, q, forced, f_max))
                })
                .collect();
            let mut candidates = Vec::new();
            for (&(p, q, forced), (f_max, split_q)) in wave.iter().zip(verdicts) {
                let children = split_q.and_then(|split_q| {
                    let first = self.subdivide(if split_q { q } else { p })?;
                    Some((first, split_q))
                });
                let Some((first, split_q)) = children else {
                    // A forced pair that could not be split (the node budget).
                    let f_max = if forced { self.f_max(p, q) } else { f_max };
                    pending.push((p, q, f_max));
                    continue;
                };
                candidates
                    .extend((first..first + 4).map(|c| if split_q { (p, c) } else { (c, q) }));
            }
            let nodes = &self.nodes;
            wave = candidates
                .into_par_iter()
                .filter(|&(gatherer, source)| {
                    faces(
                        &nodes[gatherer as usize].element,
                        &nodes[source as usize].element,
                    )
                })
                .map(|(gatherer, source)| (gatherer, source, false))
                .collect();
        }
    }

    /// Which end of a pair the oracle splits: Some(true) the source,
    /// Some(false) the gatherer, None neither (the link is fine enough, or
    /// neither end is divisible). A forced pair is split regardless.
    fn split_end(&self, p: u32, q: u32, forced: bool, f_max: f32) -> Option<bool> {
        let coarse = forced || self.transfer(p, q, f_max) > self.settings.epsilon;
        let (can_p, can_q) = (self.divisible(p), self.divisible(q));
        if !coarse || !(can_p || can_q) {
            return None;
        }
        let (ap, aq) = (
            self.nodes[p as usize].element.area,
            self.nodes[q as usize].element.area,
        );
        Some(can_q && (aq > SOURCE_SPLIT_RATIO * ap || !can_p))
    }
}
