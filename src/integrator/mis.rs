//! Multiple importance sampling weights (Veach & Guibas 1995).

/// How light sampling and BSDF sampling are combined when both can produce
/// the same path.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum MisHeuristic {
    /// No combination: with next-event estimation on, light sampling alone
    /// accounts for direct light and BSDF-sampled hits on lights are ignored.
    None,
    /// w_a = p_a / (p_a + p_b).
    Balance,
    /// w_a = p_a^2 / (p_a^2 + p_b^2), Veach's recommended default (beta = 2).
    #[default]
    Power,
}

impl MisHeuristic {
    /// Weight of a sample drawn with density `pdf_a` that strategy `b` would
    /// have drawn with density `pdf_b` (one sample from each strategy).
    #[inline]
    pub fn weight(self, pdf_a: f32, pdf_b: f32) -> f32 {
        match self {
            MisHeuristic::None => 1.0,
            MisHeuristic::Balance => pdf_a / (pdf_a + pdf_b),
            MisHeuristic::Power => {
                let (a, b) = (pdf_a * pdf_a, pdf_b * pdf_b);
                // a is finite and positive here; b may overflow for very
                // peaked lobes, in which case the weight correctly tends to 0.
                if b.is_infinite() { 0.0 } else { a / (a + b) }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_of_both_strategies_sum_to_one() {
        for h in [MisHeuristic::Balance, MisHeuristic::Power] {
            for (a, b) in [(1.0, 1.0), (0.3, 7.0), (1e-6, 1e3), (5.0, 0.0)] {
                let s = h.weight(a, b) + h.weight(b, a);
                assert!((s - 1.0).abs() < 1e-6, "{h:?} {a} {b}: {s}");
            }
        }
    }
}
